// Per-tile updates of the weather map (renderer/core/src/weather_field_update.*):
// over seeded random sequences of tile changes and new tiles, in the fine
// and the coarse snapshot, the map updated in place equals a full build of
// the same snapshots bit for bit, in both rings, every texel that changed
// lies in the rectangle reported for upload, and the max-coverage mip
// updated over those rectangles equals one built from the whole map; one level-11 tile
// rewrites about the texels its cell covers (its area over a texel's, tens
// of texels) while a move of the anchor rebuilds every texel; and every
// change that is more than tiles (layers, levels, a tile removed, the blend
// type, a coarse snapshot appearing) rebuilds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "coverage_mip.hpp"
#include "sky/weather/tiling.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::render {
namespace {

using Kind = WeatherFieldChange::Kind;
constexpr double kMetresPerDegree = 111195.0;  // of latitude, mean Earth
constexpr int kFineLevel = 11, kCoarseLevel = 9;
const geo::Geodetic kCamera{47.0, 8.0, 3000.0};

weather::CloudLayer layer(std::uint32_t id, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1000.0 * id;
  l.thickness_m = 800;
  l.coverage = coverage;
  return l;
}

// Everything of a field a frame or the GPU reads.
void expectSameField(const WeatherField& got, const WeatherField& want) {
  EXPECT_TRUE(got.texels == want.texels) << "texels differ";
  EXPECT_EQ(got.cells, want.cells);
  EXPECT_EQ(got.cellLevel, want.cellLevel);
  EXPECT_EQ(got.blendType, want.blendType);
  EXPECT_EQ(got.tiled, want.tiled);
  EXPECT_EQ(got.contentKey, want.contentKey);
}

// The texels (array layer, row, column) where two fields differ lie in the
// change's rectangles of their layer.
void expectChangesInsideRects(const WeatherField& before, const WeatherField& after, const WeatherFieldChange& c) {
  const std::size_t n = after.size;
  std::size_t outside = 0, changed = 0;
  for (std::size_t t = 0; t < after.texels.size() / kWeatherChannels; ++t) {
    if (std::equal(&before.texels[t * 4], &before.texels[t * 4] + 4, &after.texels[t * 4])) continue;
    ++changed;
    const std::uint32_t layer = std::uint32_t(t / (n * n)), y = std::uint32_t(t / n % n), x = std::uint32_t(t % n);
    const bool inside = std::any_of(c.dirty.begin(), c.dirty.end(), [&](const TexelRect& r) {
      return r.layer == layer && x >= r.x && x < r.x + r.width && y >= r.y && y < r.y + r.height;
    });
    if (!inside) ++outside;
  }
  EXPECT_EQ(outside, 0u) << "of " << changed << " changed texels";
  EXPECT_LE(changed, c.texelsRewritten);
}

// A tile of random values; layer 1's blend towards cumulonimbus.
weather::CoverageTile randomTile(std::uint64_t cell, std::uint32_t id, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  weather::CoverageTile t{cell, id, u(rng), u(rng)};
  if (id == 1) {
    t.blendType = weather::CloudType::Cumulonimbus;
    t.blend = u(rng);
  }
  return t;
}

// Snapshots of three layers (1 and 2 tiled, 3 uniform) over the cells of a
// cap, each cell present with probability 0.7; layer 1's tiles blend
// towards cumulonimbus.
weather::WeatherSnapshot randomSnapshot(const std::vector<std::uint64_t>& cells, int level, std::mt19937& rng) {
  weather::WeatherSnapshot s;
  s.tileLevel = level;
  s.layers = {layer(1, 0.0), layer(2, 0.0), layer(3, 0.45)};
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::uint64_t cell : cells)
    for (std::uint32_t id : {1u, 2u})
      if (u(rng) < 0.7f)
        s.tiles.push_back(randomTile(cell, id, rng));
  return s;
}

// One random step: new values for k tiles (most steps), k new tiles, or
// now and then a change a tile update cannot express (a tile removed, the
// uniform layer's coverage).
void randomStep(weather::WeatherSnapshot& s, const std::vector<std::uint64_t>& cells, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const std::size_t k = std::array<std::size_t, 4>{1, 5, 50, 300}[rng() % 4];
  const float op = u(rng);
  if (op < 0.7f) {
    for (std::size_t i = 0; i < k && !s.tiles.empty(); ++i) {
      weather::CoverageTile& t = s.tiles[rng() % s.tiles.size()];
      t.coverage = u(rng);
      t.density = u(rng);
      if (t.layerId == 1) t.blend = u(rng);
    }
  } else if (op < 0.9f) {
    std::set<std::pair<std::uint64_t, std::uint32_t>> present;
    for (const auto& t : s.tiles) present.insert({t.cellId, t.layerId});
    for (std::size_t i = 0; i < k; ++i) {
      const std::uint64_t cell = cells[rng() % cells.size()];
      const std::uint32_t id = 1 + rng() % 2;
      if (!present.insert({cell, id}).second) continue;
      s.tiles.push_back(randomTile(cell, id, rng));
    }
  } else if (op < 0.95f && !s.tiles.empty()) {
    s.tiles.erase(s.tiles.begin() + std::ptrdiff_t(rng() % s.tiles.size()));
  } else {
    s.layers[2].coverage = std::round(u(rng) * 100) / 100;
  }
}

TEST(WeatherUpdate, RandomTileChangesGiveTheFullBuild) {
  const geo::Geodetic anchor = weatherAnchorFor(kCamera);
  const auto fineCells = weather::coverCap({kCamera.lat_deg, kCamera.lon_deg, 120000.0}, kFineLevel, 8000);
  const auto coarseCells = weather::coverCap({kCamera.lat_deg, kCamera.lon_deg, 650000.0}, kCoarseLevel, 8000);
  constexpr int kSteps = 24;
  for (const std::uint32_t seed : {1u, 2u, 3u, 4u}) {
    // Odd seeds with a coarse snapshot (ring 1 its own), even ones without
    // (ring 1 from the fine tiles).
    const bool withCoarse = seed % 2 == 1;
    SCOPED_TRACE("seed " + std::to_string(seed) + (withCoarse ? " with" : " without") + " coarse snapshot");
    std::mt19937 rng(seed);
    weather::WeatherSnapshot fine = randomSnapshot(fineCells, kFineLevel, rng);
    weather::WeatherSnapshot coarse = randomSnapshot(coarseCells, kCoarseLevel, rng);
    const weather::WeatherSnapshot* coarsePtr = withCoarse ? &coarse : nullptr;
    WeatherFieldUpdater updater;
    ASSERT_EQ(updater.update(&fine, coarsePtr, anchor).kind, Kind::Rebuilt);
    // The full build each step reuses the cells of its own previous build
    // (the same as finding them again: NewWeatherAtTheSameAnchorReusesTheCells),
    // which keeps the test fast; the last step compares with a fresh one.
    WeatherField reference = buildWeatherField(&fine, coarsePtr, anchor);
    expectSameField(updater.field(), reference);
    std::vector<float> mip = buildCoverageMip(updater.field());
    int tileSteps = 0, rebuilds = 0;
    std::uint64_t tileTexels = 0;
    for (int step = 0; step < kSteps; ++step) {
      SCOPED_TRACE("step " + std::to_string(step));
      const std::uint32_t which = withCoarse ? rng() % 3 : 0;  // 0 fine, 1 coarse, 2 both
      if (which != 1) randomStep(fine, fineCells, rng);
      if (which != 0) randomStep(coarse, coarseCells, rng);
      const WeatherField before = updater.field();
      const WeatherFieldChange change = updater.update(&fine, coarsePtr, anchor);
      reference = buildWeatherField(&fine, coarsePtr, anchor, &reference);
      expectSameField(updater.field(), reference);
      if (change.kind == Kind::Tiles) {
        ++tileSteps;
        tileTexels += change.texelsRewritten;
        expectChangesInsideRects(before, updater.field(), change);
        // The max-coverage mip updated over the same rectangles is the one
        // built from the whole map.
        updateCoverageMip(mip, updater.field(), change.dirty);
        EXPECT_TRUE(mip == buildCoverageMip(updater.field())) << "coverage mip";
      } else if (change.kind == Kind::Rebuilt) {
        ++rebuilds;
        mip = buildCoverageMip(updater.field());
        EXPECT_FALSE(change.reason.empty());
      }
      if (::testing::Test::HasFailure()) return;
    }
    expectSameField(updater.field(), buildWeatherField(&fine, coarsePtr, anchor));
    std::printf("[ update   ] seed %u: %d of %d steps by tiles (%.0f texels each on average), %d rebuilt\n", seed,
                tileSteps, kSteps, tileSteps ? double(tileTexels) / tileSteps : 0.0, rebuilds);
    // Most steps change only tiles (op < 0.9 in randomStep, per snapshot).
    EXPECT_GE(tileSteps, kSteps / 2);
  }
}

// One uniform layer (id 1) tiled at the fine level with coverage 0.5 over a
// cap of radius_m around the camera, at most maxCells tiles.
weather::WeatherSnapshot tiledAroundCamera(double radius_m, std::size_t maxCells) {
  weather::WeatherSnapshot s;
  s.tileLevel = kFineLevel;
  s.layers = {layer(1, 0.0)};
  for (std::uint64_t cell : weather::coverCap({kCamera.lat_deg, kCamera.lon_deg, radius_m}, kFineLevel, maxCells))
    s.tiles.push_back({cell, 1, 0.5f, 1.0f});
  return s;
}

TEST(WeatherUpdate, OneTileRewritesItsCellsTexels) {
  const geo::Geodetic anchor = weatherAnchorFor(kCamera);
  weather::WeatherSnapshot s = tiledAroundCamera(60000.0, 8000);
  WeatherFieldUpdater updater;
  const WeatherFieldChange first = updater.update(&s, nullptr, anchor);
  ASSERT_EQ(first.kind, Kind::Rebuilt);
  const std::uint64_t everyTexel = std::uint64_t(kWeatherRings) * gpu::kMaxLayers * kWeatherMapSize * kWeatherMapSize;
  EXPECT_EQ(first.texelsRewritten, everyTexel);

  // The tile 20 km north of the camera.
  const std::uint64_t cell = weather::cellAt(kCamera.lat_deg + 20000.0 / kMetresPerDegree, kCamera.lon_deg, kFineLevel);
  const auto it = std::find_if(s.tiles.begin(), s.tiles.end(), [&](const auto& t) { return t.cellId == cell; });
  ASSERT_NE(it, s.tiles.end());
  it->coverage = 0.9f;
  const WeatherFieldChange one = updater.update(&s, nullptr, anchor);
  ASSERT_EQ(one.kind, Kind::Tiles);
  // The texel centres inside the cell: its area over a fine texel's (the
  // gnomonic plane's scale 20 km from its centre differs from 1 by 1e-5).
  // ~4.9 km cells and 781 m texels: ~40; the cell's edges cut texels, so
  // the count is that within a third.
  const double texel_m = 2 * kWeatherRingHalfExtent_m[0] / kWeatherMapSize;
  const double expected = weather::cellArea_m2(cell) / (texel_m * texel_m);
  // Ring 1 (the rings share the fine tiles) takes the tile at its ~4.7 km
  // texels' centres: a cell of ~24 km^2 holds at most a few of them.
  const double coarseTexel_m = 2 * kWeatherRingHalfExtent_m[1] / kWeatherMapSize;
  const double coarseAtMost = std::ceil(weather::cellArea_m2(cell) / (coarseTexel_m * coarseTexel_m)) + 3;
  std::uint64_t ring0 = 0;
  for (const TexelRect& r : one.dirty) {
    std::printf("[ update   ] one tile: layer %u rectangle %ux%u at (%u, %u)\n", r.layer, r.width, r.height, r.x, r.y);
    EXPECT_TRUE(r.layer == 0 || r.layer == gpu::kMaxLayers) << "only slice 0 of each ring has the tile";
  }
  for (std::uint32_t t = 0; t < kWeatherMapSize * kWeatherMapSize; ++t) ring0 += updater.field().cells[0][t] == cell;
  std::printf("[ update   ] one level-11 tile: %llu texels rewritten (%llu in ring 0; area ratio %.1f)\n",
              static_cast<unsigned long long>(one.texelsRewritten), static_cast<unsigned long long>(ring0), expected);
  EXPECT_NEAR(double(ring0), expected, expected / 3);
  EXPECT_GE(one.texelsRewritten, ring0);
  EXPECT_LE(double(one.texelsRewritten), double(ring0) + coarseAtMost);
  EXPECT_LT(one.texelsRewritten, 100u) << "tens of texels, not a slice's 65536";
  ASSERT_FALSE(one.dirty.empty());
  // The fine ring's rectangle is the cell's bounding box: ~7 texels a side.
  EXPECT_EQ(one.dirty[0].layer, 0u);
  EXPECT_LE(one.dirty[0].width * one.dirty[0].height, 4 * expected);
  expectSameField(updater.field(), buildWeatherField(&s, anchor));

  // The same weather with the camera 20 km on: a new anchor, every texel again.
  const geo::Geodetic moved = weatherAnchorFor({kCamera.lat_deg + 20000.0 / kMetresPerDegree, kCamera.lon_deg, 3000.0});
  const WeatherFieldChange move = updater.update(&s, nullptr, moved);
  EXPECT_EQ(move.kind, Kind::Rebuilt);
  EXPECT_EQ(move.reason, "anchor moved");
  EXPECT_EQ(move.texelsRewritten, everyTexel);
  // Nothing new: nothing done.
  const WeatherFieldChange none = updater.update(&s, nullptr, moved);
  EXPECT_EQ(none.kind, Kind::Unchanged);
  EXPECT_EQ(none.texelsRewritten, 0u);
}

// FrameInputs::weatherVersion: a version seen before stands for the same
// snapshots, so the updater does not read them (a changed tile under the
// old version is not drawn: the caller broke its promise, and the test
// shows the snapshots were not compared); a new version compares them and
// takes the change tile by tile; the same version at a new anchor still
// rebuilds. Prints what the skipped comparison costs per frame.
TEST(WeatherUpdate, AKnownVersionSkipsTheSnapshots) {
  const geo::Geodetic anchor = weatherAnchorFor(kCamera);
  weather::WeatherSnapshot s = tiledAroundCamera(200000.0, 40000);
  WeatherFieldUpdater updater;
  ASSERT_EQ(updater.update(&s, nullptr, anchor, 7).kind, Kind::Rebuilt);
  const WeatherField before = updater.field();

  s.tiles[s.tiles.size() / 2].coverage = 0.9f;
  const auto timed = [&](std::optional<std::uint64_t> version, int times) {
    const auto t0 = std::chrono::steady_clock::now();
    WeatherFieldChange c;
    for (int i = 0; i < times; ++i) c = updater.update(&s, nullptr, anchor, version);
    return std::pair(c, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / times);
  };
  const auto [kept, keptMs] = timed(7, 50);
  EXPECT_EQ(kept.kind, Kind::Unchanged);
  EXPECT_TRUE(updater.field().texels == before.texels) << "the old version's map stays";

  const auto [taken, takenMs] = timed(8, 1);
  EXPECT_EQ(taken.kind, Kind::Tiles);
  expectSameField(updater.field(), buildWeatherField(&s, anchor));
  // Without a version every call compares the snapshots (nothing changed: Unchanged).
  const auto [compared, comparedMs] = timed(std::nullopt, 50);
  EXPECT_EQ(compared.kind, Kind::Unchanged);
  std::printf("[ version  ] %zu tiles: an unchanged frame costs %.4f ms with a known version, %.3f ms comparing\n",
              s.tiles.size(), keptMs, comparedMs);

  const geo::Geodetic moved = weatherAnchorFor({kCamera.lat_deg + 0.5, kCamera.lon_deg, 3000.0});
  EXPECT_EQ(updater.update(&s, nullptr, moved, 8).kind, Kind::Rebuilt);
  expectSameField(updater.field(), buildWeatherField(&s, moved));
}

TEST(WeatherUpdate, MoreThanTilesRebuilds) {
  const geo::Geodetic anchor = weatherAnchorFor(kCamera);
  std::mt19937 rng(7);
  const auto fineCells = weather::coverCap({kCamera.lat_deg, kCamera.lon_deg, 60000.0}, kFineLevel, 8000);
  const auto coarseCells = weather::coverCap({kCamera.lat_deg, kCamera.lon_deg, 300000.0}, kCoarseLevel, 8000);
  const weather::WeatherSnapshot fine0 = randomSnapshot(fineCells, kFineLevel, rng);
  const weather::WeatherSnapshot coarse0 = randomSnapshot(coarseCells, kCoarseLevel, rng);
  struct Case {
    const char* what;
    void (*change)(weather::WeatherSnapshot& fine, weather::WeatherSnapshot& coarse);
    const char* reason;
  };
  const Case cases[] = {
      {"uniform layer's coverage", [](auto& f, auto&) { f.layers[2].coverage = 0.8; }, "layers changed"},
      {"layer type", [](auto& f, auto&) { f.layers[0].type = weather::CloudType::Stratus; }, "layers changed"},
      {"layers reordered", [](auto& f, auto&) { std::swap(f.layers[0], f.layers[1]); }, "layers changed"},
      {"fine tile removed", [](auto& f, auto&) { f.tiles.pop_back(); }, "a tile removed"},
      {"coarse tile removed", [](auto&, auto& c) { c.tiles.erase(c.tiles.begin()); }, "a tile removed"},
      {"coarse level", [](auto&, auto& c) { c.tileLevel = 10; }, "tile level changed"},
      {"uniform layer gains a tile", [](auto& f, auto&) { f.tiles.push_back({f.tiles[0].cellId, 3, 1.0f, 1.0f}); },
       "a layer gained or lost its tiles"},
      {"blend type", [](auto&, auto& c) {
         for (auto& t : c.tiles) t.blendType = weather::CloudType::Stratus;
       }, "blend type of a slice changed"},
      {"cell named twice", [](auto& f, auto&) { f.tiles.push_back(f.tiles[0]); }, "a cell named twice in one snapshot"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    WeatherFieldUpdater updater;
    updater.update(&fine0, &coarse0, anchor);
    weather::WeatherSnapshot fine = fine0, coarse = coarse0;
    c.change(fine, coarse);
    const WeatherFieldChange change = updater.update(&fine, &coarse, anchor);
    EXPECT_EQ(change.kind, Kind::Rebuilt);
    EXPECT_EQ(change.reason, c.reason);
    expectSameField(updater.field(), buildWeatherField(&fine, &coarse, anchor));
  }
  // A coarse snapshot coming and going.
  WeatherFieldUpdater updater;
  updater.update(&fine0, nullptr, anchor);
  EXPECT_EQ(updater.update(&fine0, &coarse0, anchor).reason, "coarse weather appeared or went away");
  expectSameField(updater.field(), buildWeatherField(&fine0, &coarse0, anchor));
  EXPECT_EQ(updater.update(&fine0, nullptr, anchor).kind, Kind::Rebuilt);
  expectSameField(updater.field(), buildWeatherField(&fine0, anchor));
  // A change of wind alone leaves the map as it is.
  weather::WeatherSnapshot windy = fine0;
  windy.layers[0].wind.speed_mps = 30;
  EXPECT_EQ(updater.update(&windy, nullptr, anchor).kind, Kind::Unchanged);
  // Clear sky and back.
  EXPECT_EQ(updater.update(nullptr, nullptr, anchor).kind, Kind::Rebuilt);
  expectSameField(updater.field(), buildWeatherField(nullptr, anchor));
  EXPECT_EQ(updater.update(&fine0, nullptr, anchor).kind, Kind::Rebuilt);
  expectSameField(updater.field(), buildWeatherField(&fine0, anchor));
}

}  // namespace
}  // namespace sky::render
