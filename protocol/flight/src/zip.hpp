// The KML inside a KMZ: a zip archive read from memory (PKWARE APPNOTE.TXT
// 6.3: end of central directory, central directory, local headers), its
// entry inflated by zlib under a size bound. Private to protocol/flight/src.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "sky/core/result.hpp"

namespace sky::flight::detail {

struct ZipText {
  std::string entryName;  // as the archive names it, shown through messageText
  std::string text;
};

// The entry "doc.kml" (any letter case, at the top of the archive), else the
// first entry whose name ends in ".kml", decompressed. Errors (source named
// as src): not a zip; more than maxEntries entries; no .kml entry; an entry
// that is encrypted, ZIP64 or compressed other than stored or deflate;
// headers or data outside the archive; a CRC-32 that does not match; more
// than maxBytes once decompressed.
Result<ZipText> readKmlFromZip(std::string_view zip, const std::string& src, std::size_t maxEntries,
                               std::size_t maxBytes);

}  // namespace sky::flight::detail
