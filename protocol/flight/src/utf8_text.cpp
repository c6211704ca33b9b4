// UTF-8 for flight files and messages (see utf8_text.hpp): the checks
// themselves are sky::utf8's (protocol/core), shared with the server.
#include "sky/flight/utf8_text.hpp"

#include "sky/core/utf8.hpp"

namespace sky::flight {

std::optional<std::size_t> firstInvalidUtf8(std::string_view text) {
  const std::size_t valid = utf8::validPrefix(text);
  if (valid == text.size()) return std::nullopt;
  return valid;
}

std::string replaceInvalidUtf8(std::string_view text) { return utf8::sanitise(text); }

std::string_view cutUtf8(std::string_view text, std::size_t maxBytes) { return utf8::cut(text, maxBytes); }
std::string messageText(std::string_view text, std::size_t maxBytes) {
  std::string clean = replaceInvalidUtf8(text);
  for (char& c : clean)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';
  const std::string_view cut = cutUtf8(clean, maxBytes);
  if (cut.size() == clean.size()) return clean;
  return std::string(cut) + "...";
}

}  // namespace sky::flight
