// GET /api/radar (see radar_api.hpp).
#include "sky/server/radar_api.hpp"

#include <algorithm>
#include <cmath>

#include "sky/server/conditions_api.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/radar.hpp"

namespace sky::server {

namespace {

// Level 11 (about 5 km) is what a renderer's 120 km subscription holds; a
// radar picture of 300 km in 256 cells has cells of 2.3 km.
constexpr int kRadarTileLevel = kDefaultConditionsLevel;

}  // namespace

nlohmann::json radarJson(const LiveWeather& weather, const RadarQuery& q) {
  const double clock_s = weather.clockNow();
  const weather::RadarSite site{q.lat_deg, q.lon_deg, q.alt_m, q.range_km * 1000.0, q.tilt_deg, q.size};
  const weather::WeatherSnapshot snapshot =
      subscriberSnapshot(weather, clock_s, {q.lat_deg, q.lon_deg, site.range_m}, kRadarTileLevel);
  const std::vector<float> dbz = weather::radarPicture(snapshot.layers, weather::snapshotLookup(snapshot, clock_s), site);
  nlohmann::json rows = nlohmann::json::array();
  double most = weather::kNoEcho_dBZ;
  std::size_t echoes = 0;
  for (int i = 0; i < q.size; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < q.size; ++j) {
      const double v = dbz[static_cast<std::size_t>(i) * q.size + j];
      if (v <= weather::kNoEcho_dBZ) {
        row.push_back(nullptr);
        continue;
      }
      ++echoes;
      most = std::max(most, v);
      row.push_back(std::round(v * 10) / 10);
    }
    rows.push_back(std::move(row));
  }
  return {{"weather_clock_s", clock_s},
          {"lat_deg", q.lat_deg},
          {"lon_deg", q.lon_deg},
          {"alt_m", q.alt_m},
          {"range_km", q.range_km},
          {"tilt_deg", q.tilt_deg},
          {"size", q.size},
          {"cell_m", 2 * site.range_m / q.size},
          {"tile_level", snapshot.tileLevel},
          {"echoes", echoes},
          {"max_dbz", echoes ? nlohmann::json(std::round(most * 10) / 10) : nlohmann::json(nullptr)},
          {"laws", "rain and hail: Z = 200 R^1.6 (Marshall-Palmer); snow: Z = 2000 R^2 (Gunn-Marshall); sleet: their mean"},
          // Rows from north to south, columns from west to east; null: no
          // echo, or past the range.
          {"dbz", std::move(rows)}};
}

}  // namespace sky::server
