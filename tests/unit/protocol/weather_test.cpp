// Weather model: validation names the bad field; tiling covers caps at the
// poles and across the antimeridian; advection moves air downwind.
#include <gtest/gtest.h>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/advection.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::weather {
namespace {

CloudLayer goodLayer() {
  CloudLayer l;
  l.id = 3;
  l.base_m = 1500;
  l.thickness_m = 1000;
  l.coverage = 0.5;
  return l;
}

TEST(Layer, ValidationNamesTheField) {
  EXPECT_TRUE(validate(goodLayer()));
  CloudLayer l = goodLayer();
  l.coverage = 1.4;
  auto r = validate(l);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("layer 3: coverage"), std::string::npos) << r.error().detail;
  l = goodLayer();
  l.thickness_m = 0;
  r = validate(l);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("thickness_m"), std::string::npos);
}

TEST(CloudTypes, NamesRoundTripWithCigiValues) {
  EXPECT_EQ(static_cast<int>(*cloudTypeFromString("cumulus")), 7);
  EXPECT_EQ(static_cast<int>(*cloudTypeFromString("stratus")), 10);
  EXPECT_EQ(toString(CloudType::Cumulonimbus), "cumulonimbus");
  EXPECT_FALSE(cloudTypeFromString("cumulous"));
}

// Every point sampled inside the cap must fall in a cell of the covering.
void expectCovers(const SphericalCap& cap, int level) {
  const auto cells = coverCap(cap, level, 100000);
  ASSERT_FALSE(cells.empty());
  for (int i = 0; i < 36; ++i) {
    for (double frac : {0.0, 0.5, 0.95}) {
      double lat = 0, lon = 0;
      // Walk along azimuth i*10 deg using advection by a fake wind of 1 m/s.
      const SurfacePoint p = advect({cap.centerLat_deg, cap.centerLon_deg},
                                    LayerWind{1.0, i * 10.0 + 180.0, 0}, cap.radius_m * frac);
      lat = p.lat_deg;
      lon = p.lon_deg;
      const std::uint64_t c = cellAt(lat, lon, level);
      EXPECT_NE(std::find(cells.begin(), cells.end(), c), cells.end())
          << "point " << lat << "," << lon << " not covered";
    }
  }
}

TEST(Tiling, CoversCapsAtThePoleAndAcrossTheAntimeridian) {
  expectCovers({46.2, 12.8, 50000}, 9);
  expectCovers({89.99, 0, 50000}, 9);
  expectCovers({-89.99, 45, 50000}, 9);
  expectCovers({10, 179.99, 50000}, 9);
}

TEST(Advection, MovesDownwindBySpeedTimesTime) {
  // Wind from the west (270) at 10 m/s for 1000 s: 10 km east.
  const SurfacePoint p = advect({0, 0}, {10, 270, 0}, 1000);
  EXPECT_NEAR(p.lat_deg, 0, 1e-9);
  EXPECT_NEAR(geo::geodesicDistance_m(0, 0, p.lat_deg, p.lon_deg), 10000, 1e-6);
  EXPECT_GT(p.lon_deg, 0);
  // Across the antimeridian the longitude wraps.
  const SurfacePoint q = advect({0, 179.99}, {10, 270, 0}, 10000);
  EXPECT_LT(q.lon_deg, -179.0);
}

}  // namespace
}  // namespace sky::weather
