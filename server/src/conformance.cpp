// GET /api/conformance (see conformance.hpp).
#include "sky/server/conformance.hpp"

#include "query_number.hpp"
#include "sky/geo/geodetic.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "sky/server/live_weather.hpp"
#include "sky/server/metar_changes.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/weather/clock.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/region.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {

namespace {

struct Layer {
  std::uint32_t id = 0;
  int oktas = 0;
  double base_m = 0;
};

// The lowest base with 5 oktas or more; fog (its slot) is an obscuration
// whose visibility the check compares instead.
std::optional<double> ceilingOf(const std::vector<Layer>& layers) {
  std::optional<double> c;
  for (const Layer& l : layers)
    if (l.id != kMetarFogSlot && l.oktas >= 5 && (!c || l.base_m < *c)) c = l.base_m;
  return c;
}

nlohmann::json layersJson(const std::vector<Layer>& layers) {
  nlohmann::json a = nlohmann::json::array();
  for (const Layer& l : layers) a.push_back({{"id", l.id}, {"oktas", l.oktas}, {"base_m", l.base_m}});
  return a;
}

nlohmann::json optional(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

// A pilot's eye over the station's ground (the visibility a METAR reports).
constexpr double kEyeHeight_m = 2;

// The visibility a station reports (its fog and precipitation slots as
// mapped: metar.hpp) or a renderer draws at a point (the point query's
// extinction), m; none: 10 km or more, no obscuration in the weather.
std::optional<double> clearOrLess(double extinction_perm) {
  const double v = weather::koschmiederVisibility_m(extinction_perm);
  return v < kClearVisibility_m ? std::optional<double>(v) : std::nullopt;
}
std::optional<double> reportedVisibility(const std::vector<weather::CloudLayer>& layers) {
  double extinction_perm = 0;
  for (const auto& l : layers) {
    if (l.id == kMetarFogSlot) extinction_perm += weather::kCloudExtinctionPerDensity_perm * l.coverage * l.density;
    if (l.id == kMetarPrecipitationSlot)
      extinction_perm += weather::kPrecipitationExtinctionPerDensity_perm * l.coverage * l.density;
  }
  return clearOrLess(extinction_perm);
}
std::optional<double> drawnVisibility(const weather::PointWeather& pw) { return clearOrLess(pw.extinction_perm); }

}  // namespace

double visibilityTolerance_m(double visibility_m) {
  if (visibility_m <= 600) return 50;
  return (visibility_m <= 1500 ? 0.1 : 0.2) * visibility_m;
}

int oktas(double cover) {
  if (!(cover > 0)) return 0;
  if (cover >= 1) return 8;
  return std::clamp(static_cast<int>(std::lround(cover * 8)), 1, 7);
}

Result<ConformanceQuery> parseConformanceQuery(std::string_view query) {
  ConformanceQuery q;
  const auto pairs = forEachQueryPair(query, [&](std::string_view key, std::string_view value) -> Result<void> {
    Result<double> v = 0.0;
    if (key == "stations") {
      if (!(v = queryNumber(key, value, 0, 10000))) return tl::unexpected(v.error());
      q.maxStations = static_cast<std::size_t>(*v);
    } else if (key == "grid_points") {
      if (!(v = queryNumber(key, value, 0, 2000))) return tl::unexpected(v.error());
      q.gridPoints = static_cast<std::size_t>(*v);
    } else if (key == "lat_deg") {
      if (!(v = queryNumber(key, value, -90, 90))) return tl::unexpected(v.error());
      q.lat_deg = *v;
    } else if (key == "lon_deg") {
      if (!(v = queryNumber(key, value, -180, 180))) return tl::unexpected(v.error());
      q.lon_deg = *v;
    } else if (key == "clock_s") {
      if (!(v = queryNumber(key, value, -weather::kMaxAskedClock_s, weather::kMaxAskedClock_s)))
        return tl::unexpected(v.error());
      q.clock_s = *v;
    } else if (key == "radius_m") {
      if (!(v = queryNumber(key, value, 1, 2e7))) return tl::unexpected(v.error());
      q.radius_m = *v;
    } else {
      return fail(ErrorCode::InvalidArgument, "query: unknown key '" + std::string(key) + "'");
    }
    return {};
  });
  if (!pairs) return tl::unexpected(pairs.error());
  if (q.lat_deg.has_value() != q.lon_deg.has_value() || q.lat_deg.has_value() != (q.radius_m > 0))
    return fail(ErrorCode::InvalidArgument, "lat_deg, lon_deg, radius_m: give all three or none");
  return q;
}

nlohmann::json conformanceJson(const LiveWeather& weather, std::span<const Station> stations,
                               const ConformanceQuery& q) {
  const double clock_s = q.clock_s.value_or(weather.clockNow());
  const std::vector<weather::CloudLayer> globals = weather.layersAt(clock_s);
  const std::vector<weather::Region> regions = weather.regionsAt(clock_s);
  const std::vector<weather::CloudLayer> table = snapshotLayers(globals, regions);
  const auto field = weather.fieldAt(clock_s);
  auto inArea = [&](double lat, double lon) {
    return !q.lat_deg || geo::geodesicDistance_m(*q.lat_deg, *q.lon_deg, lat, lon) <= q.radius_m;
  };

  // The points: station regions, then forecast grid points.
  struct StationPoint {
    const weather::Region* region;
    std::string icao;
    std::optional<double> elevation_m;
  };
  std::vector<StationPoint> stationPoints;
  std::size_t stationsInArea = 0;
  for (const auto& r : regions) {
    if (r.id < kMetarRegionFirst || r.id > kMetarRegionLast || !inArea(r.centerLat_deg, r.centerLon_deg)) continue;
    ++stationsInArea;
    if (stationPoints.size() >= q.maxStations) continue;
    std::string icao;
    std::optional<double> elevation_m;
    // The region's centre is the station's (its longitude normalised).
    for (const Station& s : stations)
      if (std::abs(s.lat_deg - r.centerLat_deg) < 1e-9 && std::abs(std::remainder(s.lon_deg - r.centerLon_deg, 360.0)) < 1e-9) {
        icao = s.icao;
        elevation_m = s.elevation_m;
      }
    stationPoints.push_back({&r, icao, elevation_m});
  }
  struct GridPoint {
    double lat, lon;
    int i, j;
  };
  std::vector<GridPoint> gridPoints;
  const ForecastLayer* gridOf = nullptr;
  if (field && q.gridPoints > 0) {
    gridOf = &field->forecast().layers().front();
    const GribGrid& g = gridOf->steps.front().cover->grid;
    std::vector<GridPoint> all;
    for (int j = 0; j < g.nj; ++j)
      for (int i = 0; i < g.ni; ++i) {
        const LatLon at = gridLatLon(g, i, j);
        if (inArea(at.lat_deg, at.lon_deg)) all.push_back({at.lat_deg, at.lon_deg, i, j});
      }
    const std::size_t stride = std::max<std::size_t>(1, (all.size() + q.gridPoints - 1) / q.gridPoints);
    for (std::size_t k = 0; k < all.size() && gridPoints.size() < q.gridPoints; k += stride) gridPoints.push_back(all[k]);
  }

  // The tiles of every point's cell, as a renderer's snapshot has them.
  std::set<std::uint64_t> cellSet;
  for (const auto& s : stationPoints)
    cellSet.insert(weather::cellAt(s.region->centerLat_deg, s.region->centerLon_deg, kConformanceLevel));
  for (const auto& g : gridPoints) cellSet.insert(weather::cellAt(g.lat, g.lon, kConformanceLevel));
  const std::vector<std::uint64_t> cells(cellSet.begin(), cellSet.end());
  weather::WeatherSnapshot snapshot;
  snapshot.weatherClock_s = clock_s;
  snapshot.layers = table;
  snapshot.tileLevel = kConformanceLevel;
  snapshot.tiles = deriveTiles(cells, table, regions, field.get());
  for (weather::CoverageTile& t : snapshot.tiles) {
    t.coverage = weather::dequantizeUnit(weather::quantizeUnit(t.coverage));
    t.density = weather::dequantizeUnit(weather::quantizeUnit(t.density));
  }
  const weather::CoverageLookup lookup = weather::snapshotLookup(snapshot, clock_s);
  auto drawnAt = [&](double lat, double lon) {
    std::vector<Layer> out;
    for (const auto& l : table) {
      if (weather::isPrecipitation(l.type)) continue;  // not cloud: its visibility is checked
      const auto tile = lookup(l, lat, lon);
      const double cover = tile ? tile->coverage : l.coverage;
      if (const int o = oktas(cover); o > 0) out.push_back({l.id, o, l.base_m});
    }
    return out;
  };

  nlohmann::json stationRows = nlohmann::json::array();
  std::size_t stationsOk = 0;
  for (const auto& s : stationPoints) {
    const weather::Region& r = *s.region;
    std::vector<Layer> reported;
    for (const auto& l : r.layers)
      if (l.id >= kMetarFogSlot && l.id <= kMetarLastSlot && oktas(l.coverage) > 0)
        reported.push_back({l.id, oktas(l.coverage), l.base_m});
    // A renderer at the station gets the table made round it (its own
    // report's bases for the slots only stations have): the bases drawn.
    const weather::CellCentre here{r.centerLat_deg, r.centerLon_deg};
    const std::vector<weather::CloudLayer> local = snapshotLayers(globals, regions, &here);
    std::vector<Layer> drawn = drawnAt(r.centerLat_deg, r.centerLon_deg);
    for (Layer& l : drawn)
      for (const auto& t : local)
        if (t.id == l.id) l.base_m = t.base_m;
    // Per layer id in either: the okta difference.
    std::map<std::uint32_t, std::pair<int, int>> byId;
    for (const Layer& l : reported) byId[l.id].first = l.oktas;
    for (const Layer& l : drawn) byId[l.id].second = l.oktas;
    int worst = 0;
    for (const auto& [id, p] : byId) worst = std::max(worst, std::abs(p.second - p.first));
    const auto cr = ceilingOf(reported), cd = ceilingOf(drawn);
    const bool ceilingOk = (!cr && !cd) || (cr && cd && std::abs(*cr - *cd) <= kCeilingTolerance_m);
    // Visibility at a pilot's eye over the station's ground (the station
    // table's elevation; for a station it does not know, the fog's base),
    // through the same point query the CIGI answer uses.
    const std::optional<double> vr = reportedVisibility(r.layers);
    double ground_m = 0;
    for (const auto& l : r.layers)
      if (l.id == kMetarFogSlot || l.id == kMetarPrecipitationSlot) ground_m = l.base_m;
    ground_m = s.elevation_m.value_or(ground_m);
    const std::optional<double> vd =
        drawnVisibility(weather::weatherAt(local, lookup, r.centerLat_deg, r.centerLon_deg, ground_m + kEyeHeight_m));
    const bool visibilityOk = (!vr && !vd) || (vr && vd && std::abs(*vd - *vr) <= visibilityTolerance_m(*vr));
    const bool ok = worst <= kOktaTolerance && ceilingOk && visibilityOk;
    stationsOk += ok;
    stationRows.push_back({{"region_id", r.id},
                           {"icao", s.icao.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.icao)},
                           {"lat_deg", r.centerLat_deg},
                           {"lon_deg", r.centerLon_deg},
                           {"reported", {{"layers", layersJson(reported)}, {"ceiling_m", optional(cr)}, {"visibility_m", optional(vr)}}},
                           {"drawn", {{"layers", layersJson(drawn)}, {"ceiling_m", optional(cd)}, {"visibility_m", optional(vd)}}},
                           {"oktas_off", worst},
                           {"ceiling_off_m", cr && cd ? nlohmann::json(*cd - *cr) : nlohmann::json(nullptr)},
                           {"visibility_off_m", vr && vd ? nlohmann::json(*vd - *vr) : nlohmann::json(nullptr)},
                           {"visibility_ok", visibilityOk},
                           {"ok", ok}});
  }

  nlohmann::json gridRows = nlohmann::json::array();
  std::size_t gridOk = 0;
  if (field)
    for (const GridPoint& g : gridPoints) {
      nlohmann::json layers = nlohmann::json::array();
      int worst = 0;
      bool any = false;
      for (const ForecastLayer& fl : field->forecast().layers()) {
        const float cover = field->forecast().coverage(fl, g.lat, g.lon, field->valid_unix());
        if (std::isnan(cover)) continue;
        any = true;
        const auto tile = lookup(fl.layer, g.lat, g.lon);
        const int want = oktas(cover), got = oktas(tile ? tile->coverage : 0);
        worst = std::max(worst, std::abs(got - want));
        layers.push_back({{"id", fl.layer.id}, {"forecast_oktas", want}, {"drawn_oktas", got}});
      }
      if (!any) continue;
      // Within a station's reach its report overrides the forecast: the
      // difference is the report's, and the station's row checks it.
      double station = 0;
      for (const auto& r : regions)
        if (r.replacesAllLayers) station = std::max(station, weather::regionWeight(r, g.lat, g.lon));
      const bool ok = worst <= kOktaTolerance || station > 0;
      gridOk += ok;
      gridRows.push_back({{"lat_deg", g.lat}, {"lon_deg", g.lon}, {"i", g.i}, {"j", g.j}, {"layers", layers},
                          {"oktas_off", worst}, {"station_weight", station}, {"ok", ok}});
    }

  return {{"clock_s", clock_s},
          {"tile_level", kConformanceLevel},
          {"tolerances", {{"oktas", kOktaTolerance}, {"ceiling_m", kCeilingTolerance_m},
                          {"visibility", "WMO-No. 8: 50 m up to 600 m, 10 % to 1500 m, 20 % above"}}},
          {"forecast", field ? nlohmann::json(field->forecast().name()) : nlohmann::json(nullptr)},
          {"stations", stationRows},
          {"grid", gridRows},
          {"summary",
           {{"stations", stationRows.size()},
            {"stations_in_area", stationsInArea},
            {"stations_ok", stationsOk},
            {"grid_points", gridRows.size()},
            {"grid_ok", gridOk}}}};
}

}  // namespace sky::server
