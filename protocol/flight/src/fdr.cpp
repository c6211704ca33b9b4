// X-Plane flight data recorder (.fdr, text) reader: the header rows X-Plane
// documents (x-plane.com/kb/creating-fdr-files: ACFT, TAIL, TIME, DATE, PRES,
// ..., COMM, DREF) and the data rows, version 4's bare CSV rows (time, lon,
// lat, altitude, heading, pitch, roll, then DREF columns) and versions 1-3's
// DATA rows. Every rule, and where each column's meaning comes from, is in
// flight.hpp.
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "reader_common.hpp"
#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::flight {

namespace {

using detail::printable;
using detail::WarningKind;

using detail::kMetresPerFoot;
// The ADS-B reader's range of geometric altitude.
constexpr double kMinAlt_m = detail::kMinGeoAltitude_m, kMaxAlt_m = detail::kMaxGeoAltitude_m;
constexpr double kSecondsPerDay = 86400.0;
// A row's time of day falling back by more than this is a crossing of
// midnight UTC (as in IGC): a day is added.
constexpr double kMidnightFallback_s = 43200.0;
// A two-digit year below this is 20YY, else 19YY (as the IGC reader).
constexpr int kTwoDigitYearPivot = 80;
// Seconds columns (DATA rows, bare-number v4 times) up to a year of recording.
constexpr double kMaxSeconds_s = 3.2e7;

// Columns of a version 4 row (X-Plane's rule for v4 files, as restated in the
// header comment of a Rust FDR writer's fdr module (crate "hangar") and
// written by 42fdr (github.com/MadReasonable/42fdr): "the first 7 columns
// must be: zulu time (hh:mm:ss), longitude, latitude, altitude (feet),
// magnetic heading, pitch, roll"; further columns are DREFs).
constexpr std::size_t kV4Time = 0, kV4Lon = 1, kV4Lat = 2, kV4Alt = 3, kV4Heading = 4, kV4Pitch = 5, kV4Roll = 6;
constexpr std::size_t kV4Columns = 7;
// Columns of a version 1-3 DATA row (after "DATA"), X-Plane's "Creating FDR
// Files" table: time (s), temperature, longitude, latitude, altitude (ft
// MSL), ... The attitude columns of that table could not be confirmed
// offline, so DATA rows give position only.
constexpr std::size_t kDataTime = 0, kDataLon = 2, kDataLat = 3, kDataAlt = 4;
constexpr std::size_t kDataColumns = 5;
// A tail number is a few characters; a longer one is kept cut.
constexpr std::size_t kMaxTailChars = 16;
// Fields split out of a row: the columns read, and one more to count; DREF
// columns beyond are not split.
constexpr std::size_t kMaxSplitFields = 8;

// The first max fields of a comma-separated line (the rest not split).
void splitFields(std::string_view line, std::vector<std::string_view>& out, std::size_t max) {
  out.clear();
  while (out.size() < max) {
    const auto comma = line.find(',');
    out.push_back(detail::trimSpace(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

// "hh:mm:ss[.fff]" as seconds of the day.
std::optional<double> timeOfDay(std::string_view f) {
  f = detail::trimSpace(f);
  if (f.size() < 8 || f[2] != ':' || f[5] != ':') return std::nullopt;
  const long long h = detail::digitsValue(f.substr(0, 2)), m = detail::digitsValue(f.substr(3, 2)),
                  s = detail::digitsValue(f.substr(6, 2));
  if (h < 0 || h > 23 || m < 0 || m > 59 || s < 0 || s > 60) return std::nullopt;
  double fraction = 0;
  if (f.size() > 8) {
    if (f[8] != '.' || f.size() == 9) return std::nullopt;
    double scale = 0.1;
    for (char c : f.substr(9)) {
      if (!detail::isDigit(c)) return std::nullopt;
      fraction += (c - '0') * scale;
      scale /= 10;
    }
  }
  return static_cast<double>(h * 3600 + m * 60 + s) + fraction;
}

struct Date {
  int y;
  unsigned m, d;
};

// "MM/DD/YY" or "MM/DD/YYYY" (X-Plane writes the US order: the files of
// 42fdr and xpwebapi say "01/18/2023").
std::optional<Date> date(std::string_view f) {
  f = detail::trimSpace(f);
  const auto a = f.find('/');
  const auto b = a == std::string_view::npos ? a : f.find('/', a + 1);
  if (b == std::string_view::npos) return std::nullopt;
  const long long m = detail::digitsValue(f.substr(0, a)), d = detail::digitsValue(f.substr(a + 1, b - a - 1));
  const std::string_view ys = f.substr(b + 1);
  long long y = detail::digitsValue(ys);
  if (m < 1 || m > 12 || d < 1 || d > 31 || y < 0 || (ys.size() != 2 && ys.size() != 4)) return std::nullopt;
  if (ys.size() == 2) y += y < kTwoDigitYearPivot ? 2000 : 1900;
  return Date{static_cast<int>(y), static_cast<unsigned>(m), static_cast<unsigned>(d)};
}

struct Row {
  double t_s;            // seconds: of the day (v4 hh:mm:ss) or from the start
  double lat_deg, lon_deg, alt_m;
  std::optional<double> pitch_deg, roll_deg;
  std::size_t line;
};

}  // namespace

Result<ParsedFlight> parseFdr(std::string_view text, std::string_view sourceName) {
  detail::Warnings warnings(sourceName);
  const std::string& src = warnings.source();
  std::optional<Error> error;
  int version = 0;
  bool lineEndingSeen = false;
  std::optional<Date> day;
  std::optional<double> startTime_s;  // TIME header, seconds of the day
  std::vector<Row> rows;
  bool clockRows = false, secondsRows = false;  // v4 hh:mm:ss rows; seconds rows
  std::vector<std::string_view> fields;
  std::size_t dataRows = 0;
  std::string tail;  // TAIL header

  detail::forEachLine(text, [&](std::string_view rawLine, std::size_t lineNo) {
    if (error) return;
    const std::string at = src + ":" + std::to_string(lineNo) + ": ";
    if (rawLine.size() > kMaxFdrLineBytes) {
      error = Error{ErrorCode::TooLarge, at + "line of " + std::to_string(rawLine.size()) + " bytes, at most " +
                                             std::to_string(kMaxFdrLineBytes) + " read"};
      return;
    }
    std::string_view line = rawLine;
    if (const auto comment = line.find("//"); comment != std::string_view::npos) line = line.substr(0, comment);
    line = detail::trimSpace(line);
    if (line.empty()) return;
    if (!lineEndingSeen) {
      if (line != "A" && line != "I") {
        error = Error{ErrorCode::Malformed, at + "field 'line ending': '" + printable(line) +
                                                "', an X-Plane FDR file starts with 'A' or 'I'"};
        return;
      }
      lineEndingSeen = true;
      return;
    }
    if (version == 0) {
      if (line.size() != 1 || line[0] < '1' || line[0] > '4') {
        error = Error{ErrorCode::Unsupported, at + "field 'version': '" + printable(line) + "', versions 1 to 4 are read"};
        return;
      }
      version = line[0] - '0';
      return;
    }
    const bool isKey = line.size() >= 4 && detail::isUpper(line[0]) && detail::isUpper(line[1]) &&
                       detail::isUpper(line[2]) && detail::isUpper(line[3]) && (line.size() == 4 || line[4] == ',');
    const std::string_view key = isKey ? line.substr(0, 4) : std::string_view();
    const std::string_view value = isKey && line.size() > 5 ? detail::trimSpace(line.substr(5)) : std::string_view();
    if (isKey && key != "DATA") {
      if (key == "DATE") {
        day = date(value);
        if (!day)
          warnings.add(WarningKind::Other, lineNo,
                       "field 'DATE': '" + printable(value) + "' is not MM/DD/YY or MM/DD/YYYY; no start date");
      } else if (key == "TAIL") {
        tail = messageText(value, kMaxTailChars);
      } else if (key == "TIME") {
        startTime_s = timeOfDay(value);
        if (!startTime_s)
          warnings.add(WarningKind::Other, lineNo, "field 'TIME': '" + printable(value) + "' is not hh:mm:ss, ignored");
      }
      // ACFT, TAIL, PRES, TEMP, WIND, CALI, WARN, TEXT, MARK, EVNT, COMM,
      // DREF and others: nothing a pose needs (the altitude column is MSL,
      // so PRES converts nothing).
      return;
    }
    const bool dataRow = isKey;  // "DATA, ..." (versions 1-3)
    if (!dataRow && version < 4) {
      warnings.add(WarningKind::Junk, lineNo, "not a header or DATA row in a version " + std::to_string(version) +
                                                  " file, line skipped");
      return;
    }
    if (++dataRows > kMaxFdrRows) {
      error = Error{ErrorCode::TooLarge, at + "more than " + std::to_string(kMaxFdrRows) + " data rows"};
      return;
    }
    splitFields(dataRow ? value : line, fields, kMaxSplitFields);
    const std::size_t need = dataRow ? kDataColumns : kV4Columns;
    if (fields.size() < need) {
      error = Error{ErrorCode::Malformed, at + std::to_string(fields.size()) + " columns, a " +
                                             (dataRow ? "DATA" : "version 4 data") + " row has at least " +
                                             std::to_string(need)};
      return;
    }
    const auto value_ = [&](std::size_t col, std::string_view name, double lo, double hi) -> std::optional<double> {
      const auto v = detail::parseDecimal(fields[col]);
      if (!v) {
        error = Error{ErrorCode::Malformed, at + "field '" + std::string(name) + "': '" + printable(fields[col]) +
                                               "' is not a number"};
      } else if (*v < lo || *v > hi) {
        error = Error{ErrorCode::InvalidArgument, at + "field '" + std::string(name) + "': " +
                                                      printable(fields[col]) + " is outside [" + std::to_string(lo) +
                                                      ", " + std::to_string(hi) + "]"};
        return std::nullopt;
      }
      return v;
    };
    Row r{};
    r.line = lineNo;
    const std::size_t timeCol = dataRow ? kDataTime : kV4Time;
    std::optional<double> t;
    if (!dataRow) t = timeOfDay(fields[timeCol]);
    if (t) {
      clockRows = true;
    } else {
      t = value_(timeCol, "time", 0, kMaxSeconds_s);
      if (!t) {
        if (!dataRow && !detail::parseDecimal(fields[timeCol]))
          error = Error{ErrorCode::Malformed, at + "field 'time': '" + printable(fields[timeCol]) +
                                                 "' is neither hh:mm:ss[.f] (zulu) nor seconds"};
        return;
      }
      secondsRows = true;
    }
    r.t_s = *t;
    const auto lon = value_(dataRow ? kDataLon : kV4Lon, "longitude", -180, 180);
    const auto lat = value_(dataRow ? kDataLat : kV4Lat, "latitude", -90, 90);
    const auto alt = value_(dataRow ? kDataAlt : kV4Alt, "altitude (ft MSL)", kMinAlt_m / kMetresPerFoot,
                            kMaxAlt_m / kMetresPerFoot);
    if (!lon || !lat || !alt) return;
    r.lat_deg = *lat;
    r.lon_deg = *lon;
    r.alt_m = *alt * kMetresPerFoot;
    if (!dataRow) {
      if (!value_(kV4Heading, "heading", -360, 360)) return;
      r.pitch_deg = value_(kV4Pitch, "pitch", -90, 90);
      r.roll_deg = value_(kV4Roll, "roll", -180, 180);
      if (!r.pitch_deg || !r.roll_deg) return;
    }
    rows.push_back(r);
  });

  if (error) return tl::unexpected(*error);
  if (!lineEndingSeen || version == 0)
    return fail(ErrorCode::Malformed, src + ": no 'A'/'I' line and version line: not an X-Plane FDR file");
  if (clockRows && secondsRows)
    return fail(ErrorCode::Malformed,
                src + ": data rows mix zulu times (hh:mm:ss) and seconds; a file keeps to one");

  // Times: zulu clock rows cross midnight forwards; seconds rows count from
  // the TIME header (when there is one).
  ParsedFlight flight;
  detail::TimeOrder order;
  std::vector<double> times_s;
  std::vector<Row> kept;
  double dayOffset_s = 0, previous_s = -1;
  for (const Row& r : rows) {
    double t = r.t_s;
    if (clockRows) {
      if (previous_s >= 0 && t + dayOffset_s < previous_s - kMidnightFallback_s) dayOffset_s += kSecondsPerDay;
      t += dayOffset_s;
    }
    previous_s = t;
    if (!order.accept(t, r.line, warnings)) continue;
    times_s.push_back(t);
    kept.push_back(r);
  }
  if (kept.size() < 2)
    return fail(ErrorCode::InvalidArgument, src + ": " + std::to_string(kept.size()) +
                                                " usable data rows, a flight needs at least two");
  // The recording's zulu start: the first row's time of day (clock rows) or
  // the TIME header plus the first row's seconds, on the DATE header's day.
  std::optional<double> firstZulu_s;
  if (clockRows) firstZulu_s = times_s.front();
  else if (startTime_s) firstZulu_s = *startTime_s + times_s.front();
  const double origin_s = firstZulu_s ? std::floor(*firstZulu_s) - (*firstZulu_s - times_s.front()) : times_s.front();
  if (firstZulu_s && day)
    flight.startUtc_s = daysFromCivil(day->y, day->m, day->d) * 86400 + static_cast<std::int64_t>(std::floor(*firstZulu_s));
  else
    warnings.add(WarningKind::Other, 0,
                 std::string("no ") + (day ? "zulu time (TIME header or hh:mm:ss rows)" : "DATE header") +
                     ": no start date");
  bool attitude = false;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const Row& r = kept[i];
    flight.fixes.push_back(Fix{times_s[i] - origin_s, {{r.lat_deg, r.lon_deg, r.alt_m}, 0, r.pitch_deg.value_or(0),
                                                      r.roll_deg.value_or(0)}});
    flight.fixLines.push_back(r.line);
    attitude = attitude || r.pitch_deg.has_value();
  }
  // Yaw from the track: the file's heading is magnetic and no magnetic
  // model is at hand (GeographicLib's needs data files we do not ship).
  // Pitch and roll: the file's when its rows give them, else the track's.
  Flight derived = flight;
  deriveAttitude(derived);
  for (std::size_t i = 0; i < flight.fixes.size(); ++i) {
    flight.fixes[i].pose.yaw_deg = derived.fixes[i].pose.yaw_deg;
    if (!attitude) {
      flight.fixes[i].pose.pitch_deg = derived.fixes[i].pose.pitch_deg;
      flight.fixes[i].pose.roll_deg = derived.fixes[i].pose.roll_deg;
    }
  }
  flight.attitudeFromTrack = !attitude;  // else the cleaning keeps the file's pitch and roll
  if (!tail.empty()) flight.aircraft = "tail " + tail;
  flight.geometricAltitudeFixes = flight.fixes.size();
  flight.altitudeSource = "MSL (the FDR altitude column, ft) for " + std::to_string(flight.fixes.size()) +
                          (flight.fixes.size() == 1 ? " fix" : " fixes") +
                          (attitude ? "; pitch and roll from the file, heading from the track"
                                    : "; attitude from the track");
  flight.warnings = warnings.finish();
  return flight;
}

}  // namespace sky::flight
