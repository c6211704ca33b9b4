// A loaded forecast's storms flash. GFS's convective layer is cumulus whose
// tiles blend into cumulonimbus where its cover is large (forecast_test.cpp);
// no layer of the forecast is of cumulonimbus type, so the storm process must
// let the tiles decide (lightning_service.cpp). It once skipped every weather
// without a cumulonimbus layer or region, and a forecast's storms never
// flashed.
#include <algorithm>
#include <chrono>

#include <gtest/gtest.h>

#include "forecast_samples.hpp"
#include "sky/server/lightning_service.hpp"
#include "sky/server/live_weather.hpp"

namespace sky::server {
namespace {

TEST(ForecastLightning, AGfsConvectiveStormFlashesWhereItsCoverIs) {
  const WallClock::time_point t0{std::chrono::seconds(1000)};
  LiveWeather weather{Scenario{}, t0, [t0] { return t0; }, [] { return std::int64_t{1700000000000}; }};
  const auto fc = loadSample(kGfs);
  LoadedForecast loaded;
  loaded.placement = {weather.clockNow(), fc->firstValid_unix()};
  loaded.forecast = fc;
  loaded.files = {{"key", "gfs.grib2"}};
  ASSERT_TRUE(weather.loadForecast(std::move(loaded), "test", "grib"));
  for (const auto& l : weather.layersAt(weather.clockNow()))
    ASSERT_NE(l.type, weather::CloudType::Cumulonimbus) << "the test needs a forecast without a cumulonimbus layer";

  // The grid point of the largest convective cover (message 5), where the
  // layer's tiles are cumulonimbus.
  const auto conv = gribGetData(kGfs, 5);
  const auto big = std::max_element(conv.begin(), conv.end(), [](const Point& a, const Point& b) { return a.value < b.value; });
  ASSERT_GT(big->value, 70);
  const weather::SphericalCap area{big->lat, big->lon, 20'000};
  LightningService service({6.0, 7});  // 6 a minute per 100 km^2: tens in a minute
  const double clock_s = weather.clockNow();
  EXPECT_TRUE(service.tick(weather, clock_s, {&area, 1}).empty());  // the first tick only starts the clock
  const std::vector<weather::LightningFlash> flashes = service.tick(weather, clock_s + 60, {&area, 1});
  std::printf("[ storm    ] %zu flashes in 60 s over the S2 cells of a %.0f km area at the GFS convective maximum "
              "(%.0f %% at %.2f, %.2f)\n",
              flashes.size(), area.radius_m / 1000, big->value, big->lat, big->lon);
  ASSERT_FALSE(flashes.empty());
  for (const auto& f : flashes) {
    EXPECT_TRUE(flashReaches(area, f));
    EXPECT_GE(f.time_s, clock_s);
    EXPECT_LT(f.time_s, clock_s + 60);
  }
}

}  // namespace
}  // namespace sky::server
