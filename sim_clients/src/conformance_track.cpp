// Conformance along a replayed flight (see conformance_track.hpp).
#include "sky/sim/conformance_track.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

#include "sky/core/assert.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/weather/clock.hpp"

namespace sky::sim {

namespace {

using nlohmann::json;

// Flight times and frame numbers a replay can reach (a week of flight).
constexpr double kMaxFlightTime_s = 7 * 86400.0;
constexpr double kMaxFrame = 1e12;
// Altitudes a flight may have (below the Dead Sea to past any aircraft's
// ceiling): the check asks in two dimensions, the altitude is only shown.
constexpr double kMinAlt_m = -1000, kMaxAlt_m = 100000;
constexpr std::size_t kMaxNameBytes = 16;

Result<double> numberField(const json& o, const char* key, double lo, double hi, const std::string& where) {
  const auto it = o.find(key);
  if (it == o.end()) return fail(ErrorCode::InvalidArgument, where + key + ": missing");
  if (!it->is_number()) return fail(ErrorCode::InvalidArgument, where + key + ": not a number");
  const double v = it->get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) {
    char text[160];
    std::snprintf(text, sizeof text, "%s: %.9g is outside [%g, %g]", key, v, lo, hi);
    return fail(ErrorCode::InvalidArgument, where + text);
  }
  return v;
}

std::optional<double> optionalNumber(const json& o, const char* key) {
  const auto it = o.find(key);
  if (it == o.end() || !it->is_number()) return std::nullopt;
  const double v = it->get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

// A station's name as the tables show it: letters, digits and '-' (an ICAO
// code is four letters or digits), anything else '?', at most kMaxNameBytes.
std::string stationName(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, kMaxNameBytes))
    out.push_back(std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '?');
  return out;
}

json optionalJson(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::string fixed(double v, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

}  // namespace

Result<TrackPoint> parseTrackLine(std::string_view line) {
  if (line.size() > kMaxTrackLine_bytes)
    return fail(ErrorCode::InvalidArgument, "line of " + std::to_string(line.size()) + " bytes (at most " +
                                                std::to_string(kMaxTrackLine_bytes) + ")");
  const json o = json::parse(line, nullptr, false);
  if (o.is_discarded() || !o.is_object()) return fail(ErrorCode::InvalidArgument, "not a JSON object");
  TrackPoint p;
  const std::string where;
  auto frame = numberField(o, "frame", 0, kMaxFrame, where);
  if (!frame) return tl::unexpected(frame.error());
  p.frame = static_cast<std::uint64_t>(*frame);
  auto t = numberField(o, "host_time_s", -kMaxFlightTime_s, kMaxFlightTime_s, where);
  if (!t) return tl::unexpected(t.error());
  p.flight_s = *t;
  auto lat = numberField(o, "lat_deg", -90, 90, where);
  if (!lat) return tl::unexpected(lat.error());
  p.lat_deg = *lat;
  auto lon = numberField(o, "lon_deg", -540, 540, where);
  if (!lon) return tl::unexpected(lon.error());
  p.lon_deg = std::remainder(*lon, 360.0);
  auto alt = numberField(o, "alt_m", kMinAlt_m, kMaxAlt_m, where);
  if (!alt) return tl::unexpected(alt.error());
  p.alt_m = *alt;
  auto clock = numberField(o, "weather_clock_s", -weather::kMaxAskedClock_s, weather::kMaxAskedClock_s, where);
  if (!clock) return tl::unexpected(clock.error());
  p.weatherClock_s = *clock;
  return p;
}

Result<std::vector<TrackPoint>> sampleTrack(std::istream& in, const std::string& name, const TrackSampling& sampling) {
  SKY_ASSERT(sampling.every_s > 0);
  std::vector<TrackPoint> kept;
  std::optional<double> last_s;
  std::string line;
  std::size_t lineNo = 0;
  // Reads a line without letting it grow past the bound.
  auto readLine = [&]() -> std::optional<bool> {
    line.clear();
    char c;
    bool any = false;
    while (in.get(c)) {
      any = true;
      if (c == '\n') return true;
      if (line.size() >= kMaxTrackLine_bytes) return std::nullopt;
      line.push_back(c);
    }
    return any;
  };
  for (;;) {
    const auto got = readLine();
    ++lineNo;
    const std::string where = name + ":" + std::to_string(lineNo) + ": ";
    if (!got) return fail(ErrorCode::InvalidArgument, where + "line longer than " + std::to_string(kMaxTrackLine_bytes) + " bytes");
    if (!*got) break;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto p = parseTrackLine(line);
    if (!p) return fail(ErrorCode::InvalidArgument, where + p.error().detail);
    if (last_s && p->flight_s < *last_s)
      return fail(ErrorCode::InvalidArgument, where + "host_time_s " + fixed(p->flight_s, 3) +
                                                  " goes back (the line before: " + fixed(*last_s, 3) + ")");
    last_s = p->flight_s;
    if (kept.size() >= sampling.maxPoints) continue;  // the rest is read for its errors only
    if (kept.empty() || p->flight_s >= kept.back().flight_s + sampling.every_s) kept.push_back(*p);
  }
  if (in.bad()) return fail(ErrorCode::Io, name + ": read failed");
  return kept;
}

std::string conformanceTarget(const TrackPoint& at, const TrackCheckOptions& o) {
  char text[320];
  std::snprintf(text, sizeof text,
                "/api/conformance?lat_deg=%.7f&lon_deg=%.7f&radius_m=%.1f&clock_s=%.3f&stations=%zu&grid_points=%zu",
                at.lat_deg, at.lon_deg, o.radius_m, at.weatherClock_s, o.stations, o.gridPoints);
  return text;
}

Result<PointCheck> readPointCheck(const TrackPoint& at, std::string_view body, std::size_t maxStations) {
  const json doc = json::parse(body, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return fail(ErrorCode::InvalidArgument, "answer: not a JSON object");
  PointCheck out;
  out.at = at;
  const auto stations = doc.find("stations");
  if (stations == doc.end() || !stations->is_array()) return fail(ErrorCode::InvalidArgument, "answer: stations: not an array");
  const std::size_t keep = std::min(maxStations, kMaxStationsPerPoint);
  for (std::size_t i = 0; i < stations->size() && i < keep; ++i) {
    const json& s = (*stations)[i];
    const std::string where = "answer: stations[" + std::to_string(i) + "].";
    if (!s.is_object()) return fail(ErrorCode::InvalidArgument, where + ": not an object");
    StationCheck c;
    auto lat = numberField(s, "lat_deg", -90, 90, where);
    if (!lat) return tl::unexpected(lat.error());
    auto lon = numberField(s, "lon_deg", -540, 540, where);
    if (!lon) return tl::unexpected(lon.error());
    c.lat_deg = *lat;
    c.lon_deg = std::remainder(*lon, 360.0);
    auto off = numberField(s, "oktas_off", 0, 8, where);
    if (!off) return tl::unexpected(off.error());
    c.oktasOff = static_cast<int>(*off);
    const auto ok = s.find("ok");
    if (ok == s.end() || !ok->is_boolean()) return fail(ErrorCode::InvalidArgument, where + "ok: not true or false");
    c.ok = ok->get<bool>();
    const auto icao = s.find("icao");
    if (icao != s.end() && icao->is_string()) {
      c.name = stationName(icao->get_ref<const std::string&>());
    } else {
      const auto id = optionalNumber(s, "region_id");
      c.name = "region " + (id && *id >= 0 && *id < 1e9 ? std::to_string(static_cast<long>(*id)) : std::string("?"));
    }
    for (const auto& [side, ceiling, visibility] :
         {std::tuple{"reported", &c.ceilingReported_m, &c.visibilityReported_m},
          std::tuple{"drawn", &c.ceilingDrawn_m, &c.visibilityDrawn_m}}) {
      const auto part = s.find(side);
      if (part == s.end() || !part->is_object()) continue;
      *ceiling = optionalNumber(*part, "ceiling_m");
      // A visibility is a range: a negative or absurd one is not shown.
      const auto v = optionalNumber(*part, "visibility_m");
      if (v && *v >= 0 && *v <= 1e9) *visibility = v;
    }
    c.distance_km = geo::geodesicDistance_m(at.lat_deg, at.lon_deg, c.lat_deg, c.lon_deg) / 1000;
    out.stations.push_back(std::move(c));
  }
  const auto grid = doc.find("grid");
  if (grid != doc.end()) {
    if (!grid->is_array()) return fail(ErrorCode::InvalidArgument, "answer: grid: not an array");
    for (const json& g : *grid) {
      if (!g.is_object()) return fail(ErrorCode::InvalidArgument, "answer: grid: an entry is not an object");
      ++out.gridPoints;
      const auto ok = g.find("ok");
      if (ok != g.end() && ok->is_boolean() && ok->get<bool>()) ++out.gridOk;
      if (const auto off = optionalNumber(g, "oktas_off"); off && *off >= 0 && *off <= 8)
        out.worstGridOktasOff = std::max(out.worstGridOktasOff, static_cast<int>(*off));
    }
  }
  return out;
}

namespace {

// What the summary counts over the whole flight.
struct Totals {
  std::set<std::string> stationsMet, stationsFailed;
  std::size_t stationChecks = 0, stationChecksOk = 0, pointsInReach = 0;
  std::size_t gridPoints = 0, gridOk = 0;
  int worstOktasOff = 0;
  double worstCeilingOff_m = 0;
  double worstVisibilityOff_m = 0;
};

Totals totalsOf(const std::vector<PointCheck>& checks) {
  Totals t;
  for (const PointCheck& p : checks) {
    t.pointsInReach += !p.stations.empty() || p.gridPoints > 0;
    for (const StationCheck& s : p.stations) {
      t.stationsMet.insert(s.name);
      ++t.stationChecks;
      t.stationChecksOk += s.ok;
      if (!s.ok) t.stationsFailed.insert(s.name);
      t.worstOktasOff = std::max(t.worstOktasOff, s.oktasOff);
      if (s.ceilingReported_m && s.ceilingDrawn_m)
        t.worstCeilingOff_m = std::max(t.worstCeilingOff_m, std::abs(*s.ceilingDrawn_m - *s.ceilingReported_m));
      if (s.visibilityReported_m && s.visibilityDrawn_m)
        t.worstVisibilityOff_m =
            std::max(t.worstVisibilityOff_m, std::abs(*s.visibilityDrawn_m - *s.visibilityReported_m));
    }
    t.gridPoints += p.gridPoints;
    t.gridOk += p.gridOk;
  }
  return t;
}

}  // namespace

json trackJson(const std::vector<PointCheck>& checks, const TrackCheckOptions& o) {
  json points = json::array();
  for (const PointCheck& p : checks) {
    json stations = json::array();
    for (const StationCheck& s : p.stations)
      stations.push_back({{"name", s.name},
                          {"lat_deg", s.lat_deg},
                          {"lon_deg", s.lon_deg},
                          {"distance_km", s.distance_km},
                          {"ok", s.ok},
                          {"oktas_off", s.oktasOff},
                          {"ceiling_reported_m", optionalJson(s.ceilingReported_m)},
                          {"ceiling_drawn_m", optionalJson(s.ceilingDrawn_m)},
                          {"visibility_reported_m", optionalJson(s.visibilityReported_m)},
                          {"visibility_drawn_m", optionalJson(s.visibilityDrawn_m)}});
    points.push_back({{"frame", p.at.frame},
                      {"flight_s", p.at.flight_s},
                      {"lat_deg", p.at.lat_deg},
                      {"lon_deg", p.at.lon_deg},
                      {"alt_m", p.at.alt_m},
                      {"weather_clock_s", p.at.weatherClock_s},
                      {"stations", stations},
                      {"grid_points", p.gridPoints},
                      {"grid_ok", p.gridOk},
                      {"grid_worst_oktas_off", p.worstGridOktasOff}});
  }
  const Totals t = totalsOf(checks);
  return {{"radius_m", o.radius_m},
          {"points", points},
          {"summary",
           {{"points", checks.size()},
            {"points_in_reach", t.pointsInReach},
            {"stations_met", t.stationsMet.size()},
            {"stations_failed", std::vector<std::string>(t.stationsFailed.begin(), t.stationsFailed.end())},
            {"station_checks", t.stationChecks},
            {"station_checks_ok", t.stationChecksOk},
            {"worst_oktas_off", t.worstOktasOff},
            {"worst_ceiling_off_m", t.worstCeilingOff_m},
            {"worst_visibility_off_m", t.worstVisibilityOff_m},
            {"grid_points", t.gridPoints},
            {"grid_ok", t.gridOk}}}};
}

std::string trackMarkdown(const std::vector<PointCheck>& checks, const TrackCheckOptions& o) {
  const Totals t = totalsOf(checks);
  std::string md = "Conformance along the flight: the weather server's check (`GET /api/conformance`) at " +
                   std::to_string(checks.size()) + " points of the flight, each at the weather clock its frame drew, " +
                   "stations and forecast grid points within " + fixed(o.radius_m / 1000, 0) + " km.\n\n";
  md += "Stations met: " + std::to_string(t.stationsMet.size()) + "; checks passed: " +
        std::to_string(t.stationChecksOk) + " of " + std::to_string(t.stationChecks) +
        "; worst layer difference: " + std::to_string(t.worstOktasOff) + " oktas; worst ceiling difference: " +
        fixed(t.worstCeilingOff_m, 0) + " m; worst visibility difference: " + fixed(t.worstVisibilityOff_m, 0) +
        " m; forecast grid points passed: " + std::to_string(t.gridOk) + " of " +
        std::to_string(t.gridPoints) + ".\n\n";
  if (t.pointsInReach == 0) return md + "No station or forecast grid point lies within reach of the flight.\n";
  md += "| flight s | position | stations (distance km: ceiling reported / drawn m, oktas off; visibility reported / "
        "drawn m where under 10 km) | grid points ok |\n";
  md += "|---|---|---|---|\n";
  auto ceiling = [](const std::optional<double>& c) { return c ? fixed(*c, 0) : std::string("none"); };
  for (const PointCheck& p : checks) {
    if (p.stations.empty() && p.gridPoints == 0) continue;
    std::string cells;
    for (const StationCheck& s : p.stations) {
      if (!cells.empty()) cells += "; ";
      cells += (s.ok ? "" : "**") + s.name + " (" + fixed(s.distance_km, 0) + ": " + ceiling(s.ceilingReported_m) +
               " / " + ceiling(s.ceilingDrawn_m) + ", " + std::to_string(s.oktasOff) +
               (s.visibilityReported_m || s.visibilityDrawn_m
                    ? "; visibility " + ceiling(s.visibilityReported_m) + " / " + ceiling(s.visibilityDrawn_m)
                    : std::string()) +
               ")" + (s.ok ? "" : " FAILS**");
    }
    md += "| " + fixed(p.at.flight_s, 0) + " | " + fixed(p.at.lat_deg, 3) + ", " + fixed(p.at.lon_deg, 3) + " | " +
          (cells.empty() ? std::string("none") : cells) + " | " + std::to_string(p.gridOk) + " of " +
          std::to_string(p.gridPoints) + " |\n";
  }
  return md;
}

}  // namespace sky::sim
