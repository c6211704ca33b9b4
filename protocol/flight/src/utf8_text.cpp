// UTF-8 well-formedness, replacement and cutting (see utf8_text.hpp).
#include "sky/flight/utf8_text.hpp"

namespace sky::flight {

namespace {

constexpr char kReplacement[] = "\xEF\xBF\xBD";  // U+FFFD in UTF-8

struct Step {
  std::size_t length;  // bytes of the sequence, or of its maximal ill-formed subpart
  bool valid;
};

// The sequence starting at text[i] (Unicode 15 Table 3-7: the allowed second
// byte depends on the lead byte; later bytes are 80..BF).
Step step(std::string_view text, std::size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  if (c < 0x80) return {1, true};
  std::size_t trail = 0;
  unsigned char lo = 0x80, hi = 0xBF;
  if (c >= 0xC2 && c <= 0xDF) {
    trail = 1;
  } else if (c == 0xE0) {
    trail = 2, lo = 0xA0;  // no overlong 3-byte forms
  } else if ((c >= 0xE1 && c <= 0xEC) || c == 0xEE || c == 0xEF) {
    trail = 2;
  } else if (c == 0xED) {
    trail = 2, hi = 0x9F;  // no surrogates D800-DFFF
  } else if (c == 0xF0) {
    trail = 3, lo = 0x90;  // no overlong 4-byte forms
  } else if (c >= 0xF1 && c <= 0xF3) {
    trail = 3;
  } else if (c == 0xF4) {
    trail = 3, hi = 0x8F;  // nothing above U+10FFFF
  } else {
    return {1, false};  // 80-C1 (continuation or overlong lead), F5-FF
  }
  for (std::size_t k = 1; k <= trail; ++k) {
    if (i + k >= text.size()) return {k, false};
    const auto b = static_cast<unsigned char>(text[i + k]);
    if (k == 1 ? (b < lo || b > hi) : (b < 0x80 || b > 0xBF)) return {k, false};
  }
  return {trail + 1, true};
}

}  // namespace

std::optional<std::size_t> firstInvalidUtf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const Step s = step(text, i);
    if (!s.valid) return i;
    i += s.length;
  }
  return std::nullopt;
}

std::string replaceInvalidUtf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const Step s = step(text, i);
    if (s.valid)
      out.append(text.substr(i, s.length));
    else
      out += kReplacement;
    i += s.length;
  }
  return out;
}

std::string_view cutUtf8(std::string_view text, std::size_t maxBytes) {
  if (text.size() <= maxBytes) return text;
  std::size_t n = maxBytes;
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;
  return text.substr(0, n);
}

std::string messageText(std::string_view text, std::size_t maxBytes) {
  std::string clean = replaceInvalidUtf8(text);
  for (char& c : clean)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';
  const std::string_view cut = cutUtf8(clean, maxBytes);
  if (cut.size() == clean.size()) return clean;
  return std::string(cut) + "...";
}

}  // namespace sky::flight
