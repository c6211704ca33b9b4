// Test builders shared by the server's region, tile-cache, area-frame and
// state-cell tests: a square region (CIGI Environmental Region Control
// shape, no rotation or rounding), a cloud layer stacked by its id, and a
// live weather on a test clock.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "sky/server/live_weather.hpp"
#include "sky/weather/region.hpp"

namespace sky::server::test {

inline weather::Region squareRegion(std::uint32_t id, double lat, double lon, double size_m, double transition_m,
                                    std::vector<weather::CloudLayer> layers) {
  weather::Region r;
  r.id = id;
  r.centerLat_deg = lat;
  r.centerLon_deg = lon;
  r.sizeX_m = size_m;
  r.sizeY_m = size_m;
  r.transition_m = transition_m;
  r.layers = std::move(layers);
  return r;
}

// Layer `id` 1000 m deep with its base at 1500 + 2000 * id m, density 0.8,
// a 10 m/s west wind.
inline weather::CloudLayer stackedLayer(std::uint32_t id, weather::CloudType type, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = type;
  l.base_m = 1500.0 + 2000.0 * id;
  l.thickness_m = 1000;
  l.coverage = coverage;
  l.density = 0.8;
  l.wind = {10, 270, 0};
  return l;
}

// A live weather whose wall clock the test moves (`now`), started at weather
// clock 1000 s, rate 1, with `layers`.
struct WeatherFixture {
  WallClock::time_point now{std::chrono::hours(1000)};
  std::int64_t unixMs = 1'700'000'000'000;
  LiveWeather weather;
  explicit WeatherFixture(std::vector<weather::CloudLayer> layers)
      : weather(
            [&] {
              Scenario s;
              s.clock = {1000.0, 1.0};
              s.layers = std::move(layers);
              return s;
            }(),
            now, [this] { return now; }, [this] { return unixMs; }) {}
  Result<AppliedChange> submit(std::vector<WeatherChange> changes) {
    return weather.submit(ChangeRequest{std::move(changes), "test", "api"});
  }
};

}  // namespace sky::server::test
