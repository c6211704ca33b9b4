// UTF-8 validation, repair and cutting (see utf8.hpp).
#include "sky/core/utf8.hpp"

namespace sky::utf8 {

namespace {

// Length of the valid sequence at the start of `s` (1..4), or 0 with
// `*subpart` = the bytes of its maximal ill-formed subpart (>= 1). The
// second byte's range depends on the first (RFC 3629 section 4, Unicode
// table 3-7): E0 needs A0..BF (no overlong), ED 80..9F (no surrogate), F0
// 90..BF (no overlong), F4 80..8F (nothing past U+10FFFF).
std::size_t sequence(std::string_view s, std::size_t* subpart) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char b0 = byte(0);
  if (b0 < 0x80) return 1;
  std::size_t length = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the second byte's range
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    length = 2;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    length = 3;
    if (b0 == 0xE0) lo = 0xA0;
    if (b0 == 0xED) hi = 0x9F;
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    length = 4;
    if (b0 == 0xF0) lo = 0x90;
    if (b0 == 0xF4) hi = 0x8F;
  } else {
    *subpart = 1;  // a continuation byte without a lead, C0, C1, F5..FF
    return 0;
  }
  for (std::size_t i = 1; i < length; ++i) {
    const unsigned char low = i == 1 ? lo : 0x80, high = i == 1 ? hi : 0xBF;
    if (i >= s.size() || byte(i) < low || byte(i) > high) {
      *subpart = i;
      return 0;
    }
  }
  return length;
}

}  // namespace

std::size_t validPrefix(std::string_view text) {
  std::size_t at = 0, subpart = 0;
  while (at < text.size()) {
    const std::size_t n = sequence(text.substr(at), &subpart);
    if (n == 0) return at;
    at += n;
  }
  return at;
}

bool valid(std::string_view text) { return validPrefix(text) == text.size(); }

std::string sanitise(std::string_view text) {
  std::size_t good = validPrefix(text);
  if (good == text.size()) return std::string(text);
  std::string out(text.substr(0, good));
  out.reserve(text.size() + 8);
  std::size_t at = good, subpart = 0;
  while (at < text.size()) {
    const std::size_t n = sequence(text.substr(at), &subpart);
    if (n == 0) {
      out += kReplacement;
      at += subpart;
    } else {
      out.append(text.substr(at, n));
      at += n;
    }
  }
  return out;
}

std::string_view cut(std::string_view text, std::size_t maxBytes) {
  if (text.size() <= maxBytes) return text;
  std::size_t end = maxBytes;
  // Back over continuation bytes (10xxxxxx) to the lead byte of the
  // character the limit falls in: at most three of them in UTF-8.
  for (int back = 0; back < 3 && end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80; ++back) --end;
  if ((static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) end = maxBytes;  // no lead within reach: not UTF-8
  return text.substr(0, end);
}

std::string sanitiseAndCut(std::string_view text, std::size_t maxBytes) {
  return std::string(cut(sanitise(text), maxBytes));
}

}  // namespace sky::utf8
