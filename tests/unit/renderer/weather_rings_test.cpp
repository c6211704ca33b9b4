// The weather map's rings of detail (renderer/core/src/weather_field.*), the
// sampler the CPU reference uses and the GPU mirrors: weather the server sent
// 300 km from the camera, beyond the fine ring, reaches the renderer through
// the coarse ring (the fine ring alone, the map before rings, gives nothing
// there); a uniform layer reaches to the coarse ring's edge; and across the
// fine ring's edge the sampled coverage is continuous (at most 0.01 between
// samples 10 m apart) although the two rings differ by far more there. The
// map's anchor is the camera's lattice point, within 4.4 km of it anywhere
// (poles, antimeridian, orbit); new weather at the same anchor reuses the
// texels' cells and gives the same map as a fresh build.
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>

#include <glm/vec2.hpp>
#include <gtest/gtest.h>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/tiling.hpp"
#include "weather_field.hpp"

namespace sky::render {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMetresPerDegree = 111195.0;  // of latitude, mean Earth

// Gnomonic plane coordinates of a ground point in the field's anchor plane,
// computed here from the ECEF geometry (not by the field): direction from
// the anchor sphere's centre, scaled to meet the plane tangent at the anchor.
glm::dvec2 planeOf(const WeatherField& f, double lat_deg, double lon_deg) {
  const geo::Vec3d d = geo::toEcef({lat_deg, lon_deg, 0.0}) - f.centreEcef_m;
  const double e = geo::dot(d, f.frame.east), n = geo::dot(d, f.frame.north), u = geo::dot(d, f.frame.up);
  return glm::dvec2(e, n) * (f.radius_m / u);
}

weather::CloudLayer tiledLayer() {
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1000;
  l.thickness_m = 1500;
  l.coverage = 0;  // only the tiles make cloud
  return l;
}

TEST(WeatherRings, FarWeatherComesThroughTheCoarseRing) {
  constexpr int kLevel = 11;  // ~4.9 km cells, what the renderer subscribes to
  const geo::Geodetic camera{47.0, 8.0, 10000.0};
  const double farLat = camera.lat_deg + 300000.0 / kMetresPerDegree;
  weather::WeatherSnapshot s;
  s.tileLevel = kLevel;
  s.layers = {tiledLayer()};
  weather::CloudLayer deck = tiledLayer();
  deck.id = 2;
  deck.coverage = 0.6;  // uniform, no tiles
  deck.density = 0.5;
  s.layers.push_back(deck);
  // A 40 km patch of tiles at coverage 0.7, density 0.8, centred 300 km north.
  for (std::uint64_t cell : weather::coverCap({farLat, camera.lon_deg, 40000.0}, kLevel, 4000))
    s.tiles.push_back({cell, 1, 0.7f, 0.8f});
  ASSERT_GT(s.tiles.size(), 100u);
  const WeatherField f = buildWeatherField(&s, camera);
  const glm::dvec2 farPoint = planeOf(f, farLat, camera.lon_deg);
  EXPECT_NEAR(farPoint.x, 0.0, 1000.0);
  EXPECT_GT(farPoint.y, 290000.0);
  ASSERT_LT(farPoint.y, f.halfExtent_m[1]);
  ASSERT_GT(farPoint.y, f.halfExtent_m[0]) << "the point must lie beyond the fine ring";
  const glm::dvec3 v = f.sample(0, farPoint.x, farPoint.y);
  EXPECT_NEAR(v.x, 0.7, 1.0 / 255);
  EXPECT_NEAR(v.y, 0.8, 1.0 / 255);
  EXPECT_EQ(f.sampleRing(0, 0, farPoint.x, farPoint.y), glm::dvec3(0.0)) << "the fine ring does not reach 300 km";
  // Beside the patch (150 km north) the server sent nothing: empty.
  const glm::dvec2 gap = planeOf(f, camera.lat_deg + 150000.0 / kMetresPerDegree, camera.lon_deg);
  EXPECT_EQ(f.sample(0, gap.x, gap.y).x, 0.0);
  // The uniform deck reaches 550 km in every direction; past the coarse
  // ring's edge there is nothing.
  for (const glm::dvec2 p : {glm::dvec2(550000, 0), glm::dvec2(0, -550000), glm::dvec2(-400000, 400000)}) {
    EXPECT_NEAR(f.sample(1, p.x, p.y).x, 0.6, 1.0 / 255);
    EXPECT_NEAR(f.sample(1, p.x, p.y).y, 0.5, 1.0 / 255);
  }
  EXPECT_EQ(f.sample(1, 0.0, f.halfExtent_m[1] + 10000.0).x, 0.0);
}

TEST(WeatherRings, CoverageIsContinuousAcrossTheRingBoundary) {
  constexpr int kLevel = 11;
  const geo::Geodetic camera{47.0, 8.0, 3000.0};
  weather::WeatherSnapshot s;
  s.tileLevel = kLevel;
  s.layers = {tiledLayer()};
  // Coverage waving with a 30 km period east-west and north-south around the
  // camera, so the coarse ring's ~4.7 km texels differ from the fine ring's.
  const double cosLat = std::cos(camera.lat_deg * kPi / 180);
  for (std::uint64_t cell : weather::coverCap({camera.lat_deg, camera.lon_deg, 160000.0}, kLevel, 8000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    const double x = (c.lon_deg - camera.lon_deg) * kMetresPerDegree * cosLat;
    const double y = (c.lat_deg - camera.lat_deg) * kMetresPerDegree;
    const float cover = float(0.5 + 0.2 * std::sin(2 * kPi * x / 30000.0) + 0.2 * std::cos(2 * kPi * y / 30000.0));
    s.tiles.push_back({cell, 1, cover, 1.0f});
  }
  const WeatherField f = buildWeatherField(&s, camera);
  // Along the east axis and a diagonal, from inside the blend band's start
  // to beyond its end (the fine ring's edge at 100 km in the max norm).
  constexpr double kStep_m = 10.0, kTolerance = 0.01;
  for (const glm::dvec2 dir : {glm::dvec2(1, 0), glm::dvec2(std::sqrt(0.5), std::sqrt(0.5)), glm::dvec2(0, -1)}) {
    SCOPED_TRACE(dir.x);
    const double scale = std::max(std::abs(dir.x), std::abs(dir.y));  // max norm of dir
    double worstJump = 0, worstRingGap = 0;
    double previous = f.sample(0, 70000.0 / scale * dir.x, 70000.0 / scale * dir.y).x;
    for (double r = 70000.0 + kStep_m; r <= 105000.0; r += kStep_m) {
      const glm::dvec2 p = dir * (r / scale);
      const double c = f.sample(0, p.x, p.y).x;
      worstJump = std::max(worstJump, std::abs(c - previous));
      previous = c;
      if (r <= 99000.0)
        worstRingGap = std::max(worstRingGap, std::abs(f.sampleRing(0, 0, p.x, p.y).x - f.sampleRing(1, 0, p.x, p.y).x));
    }
    std::printf("[ rings    ] direction (%.2f, %.2f): largest step %.4f per 10 m, rings differ by up to %.3f\n", dir.x,
                dir.y, worstJump, worstRingGap);
    EXPECT_LT(worstJump, kTolerance);
    // A hard switch between the rings anywhere in the band would jump by this.
    EXPECT_GT(worstRingGap, 5 * kTolerance);
  }
  // The blend weight itself: 0 inside 85 km, 1 beyond 95 km, linear between.
  EXPECT_EQ(ringBlendWeight(84000.0, -30000.0), 0.0);
  EXPECT_NEAR(ringBlendWeight(-90000.0, 10000.0), 0.5, 1e-12);
  EXPECT_EQ(ringBlendWeight(20000.0, 96000.0), 1.0);
}

TEST(WeatherRings, AnchorIsTheCamerasLatticePoint) {
  for (const geo::Geodetic camera : {geo::Geodetic{47.0, 8.0, 500.0}, geo::Geodetic{89.999, 30.0, 10000.0},
                                     geo::Geodetic{-89.9, -120.0, 0.0}, geo::Geodetic{0.01, 179.999, 12000.0},
                                     geo::Geodetic{-33.9, 151.2, 400000.0}}) {
    SCOPED_TRACE(camera.lat_deg);
    const geo::Geodetic a = weatherAnchorFor(camera);
    EXPECT_EQ(a.alt_m, 0.0);
    // Horizontal distance: the great circle between the two directions, on
    // the ground; half the lattice cube's diagonal is 4.33 km, and seen from
    // orbit the direction moves less.
    EXPECT_LT(geo::geodesicDistance_m(camera.lat_deg, camera.lon_deg, a.lat_deg, a.lon_deg), 4400.0);
    // The same camera, the same anchor, bit for bit (the GPU map and the CPU
    // reference's must agree).
    const geo::Geodetic b = weatherAnchorFor(camera);
    EXPECT_EQ(a.lat_deg, b.lat_deg);
    EXPECT_EQ(a.lon_deg, b.lon_deg);
  }
  // Moving 20 km moves the anchor.
  const geo::Geodetic here = weatherAnchorFor({47.0, 8.0, 500.0});
  const geo::Geodetic there = weatherAnchorFor({47.0 + 20000.0 / kMetresPerDegree, 8.0, 500.0});
  EXPECT_GT(geo::geodesicDistance_m(here.lat_deg, here.lon_deg, there.lat_deg, there.lon_deg), 10000.0);
}

TEST(WeatherRings, NewWeatherAtTheSameAnchorReusesTheCells) {
  constexpr int kLevel = 11;
  const geo::Geodetic anchor = weatherAnchorFor({47.0, 8.0, 3000.0});
  weather::WeatherSnapshot first;
  first.tileLevel = kLevel;
  first.layers = {tiledLayer()};
  const auto cells = weather::coverCap({47.0, 8.0, 150000.0}, kLevel, 8000);
  for (std::size_t i = 0; i < cells.size(); ++i) first.tiles.push_back({cells[i], 1, float(i % 7) / 7.0f, 1.0f});
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const WeatherField a = buildWeatherField(&first, anchor);
  const auto t1 = Clock::now();
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring) {
    ASSERT_EQ(a.cellLevel[ring], kLevel);
    ASSERT_EQ(a.cells[ring].size(), std::size_t(kWeatherMapSize) * kWeatherMapSize);
  }
  // New weather: every third tile changes coverage, some tiles go away.
  weather::WeatherSnapshot second = first;
  for (std::size_t i = 0; i < second.tiles.size(); i += 3) second.tiles[i].coverage = 0.9f;
  second.tiles.resize(second.tiles.size() - 200);
  const auto t2 = Clock::now();
  const WeatherField reused = buildWeatherField(&second, anchor, &a);
  const auto t3 = Clock::now();
  const WeatherField fresh = buildWeatherField(&second, anchor);
  const auto t4 = Clock::now();
  EXPECT_EQ(reused.texels, fresh.texels);
  EXPECT_EQ(reused.cells, fresh.cells);
  EXPECT_NE(reused.texels, a.texels);
  auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  std::printf("[ rings    ] map build: fresh %.1f ms, %.1f ms; reusing the cells %.1f ms\n", ms(t1 - t0), ms(t4 - t3),
              ms(t3 - t2));
  // Another anchor or tile level: the cells are found again, same result.
  const geo::Geodetic elsewhere = weatherAnchorFor({47.2, 8.0, 3000.0});
  EXPECT_EQ(buildWeatherField(&second, elsewhere, &a).texels, buildWeatherField(&second, elsewhere).texels);
}

}  // namespace
}  // namespace sky::render
