// IGC flight reader (FAI Technical Specification for IGC-approved GNSS flight
// recorders, Appendix A): H date, I extensions, B fixes. Lenient by design:
// a bad line is skipped with a warning (see flight.hpp for every rule).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "reader_common.hpp"
#include "sky/flight/flight.hpp"

namespace sky::flight {

namespace {

using detail::digitsValue;
using detail::sub;
using detail::printable;
using detail::WarningKind;

constexpr double kSecondsPerDay = 86400.0;
// A time-of-day that falls back by more than half a day is the next day: no
// logger is out of order by 12 h, and no flight gap in one file is 12 h long.
constexpr double kMidnightJump_s = kSecondsPerDay / 2;
// B record layout, 0-based byte offsets (spec A4.1).
constexpr std::size_t kBMinLength = 35;
constexpr std::size_t kBFirstExtensionByte = 36;  // 1-based, as I records count
constexpr std::size_t kMaxExtraDigits = 9;        // LAD/LOD digits that still matter

struct Date {
  std::int64_t y;
  unsigned m, d;
};

bool isLeap(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }
unsigned daysInMonth(std::int64_t y, unsigned m) {
  constexpr unsigned kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return m == 2 && isLeap(y) ? 29 : kDays[m - 1];
}

// "HFDTE030416" or "HFDTEDATE:040920,01" (the second form is from the 2016
// amendment of the spec; the ",NN" flight number is ignored).
std::optional<Date> parseDate(std::string_view line) {
  std::string_view rest = sub(line, 5);
  if (rest.substr(0, 5) == "DATE:") rest.remove_prefix(5);
  if (rest.size() < 6) return std::nullopt;
  const long long dd = digitsValue(rest.substr(0, 2)), mm = digitsValue(rest.substr(2, 2)),
                  yy = digitsValue(rest.substr(4, 2));
  if (dd < 1 || mm < 1 || mm > 12 || yy < 0) return std::nullopt;
  // IGC files exist from the 1990s on; two-digit years below 80 are 20YY.
  const std::int64_t y = yy < 80 ? 2000 + yy : 1900 + yy;
  if (static_cast<unsigned>(dd) > daysInMonth(y, static_cast<unsigned>(mm))) return std::nullopt;
  return Date{y, static_cast<unsigned>(mm), static_cast<unsigned>(dd)};
}

struct Extension {
  std::size_t first = 0, last = 0;  // 0-based byte offsets, inclusive
};

struct Extensions {
  std::optional<Extension> lad, lod;  // extra digits of latitude/longitude minutes
};

// "I" NN then NN times SS FF CCC (1-based start and finish byte, code).
std::optional<Extensions> parseIRecord(std::string_view line) {
  const long long n = digitsValue(sub(line, 1, 2));
  if (n < 0 || line.size() < 3 + 7 * static_cast<std::size_t>(n)) return std::nullopt;
  Extensions out;
  for (long long k = 0; k < n; ++k) {
    const std::string_view e = line.substr(3 + 7 * static_cast<std::size_t>(k), 7);
    const long long s = digitsValue(e.substr(0, 2)), f = digitsValue(e.substr(2, 2));
    if (s < static_cast<long long>(kBFirstExtensionByte) || f < s) return std::nullopt;
    const Extension x{static_cast<std::size_t>(s - 1), static_cast<std::size_t>(f - 1)};
    if (e.substr(4) == "LAD") out.lad = x;
    if (e.substr(4) == "LOD") out.lod = x;
  }
  return out;
}

struct BFix {
  double timeOfDay_s;
  double lat_deg, lon_deg;
  char validity;
  long long pressureAlt_m, gnssAlt_m;
};

// A signed 5-byte altitude in metres: digits, or '-' and four digits.
std::optional<long long> altitudeValue(std::string_view s) {
  const bool negative = !s.empty() && s.front() == '-';
  const long long v = digitsValue(negative ? s.substr(1) : s);
  if (v < 0) return std::nullopt;
  return negative ? -v : v;
}

// Degrees from DD(D) MMmmm [+ extra digits]; nullopt when not digits or
// minutes >= 60.
std::optional<double> angle(std::string_view deg, std::string_view minutesMilli, std::string_view extra) {
  const long long d = digitsValue(deg), mm = digitsValue(minutesMilli);
  if (d < 0 || mm < 0 || mm >= 60000) return std::nullopt;
  double minutes = static_cast<double>(mm) / 1000.0;
  // An I record may declare a wide LAD/LOD; past 9 extra digits (1e-12
  // minutes, a micrometre) nothing is left to refine, so the rest only has to
  // be digits. Without the cut a long run overflowed the value.
  const bool extraIsDigits = std::all_of(extra.begin(), extra.end(), detail::isDigit);
  const std::string_view used = extra.substr(0, std::min<std::size_t>(extra.size(), kMaxExtraDigits));
  const long long x = extraIsDigits ? digitsValue(used) : -1;
  if (x >= 0) minutes += static_cast<double>(x) / (1000.0 * std::pow(10.0, static_cast<double>(used.size())));
  return static_cast<double>(d) + minutes / 60.0;
}

std::string_view extensionField(std::string_view line, const std::optional<Extension>& x) {
  if (!x || x->last >= line.size()) return {};
  return line.substr(x->first, x->last - x->first + 1);
}

// Parses a B record, or says which field is wrong ("field 'latitude': ...").
std::optional<BFix> parseB(std::string_view line, const Extensions& ext, std::string& why) {
  if (line.size() < kBMinLength) {
    why = "B record of " + std::to_string(line.size()) + " bytes, at least " + std::to_string(kBMinLength) +
          " expected";
    return std::nullopt;
  }
  const auto bad = [&](const char* field, std::string_view value) {
    why = std::string("field '") + field + "': '" + printable(value) + "' does not parse";
    return std::nullopt;
  };
  const long long hh = digitsValue(line.substr(1, 2)), mi = digitsValue(line.substr(3, 2)),
                  ss = digitsValue(line.substr(5, 2));
  if (hh < 0 || hh > 23 || mi < 0 || mi > 59 || ss < 0 || ss > 59) return bad("time", line.substr(1, 6));
  BFix b{};
  b.timeOfDay_s = static_cast<double>(hh * 3600 + mi * 60 + ss);
  const auto lat = angle(line.substr(7, 2), line.substr(9, 5), extensionField(line, ext.lad));
  const char ns = line[14];
  if (!lat || *lat > 90.0 || (ns != 'N' && ns != 'S')) return bad("latitude", line.substr(7, 8));
  b.lat_deg = ns == 'S' ? -*lat : *lat;
  const auto lon = angle(line.substr(15, 3), line.substr(18, 5), extensionField(line, ext.lod));
  const char ew = line[23];
  if (!lon || *lon > 180.0 || (ew != 'E' && ew != 'W')) return bad("longitude", line.substr(15, 9));
  b.lon_deg = ew == 'W' ? -*lon : *lon;
  b.validity = line[24];
  if (b.validity != 'A' && b.validity != 'V') return bad("validity", line.substr(24, 1));
  const auto pressure = altitudeValue(line.substr(25, 5));
  if (!pressure) return bad("pressure altitude", line.substr(25, 5));
  const auto gnss = altitudeValue(line.substr(30, 5));
  if (!gnss) return bad("gnss altitude", line.substr(30, 5));
  b.pressureAlt_m = *pressure;
  b.gnssAlt_m = *gnss;
  return b;
}

}  // namespace

Result<ParsedFlight> parseIgc(std::string_view text, std::string_view sourceName) {
  detail::Warnings warnings(sourceName);
  detail::TimeOrder order;
  std::optional<Date> date;
  bool dateSeen = false;
  Extensions ext;
  double dayOffset_s = 0;
  std::optional<double> lastB_s;  // time of the last readable B record, for midnight
  bool pressureNoted = false;
  ParsedFlight flight;

  detail::forEachLine(text, [&](std::string_view line, std::size_t lineNo) {
    if (line.empty()) return;
    if (!detail::isUpper(line.front())) {
      warnings.add(WarningKind::Junk, lineNo, "'" + printable(line) + "' is not an IGC record, line skipped");
      return;
    }
    if (line.front() == 'H' && sub(line, 2, 3) == "DTE") {
      if (dateSeen) return;
      dateSeen = true;
      date = parseDate(line);
      if (!date)
        warnings.add(WarningKind::Other, lineNo,
                     "field 'date': '" + printable(sub(line, 5)) + "' is not DDMMYY, no start date");
      return;
    }
    if (line.front() == 'I') {
      const auto parsed = parseIRecord(line);
      if (parsed) {
        ext = *parsed;
      } else {
        ext = {};
        warnings.add(WarningKind::Other, lineNo,
                     "field 'extensions': '" + printable(line) + "' does not parse, B extensions ignored");
      }
      return;
    }
    if (line.front() != 'B') return;

    std::string why;
    const auto b = parseB(line, ext, why);
    if (!b) {
      warnings.add(WarningKind::Junk, lineNo, why + ", line skipped");
      return;
    }
    double t_s = b->timeOfDay_s + dayOffset_s;
    if (lastB_s && t_s < *lastB_s - kMidnightJump_s) {
      dayOffset_s += kSecondsPerDay;
      t_s += kSecondsPerDay;
    }
    lastB_s = t_s;
    if (b->validity == 'V') {
      warnings.add(WarningKind::Validity, lineNo, "field 'validity': 'V' (2D or no GNSS fix), fix skipped");
      return;
    }
    if (b->gnssAlt_m == 0 && b->pressureAlt_m == 0) {
      warnings.add(WarningKind::NoAltitude, lineNo,
                   "fields 'pressure altitude', 'gnss altitude': both 0 (no altitude), fix skipped");
      return;
    }
    if (!order.accept(t_s, lineNo, warnings)) return;
    double alt_m = static_cast<double>(b->gnssAlt_m);
    if (b->gnssAlt_m == 0) {
      alt_m = static_cast<double>(b->pressureAlt_m);
      if (!pressureNoted)
        warnings.add(WarningKind::Other, lineNo,
                     "field 'gnss altitude': 0, using pressure altitude (ISA) for this and every such fix");
      pressureNoted = true;
    }
    flight.fixes.push_back(Fix{t_s, {{b->lat_deg, b->lon_deg, alt_m}, 0, 0, 0}});
    flight.fixLines.push_back(lineNo);
  });

  if (!dateSeen) warnings.add(WarningKind::Other, 0, "no HFDTE date record, no start date");
  if (flight.fixes.size() < 2)
    return fail(ErrorCode::Malformed, warnings.source() + ": " + std::to_string(flight.fixes.size()) +
                                          " usable B fixes, a flight needs at least two");
  const double first_s = flight.fixes.front().time_s;
  for (Fix& f : flight.fixes) f.time_s -= first_s;
  if (date)
    flight.startUtc_s = daysFromCivil(date->y, date->m, date->d) * 86400 + static_cast<std::int64_t>(first_s);
  deriveAttitude(flight);
  flight.attitudeFromTrack = true;
  flight.warnings = warnings.finish();
  return flight;
}

}  // namespace sky::flight
