// Pieces the IGC, GPX and ADS-B readers share: byte classes that ignore the locale,
// capped warnings, and the time-order rules documented in flight.hpp.
// Private to protocol/flight/src.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sky/flight/flight.hpp"

namespace sky::flight::detail {

// <cctype> takes int and is undefined for negative chars (bytes >= 0x80).
constexpr bool isDigit(char c) { return c >= '0' && c <= '9'; }
constexpr bool isUpper(char c) { return c >= 'A' && c <= 'Z'; }

// s.substr(pos, n) that is empty instead of throwing when pos > s.size()
// (records from outside are any length).
constexpr std::string_view sub(std::string_view s, std::size_t pos, std::size_t n = std::string_view::npos) {
  return pos > s.size() ? std::string_view() : s.substr(pos, n);
}

inline constexpr double kMetresPerFoot = 0.3048;  // international foot, exact
// Altitudes the ADS-B, readsb and FDR readers accept. Barometric: the
// domain of the standard atmosphere's pressure (isaPressure_hpa, -1 to
// 20 km); geometric: from the Dead Sea to where balloons still report, well
// past any aircraft.
inline constexpr double kMinBaroAltitude_m = -1000.0, kMaxBaroAltitude_m = 20000.0;
inline constexpr double kMinGeoAltitude_m = -1000.0, kMaxGeoAltitude_m = 100000.0;
// Unix seconds up to the year 5138: beyond any recording, and small enough
// that the whole second fits an int64 exactly.
inline constexpr double kMaxUnixTime_s = 1.0e11;

// Most digits digitsValue reads: 18 always fit a long long.
constexpr std::size_t kMaxValueDigits = 18;

// Value of s (all digits, non-empty, at most kMaxValueDigits) or -1. Longer
// runs are refused rather than overflowing: no fixed-width field we read is
// that wide, so such a run is junk.
constexpr long long digitsValue(std::string_view s) {
  if (s.empty() || s.size() > kMaxValueDigits) return -1;
  long long v = 0;
  for (char c : s) {
    if (!isDigit(c)) return -1;
    v = v * 10 + (c - '0');
  }
  return v;
}

// s without the white space around it: spaces, tabs and line ends (a CRLF
// file's '\r' at the end of a row, XML's newlines and indentation).
constexpr std::string_view trimSpace(std::string_view s) {
  constexpr auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

// The finite decimal number that is all of s (white space around it and a
// leading '+' allowed, as CSV exports and XML Schema's decimals write it),
// or nullopt: no locale, no trailing junk, no inf or nan.
std::optional<double> parseDecimal(std::string_view s);

// Printable rendering of a field for a message: bytes outside ASCII
// printables become '?', and long fields are cut.
std::string printable(std::string_view s);

// ISO 8601 / RFC 3339 date-time "YYYY-MM-DDThh:mm:ss[.fff][Z|+hh:mm|-hh:mm]"
// (XML white space around it allowed) as UTC seconds since 1970, as GPX and
// KML write times. A time zone is required (a local time is not a recording
// time we can place).
std::optional<double> isoUtc_s(std::string_view s);

enum class WarningKind : std::size_t {
  OutOfOrder,
  Duplicate,
  Gap,
  Validity,
  NoAltitude,
  Junk,
  EmptyField,
  OnGround,
  NewLeg,
  Stale,
  Other,
  Count_,
};

// Warnings of one reader; at most kMaxWarningsPerKind per kind are listed.
class Warnings {
 public:
  // source is shown as messageText shows it (utf8_text.hpp).
  explicit Warnings(std::string_view source);
  // "source:line: text" (line 0: "source: text").
  void add(WarningKind kind, std::size_t line, const std::string& text);
  // Appends the "N more ..." summaries and hands the list over.
  std::vector<std::string> finish();
  const std::string& source() const { return source_; }

 private:
  std::string source_;
  std::vector<std::string> list_;
  std::array<std::size_t, static_cast<std::size_t>(WarningKind::Count_)> counts_{};
};

// Splits text into lines at "\n", "\r\n" or "\r"; calls f(line, lineNo)
// with lineNo from 1 and the ending removed.
template <class F>
void forEachLine(std::string_view text, F&& f) {
  std::size_t lineNo = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    f(text.substr(pos, end - pos), ++lineNo);
    if (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n') ++end;
    pos = end + 1;
  }
}

// Applies the shared time rules to a candidate fix at t (any origin, s).
// Returns whether to keep it; warns for skipped fixes and gaps.
class TimeOrder {
 public:
  bool accept(double t_s, std::size_t line, Warnings& warnings);

 private:
  bool any_ = false;
  double last_s_ = 0;
};

}  // namespace sky::flight::detail
