// Weather model: validation names the bad field; tiling covers caps at the
// poles and across the antimeridian; advection moves air downwind.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/advection.hpp"
#include "sky/weather/clock.hpp"
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

// Property test: random points inside the cap lie in the covering, and the
// covering's area stays within a stated factor of the cap's.
void coverageProperty(const SphericalCap& cap, std::uint32_t seed) {
  constexpr std::size_t kMaxCells = 4000;
  const int level = levelForRadius(cap.radius_m, kMaxCells);
  const auto cells = coverCap(cap, level, kMaxCells * 2);
  ASSERT_LE(cells.size(), kMaxCells) << "levelForRadius underestimated at level " << level;
  const std::set<std::uint64_t> set(cells.begin(), cells.end());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    // Uniform in area on the (locally flat) cap: distance ~ r sqrt(u).
    const double az = 360.0 * u(rng), dist = cap.radius_m * std::sqrt(u(rng)) * 0.999;
    const SurfacePoint p = advect({cap.centerLat_deg, cap.centerLon_deg}, {1.0, az + 180.0, 0}, dist);
    ASSERT_TRUE(set.count(cellAt(p.lat_deg, p.lon_deg, level)))
        << "point " << p.lat_deg << "," << p.lon_deg << " outside the covering of cap at " << cap.centerLat_deg
        << "," << cap.centerLon_deg;
  }
  double area_m2 = 0;
  for (auto c : cells) area_m2 += cellArea_m2(c);
  const double capArea_m2 = 2 * M_PI * 6371008.8 * 6371008.8 * (1 - std::cos(cap.radius_m / 6371008.8));
  // A covering by cells of edge e exceeds the cap by about its perimeter x e;
  // levelForRadius keeps e small against r, so twice the cap bounds it.
  EXPECT_GE(area_m2, capArea_m2 * 0.99);
  EXPECT_LE(area_m2, capArea_m2 * 2.0) << "level " << level << ", " << cells.size() << " cells";
}

TEST(Tiling, RandomPointsAreCoveredEverywhere) {
  coverageProperty({0, 0, 100000}, 1);           // equator
  coverageProperty({90, 0, 100000}, 2);          // north pole
  coverageProperty({-90, 0, 100000}, 3);         // south pole
  coverageProperty({-12, 180, 100000}, 4);       // across the antimeridian
  coverageProperty({65, -179.95, 30000}, 5);     // antimeridian, high latitude, small cap
}

TEST(Tiling, LevelForRadiusGetsCoarserForLargerAreas) {
  EXPECT_GT(levelForRadius(10000, 4000), levelForRadius(100000, 4000));
  EXPECT_GT(levelForRadius(100000, 4000), levelForRadius(1000000, 4000));
  EXPECT_EQ(levelForRadius(1.0, 4000, 13), 13);
}

TEST(Advection, MatchesHandComputedDisplacements) {
  // Along the equator (a geodesic of radius a): 100 km east is 100000/a rad.
  SurfacePoint p = advect({0, 10}, {10, 270, 0}, 10000);
  EXPECT_NEAR(p.lat_deg, 0, 1e-12);
  EXPECT_NEAR(p.lon_deg, 10 + 100000.0 / 6378137.0 * 180 / M_PI, 1e-9);
  // Across the north pole: from 89.9N 0E blowing north (wind from 180) twice
  // the distance to the pole lands at 89.9N 180E. Near the pole the meridian's
  // radius of curvature is a^2/b = 6399593.626 m, so 0.1 deg is 11169.3 m.
  const double toPole_m = 0.1 * M_PI / 180 * 6399593.626;
  p = advect({89.9, 0}, {1, 180, 0}, 2 * toPole_m);
  EXPECT_NEAR(p.lat_deg, 89.9, 1e-6);
  EXPECT_NEAR(std::abs(p.lon_deg), 180, 1e-6);
  // Local north at 180E points over the pole again: the same wind from 180
  // there carries the parcel back to where it started.
  const SurfacePoint back = advect(p, {1, 180, 0}, 2 * toPole_m);
  EXPECT_NEAR(back.lat_deg, 89.9, 1e-6);
  EXPECT_NEAR(back.lon_deg, 0, 1e-6);
}

TEST(WeatherClock, AReanchoredCopyAgreesWithTheOriginal) {
  // The server's clock, and a renderer's copy re-anchored from a Heartbeat
  // that carried the server's clock at wall time t1: both give the same
  // weather time at any later wall time.
  const auto t0 = WallClock::time_point{} + std::chrono::seconds(1000);
  const WeatherClock server(3600.0, 10.0, t0);
  const auto t1 = t0 + std::chrono::milliseconds(2500);
  const WeatherClock renderer(server.at(t1), server.rate(), t1);
  const auto t2 = t1 + std::chrono::seconds(7);
  EXPECT_DOUBLE_EQ(server.at(t2), 3600.0 + 10.0 * 9.5);
  EXPECT_NEAR(renderer.at(t2), server.at(t2), 1e-9);
  const WeatherClock paused(50.0, 0.0, t0);
  EXPECT_EQ(paused.at(t2), 50.0);
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

namespace sky::weather {
namespace {

// diffSnapshots against applyDelta on random pairs: whenever it gives a
// delta, applying it to `before` yields `after` exactly; it refuses what a
// delta cannot say; an unchanged snapshot gives an empty delta.
TEST(Delta, DiffThenApplyIsTheNewSnapshot) {
  std::mt19937 rng(11);
  auto makeLayer = [&](std::uint32_t id) {
    CloudLayer l;
    l.id = id;
    l.thickness_m = 500;
    l.coverage = std::uniform_int_distribution<int>(0, 4)(rng) / 4.0;
    return l;
  };
  const std::uint64_t cells[] = {cellAt(0, 0, 10), cellAt(1, 1, 10), cellAt(2, 2, 10), cellAt(3, 3, 10)};
  auto makeSnapshot = [&] {
    WeatherSnapshot s;
    s.tileLevel = 10;
    for (std::uint32_t id = 1; id <= 4; ++id) {
      if (rng() % 4 == 0) continue;
      s.layers.push_back(makeLayer(id));
      if (rng() % 2)
        for (std::uint64_t c : cells)
          s.tiles.push_back({c, id, float(std::uniform_int_distribution<int>(0, 2)(rng)) / 2, 1.0f});
    }
    return s;
  };
  int deltas = 0, refused = 0;
  for (int i = 0; i < 2000; ++i) {
    const WeatherSnapshot before = makeSnapshot();
    WeatherSnapshot after = rng() % 3 == 0 ? before : makeSnapshot();
    after.weatherClock_s = 5;
    const auto d = diffSnapshots(before, after);
    if (!d) {
      ++refused;
      continue;
    }
    ++deltas;
    WeatherSnapshot applied = before;
    ASSERT_TRUE(applyDelta(applied, *d));
    ASSERT_EQ(applied.layers.size(), after.layers.size()) << i;
    for (std::size_t k = 0; k < after.layers.size(); ++k) {
      EXPECT_EQ(applied.layers[k].id, after.layers[k].id) << i;
      EXPECT_EQ(applied.layers[k].coverage, after.layers[k].coverage) << i;
    }
    auto sorted = [](std::vector<CoverageTile> t) {
      std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) {
        return std::pair{a.cellId, a.layerId} < std::pair{b.cellId, b.layerId};
      });
      return t;
    };
    EXPECT_EQ(sorted(applied.tiles), sorted(after.tiles)) << i;
    EXPECT_EQ(applied.tileLevel, after.tileLevel) << i;
    EXPECT_EQ(applied.weatherClock_s, 5);
  }
  EXPECT_GT(deltas, 500);
  EXPECT_GT(refused, 100);  // tiles dropped, reorders: snapshots then
  // Unchanged: nothing but the clock.
  const WeatherSnapshot s = makeSnapshot();
  const auto same = diffSnapshots(s, s);
  ASSERT_TRUE(same);
  EXPECT_TRUE(same->layers.empty() && same->tiles.empty() && same->removedLayerIds.empty());
}

}  // namespace
}  // namespace sky::weather
