// UTF-8 checks for text read from outside (flight files, scenario files,
// bodies from a server) and for echoing such text in a message without
// passing on bytes a terminal or a log reader would choke on.
// Thin names over sky::utf8 (protocol/core), plus messageText.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace sky::flight {

// Byte offset of the first ill-formed UTF-8 sequence in text, or nullopt
// when all of it is well-formed (Unicode 15 §3.9, Table 3-7: no overlong
// forms, no surrogates, nothing above U+10FFFF, no truncated sequence).
std::optional<std::size_t> firstInvalidUtf8(std::string_view text);

// text with every maximal ill-formed subpart replaced by U+FFFD (Unicode 15
// §3.9, "U+FFFD Substitution of Maximal Subparts").
std::string replaceInvalidUtf8(std::string_view text);

// The longest prefix of text of at most maxBytes bytes that does not end
// inside a character. text must be well-formed UTF-8.
std::string_view cutUtf8(std::string_view text, std::size_t maxBytes);

// text as it may appear inside an error message or a log line: ill-formed
// UTF-8 replaced (U+FFFD), control characters (C0, DEL) shown as '?', and cut
// on a character boundary at maxBytes with "..." appended when cut.
std::string messageText(std::string_view text, std::size_t maxBytes = 200);

}  // namespace sky::flight
