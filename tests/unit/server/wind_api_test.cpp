// GET /api/wind: the query's checks, and the arrows over a NAM forecast: they
// vary over the area, and each is the wind GET /api/conditions (and so a
// renderer's CIGI answer) gives at that point and height.
#include <gtest/gtest.h>

#include "grib_tools.hpp"
#include "sky/server/conditions_api.hpp"
#include "sky/server/forecast.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/wind_api.hpp"

namespace sky::server {
namespace {

TEST(WindApi, TheQueryNamesWhatIsWrong) {
  auto q = parseWindQuery("lat_deg=38&lon_deg=-97&alt_m=5000");
  ASSERT_TRUE(q);
  EXPECT_EQ(q->radius_m, 100000);
  q = parseWindQuery("lat_deg=38&lon_deg=-97&alt_m=5000&radius_m=300000");
  ASSERT_TRUE(q);
  EXPECT_EQ(q->radius_m, 300000);
  const std::pair<const char*, const char*> bad[] = {
      {"lat_deg=38&lon_deg=-97", "alt_m: missing"},
      {"lat_deg=38&lon_deg=-97&alt_m=5000&radius_m=10", "radius_m: 10 is not in"},
      {"lat_deg=38&lat_deg=39&lon_deg=-97&alt_m=1", "lat_deg: given twice"},
      {"lat_deg=38&lon_deg=-97&alt_m=1&level=3", "unknown key 'level'"},
      {"lat_deg=38&lon_deg=-97&alt_m=x", "alt_m: 'x' is not a number"},
      {"lat_deg", "is not key=value"},
  };
  for (const auto& [query, what] : bad) {
    const auto r = parseWindQuery(query);
    ASSERT_FALSE(r) << query;
    EXPECT_NE(r.error().detail.find(what), std::string::npos) << query << ": " << r.error().detail;
  }
}

TEST(WindApi, ArrowsOverANamForecastAreWhatThePointQueryAnswers) {
  const WallClock::time_point t0{std::chrono::seconds(1000)};
  LiveWeather weather{Scenario{}, t0, [t0] { return t0; }, [] { return std::int64_t{1700000000000}; }};
  auto file = readGrib(readBytes(kNam), "nam", forecastWants);
  ASSERT_TRUE(file);
  auto fc = Forecast::fromGrib({&*file}, "nam.grib2");
  ASSERT_TRUE(fc);
  LoadedForecast loaded;
  loaded.placement = {weather.clockNow(), fc->firstValid_unix()};
  loaded.forecast = std::make_shared<const Forecast>(std::move(*fc));
  loaded.files = {{"key", "nam.grib2"}};
  ASSERT_TRUE(weather.loadForecast(std::move(loaded), "test", "grib"));

  WindQuery q;
  q.lat_deg = 38;
  q.lon_deg = -97;
  q.radius_m = 400000;
  q.alt_m = 6000;
  const nlohmann::json j = windJson(weather, q);
  const auto& arrows = j["arrows"];
  ASSERT_GT(arrows.size(), 50u);
  EXPECT_LE(arrows.size(), kMaxWindArrows);
  EXPECT_FALSE(j["varying_layers"].empty());
  double lo = 1e9, hi = -1e9;
  for (const auto& a : arrows) {
    lo = std::min(lo, a["speed_mps"].get<double>());
    hi = std::max(hi, a["speed_mps"].get<double>());
  }
  std::printf("%zu arrows at 6000 m over 400 km of NAM: %.1f to %.1f m/s\n", arrows.size(), lo, hi);
  EXPECT_GT(hi - lo, 3.0);
  for (std::size_t k = 0; k < arrows.size(); k += 37) {
    const auto& a = arrows[k];
    ConditionsQuery c;
    c.lat_deg = a["lat_deg"];
    c.lon_deg = a["lon_deg"];
    c.alt_m = q.alt_m;
    const nlohmann::json point = conditionsJson(weather, c);
    SCOPED_TRACE(a.dump() + " vs " + point.dump());
    // The two queries' areas differ (400 km and the point's), so their wind
    // tiles may be of other levels, each smoothed by the same kernel.
    EXPECT_NEAR(a["speed_mps"].get<double>(), point["wind"]["speed_mps"].get<double>(), 0.5);
  }
}

}  // namespace
}  // namespace sky::server
