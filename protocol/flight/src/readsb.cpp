// readsb / tar1090 trace reader: the JSON traces readsb writes per aircraft
// (trace_full_<icao>.json, trace_recent_<icao>.json), gzip-compressed or
// not, parsed by nlohmann-json after size and nesting checks. Every rule is
// in flight.hpp; the columns follow readsb's README-json.md ("trace" rows).
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "inflate.hpp"
#include "reader_common.hpp"
#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"
#include "sky/weather/standard_atmosphere.hpp"

namespace sky::flight {

namespace {

using detail::printable;
using detail::WarningKind;
using nlohmann::json;

using detail::kMaxBaroAltitude_m;
using detail::kMaxGeoAltitude_m;
using detail::kMaxUnixTime_s;
using detail::kMetresPerFoot;
using detail::kMinBaroAltitude_m;
using detail::kMinGeoAltitude_m;
constexpr double kMaxOffset_s = 1.0e7;

// Columns of a trace row (readsb README-json.md, "trace"):
// [0] seconds after "timestamp", [1] lat, [2] lon, [3] altitude ft
// (barometric, or geometric when flags bit 3 is set) or "ground" or null,
// [4] ground speed kt, [5] track deg, [6] flags, [7] vertical rate fpm,
// [8] details object or null, [9] source type, [10] geometric altitude ft.
constexpr std::size_t kOffset = 0, kLat = 1, kLon = 2, kAlt = 3, kFlags = 6, kAltGeom = 10;
constexpr std::size_t kMinRowElements = 4;
// Flag bits of column 6 (readsb README-json.md).
constexpr long long kFlagStale = 1;          // no new position for a while: the last one repeated
constexpr long long kFlagNewLeg = 2;         // a new leg starts (a landing and take-off, or a long gap)
constexpr long long kFlagAltGeometric = 8;   // column 3 is geometric altitude

// Deepest nesting a trace needs: object > "trace" array > row > details
// object > a list in it (e.g. "mlat": [...]). A deeper document is refused
// before parsing, so nothing can recurse on attacker-chosen depth.
constexpr std::size_t kMaxDepth = 16;

// Depth of the deepest array/object in text, counted outside strings
// (stops counting once past limit).
std::size_t nestingDepth(std::string_view text, std::size_t limit) {
  std::size_t depth = 0, deepest = 0;
  bool inString = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') ++i;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

std::string lowered(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
  return out;
}

std::string fixes(std::size_t n) { return std::to_string(n) + (n == 1 ? " fix" : " fixes"); }

}  // namespace

Result<ParsedFlight> parseReadsbTrace(std::string_view bytes, std::string_view sourceName,
                                      const ReadOptions& options) {
  detail::Warnings warnings(sourceName);
  const std::string& src = warnings.source();
  std::string inflated;
  if (detail::isGzip(bytes)) {
    auto out = detail::inflateBounded(bytes, detail::Wrapper::Gzip, kMaxReadsbTraceBytes, src + ": gzip");
    if (!out) return tl::unexpected(out.error());
    inflated = std::move(*out);
    bytes = inflated;
  }
  if (bytes.size() > kMaxReadsbTraceBytes)
    return fail(ErrorCode::TooLarge, src + ": " + std::to_string(bytes.size()) + " bytes, at most " +
                                         std::to_string(kMaxReadsbTraceBytes) + " read");
  if (nestingDepth(bytes, kMaxDepth) > kMaxDepth)
    return fail(ErrorCode::Malformed, src + ": JSON nested deeper than " + std::to_string(kMaxDepth) +
                                          " levels; a readsb trace needs at most 5");
  const json doc = json::parse(bytes.begin(), bytes.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded())
    return fail(ErrorCode::Malformed, src + ": not JSON (or not UTF-8 JSON)");
  if (!doc.is_object()) return fail(ErrorCode::Malformed, src + ": JSON: the top level is not an object");

  const auto base = doc.find("timestamp");
  if (base == doc.end() || !base->is_number())
    return fail(ErrorCode::Malformed, src + ": JSON '/timestamp': missing or not a number (Unix seconds)");
  const double base_s = base->get<double>();
  if (!(base_s >= 0 && base_s <= kMaxUnixTime_s))
    return fail(ErrorCode::InvalidArgument, src + ": JSON '/timestamp': " + std::to_string(base_s) +
                                                " is outside [0, " + std::to_string(kMaxUnixTime_s) + "] s");
  std::string icao;
  if (const auto it = doc.find("icao"); it != doc.end()) {
    if (!it->is_string()) return fail(ErrorCode::Malformed, src + ": JSON '/icao': not a string");
    icao = lowered(printable(it->get<std::string>()));
  }
  if (!options.icao24.empty() && lowered(options.icao24) != icao)
    return fail(ErrorCode::InvalidArgument, src + ": the trace is of aircraft '" + icao + "', not " +
                                                printable(options.icao24));
  const auto trace = doc.find("trace");
  if (trace == doc.end() || !trace->is_array())
    return fail(ErrorCode::Malformed, src + ": JSON '/trace': missing or not an array");
  if (trace->size() > kMaxReadsbTraceRows)
    return fail(ErrorCode::TooLarge, src + ": JSON '/trace': " + std::to_string(trace->size()) +
                                         " rows, at most " + std::to_string(kMaxReadsbTraceRows) + " read");

  ParsedFlight flight;
  std::vector<double> unixTimes_s;
  detail::TimeOrder order;
  for (std::size_t i = 0; i < trace->size(); ++i) {
    const json& row = (*trace)[i];
    const std::string at = src + ": JSON '/trace/" + std::to_string(i);
    const auto bad = [&](std::size_t col, std::string_view field, std::string_view why,
                         ErrorCode code = ErrorCode::Malformed) {
      return fail(code, at + "/" + std::to_string(col) + "' (" + std::string(field) + "): " + std::string(why));
    };
    if (!row.is_array() || row.size() < kMinRowElements)
      return fail(ErrorCode::Malformed, at + "': not an array of at least " + std::to_string(kMinRowElements) +
                                            " elements");
    if (!row[kOffset].is_number()) return bad(kOffset, "seconds after timestamp", "not a number");
    const double offset_s = row[kOffset].get<double>();
    if (!(std::fabs(offset_s) <= kMaxOffset_s))
      return bad(kOffset, "seconds after timestamp", std::to_string(offset_s) + " s is outside [-1e7, 1e7]",
                 ErrorCode::InvalidArgument);
    long long flags = 0;
    if (row.size() > kFlags && !row[kFlags].is_null()) {
      if (!row[kFlags].is_number_integer()) return bad(kFlags, "flags", "not an integer");
      flags = row[kFlags].get<long long>();
    }
    const std::string path = "trace[" + std::to_string(i) + "]";
    if (flags & kFlagNewLeg && !flight.fixes.empty()) {
      warnings.add(WarningKind::NewLeg, 0,
                   path + ": a new leg starts (flags bit 1): a landing and take-off, or a long gap, "
                          "before this fix (kept)");
    }
    if (flags & kFlagStale) {
      warnings.add(WarningKind::Stale, 0, path + ": stale position (flags bit 0), fix skipped");
      continue;
    }
    std::optional<double> coord[2];
    for (std::size_t c : {kLat, kLon}) {
      const json& v = row[c];
      if (v.is_null()) continue;
      if (!v.is_number()) return bad(c, c == kLat ? "lat" : "lon", "not a number");
      const double limit = c == kLat ? 90.0 : 180.0;
      const double d = v.get<double>();
      if (!(std::fabs(d) <= limit))
        return bad(c, c == kLat ? "lat" : "lon", std::to_string(d) + " is outside [-" +
                                                      std::to_string(static_cast<int>(limit)) + ", " +
                                                      std::to_string(static_cast<int>(limit)) + "]",
                   ErrorCode::InvalidArgument);
      coord[c == kLat ? 0 : 1] = d;
    }
    if (!coord[0] || !coord[1]) {
      warnings.add(WarningKind::EmptyField, 0, path + ": no position (null lat or lon), fix skipped");
      continue;
    }
    // Geometric altitude: column 10, else column 3 when flags say so.
    std::optional<double> geo_m, baro_m;
    bool ground = false;
    const auto altitude = [&](std::size_t col, bool geometric) -> Result<std::optional<double>> {
      const json& v = row[col];
      const char* field = col == kAltGeom ? "alt_geom" : "alt_baro";
      if (v.is_null()) return std::optional<double>();
      if (v.is_string() && v.get_ref<const std::string&>() == "ground") {
        ground = true;
        return std::optional<double>();
      }
      if (!v.is_number()) return bad(col, field, "neither a number (ft) nor \"ground\"");
      const double m = v.get<double>() * kMetresPerFoot;
      const double lo = geometric ? kMinGeoAltitude_m : kMinBaroAltitude_m;
      const double hi = geometric ? kMaxGeoAltitude_m : kMaxBaroAltitude_m;
      if (!(m >= lo && m <= hi))
        return bad(col, field, std::to_string(m) + " m is outside [" + std::to_string(lo) + ", " +
                                   std::to_string(hi) + "] m", ErrorCode::InvalidArgument);
      return std::optional<double>(m);
    };
    const bool col3Geometric = (flags & kFlagAltGeometric) != 0;
    auto a3 = altitude(kAlt, col3Geometric);
    if (!a3) return tl::unexpected(a3.error());
    (col3Geometric ? geo_m : baro_m) = *a3;
    if (row.size() > kAltGeom) {
      auto a10 = altitude(kAltGeom, true);
      if (!a10) return tl::unexpected(a10.error());
      if (*a10) geo_m = *a10;
    }
    if (!geo_m && ground) {
      warnings.add(WarningKind::OnGround, 0, path + ": on the ground without a geometric altitude, fix skipped");
      continue;
    }
    if (!geo_m && !baro_m) {
      warnings.add(WarningKind::EmptyField, 0, path + ": no altitude (null), fix skipped");
      continue;
    }
    const double t_s = base_s + offset_s;
    if (!(t_s >= 0)) return bad(kOffset, "seconds after timestamp", "puts the fix before 1970");
    if (!order.accept(t_s, 0, warnings)) continue;
    const double alt_m = geo_m ? *geo_m : weather::pressureToGeometricAltitude_m(*baro_m);
    ++(geo_m ? flight.geometricAltitudeFixes : flight.barometricAltitudeFixes);
    unixTimes_s.push_back(t_s);
    flight.fixes.push_back(Fix{0, {{*coord[0], *coord[1], alt_m}, 0, 0, 0}});
  }
  if (flight.fixes.size() < 2)
    return fail(ErrorCode::InvalidArgument, src + ": " + std::to_string(flight.fixes.size()) +
                                                " usable fixes in '/trace', a flight needs at least two");
  const double start_s = std::floor(unixTimes_s.front());
  for (std::size_t i = 0; i < flight.fixes.size(); ++i) flight.fixes[i].time_s = unixTimes_s[i] - start_s;
  flight.startUtc_s = static_cast<std::int64_t>(start_s);
  std::string source;
  if (flight.geometricAltitudeFixes)
    source = "geometric ('alt_geom', ft) for " + fixes(flight.geometricAltitudeFixes);
  if (flight.barometricAltitudeFixes)
    source += (source.empty() ? "" : "; ") +
              std::string("barometric ('alt_baro', ft) to geometric by the ICAO standard atmosphere for ") +
              fixes(flight.barometricAltitudeFixes);
  flight.altitudeSource = std::move(source);
  flight.attitudeRateWindow_s = kAdsbRateWindow_s;
  deriveAttitude(flight, flight.attitudeRateWindow_s);
  flight.attitudeFromTrack = true;
  if (!icao.empty()) flight.aircraft = "icao24 " + icao;
  if (const auto r = doc.find("r"); r != doc.end() && r->is_string())
    flight.aircraft += (flight.aircraft.empty() ? "" : ", ") + std::string("registration ") +
                       printable(r->get<std::string>());
  flight.warnings = warnings.finish();
  return flight;
}

}  // namespace sky::flight
