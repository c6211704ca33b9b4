// ADS-B CSV flight reader: OpenSky state vectors and exports that use the
// same column names, the columns found by name in the header (every rule is
// in flight.hpp). Barometric altitude becomes geometric through the standard
// atmosphere of protocol/weather; attitude is derived from the track.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "reader_common.hpp"
#include "sky/flight/flight.hpp"
#include "sky/weather/standard_atmosphere.hpp"

namespace sky::flight {

namespace {

using detail::printable;
using detail::WarningKind;

using detail::kMaxBaroAltitude_m;
using detail::kMaxGeoAltitude_m;
using detail::kMaxUnixTime_s;
using detail::kMetresPerFoot;
using detail::kMinBaroAltitude_m;
using detail::kMinGeoAltitude_m;
// ICAO 24-bit address: at most six hex digits.
constexpr std::size_t kMaxIcao24Digits = 6;
// A callsign is at most 8 characters (ICAO Doc 4444); longer is kept, cut.
constexpr std::size_t kMaxCallsignChars = 8;
// Aircraft listed by name in the "several aircraft" error; the rest counted.
constexpr std::size_t kMaxListedAircraft = 20;

enum class Role { Time, Icao24, Callsign, Lat, Lon, Baro, Geo, OnGround, Unused, Count_ };
enum class NamedUnit { None, Metres, Feet, Unnamed };

struct ColumnName {
  std::string_view name;  // lower case
  Role role;
  NamedUnit unit;
};

// Every header name the reader knows. OpenSky state vectors: time, icao24,
// lat, lon, velocity, heading, vertrate, callsign, onground, baroaltitude,
// geoaltitude (metres); readsb/tar1090 names: alt_baro, alt_geom (feet).
constexpr std::array<ColumnName, 26> kNames = {{
    {"time", Role::Time, NamedUnit::None},
    {"timestamp", Role::Time, NamedUnit::None},
    {"icao24", Role::Icao24, NamedUnit::None},
    {"callsign", Role::Callsign, NamedUnit::None},
    {"lat", Role::Lat, NamedUnit::None},
    {"latitude", Role::Lat, NamedUnit::None},
    {"lon", Role::Lon, NamedUnit::None},
    {"longitude", Role::Lon, NamedUnit::None},
    {"baroaltitude", Role::Baro, NamedUnit::Metres},
    {"baro_altitude", Role::Baro, NamedUnit::Metres},
    {"altitude_m", Role::Baro, NamedUnit::Metres},
    {"altitude", Role::Baro, NamedUnit::Unnamed},
    {"altitude_ft", Role::Baro, NamedUnit::Feet},
    {"baroaltitude_ft", Role::Baro, NamedUnit::Feet},
    {"alt_baro", Role::Baro, NamedUnit::Feet},
    {"geoaltitude", Role::Geo, NamedUnit::Metres},
    {"geo_altitude", Role::Geo, NamedUnit::Metres},
    {"geoaltitude_ft", Role::Geo, NamedUnit::Feet},
    {"alt_geom", Role::Geo, NamedUnit::Feet},
    {"onground", Role::OnGround, NamedUnit::None},
    {"velocity", Role::Unused, NamedUnit::None},
    {"groundspeed", Role::Unused, NamedUnit::None},
    {"heading", Role::Unused, NamedUnit::None},
    {"track", Role::Unused, NamedUnit::None},
    {"vertrate", Role::Unused, NamedUnit::None},
    {"vertical_rate", Role::Unused, NamedUnit::None},
}};

constexpr std::size_t kRoles = static_cast<std::size_t>(Role::Count_);

char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

std::string lowered(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), lower);
  return out;
}

// 1 to 6 lower-case hex digits.
bool isIcao24(std::string_view s) {
  return !s.empty() && s.size() <= kMaxIcao24Digits &&
         std::all_of(s.begin(), s.end(), [](char c) { return detail::isDigit(c) || (c >= 'a' && c <= 'f'); });
}

// Splits a line at commas outside double quotes; a quoted field is returned
// without its quotes (a doubled quote inside stays doubled: no field we read
// holds one).
void splitFields(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t start = 0;
  bool quoted = false;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i < line.size() && line[i] == '"') quoted = !quoted;
    if (i == line.size() || (line[i] == ',' && !quoted)) {
      std::string_view f = detail::trimSpace(line.substr(start, i - start));
      if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = detail::trimSpace(f.substr(1, f.size() - 2));
      out.push_back(f);
      start = i + 1;
    }
  }
}

// OpenSky leaves unknown values empty; pandas writes them as "nan", SQL
// exports as "null" or "None".
bool isEmpty(std::string_view f) {
  if (f.empty()) return true;
  if (f.size() > 4) return false;
  const std::string l = lowered(f);
  return l == "nan" || l == "null" || l == "none";
}

bool isLeap(std::int64_t y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

// "YYYY-MM-DD[T ]hh:mm:ss[.f...][Z|+00:00]" (UTC) as Unix seconds.
std::optional<double> isoTime(std::string_view f) {
  using detail::digitsValue;
  if (f.size() < 19 || f[4] != '-' || f[7] != '-' || (f[10] != 'T' && f[10] != ' ') || f[13] != ':' ||
      f[16] != ':')
    return std::nullopt;
  const long long y = digitsValue(f.substr(0, 4)), mo = digitsValue(f.substr(5, 2)), d = digitsValue(f.substr(8, 2)),
                  h = digitsValue(f.substr(11, 2)), mi = digitsValue(f.substr(14, 2)), s = digitsValue(f.substr(17, 2));
  constexpr std::array<long long, 12> kDays = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (y < 0 || mo < 1 || mo > 12 || d < 1 || h < 0 || h > 23 || mi < 0 || mi > 59 || s < 0 || s > 59)
    return std::nullopt;
  if (d > kDays[static_cast<std::size_t>(mo - 1)] + (mo == 2 && isLeap(y) ? 1 : 0)) return std::nullopt;
  std::string_view rest = f.substr(19);
  double fraction = 0;
  if (!rest.empty() && rest.front() == '.') {
    std::size_t n = 1;
    while (n < rest.size() && detail::isDigit(rest[n])) ++n;
    if (n == 1) return std::nullopt;
    const auto [ptr, ec] = std::from_chars(rest.data(), rest.data() + n, fraction);
    if (ec != std::errc()) return std::nullopt;
    rest.remove_prefix(n);
  }
  if (!(rest.empty() || rest == "Z" || rest == "+00:00")) return std::nullopt;
  const std::int64_t days = daysFromCivil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d));
  return static_cast<double>(days * 86400 + h * 3600 + mi * 60 + s) + fraction;
}

struct Column {
  std::size_t index = 0;
  std::string name;        // as the header writes it, lower case
  double toMetres = 1.0;   // altitude columns
};

struct Header {
  std::array<std::optional<Column>, kRoles> columns;
  std::size_t fieldCount = 0;
  const std::optional<Column>& operator[](Role r) const { return columns[static_cast<std::size_t>(r)]; }
};

const ColumnName* findName(std::string_view field) {
  const std::string l = lowered(field);
  for (const ColumnName& n : kNames)
    if (n.name == l) return &n;
  return nullptr;
}

// The columns of a header, or the reason it is not an ADS-B header.
Result<Header> readHeader(const std::vector<std::string_view>& fields, AltitudeUnit unit, const std::string& at) {
  Header h;
  h.fieldCount = fields.size();
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const ColumnName* n = findName(fields[i]);
    if (!n || n->role == Role::Unused) continue;
    auto& slot = h.columns[static_cast<std::size_t>(n->role)];
    if (slot)
      return fail(ErrorCode::Malformed, at + "columns '" + slot->name + "' and '" + printable(fields[i]) +
                                            "' say the same thing; keep one");
    Column c{i, std::string(n->name), 1.0};
    if (n->role == Role::Baro || n->role == Role::Geo) {
      if (unit == AltitudeUnit::Feet || (unit == AltitudeUnit::FromColumnName && n->unit == NamedUnit::Feet))
        c.toMetres = kMetresPerFoot;
      if (unit == AltitudeUnit::FromColumnName && n->unit == NamedUnit::Unnamed)
        return fail(ErrorCode::InvalidArgument, at + "column '" + c.name +
                                                    "' does not say its unit: give the altitude unit (ft or m)");
    }
    slot = std::move(c);
  }
  for (Role r : {Role::Time, Role::Lat, Role::Lon})
    if (!h[r]) return fail(ErrorCode::Malformed, at + "header has no time, latitude or longitude column");
  if (!h[Role::Baro] && !h[Role::Geo])
    return fail(ErrorCode::Malformed, at + "header has no altitude column (baroaltitude, geoaltitude, ...)");
  return h;
}

struct Aircraft {
  std::string icao24;
  std::string callsign;
  std::size_t rows = 0;   // rows naming it
  std::size_t fixes = 0;  // of those, rows that gave a position and altitude
};

std::string unitName(double toMetres) { return toMetres == 1.0 ? "m" : "ft"; }

std::string fixes(std::size_t n) { return std::to_string(n) + (n == 1 ? " fix" : " fixes"); }

std::string listAircraft(const std::vector<Aircraft>& aircraft, bool fixes) {
  std::string out;
  for (std::size_t i = 0; i < aircraft.size() && i < kMaxListedAircraft; ++i) {
    const Aircraft& a = aircraft[i];
    out += (i ? ", " : "") + a.icao24 + (a.callsign.empty() ? "" : " " + a.callsign) + " (" +
           std::to_string(fixes ? a.fixes : a.rows) + (fixes ? " fixes)" : " rows)");
  }
  if (aircraft.size() > kMaxListedAircraft)
    out += " and " + std::to_string(aircraft.size() - kMaxListedAircraft) + " more";
  return out;
}

}  // namespace

bool isAdsbCsvHeader(std::string_view headerLine) {
  if (headerLine.size() > kMaxAdsbLineBytes) return false;  // not split: its fields would be unbounded
  std::vector<std::string_view> fields;
  splitFields(headerLine, fields);
  bool time = false, lat = false, lon = false;
  for (std::string_view f : fields) {
    const ColumnName* n = findName(f);
    if (!n) continue;
    time = time || n->role == Role::Time;
    lat = lat || n->role == Role::Lat;
    lon = lon || n->role == Role::Lon;
  }
  return time && lat && lon;
}

Result<ParsedFlight> parseAdsbCsv(std::string_view text, std::string_view sourceName, const ReadOptions& options) {
  detail::Warnings warnings(sourceName);
  const std::string& src = warnings.source();
  const std::string wanted = lowered(detail::trimSpace(options.icao24));
  if (!options.icao24.empty() && !isIcao24(wanted))
    return fail(ErrorCode::InvalidArgument,
                src + ": icao24 '" + printable(options.icao24) + "' is not 1 to 6 hex digits");

  std::optional<Header> header;
  std::optional<Error> error;
  std::vector<std::string_view> fields;
  std::vector<Aircraft> aircraft;
  std::unordered_map<std::string, std::size_t> aircraftIndex;
  std::size_t rows = 0;
  detail::TimeOrder order;
  ParsedFlight flight;
  std::vector<double> unixTimes_s;  // of the kept fixes
  std::optional<std::size_t> kept;  // index in aircraft of the one read

  detail::forEachLine(text, [&](std::string_view rawLine, std::size_t lineNo) {
    if (error) return;
    const std::string at = src + ":" + std::to_string(lineNo) + ": ";
    if (rawLine.size() > kMaxAdsbLineBytes) {
      error = Error{ErrorCode::TooLarge, at + "line of " + std::to_string(rawLine.size()) + " bytes, at most " +
                                             std::to_string(kMaxAdsbLineBytes) + " read"};
      return;
    }
    const std::string_view line = detail::trimSpace(rawLine);
    if (line.empty() || line.front() == '#') return;
    splitFields(line, fields);
    if (!header) {
      auto h = readHeader(fields, options.altitudeUnit, at);
      if (!h) {
        error = h.error();
        return;
      }
      if (!wanted.empty() && !(*h)[Role::Icao24]) {
        error = Error{ErrorCode::InvalidArgument, at + "no 'icao24' column to pick aircraft " + wanted + " by"};
        return;
      }
      header = std::move(*h);
      return;
    }
    const Header& h = *header;
    if (++rows > kMaxAdsbRows) {
      error = Error{ErrorCode::TooLarge, at + "more than " + std::to_string(kMaxAdsbRows) + " rows"};
      return;
    }
    if (fields.size() != h.fieldCount) {
      error = Error{ErrorCode::Malformed, at + std::to_string(fields.size()) + " fields, the header has " +
                                             std::to_string(h.fieldCount)};
      return;
    }
    const auto field = [&](Role r) { return fields[h[r]->index]; };
    const auto bad = [&](Role r, std::string_view why, ErrorCode code = ErrorCode::Malformed) {
      error = Error{code, at + "field '" + h[r]->name + "': '" + printable(field(r)) + "' " + std::string(why)};
    };

    // The aircraft: rows of others are counted, and only read when no
    // aircraft was chosen (to count their fixes for the error).
    std::string icao;
    if (h[Role::Icao24]) {
      icao = lowered(field(Role::Icao24));
      if (isEmpty(icao)) {
        warnings.add(WarningKind::EmptyField, lineNo, "field 'icao24': empty, row skipped");
        return;
      }
      if (!isIcao24(icao)) {
        bad(Role::Icao24, "is not 1 to 6 hex digits");
        return;
      }
    }
    auto [it, added] = aircraftIndex.try_emplace(icao, aircraft.size());
    if (added) {
      if (aircraft.size() == kMaxAdsbAircraft) {
        error = Error{ErrorCode::TooLarge, at + "more than " + std::to_string(kMaxAdsbAircraft) + " aircraft"};
        return;
      }
      aircraft.push_back(Aircraft{icao, {}, 0, 0});
    }
    Aircraft& craft = aircraft[it->second];
    ++craft.rows;
    if (h[Role::Callsign] && craft.callsign.empty())
      craft.callsign = printable(detail::trimSpace(field(Role::Callsign)).substr(0, kMaxCallsignChars));
    if (!wanted.empty() && icao != wanted) return;

    std::optional<double> values[kRoles];
    for (Role r : {Role::Time, Role::Lat, Role::Lon, Role::Geo, Role::Baro}) {
      if (!h[r] || isEmpty(field(r))) continue;
      const std::string_view f = field(r);
      if ((r == Role::Geo || r == Role::Baro) && lowered(f) == "ground") continue;
      auto& v = values[static_cast<std::size_t>(r)];
      v = detail::parseDecimal(f);
      if (!v && r == Role::Time) v = isoTime(f);
      if (!v) {
        bad(r, r == Role::Time ? "is neither Unix seconds nor an ISO 8601 UTC time" : "is not a number");
        return;
      }
      if (r == Role::Geo || r == Role::Baro) *v *= h[r]->toMetres;
      const auto [lo, hi] = r == Role::Time  ? std::pair{0.0, kMaxUnixTime_s}
                            : r == Role::Lat ? std::pair{-90.0, 90.0}
                            : r == Role::Lon ? std::pair{-180.0, 180.0}
                            : r == Role::Geo ? std::pair{kMinGeoAltitude_m, kMaxGeoAltitude_m}
                                             : std::pair{kMinBaroAltitude_m, kMaxBaroAltitude_m};
      if (*v < lo || *v > hi) {
        bad(r, "is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" +
                   (r == Role::Geo || r == Role::Baro ? " m" : ""),
            ErrorCode::InvalidArgument);
        return;
      }
    }
    bool onGround = false;
    if (h[Role::OnGround] && !isEmpty(field(Role::OnGround))) {
      const std::string g = lowered(field(Role::OnGround));
      onGround = g == "true" || g == "t" || g == "1";
      if (!onGround && g != "false" && g != "f" && g != "0") {
        bad(Role::OnGround, "is not true, false, 1 or 0");
        return;
      }
    }
    for (Role r : {Role::Time, Role::Lat, Role::Lon})
      if (!values[static_cast<std::size_t>(r)]) {
        warnings.add(WarningKind::EmptyField, lineNo, "field '" + h[r]->name + "': empty, row skipped");
        return;
      }
    const auto& geo = values[static_cast<std::size_t>(Role::Geo)];
    const auto& baro = values[static_cast<std::size_t>(Role::Baro)];
    const bool saysGround = (h[Role::Baro] && lowered(field(Role::Baro)) == "ground") ||
                            (h[Role::Geo] && lowered(field(Role::Geo)) == "ground");
    if (!geo && (saysGround || (onGround && !baro))) {
      warnings.add(WarningKind::OnGround, lineNo, "on the ground without a geometric altitude, row skipped");
      return;
    }
    if (!geo && !baro) {
      const Role r = h[Role::Geo] ? Role::Geo : Role::Baro;
      const std::string also = h[Role::Geo] && h[Role::Baro] ? " and '" + h[Role::Baro]->name + "'" : "";
      warnings.add(WarningKind::EmptyField, lineNo, "field '" + h[r]->name + "'" + also + ": empty, row skipped");
      return;
    }
    ++craft.fixes;
    if (!kept) kept = it->second;
    if (*kept != it->second) return;  // a second aircraft: an error at the end
    const double t_s = *values[static_cast<std::size_t>(Role::Time)];
    if (!order.accept(t_s, lineNo, warnings)) return;
    const double alt_m = geo ? *geo : weather::pressureToGeometricAltitude_m(*baro);
    ++(geo ? flight.geometricAltitudeFixes : flight.barometricAltitudeFixes);
    unixTimes_s.push_back(t_s);
    flight.fixLines.push_back(lineNo);
    flight.fixes.push_back(Fix{0, {{*values[static_cast<std::size_t>(Role::Lat)],
                                    *values[static_cast<std::size_t>(Role::Lon)], alt_m},
                                   0, 0, 0}});
  });

  if (error) return tl::unexpected(*error);
  if (!header) return fail(ErrorCode::Malformed, src + ": no header line");
  if (!wanted.empty() && !aircraftIndex.count(wanted))
    return fail(ErrorCode::InvalidArgument,
                src + ": no aircraft " + wanted + " in the file" +
                    (aircraft.empty() ? "" : "; it holds " + listAircraft(aircraft, false)));
  if (wanted.empty() && aircraft.size() > 1)
    return fail(ErrorCode::InvalidArgument, src + ": " + std::to_string(aircraft.size()) +
                                                " aircraft in the file, pick one by its icao24: " +
                                                listAircraft(aircraft, true));
  if (flight.fixes.size() < 2)
    return fail(ErrorCode::InvalidArgument, src + ": " + std::to_string(flight.fixes.size()) +
                                                " usable fixes, a flight needs at least two");

  const double start_s = std::floor(unixTimes_s.front());
  for (std::size_t i = 0; i < flight.fixes.size(); ++i) flight.fixes[i].time_s = unixTimes_s[i] - start_s;
  flight.startUtc_s = static_cast<std::int64_t>(start_s);
  const Header& h = *header;
  std::string source;
  if (flight.geometricAltitudeFixes)
    source = "geometric ('" + h[Role::Geo]->name + "', " + unitName(h[Role::Geo]->toMetres) + ") for " +
             fixes(flight.geometricAltitudeFixes);
  if (flight.barometricAltitudeFixes)
    source += (source.empty() ? "" : "; ") + std::string("barometric ('") + h[Role::Baro]->name + "', " +
              unitName(h[Role::Baro]->toMetres) + ") to geometric by the ICAO standard atmosphere for " +
              fixes(flight.barometricAltitudeFixes);
  flight.altitudeSource = std::move(source);
  flight.attitudeRateWindow_s = kAdsbRateWindow_s;
  deriveAttitude(flight, flight.attitudeRateWindow_s);
  flight.attitudeFromTrack = true;
  if (kept) {
    const Aircraft& a = aircraft[*kept];
    flight.aircraft = "icao24 " + a.icao24 + (a.callsign.empty() ? "" : ", callsign " + a.callsign);
  }
  flight.warnings = warnings.finish();
  return flight;
}

}  // namespace sky::flight
