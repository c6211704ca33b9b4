// GET /api/radar: the query's checks, the beam's geometry against the 4/3
// Earth formula worked by hand, and the picture over steady rain: every
// cell the beam crosses below the rain's top echoes Marshall-Palmer's dBZ
// of the rate the point query (and so a renderer) gives there, none above
// it, none past the range.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "sky/server/conditions_api.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/radar_api.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/radar.hpp"

namespace sky::server {
namespace {

TEST(RadarApi, TheQueryNamesWhatIsWrong) {
  auto q = parseRadarQuery("lat=46&lon=14");
  ASSERT_TRUE(q) << q.error().detail;
  EXPECT_EQ(q->range_km, 100);
  EXPECT_EQ(q->tilt_deg, 0.5);
  EXPECT_EQ(q->size, kDefaultRadarSize);
  q = parseRadarQuery("lat_deg=46&lon_deg=14&range_km=250&tilt_deg=1.5&size=64&alt_m=300");
  ASSERT_TRUE(q) << q.error().detail;
  EXPECT_EQ(q->range_km, 250);
  EXPECT_EQ(q->size, 64);
  const std::pair<const char*, const char*> bad[] = {
      {"lon=14", "lat: missing"},
      {"lat=46", "lon: missing"},
      {"lat=46&lon=14&range_km=0", "range_km: must be above 0"},
      {"lat=46&lon=14&range_km=301", "range_km: 301 is not in"},
      {"lat=46&lat_deg=46&lon=14", "given twice"},
      {"lat=46&lon=14&size=100000", "size: 100000 is not in"},
      {"lat=46&lon=14&size=64.5", "size: not an integer"},
      {"lat=46&lon=14&tilt_deg=nan", "tilt_deg"},
      {"lat=46&lon=14&dbz=1", "unknown key 'dbz'"},
  };
  for (const auto& [query, what] : bad) {
    const auto r = parseRadarQuery(query);
    ASSERT_FALSE(r) << query;
    EXPECT_NE(r.error().detail.find(what), std::string::npos) << query << ": " << r.error().detail;
  }
}

TEST(RadarApi, TheBeamRisesAsOverTheFourThirdsEarth) {
  // h = sqrt(r^2 + (kR)^2 + 2 r kR sin(tilt)) - kR, kR = 4/3 x 6371 km:
  // at 0.5 degrees and 100 km, 872.7 m from the tilt and 588.6 m from the
  // curvature (r^2 / 2kR), to within a metre.
  EXPECT_NEAR(weather::radarBeamHeight_m(100000, 0.5), 100000 * std::sin(0.5 * std::numbers::pi / 180) + 1e10 / (2 * 4.0 / 3 * 6371000), 1.0);
  EXPECT_NEAR(weather::radarBeamHeight_m(0, 3), 0, 1e-9);
  // Level beam: the Earth falls away, r^2 / 2kR.
  EXPECT_NEAR(weather::radarBeamHeight_m(50000, 0), 2.5e9 / (2 * 4.0 / 3 * 6371000), 0.01);
  // Ground distance a little short of the slant range: the arc under the
  // beam, kR asin(r cos(tilt) / (kR + h)), 18.7 m short at 100 km.
  const double kR = 4.0 / 3 * 6371000, h = weather::radarBeamHeight_m(100000, 0.5);
  const double g = weather::radarGroundDistance_m(100000, 0.5);
  EXPECT_NEAR(g, kR * std::asin(100000 * std::cos(0.5 * std::numbers::pi / 180) / (kR + h)), 1e-6);
  EXPECT_LT(g, 100000);
  EXPECT_GT(g, 99950);
}

TEST(RadarApi, SteadyRainEchoesItsRateBelowItsTop) {
  const WallClock::time_point t0{std::chrono::seconds(1000)};
  LiveWeather weather{Scenario{}, t0, [t0] { return t0; }, [] { return std::int64_t{1700000000000}; }};
  constexpr double kRate = 10, kTop = 2000;
  weather::CloudLayer rain;
  rain.id = 2;
  rain.type = weather::CloudType::Rain;
  rain.base_m = 0;
  rain.thickness_m = kTop;
  rain.coverage = 1;
  rain.density = weather::precipitationDensityForRate(weather::CloudType::Rain, kRate);
  weather::CloudLayer ns = rain;
  ns.id = 1;
  ns.type = weather::CloudType::Nimbostratus;
  ns.base_m = 1000;
  ns.thickness_m = 3000;
  ns.density = 1;
  ASSERT_TRUE(weather.submit({{SetLayer{ns, {}}, SetLayer{rain, {}}}, "test", "api"}));

  RadarQuery q;
  q.lat_deg = 46;
  q.lon_deg = 14;
  q.range_km = 150;
  q.size = 64;
  const nlohmann::json j = radarJson(weather, q);
  ASSERT_EQ(j["dbz"].size(), 64u);
  // What the point query answers at the ground by the radar, as a renderer
  // holding the stream's 8-bit tiles would.
  ConditionsQuery c;
  c.lat_deg = q.lat_deg;
  c.lon_deg = q.lon_deg;
  c.alt_m = 10;
  const nlohmann::json point = conditionsJson(weather, c);
  ASSERT_FALSE(point["precipitation"].is_null()) << point.dump();
  const double rate = point["precipitation"]["rate_mmph"].get<double>();
  EXPECT_NEAR(rate, kRate, 0.12 * kRate);  // the density's 8 bits
  const double expected = 10 * std::log10(200 * std::pow(rate, 1.6));
  const double cell = j["cell_m"].get<double>();
  int echoed = 0, clearAbove = 0, pastRange = 0;
  for (int i = 0; i < 64; ++i)
    for (int k = 0; k < 64; ++k) {
      const double north = (32 - i - 0.5) * cell, east = (k + 0.5 - 32) * cell;
      const double ground = std::hypot(north, east);
      const nlohmann::json& v = j["dbz"][i][k];
      const double beam = weather::radarBeamHeight_m(ground, q.tilt_deg);
      if (ground > q.range_km * 1000) {
        EXPECT_TRUE(v.is_null());
        ++pastRange;
      } else if (beam < kTop - 100) {
        ASSERT_FALSE(v.is_null()) << "cell " << i << "," << k << " at " << ground << " m, beam " << beam << " m";
        EXPECT_NEAR(v.get<double>(), expected, 0.1);
        ++echoed;
      } else if (beam > kTop + 100) {
        EXPECT_TRUE(v.is_null()) << "cell " << i << "," << k << " beam " << beam << " m above the rain's top";
        ++clearAbove;
      }
    }
  std::printf("[ radar    ] 10 mm/h rain to 2 km: %d cells echo %.1f dBZ (point query %.2f mm/h), %d cells above "
              "its top, %d past the range\n",
              echoed, expected, rate, clearAbove, pastRange);
  EXPECT_GT(echoed, 1000);
  EXPECT_GT(clearAbove, 100);
  EXPECT_GT(pastRange, 100);
  EXPECT_NEAR(j["max_dbz"].get<double>(), expected, 0.1);
}

}  // namespace
}  // namespace sky::server
