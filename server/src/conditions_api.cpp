// GET /api/conditions (see conditions_api.hpp).
#include "sky/server/conditions_api.hpp"

#include <algorithm>

#include "sky/server/live_weather.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/weather/air_field.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {

weather::WeatherSnapshot subscriberSnapshot(const LiveWeather& weather, double clock_s, const weather::SphericalCap& cap,
                                           int level, TileCache* cache) {
  const std::vector<weather::CloudLayer> layers = weather.layersAt(clock_s);
  const std::vector<weather::Region> regions = weather.regionsAt(clock_s);
  stream::Subscribe area;
  area.area = cap;
  area.tileLevel = level;
  const auto field = weather.fieldAt(clock_s);
  weather::WeatherSnapshot snapshot = buildSnapshot(area, layers, clock_s, kDefaultMaxCells, regions, cache, field.get());
  // As a subscriber holds them: the stream carries a tile's fractions in 8
  // bits (stream/messages.cpp).
  for (weather::CoverageTile& t : snapshot.tiles) {
    t.coverage = weather::dequantizeUnit(weather::quantizeUnit(t.coverage));
    t.density = weather::dequantizeUnit(weather::quantizeUnit(t.density));
    t.blend = weather::dequantizeUnit(weather::quantizeUnit(t.blend));
  }
  return snapshot;
}

nlohmann::json conditionsJson(const LiveWeather& weather, const ConditionsQuery& q) {
  const double clock_s = weather.clockNow();
  // The snapshot a subscriber of the point's surroundings would get: the
  // point's own cell (and its neighbours) at the asked level.
  const weather::WeatherSnapshot snapshot = subscriberSnapshot(weather, clock_s, {q.lat_deg, q.lon_deg, 1.0}, q.level);
  const auto field = weather.fieldAt(clock_s);
  const weather::PointWeather pw =
      weather::weatherAt(snapshot.layers, weather::snapshotLookup(snapshot, clock_s), q.lat_deg, q.lon_deg, q.alt_m,
                         weather::snapshotWindLookup(snapshot));
  // In fog: the densest layer at the point is a fog layer.
  const bool inFog = pw.layerId && std::any_of(snapshot.layers.begin(), snapshot.layers.end(), [&](const auto& l) {
                       return l.id == *pw.layerId && l.type == weather::CloudType::Fog;
                     });
  // The forecast's air where the snapshot has it, else the standard atmosphere's.
  const std::optional<weather::AirValues> air = weather::AirField(snapshot).at(q.lat_deg, q.lon_deg, q.alt_m);
  // Where each forecast layer's cover at the point comes from.
  nlohmann::json sources = nlohmann::json::object();
  if (field)
    for (const ForecastLayer& l : field->forecast().layers()) {
      const std::string src = field->forecast().sourceAt(l, q.lat_deg, q.lon_deg, field->valid_unix());
      if (!src.empty()) sources[std::to_string(l.layer.id)] = src;
    }
  return {{"lat_deg", q.lat_deg},
          {"lon_deg", q.lon_deg},
          {"alt_m", q.alt_m},
          {"clock_s", clock_s},
          {"tile_level", snapshot.tileLevel},
          {"wind",
           {{"speed_mps", pw.wind.speed_mps},
            {"from_deg", pw.wind.fromDirection_deg},
            {"vertical_mps", pw.wind.vertical_mps}}},
          {"cloud_density", pw.cloudDensity},
          // In cloud, fog or precipitation its Koschmieder range (what the
          // renderers draw and their CIGI answer gives); null in clear air,
          // whose haze the host sets.
          {"visibility_m", pw.extinction_perm > 0 ? nlohmann::json(weather::visibilityAt_m(pw)) : nlohmann::json(nullptr)},
          {"in_fog", inFog},
          {"precipitation",
           pw.precipitationType == weather::CloudType::None
               ? nlohmann::json(nullptr)
               : nlohmann::json{{"type", std::string(weather::toString(pw.precipitationType))},
                                {"rate_mmph", pw.precipitationRate_mmph},
                                {"reflectivity_dbz", weather::reflectivity_dBZ(pw.precipitationType, pw.precipitationRate_mmph)}}},
          {"layer_id", pw.layerId ? nlohmann::json(*pw.layerId) : nlohmann::json(nullptr)},
          {"air_temperature_c", air ? air->temperature_c : weather::isaTemperature_c(q.alt_m)},
          {"humidity_pct", air && air->humidity_pct >= 0 ? nlohmann::json(air->humidity_pct) : nlohmann::json(nullptr)},
          {"air_from", air ? "forecast" : "standard atmosphere"},
          {"pressure_hpa", weather::isaPressure_hpa(q.alt_m)},
          {"forecast_sources", sources}};
}

}  // namespace sky::server
