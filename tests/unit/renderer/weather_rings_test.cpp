// The weather map's rings of detail (renderer/core/src/weather_field.*), the
// sampler the CPU reference uses and the GPU mirrors: weather the server sent
// 300 km from the camera, beyond the fine ring, reaches the renderer through
// the coarse ring (the fine ring alone, the map before rings, gives nothing
// there); a uniform layer reaches to the coarse ring's edge; and across the
// fine ring's edge the sampled coverage is continuous (at most 0.01 between
// samples 10 m apart) although the two rings differ by far more there. The
// map's anchor is the camera's lattice point, within 4.4 km of it anywhere
// (poles, antimeridian, orbit); new weather at the same anchor reuses the
// texels' cells and gives the same map as a fresh build. With a second,
// coarser snapshot (FrameInputs::coarseWeather) ring 1 takes its tiles from
// it: far weather only that snapshot has is seen, uniform layers stay
// uniform, fine-only tiles leave ring 1 uniform and still win inside the
// fine ring.
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>

#include <glm/vec2.hpp>
#include <gtest/gtest.h>

#include "sky/app/drawable_weather.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/weather/tiling.hpp"
#include "frame_setup.hpp"
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

// A continent's METAR stations as the server sends them for a 300 km area
// (sky_server_tests' MetarContinent: 19 layers, level 10, 86583 tiles): the
// channel keeps the four layers with most cloud (drawableWeather) and builds
// its map from their tiles; printed: the selection, a fresh build, and a
// rebuild after one station's report changed its layer's tiles nearby
// (reusing the cells). The rebuild gives what a fresh build gives.
TEST(WeatherRings, AContinentsStationsBuildTheMapOfTheDrawnLayers) {
  constexpr int kLevel = 10;
  const geo::Geodetic camera{47.0, 8.0, 3000.0};
  const geo::Geodetic anchor = weatherAnchorFor(camera);
  weather::WeatherSnapshot s;
  s.tileLevel = kLevel;
  const auto cells = weather::coverCap({47.0, 8.0, 300000.0}, kLevel, 8000);
  for (std::uint32_t id = 40; id < 59; ++id) {
    weather::CloudLayer l = tiledLayer();
    l.id = id;
    l.base_m = 300.0 + 250.0 * (id - 40);
    l.thickness_m = 200;
    s.layers.push_back(l);
    for (std::size_t i = 0; i < cells.size(); ++i)
      if ((i + id) % 5 != 0) s.tiles.push_back({cells[i], id, float((i * 7 + id) % 9) / 8.0f, 1.0f});
  }
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const auto t0 = Clock::now();
  const weather::WeatherSnapshot drawn = app::drawableWeather(s, gpu::kMaxLayers, nullptr);
  const auto t1 = Clock::now();
  const WeatherField fresh = buildWeatherField(&drawn, anchor);
  const auto t2 = Clock::now();
  ASSERT_EQ(drawn.layers.size(), std::size_t(gpu::kMaxLayers));
  // One station's newer report: its layer's tiles within 30 km change.
  weather::WeatherSnapshot next = s;
  const std::uint32_t changed = drawn.layers[1].id;
  for (auto& t : next.tiles) {
    const weather::CellCentre c = weather::cellCentre(t.cellId);
    if (t.layerId == changed && std::abs(c.lat_deg - 47.1) < 0.27 && std::abs(c.lon_deg - 8.1) < 0.4) t.coverage = 1.0f;
  }
  const auto t3 = Clock::now();
  const weather::WeatherSnapshot nextDrawn = app::drawableWeather(next, gpu::kMaxLayers, nullptr);
  const WeatherField rebuilt = buildWeatherField(&nextDrawn, anchor, &fresh);
  const auto t4 = Clock::now();
  std::printf("[ rings    ] %zu layers, %zu tiles at level %d: the drawn %zu layers' %zu tiles chosen in %.1f ms, map "
              "built in %.1f ms; one station's change: %.1f ms\n",
              s.layers.size(), s.tiles.size(), kLevel, drawn.layers.size(), drawn.tiles.size(), ms(t1 - t0),
              ms(t2 - t1), ms(t4 - t3));
  EXPECT_EQ(rebuilt.texels, buildWeatherField(&nextDrawn, anchor).texels);
  EXPECT_NE(rebuilt.texels, fresh.texels);
}

// The coverage the coarse snapshot gives a level-9 cell: varying from cell
// to cell (by the cell's position along S2's curve), so a lookup of the
// wrong cell or level shows.
float coarseCoverage(std::uint64_t cell) { return 0.3f + 0.1f * float((cell >> 45) % 7); }

struct TwoSnapshots {
  weather::WeatherSnapshot fine, coarse;
};

// Fine (level 11, 120 km around the camera) and coarse (level 9, wider)
// snapshots of four layers: 1 tiled in both (fine 0.4 near the camera,
// coarse coarseCoverage over a patch 300 km north and 0.2 around the
// camera), 2 uniform (0.6, 0.5; the coarse snapshot says 0.1, unused),
// 3 tiled only in the fine snapshot (0.9 on its tiles, 0.3 its own), 4
// tiled only in the coarse one (0.25 its own, coarse tiles 0.8 around the
// camera). The coarse snapshot also tiles a layer 99 the fine one lacks.
constexpr int kFineLevel = 11, kCoarseLevel = 9;
TwoSnapshots twoSnapshots(const geo::Geodetic& camera) {
  TwoSnapshots t;
  weather::WeatherSnapshot& f = t.fine;
  f.tileLevel = kFineLevel;
  f.layers = {tiledLayer(), tiledLayer(), tiledLayer(), tiledLayer()};
  f.layers[1].id = 2;
  f.layers[1].coverage = 0.6;
  f.layers[1].density = 0.5;
  f.layers[2].id = 3;
  f.layers[2].coverage = 0.3;
  f.layers[3].id = 4;
  f.layers[3].coverage = 0.25;
  for (std::uint64_t cell : weather::coverCap({camera.lat_deg, camera.lon_deg, 30000.0}, kFineLevel, 4000)) {
    f.tiles.push_back({cell, 1, 0.4f, 1.0f});
    f.tiles.push_back({cell, 3, 0.9f, 1.0f});
  }
  weather::WeatherSnapshot& c = t.coarse;
  c.tileLevel = kCoarseLevel;
  c.layers = f.layers;
  c.layers[1].coverage = 0.1;  // a coarse layer's own numbers are not used
  const double farLat = camera.lat_deg + 300000.0 / kMetresPerDegree;
  for (std::uint64_t cell : weather::coverCap({farLat, camera.lon_deg, 60000.0}, kCoarseLevel, 4000))
    c.tiles.push_back({cell, 1, coarseCoverage(cell), 0.9f});
  for (std::uint64_t cell : weather::coverCap({camera.lat_deg, camera.lon_deg, 60000.0}, kCoarseLevel, 4000)) {
    c.tiles.push_back({cell, 1, 0.2f, 0.9f});
    c.tiles.push_back({cell, 4, 0.8f, 1.0f});
  }
  return t;
}

// A value as the map stores it: a float (as tiles carry it and the map
// takes layers' numbers) quantised to 1/255.
double quantized(float v) { return weather::quantizeUnit(v) / 255.0; }

TEST(WeatherRings, CoarseSnapshotFillsTheCoarseRing) {
  const geo::Geodetic camera{47.0, 8.0, 10000.0};
  const TwoSnapshots t = twoSnapshots(camera);
  const WeatherField both = buildWeatherField(&t.fine, &t.coarse, camera);
  const WeatherField fineOnly = buildWeatherField(&t.fine, camera);
  EXPECT_EQ(both.cellLevel[0], kFineLevel);
  EXPECT_EQ(both.cellLevel[1], kCoarseLevel);

  // 300 km north, beyond the fine ring: the coarse tile of the cell there,
  // sampled at that cell's centre (a level-9 cell is ~4 coarse texels
  // across, so all four filtered texels lie in it).
  const double farLat = camera.lat_deg + 300000.0 / kMetresPerDegree;
  const std::uint64_t farCell = weather::cellAt(farLat, camera.lon_deg, kCoarseLevel);
  const weather::CellCentre centre = weather::cellCentre(farCell);
  const glm::dvec2 far = planeOf(both, centre.lat_deg, centre.lon_deg);
  ASSERT_GT(far.y, both.halfExtent_m[0] * kRingBlendEnd) << "the point must lie beyond the fine ring";
  const glm::dvec3 v = both.sample(0, far.x, far.y);
  EXPECT_NEAR(v.x, quantized(coarseCoverage(farCell)), 1e-9);
  EXPECT_NEAR(v.y, quantized(0.9), 1e-9);
  // Without the coarse snapshot ring 1 has only the fine tiles, which end
  // 30 km out: nothing there.
  EXPECT_EQ(fineOnly.sample(0, far.x, far.y).x, 0.0);

  // The uniform layer is uniform in both rings at the fine snapshot's
  // numbers, out to the coarse ring's edge.
  for (const glm::dvec2 p : {glm::dvec2(0, 0), glm::dvec2(550000, 0), glm::dvec2(-400000, 400000), far}) {
    EXPECT_NEAR(both.sample(1, p.x, p.y).x, quantized(0.6), 1e-9);
    EXPECT_NEAR(both.sample(1, p.x, p.y).y, quantized(0.5), 1e-9);
  }
  EXPECT_FALSE(both.tiled[1]);

  // Layer 3, tiled only in the fine snapshot: its tiles in ring 0, and ring
  // 1 uniform at the layer's own 0.3, under the fine tiles too.
  const glm::dvec2 near = planeOf(both, camera.lat_deg + 10000.0 / kMetresPerDegree, camera.lon_deg);
  EXPECT_NEAR(both.sampleRing(0, 2, near.x, near.y).x, quantized(0.9), 1e-9);
  EXPECT_EQ(both.sampleRing(0, 2, 60000.0, 0.0).x, 0.0) << "beyond its tiles the fine ring is empty";
  for (const glm::dvec2 p : {near, glm::dvec2(60000, 0), far, glm::dvec2(0, -500000)})
    EXPECT_NEAR(both.sampleRing(1, 2, p.x, p.y).x, quantized(0.3), 1e-9);
  EXPECT_TRUE(both.tiled[2]);

  // Layer 4, tiled only in the coarse snapshot: ring 0 uniform at 0.25,
  // ring 1 its tiles (0.8 around the camera, empty far out).
  EXPECT_NEAR(both.sampleRing(0, 3, near.x, near.y).x, quantized(0.25), 1e-9);
  EXPECT_NEAR(both.sampleRing(0, 3, 90000.0, 0.0).x, quantized(0.25), 1e-9);
  EXPECT_NEAR(both.sampleRing(1, 3, near.x, near.y).x, quantized(0.8), 1e-9);
  EXPECT_EQ(both.sampleRing(1, 3, far.x, far.y).x, 0.0);
  EXPECT_TRUE(both.tiled[3]);
  EXPECT_FALSE(fineOnly.tiled[3]);

  // Layer 1 near the camera: the fine tiles win inside the fine ring (0.4)
  // although ring 1 holds the coarse 0.2 there.
  EXPECT_NEAR(both.sample(0, near.x, near.y).x, quantized(0.4), 1e-9);
  EXPECT_NEAR(both.sampleRing(1, 0, near.x, near.y).x, quantized(0.2), 1e-9);

  // Coarse tiles of a layer the fine snapshot lacks change nothing.
  TwoSnapshots extra = t;
  for (std::uint64_t cell : weather::coverCap({camera.lat_deg, camera.lon_deg, 100000.0}, kCoarseLevel, 4000))
    extra.coarse.tiles.push_back({cell, 99, 1.0f, 1.0f});
  EXPECT_EQ(buildWeatherField(&extra.fine, &extra.coarse, camera).texels, both.texels);

  // The map's key sees the coarse snapshot and its tiles; the structure key
  // (whose change drops an interleaved renderer's history) sees the coarse
  // snapshot but not its tiles' values (a change of tiles keeps the history).
  EXPECT_NE(weatherContentKey(&t.fine, &t.coarse), weatherContentKey(&t.fine));
  EXPECT_EQ(weatherContentKey(&t.fine, nullptr), weatherContentKey(&t.fine));
  TwoSnapshots changed = t;
  changed.coarse.tiles[3].coverage = 0.95f;
  EXPECT_NE(weatherContentKey(&changed.fine, &changed.coarse), weatherContentKey(&t.fine, &t.coarse));
  EXPECT_EQ(weatherStructureKey(&changed.fine, &changed.coarse), weatherStructureKey(&t.fine, &t.coarse));
  EXPECT_NE(weatherStructureKey(&t.fine, &t.coarse), weatherStructureKey(&t.fine));
  TwoSnapshots moved = t;
  moved.fine.layers[0].base_m += 100;
  EXPECT_NE(weatherStructureKey(&moved.fine, &moved.coarse), weatherStructureKey(&t.fine, &t.coarse));
  EXPECT_EQ(weatherContentKey(&moved.fine, &moved.coarse), weatherContentKey(&t.fine, &t.coarse));
}

TEST(WeatherRings, BlendTypeCountsTheTilesOfBothRings) {
  const geo::Geodetic camera{47.0, 8.0, 10000.0};
  TwoSnapshots t = twoSnapshots(camera);
  // Layer 1's fine tiles blend towards cumulonimbus (0.3 each), its coarse
  // ones towards stratus (1 each): the ~200 fine tiles weigh ~60, the
  // coarse ones more than that only if there are over 60 of them.
  std::size_t coarseTiles = 0;
  for (auto& tile : t.fine.tiles)
    if (tile.layerId == 1) {
      tile.blendType = weather::CloudType::Cumulonimbus;
      tile.blend = 0.3f;
    }
  for (auto& tile : t.coarse.tiles)
    if (tile.layerId == 1) {
      tile.blendType = weather::CloudType::Stratus;
      tile.blend = 1.0f;
      ++coarseTiles;
    }
  double fineWeight = 0;
  for (const auto& tile : t.fine.tiles)
    if (tile.layerId == 1) fineWeight += tile.blend;
  ASSERT_GT(double(coarseTiles), fineWeight) << "the test needs the coarse tiles to outweigh the fine ones";
  EXPECT_EQ(buildWeatherField(&t.fine, camera).blendType[0], weather::CloudType::Cumulonimbus);
  const WeatherField both = buildWeatherField(&t.fine, &t.coarse, camera);
  EXPECT_EQ(both.blendType[0], weather::CloudType::Stratus);
  // A slice holds one blend type: the coarse tiles blend in ring 1, the
  // fine (cumulonimbus) tiles draw unblended in ring 0.
  const glm::dvec2 near = planeOf(both, camera.lat_deg + 10000.0 / kMetresPerDegree, camera.lon_deg);
  EXPECT_NEAR(both.sampleRing(1, 0, near.x, near.y).z, 1.0, 1e-9);
  EXPECT_EQ(both.sampleRing(0, 0, near.x, near.y).z, 0.0);
}

TEST(WeatherRings, CoarseWeatherIsValidatedByName) {
  const geo::Geodetic camera{47.0, 8.0, 10000.0};
  TwoSnapshots t = twoSnapshots(camera);
  FrameInputs in;
  in.camera.position = camera;
  in.weather = &t.fine;
  in.coarseWeather = &t.coarse;
  EXPECT_TRUE(validateInputs(in));
  t.coarse.layers.resize(gpu::kMaxLayers + 1, t.coarse.layers[0]);
  auto tooMany = validateInputs(in);
  ASSERT_FALSE(tooMany);
  EXPECT_NE(tooMany.error().detail.find("coarseWeather"), std::string::npos) << tooMany.error().detail;
  t = twoSnapshots(camera);
  t.coarse.tiles[0].coverage = 1.5f;
  auto badTile = validateInputs(in);
  ASSERT_FALSE(badTile);
  EXPECT_NE(badTile.error().detail.find("coarseWeather"), std::string::npos) << badTile.error().detail;
  t = twoSnapshots(camera);
  t.coarse.tileLevel = 31;
  EXPECT_FALSE(validateInputs(in));
  // The fine snapshot's messages are as they were (no input named).
  t = twoSnapshots(camera);
  t.fine.tileLevel = -1;
  auto badFine = validateInputs(in);
  ASSERT_FALSE(badFine);
  EXPECT_EQ(badFine.error().detail, "frame inputs: tileLevel -1 outside [0, 30]");
}

}  // namespace
}  // namespace sky::render
