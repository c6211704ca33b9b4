// UTF-8 at the edges: text from outside (HTTP targets and headers, JSON
// strings, names stored in a database) is checked, repaired or cut here, so a
// JSON writer never meets an invalid sequence and a byte limit never splits a
// character. Pure: the server, the renderer and the tools share it.
// Validity is RFC 3629: no overlong forms, no surrogates (U+D800..U+DFFF), no
// code point past U+10FFFF.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace sky::utf8 {

// The replacement character U+FFFD, as UTF-8.
inline constexpr std::string_view kReplacement = "\xEF\xBF\xBD";

// Whether `text` is entirely valid UTF-8 (the empty string is).
bool valid(std::string_view text);

// Length in bytes of the longest valid prefix of `text` (== text.size() when
// the whole text is valid).
std::size_t validPrefix(std::string_view text);

// `text` with each ill-formed subsequence replaced by one U+FFFD, following
// Unicode's "maximal subpart" practice (Unicode 15, section 3.9, U+FFFD
// substitution): a truncated sequence becomes one U+FFFD, every other
// invalid byte one each. Valid input comes back unchanged.
std::string sanitise(std::string_view text);

// The longest prefix of `text` of at most `maxBytes` bytes that does not end
// inside a character (a view into `text`). Meant for valid UTF-8: the prefix
// of valid text is valid. Invalid text is cut at `maxBytes` where no
// character boundary is within three bytes.
std::string_view cut(std::string_view text, std::size_t maxBytes);

// sanitise() then cut(): text from outside, made safe to store and show,
// at most `maxBytes` bytes.
std::string sanitiseAndCut(std::string_view text, std::size_t maxBytes);

}  // namespace sky::utf8
