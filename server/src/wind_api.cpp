// GET /api/wind (see wind_api.hpp).
#include "sky/server/wind_api.hpp"

#include <cmath>

#include "query_number.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/wind_tiles.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::server {

Result<WindQuery> parseWindQuery(std::string_view query) {
  WindQuery q;
  bool lat = false, lon = false, alt = false, radius = false;
  if (query.size() > 512) return fail(ErrorCode::InvalidArgument, "query: longer than 512 bytes");
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
    const std::size_t eq = pair.find('=');
    if (eq == std::string_view::npos) return fail(ErrorCode::Malformed, "query: '" + std::string(pair) + "' is not key=value");
    const std::string_view key = pair.substr(0, eq), value = pair.substr(eq + 1);
    struct Key {
      std::string_view name;
      bool* seen;
      double* out;
      double lo, hi;
    };
    const Key keys[] = {{"lat_deg", &lat, &q.lat_deg, -90, 90},
                        {"lon_deg", &lon, &q.lon_deg, -180, 180},
                        {"alt_m", &alt, &q.alt_m, -1000, 20000},
                        {"radius_m", &radius, &q.radius_m, 1000, 2e6}};
    const Key* k = nullptr;
    for (const Key& c : keys)
      if (c.name == key) k = &c;
    if (!k)
      return fail(ErrorCode::InvalidArgument,
                  "query: unknown key '" + std::string(key) + "' (lat_deg, lon_deg, alt_m, radius_m)");
    if (*k->seen) return fail(ErrorCode::InvalidArgument, std::string(key) + ": given twice");
    *k->seen = true;
    const auto v = queryNumber(key, value, k->lo, k->hi);
    if (!v) return tl::unexpected(v.error());
    *k->out = *v;
  }
  if (!lat) return fail(ErrorCode::InvalidArgument, "lat_deg: missing");
  if (!lon) return fail(ErrorCode::InvalidArgument, "lon_deg: missing");
  if (!alt) return fail(ErrorCode::InvalidArgument, "alt_m: missing");
  return q;
}

nlohmann::json windJson(const LiveWeather& weather, const WindQuery& q) {
  const double clock_s = weather.clockNow();
  const std::vector<weather::CloudLayer> layers = weather.layersAt(clock_s);
  const std::vector<weather::Region> regions = weather.regionsAt(clock_s);
  const auto field = weather.fieldAt(clock_s);
  const weather::SphericalCap cap{q.lat_deg, q.lon_deg, q.radius_m};
  // The layer table and wind tiles a subscriber of this area gets.
  const weather::CellCentre centre{q.lat_deg, q.lon_deg};
  const std::vector<weather::CloudLayer> table = snapshotLayers(layers, regions, &centre);
  const WindTiles tiles = deriveWindTiles(cap, table, regions, field.get());
  const weather::WindField wind(tiles.level, tiles.tiles);
  const auto lookup = [&wind](const weather::CloudLayer& l, double lat, double lon) { return wind.windAt(l, lat, lon); };
  const Covering arrows = coverArea(cap, std::max(tiles.level, kWindTileLevel), kMaxWindArrows);
  nlohmann::json out = nlohmann::json::array();
  for (std::uint64_t cell : arrows.cells) {
    const weather::CellCentre c = weather::cellCentre(cell);
    const weather::PointWeather pw = weather::weatherAt(table, nullptr, c.lat_deg, c.lon_deg, q.alt_m, lookup);
    out.push_back({{"lat_deg", c.lat_deg},
                   {"lon_deg", c.lon_deg},
                   {"speed_mps", pw.wind.speed_mps},
                   {"from_deg", pw.wind.fromDirection_deg},
                   {"vertical_mps", pw.wind.vertical_mps}});
  }
  std::vector<std::uint32_t> varying;
  for (const auto& t : tiles.tiles)
    if (varying.empty() || varying.back() != t.layerId) varying.push_back(t.layerId);
  return {{"weather_clock_s", clock_s},
          {"alt_m", q.alt_m},
          {"arrow_level", arrows.level},
          {"wind_tile_level", tiles.level},
          {"varying_layers", varying},
          {"arrows", out}};
}

}  // namespace sky::server
