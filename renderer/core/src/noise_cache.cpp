// Noise cache files and the load-or-generate policy (see noise_cache.hpp).
// The encoder and decoder are pure (bytes in, bytes out): the fuzz build
// compiles this file alone for fuzz_noise_cache.
#include "sky/render/noise_cache.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

namespace sky::render {

namespace {

constexpr std::array<std::uint8_t, 8> kMagic = {'S', 'K', 'Y', 'N', 'O', 'I', 'S', 'E'};
// Bumped when the file layout changes.
constexpr std::uint32_t kFormatVersion = 2;
// Largest cube edge a cache file may claim: 512^3 = 128 MiB, far above the
// renderer's textures, so a damaged length cannot ask for gigabytes.
constexpr std::uint32_t kMaxNoiseSize = 512;
constexpr std::uint32_t kMaxChannels = 4;

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void putU64(std::vector<std::uint8_t>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

// Reads little-endian fields front to back; any read past the end fails.
class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  bool u32(std::uint32_t& v) { return take(4, [&](const std::uint8_t* p) { v = std::uint32_t(le(p, 4)); }); }
  bool u64(std::uint64_t& v) { return take(8, [&](const std::uint8_t* p) { v = le(p, 8); }); }
  bool bytes(std::size_t n, std::span<const std::uint8_t>& out) {
    return take(n, [&](const std::uint8_t* p) { out = std::span(p, n); });
  }
  std::size_t left() const { return bytes_.size() - at_; }

 private:
  static std::uint64_t le(const std::uint8_t* p, int n) {
    std::uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
    return v;
  }
  template <class F>
  bool take(std::size_t n, F&& f) {
    if (left() < n) return false;
    f(bytes_.data() + at_);
    at_ += n;
    return true;
  }
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

Result<std::vector<std::uint8_t>> readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, path.string() + ": cannot open");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return fail(ErrorCode::Io, path.string() + ": read failed");
  return bytes;
}

Result<void> writeFileAtomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  if (ec) return fail(ErrorCode::Io, path.parent_path().string() + ": cannot create: " + ec.message());
  // Unique per process: two renderers starting together each write their
  // own temporary file; the renames replace one identical file by another.
  const std::filesystem::path tmp = path.string() + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      return fail(ErrorCode::Io, tmp.string() + ": write failed");
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return fail(ErrorCode::Io, path.string() + ": cannot rename into place: " + ec.message());
  }
  return {};
}

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes) {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64-bit offset basis
  for (std::uint8_t b : bytes) {
    h ^= b;
    h *= 1099511628211ull;  // FNV 64-bit prime
  }
  return h;
}

std::string noiseFileName(const NoiseKey& k) {
  return k.kind + "-g" + std::to_string(k.generatorVersion) + "-s" + std::to_string(k.seed) + "-n" +
         std::to_string(k.size) + "-c" + std::to_string(k.channels) + "-" + hex64(k.fingerprint) + ".noise";
}

std::vector<std::uint8_t> encodeNoiseFile(const NoiseKey& k, std::span<const std::uint8_t> texels) {
  std::vector<std::uint8_t> out(kMagic.begin(), kMagic.end());
  putU32(out, kFormatVersion);
  putU32(out, k.generatorVersion);
  putU32(out, k.seed);
  putU32(out, k.size);
  putU32(out, k.channels);
  putU64(out, k.fingerprint);
  putU64(out, texels.size());
  putU64(out, fnv1a64(texels));
  out.push_back(static_cast<std::uint8_t>(std::min<std::size_t>(k.kind.size(), 255)));
  out.insert(out.end(), k.kind.begin(), k.kind.begin() + std::ptrdiff_t(std::min<std::size_t>(k.kind.size(), 255)));
  out.insert(out.end(), texels.begin(), texels.end());
  return out;
}

Result<std::vector<std::uint8_t>> decodeNoiseFile(std::span<const std::uint8_t> bytes, const NoiseKey& want) {
  Reader r(bytes);
  std::span<const std::uint8_t> magic;
  if (!r.bytes(kMagic.size(), magic) || !std::equal(magic.begin(), magic.end(), kMagic.begin()))
    return fail(ErrorCode::Malformed, "not a Skyshell noise file (bad magic)");
  std::uint32_t format = 0, version = 0, seed = 0, size = 0, channels = 0;
  std::uint64_t fingerprint = 0, length = 0, checksum = 0;
  if (!r.u32(format)) return fail(ErrorCode::Malformed, "truncated header");
  if (format != kFormatVersion)
    return fail(ErrorCode::Malformed, "format version " + std::to_string(format) + ", expected " +
                                          std::to_string(kFormatVersion));
  if (!r.u32(version) || !r.u32(seed) || !r.u32(size) || !r.u32(channels) || !r.u64(fingerprint) || !r.u64(length) ||
      !r.u64(checksum))
    return fail(ErrorCode::Malformed, "truncated header");
  std::span<const std::uint8_t> kindLength, kind;
  if (!r.bytes(1, kindLength) || !r.bytes(kindLength[0], kind)) return fail(ErrorCode::Malformed, "truncated header");
  if (std::string(kind.begin(), kind.end()) != want.kind) return fail(ErrorCode::Malformed, "noise kind differs");
  if (version != want.generatorVersion)
    return fail(ErrorCode::Malformed, "generator version " + std::to_string(version) + ", expected " +
                                          std::to_string(want.generatorVersion));
  if (seed != want.seed) return fail(ErrorCode::Malformed, "seed " + std::to_string(seed) + ", expected " +
                                                               std::to_string(want.seed));
  if (size != want.size || size == 0 || size > kMaxNoiseSize)
    return fail(ErrorCode::Malformed, "size " + std::to_string(size) + ", expected " + std::to_string(want.size));
  if (channels != want.channels || channels == 0 || channels > kMaxChannels)
    return fail(ErrorCode::Malformed, "channels " + std::to_string(channels) + ", expected " +
                                          std::to_string(want.channels));
  if (fingerprint != want.fingerprint) return fail(ErrorCode::Malformed, "generator fingerprint differs");
  const std::uint64_t texels = std::uint64_t(size) * size * size * channels;
  if (length != texels)
    return fail(ErrorCode::Malformed, "payload length " + std::to_string(length) + " for a " + std::to_string(size) +
                                          "^3 volume of " + std::to_string(channels) + " channel(s)");
  if (r.left() != texels)
    return fail(ErrorCode::Malformed, "payload is " + std::to_string(r.left()) + " bytes, expected " +
                                          std::to_string(texels) + " (truncated or padded file)");
  std::span<const std::uint8_t> payload;
  r.bytes(std::size_t(texels), payload);
  if (fnv1a64(payload) != checksum) return fail(ErrorCode::Malformed, "checksum mismatch (damaged file)");
  return std::vector<std::uint8_t>(payload.begin(), payload.end());
}

CachedNoise loadOrGenerateNoise(const std::filesystem::path& directory, const NoiseKey& key,
                                const std::function<std::vector<std::uint8_t>()>& generate) {
  CachedNoise out;
  if (directory.empty()) {
    out.texels = generate();
    return out;
  }
  out.path = directory / noiseFileName(key);
  std::error_code ec;
  if (std::filesystem::exists(out.path, ec)) {
    auto bytes = readFile(out.path);
    auto texels = bytes ? decodeNoiseFile(*bytes, key) : Result<std::vector<std::uint8_t>>(tl::unexpected(bytes.error()));
    if (texels) {
      out.texels = std::move(*texels);
      out.source = NoiseSource::Loaded;
      return out;
    }
    out.source = NoiseSource::Regenerated;
    out.note = out.path.string() + ": " + texels.error().detail;
  }
  out.texels = generate();
  if (auto ok = writeFileAtomically(out.path, encodeNoiseFile(key, out.texels)); !ok)
    out.note += (out.note.empty() ? "" : "; ") + std::string("not cached: ") + ok.error().detail;
  return out;
}

std::filesystem::path defaultCacheDirectory() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/')
    return std::filesystem::path(xdg) / "skyshell";
  if (const char* home = std::getenv("HOME"); home != nullptr && *home == '/')
    return std::filesystem::path(home) / ".cache" / "skyshell";
  return {};
}

}  // namespace sky::render
