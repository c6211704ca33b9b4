// A whole XML text through expat, for the GPX and KML readers: the parser's
// owner, and the text fed in slices with one error rule. Private to
// protocol/flight/src.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <expat.h>

#include "sky/core/result.hpp"

namespace sky::flight::detail {

struct XmlParserFree {
  void operator()(XML_Parser p) const { XML_ParserFree(p); }
};
using XmlParser = std::unique_ptr<XML_ParserStruct, XmlParserFree>;

// expat takes int lengths: large documents go in slices.
inline constexpr std::size_t kXmlSliceBytes = std::size_t{1} << 24;

// Feeds text to parser. A failure is the handlers' own error when they set
// one (`handlerError`, which stops the parser), else expat's, naming src and
// the line.
inline Result<void> parseXmlText(XML_Parser parser, std::string_view text, const std::string& src,
                                 const std::optional<Error>& handlerError) {
  std::size_t pos = 0;
  do {
    const std::size_t n = std::min(kXmlSliceBytes, text.size() - pos);
    const bool last = pos + n == text.size();
    if (XML_Parse(parser, text.data() + pos, static_cast<int>(n), last) != XML_STATUS_OK) {
      if (handlerError) return tl::unexpected(*handlerError);
      return fail(ErrorCode::Malformed, src + ":" + std::to_string(XML_GetCurrentLineNumber(parser)) +
                                            ": XML: " + XML_ErrorString(XML_GetErrorCode(parser)));
    }
    pos += n;
  } while (pos < text.size());
  return {};
}

}  // namespace sky::flight::detail
