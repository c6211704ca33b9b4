// Bounded decompression for the flight readers: gzip (readsb writes its
// trace files gzip-compressed under a .json name) and the raw deflate of zip
// entries (KMZ). Built on zlib; private to protocol/flight/src.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "sky/core/result.hpp"

namespace sky::flight::detail {

enum class Wrapper {
  Gzip,        // RFC 1952 member(s)
  RawDeflate,  // RFC 1951 stream, as a zip entry stores it
};

// The bytes compressed decompresses to, or an error: TooLarge when they
// would exceed maxBytes (a zip bomb stops there, having allocated at most
// maxBytes), Malformed when the stream is corrupt or ends early. what names
// the input in messages ("a.kmz: entry 'doc.kml'").
Result<std::string> inflateBounded(std::string_view compressed, Wrapper wrapper, std::size_t maxBytes,
                                   const std::string& what);

// Whether bytes start with the gzip magic (RFC 1952 §2.3.1: 1f 8b).
constexpr bool isGzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

}  // namespace sky::flight::detail
