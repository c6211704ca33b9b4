// Just enough of the zip format to take one entry out of a KMZ in memory
// (zip.hpp). Offsets and sizes are those of PKWARE's APPNOTE.TXT 6.3,
// sections 4.3.7 (local file header), 4.3.12 (central directory header) and
// 4.3.16 (end of central directory record). Every offset read from the
// archive is checked against its size before use.
#include "zip.hpp"

#include <cstdint>
#include <optional>

#include <zlib.h>

#include "inflate.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::flight::detail {

namespace {

constexpr std::uint32_t kLocalSignature = 0x04034b50;
constexpr std::uint32_t kCentralSignature = 0x02014b50;
constexpr std::uint32_t kEndSignature = 0x06054b50;
constexpr std::size_t kLocalHeaderBytes = 30;
constexpr std::size_t kCentralHeaderBytes = 46;
constexpr std::size_t kEndRecordBytes = 22;
constexpr std::size_t kMaxCommentBytes = 0xffff;  // the end record's comment length is 16 bits
constexpr std::uint32_t kZip64Marker = 0xffffffff;  // a size or offset that lives in a ZIP64 extra field
constexpr std::uint16_t kFlagEncrypted = 1;          // general purpose bit 0
constexpr std::uint16_t kMethodStored = 0, kMethodDeflate = 8;

std::uint32_t u16(std::string_view b, std::size_t at) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at])) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 1])) << 8;
}
std::uint32_t u32(std::string_view b, std::size_t at) { return u16(b, at) | u16(b, at + 2) << 16; }

char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

bool endsWithKml(std::string_view name) {
  if (name.size() < 4) return false;
  const std::string_view e = name.substr(name.size() - 4);
  return e[0] == '.' && lower(e[1]) == 'k' && lower(e[2]) == 'm' && lower(e[3]) == 'l';
}

bool isDocKml(std::string_view name) {
  constexpr std::string_view kDoc = "doc.kml";
  if (name.size() != kDoc.size()) return false;
  for (std::size_t i = 0; i < name.size(); ++i)
    if (lower(name[i]) != kDoc[i]) return false;
  return true;
}

struct Entry {
  std::string_view name;
  std::uint16_t flags = 0, method = 0;
  std::uint32_t crc = 0, compressed = 0, uncompressed = 0, localOffset = 0;
};

}  // namespace

Result<ZipText> readKmlFromZip(std::string_view zip, const std::string& src, std::size_t maxEntries,
                               std::size_t maxBytes) {
  const auto bad = [&](const std::string& why) { return fail(ErrorCode::Malformed, src + ": zip: " + why); };
  if (zip.size() < kEndRecordBytes || u32(zip, 0) != kLocalSignature) return bad("not a zip archive (no PK header)");
  // The end record is the last 22 bytes plus a comment of up to 64 KiB:
  // search backwards for its signature.
  std::size_t end = std::string_view::npos;
  const std::size_t lowest = zip.size() > kEndRecordBytes + kMaxCommentBytes ? zip.size() - kEndRecordBytes - kMaxCommentBytes : 0;
  for (std::size_t at = zip.size() - kEndRecordBytes + 1; at-- > lowest;)
    if (u32(zip, at) == kEndSignature && at + kEndRecordBytes + u16(zip, at + 20) == zip.size()) {
      end = at;
      break;
    }
  if (end == std::string_view::npos) return bad("no end of central directory record");
  const std::uint32_t count = u16(zip, end + 10), cdSize = u32(zip, end + 12), cdOffset = u32(zip, end + 16);
  if (count == 0xffff || cdSize == kZip64Marker || cdOffset == kZip64Marker)
    return fail(ErrorCode::Unsupported, src + ": zip: ZIP64 archives are not read");
  if (count > maxEntries)
    return fail(ErrorCode::TooLarge, src + ": zip: " + std::to_string(count) + " entries, at most " +
                                         std::to_string(maxEntries) + " read");
  if (static_cast<std::uint64_t>(cdOffset) + cdSize > end) return bad("central directory outside the archive");

  std::optional<Entry> chosen;
  std::size_t at = cdOffset;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (at + kCentralHeaderBytes > end || u32(zip, at) != kCentralSignature)
      return bad("central directory entry " + std::to_string(i) + " is not where the directory says");
    Entry e;
    e.flags = static_cast<std::uint16_t>(u16(zip, at + 8));
    e.method = static_cast<std::uint16_t>(u16(zip, at + 10));
    e.crc = u32(zip, at + 16);
    e.compressed = u32(zip, at + 20);
    e.uncompressed = u32(zip, at + 24);
    const std::size_t nameLen = u16(zip, at + 28), extraLen = u16(zip, at + 30), commentLen = u16(zip, at + 32);
    e.localOffset = u32(zip, at + 42);
    if (at + kCentralHeaderBytes + nameLen + extraLen + commentLen > end)
      return bad("central directory entry " + std::to_string(i) + " runs past the directory");
    e.name = zip.substr(at + kCentralHeaderBytes, nameLen);
    at += kCentralHeaderBytes + nameLen + extraLen + commentLen;
    if (isDocKml(e.name)) {
      chosen = e;
      break;
    }
    if (!chosen && endsWithKml(e.name)) chosen = e;
  }
  if (!chosen) return fail(ErrorCode::Malformed, src + ": zip: no .kml entry (a KMZ holds doc.kml)");
  const Entry& e = *chosen;
  const std::string what = src + ": zip entry '" + messageText(e.name, 80) + "'";
  if (e.flags & kFlagEncrypted) return fail(ErrorCode::Unsupported, what + ": encrypted");
  if (e.compressed == kZip64Marker || e.uncompressed == kZip64Marker || e.localOffset == kZip64Marker)
    return fail(ErrorCode::Unsupported, what + ": ZIP64 entries are not read");
  if (e.method != kMethodStored && e.method != kMethodDeflate)
    return fail(ErrorCode::Unsupported, what + ": compression method " + std::to_string(e.method) +
                                            " (only stored and deflate are read)");
  if (e.uncompressed > maxBytes)
    return fail(ErrorCode::TooLarge, what + ": " + std::to_string(e.uncompressed) + " bytes, at most " +
                                         std::to_string(maxBytes) + " read");
  const std::size_t local = e.localOffset;
  if (local + kLocalHeaderBytes > end || u32(zip, local) != kLocalSignature)
    return fail(ErrorCode::Malformed, what + ": no local header where the directory says");
  const std::size_t data = local + kLocalHeaderBytes + u16(zip, local + 26) + u16(zip, local + 28);
  if (data > end || e.compressed > end - data) return fail(ErrorCode::Malformed, what + ": data run past the archive");
  const std::string_view stored = zip.substr(data, e.compressed);
  ZipText out{std::string(e.name), {}};
  if (e.method == kMethodStored) {
    if (e.compressed != e.uncompressed) return fail(ErrorCode::Malformed, what + ": stored entry whose two sizes differ");
    out.text = std::string(stored);
  } else {
    auto text = inflateBounded(stored, Wrapper::RawDeflate, maxBytes, what);
    if (!text) return tl::unexpected(text.error());
    out.text = std::move(*text);
  }
  const uLong crc = crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(out.text.data()), out.text.size());
  if (crc != e.crc) return fail(ErrorCode::Malformed, what + ": CRC-32 does not match (damaged archive)");
  out.entryName = messageText(e.name, 80);
  return out;
}

}  // namespace sky::flight::detail
