// zlib's inflate behind a size bound (inflate.hpp).
#include "inflate.hpp"

#include <algorithm>
#include <climits>

#include <zlib.h>

namespace sky::flight::detail {

namespace {

// zlib window bits (zlib.h, inflateInit2): 15 = the 32 KiB window every
// deflate stream may use; +16 = expect a gzip wrapper; negative = raw.
constexpr int kWindowBits = 15;
constexpr int kGzipWrapperBits = 16;
// Output grows in steps of this much (then at most to maxBytes).
constexpr std::size_t kOutStep = std::size_t{1} << 20;

}  // namespace

Result<std::string> inflateBounded(std::string_view compressed, Wrapper wrapper, std::size_t maxBytes,
                                   const std::string& what) {
  z_stream z{};
  const int bits = wrapper == Wrapper::Gzip ? kWindowBits + kGzipWrapperBits : -kWindowBits;
  if (inflateInit2(&z, bits) != Z_OK) return fail(ErrorCode::Io, what + ": cannot start zlib (out of memory)");
  std::string out;
  std::size_t in = 0;
  int rc = Z_OK;
  while (true) {
    if (z.avail_in == 0 && in < compressed.size()) {
      const std::size_t n = std::min<std::size_t>(compressed.size() - in, UINT_MAX);
      z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + in));
      z.avail_in = static_cast<uInt>(n);
      in += n;
    }
    if (out.size() == maxBytes) {
      // Full: one byte more would be too many; ask zlib whether any come.
      unsigned char probe = 0;
      z.next_out = &probe;
      z.avail_out = 1;
      rc = inflate(&z, Z_NO_FLUSH);
      if (z.avail_out == 0) {
        inflateEnd(&z);
        return fail(ErrorCode::TooLarge,
                    what + ": decompresses to more than " + std::to_string(maxBytes) + " bytes, the most read");
      }
    } else {
      const std::size_t old = out.size();
      const std::size_t grow = std::min({kOutStep, maxBytes - old, std::size_t{UINT_MAX}});
      out.resize(old + grow);
      z.next_out = reinterpret_cast<Bytef*>(out.data() + old);
      z.avail_out = static_cast<uInt>(grow);
      rc = inflate(&z, Z_NO_FLUSH);
      out.resize(old + grow - z.avail_out);
    }
    if (rc == Z_STREAM_END) {
      // gzip may hold several members (RFC 1952 §2.2): go on while input is left.
      if (wrapper == Wrapper::Gzip && (z.avail_in > 0 || in < compressed.size())) {
        if (inflateReset(&z) != Z_OK) break;
        continue;
      }
      inflateEnd(&z);
      return out;
    }
    if (rc == Z_BUF_ERROR && z.avail_in == 0 && in == compressed.size()) break;  // input ended early
    if (rc != Z_OK && rc != Z_BUF_ERROR) break;
  }
  const std::string why = rc == Z_OK || rc == Z_BUF_ERROR ? "the compressed data end early"
                                                          : std::string("corrupt compressed data (zlib: ") +
                                                                (z.msg ? z.msg : "no detail") + ")";
  inflateEnd(&z);
  return fail(ErrorCode::Malformed, what + ": " + why);
}

}  // namespace sky::flight::detail
