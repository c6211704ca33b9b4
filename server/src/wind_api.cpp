// GET /api/wind (see wind_api.hpp).
#include "sky/server/wind_api.hpp"

#include <cmath>

#include "sky/server/live_weather.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/wind_tiles.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::server {

nlohmann::json windJson(const LiveWeather& weather, const WindQuery& q) {
  const double clock_s = weather.clockNow();
  const std::vector<weather::CloudLayer> layers = weather.layersAt(clock_s);
  const std::vector<weather::Region> regions = weather.regionsAt(clock_s);
  const auto field = weather.fieldAt(clock_s);
  const weather::SphericalCap cap{q.lat_deg, q.lon_deg, q.radius_m};
  // The layer table and wind tiles a subscriber of this area gets.
  const weather::CellCentre centre{q.lat_deg, q.lon_deg};
  const std::vector<weather::CloudLayer> table = snapshotLayers(layers, regions, &centre, q.radius_m);
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
