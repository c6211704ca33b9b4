// The server's TileCache never hands back stale tiles: after a layer changes
// (globally or in a region), a region moves, grows, turns, is removed or
// reordered, or many regions share an area, a snapshot built through the
// cache equals one built from scratch without it (the plain deriveTiles path,
// which keeps nothing between calls); and the memo is really used (layers no
// change touched come back as hits), so these comparisons test it.
#include <algorithm>
#include <functional>

#include <gtest/gtest.h>

#include "region_builder.hpp"

#include "sky/server/snapshot_builder.hpp"

namespace sky::server {
namespace {

constexpr auto layer = test::stackedLayer;

constexpr auto region = test::squareRegion;

stream::Subscribe around(double lat, double lon, double radius_m, int level = 13) {
  stream::Subscribe s;
  s.area = {lat, lon, radius_m};
  s.tileLevel = level;
  return s;
}

std::vector<weather::CoverageTile> tilesOf(const weather::WeatherSnapshot& s, std::uint32_t layerId) {
  std::vector<weather::CoverageTile> out;
  for (const auto& t : s.tiles)
    if (t.layerId == layerId) out.push_back(t);
  return out;
}

// The snapshot through the cache, after checking it against one from scratch.
weather::WeatherSnapshot checked(TileCache& cache, const stream::Subscribe& area,
                                 const std::vector<weather::CloudLayer>& global,
                                 const std::vector<weather::Region>& regions, const std::string& step) {
  const auto plain = buildSnapshot(area, global, 0.0, kDefaultMaxCells, regions);
  auto cached = buildSnapshot(area, global, 0.0, kDefaultMaxCells, regions, &cache);
  EXPECT_EQ(cached.tileLevel, plain.tileLevel) << step;
  EXPECT_EQ(cached.layers.size(), plain.layers.size()) << step;
  EXPECT_EQ(cached.tiles.size(), plain.tiles.size()) << step;
  EXPECT_TRUE(cached.tiles == plain.tiles) << step << ": the cache gave other tiles than deriving them";
  return cached;
}

class TileCacheTest : public ::testing::Test {
 protected:
  // Three global layers; a clearing of layer 1 that thickens layer 2 over
  // the area's centre, and a storm cell of a layer only it has, east of it.
  std::vector<weather::CloudLayer> global = {layer(1, weather::CloudType::Cumulus, 0.8),
                                             layer(2, weather::CloudType::Altostratus, 0.5),
                                             layer(3, weather::CloudType::Cirrus, 0.3)};
  std::vector<weather::Region> regions = {
      region(1, 46, 13.1, 30000, 10000,
             {layer(1, weather::CloudType::Cumulus, 0.0), layer(2, weather::CloudType::Altostratus, 0.9)}),
      region(2, 46, 13.39, 8000, 4000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)})};
  const stream::Subscribe area = around(46, 13.2, 60000);
  TileCache cache;
};

TEST_F(TileCacheTest, AChangedLayerIsDerivedAgain) {
  const auto before = checked(cache, area, global, regions, "first");
  ASSERT_FALSE(tilesOf(before, 1).empty());
  ASSERT_FALSE(tilesOf(before, 2).empty());
  ASSERT_FALSE(tilesOf(before, 6).empty());

  // The global layer 2 thins: its tiles change, layer 1's and 6's come back.
  global[1].coverage = 0.4;
  auto hits = cache.tileHits();
  const auto thinner = checked(cache, area, global, regions, "global layer 2 coverage");
  EXPECT_NE(tilesOf(thinner, 2), tilesOf(before, 2)) << "the change shows in its layer's tiles";
  EXPECT_EQ(tilesOf(thinner, 1), tilesOf(before, 1));
  EXPECT_GE(cache.tileHits(), hits + 2) << "layers 1 and 6 (and 3, uniform) were not touched";

  // The region's own layer 1 changes its coverage, then its density.
  regions[0].layers[0].coverage = 0.4;
  const auto regional = checked(cache, area, global, regions, "region layer 1 coverage");
  EXPECT_NE(tilesOf(regional, 1), tilesOf(before, 1));
  regions[0].layers[0].density = 0.2;
  checked(cache, area, global, regions, "region layer 1 density");

  // Types alone: the blend type tiles carry.
  regions[0].layers[1].type = weather::CloudType::Stratus;
  const auto stratus = checked(cache, area, global, regions, "region layer 2 type");
  EXPECT_NE(tilesOf(stratus, 2), tilesOf(thinner, 2));
  global[0].type = weather::CloudType::Stratocumulus;
  checked(cache, area, global, regions, "global layer 1 type");
  regions[1].layers[0].coverage = 0.5;  // the storm's own layer
  checked(cache, area, global, regions, "storm layer coverage");

  // A uniform layer changes: still no tiles for it, and the others' hold.
  global[2].density = 0.1;
  hits = cache.tileHits();
  checked(cache, area, global, regions, "global layer 3 density");
  EXPECT_GE(cache.tileHits(), hits + 3);

  // Layer 2 leaves the global table (the region's layer 2 then blends from
  // coverage 0), then returns: its memo must not outlive it.
  const auto layer2 = global[1];
  global.erase(global.begin() + 1);
  const auto without = checked(cache, area, global, regions, "global layer 2 removed");
  EXPECT_NE(tilesOf(without, 2), tilesOf(stratus, 2));
  global.insert(global.begin() + 1, layer2);
  checked(cache, area, global, regions, "global layer 2 back");

  // The same values again after all that: equal tiles to the very first.
  global = {layer(1, weather::CloudType::Cumulus, 0.8), layer(2, weather::CloudType::Altostratus, 0.5),
            layer(3, weather::CloudType::Cirrus, 0.3)};
  regions[0].layers = {layer(1, weather::CloudType::Cumulus, 0.0), layer(2, weather::CloudType::Altostratus, 0.9)};
  regions[1].layers[0].coverage = 1.0;
  EXPECT_EQ(checked(cache, area, global, regions, "back to the start").tiles, before.tiles);
}

TEST_F(TileCacheTest, AMovedRegionIsDerivedAgain) {
  const auto before = checked(cache, area, global, regions, "first");

  // The clearing moves by less than a cell (1 km cells): the tiles along its
  // transition change.
  regions[0].centerLon_deg += 0.004;
  const auto nudged = checked(cache, area, global, regions, "moved 300 m east");
  EXPECT_NE(tilesOf(nudged, 1), tilesOf(before, 1));
  regions[0].centerLat_deg -= 0.05;
  checked(cache, area, global, regions, "moved 5 km south");

  // Its shape, one field at a time.
  regions[0].sizeX_m = 40000;
  checked(cache, area, global, regions, "size x");
  regions[0].sizeY_m = 20000;
  checked(cache, area, global, regions, "size y");
  regions[0].rotation_deg = 30;
  const auto turned = checked(cache, area, global, regions, "rotation");
  EXPECT_NE(tilesOf(turned, 1), tilesOf(nudged, 1));
  regions[0].cornerRadius_m = 8000;
  checked(cache, area, global, regions, "corner radius");
  regions[0].transition_m = 2000;
  checked(cache, area, global, regions, "transition");

  // Order and count: regions swap places, the first goes, comes back.
  std::swap(regions[0], regions[1]);
  checked(cache, area, global, regions, "swapped");
  const auto clearing = regions[1];
  regions.erase(regions.begin() + 1);
  const auto gone = checked(cache, area, global, regions, "clearing removed");
  EXPECT_TRUE(tilesOf(gone, 1).empty()) << "layer 1 is uniform without the clearing";
  regions.insert(regions.begin(), clearing);
  checked(cache, area, global, regions, "clearing back, first");

  // The storm leaves the area for good (no region reaches it: no tiles, no
  // covering), then comes back from the other side.
  regions[1].centerLon_deg = 20;
  regions[0].centerLon_deg = 25;
  EXPECT_TRUE(checked(cache, area, global, regions, "both far").tiles.empty());
  regions[1].centerLon_deg = 12.9;
  regions[0].centerLon_deg = 13.1;
  checked(cache, area, global, regions, "both back");
}

TEST_F(TileCacheTest, OverlappingAreasAndManyRegions) {
  // Two areas that share cells (weights are shared across coverings by
  // cell), one at a coarser level (other cells), and more regions than a
  // covering keeps shapes for.
  const stream::Subscribe east = around(46, 13.35, 50000), coarse = around(46, 13.2, 60000, 11);
  for (int i = 0; i < 12; ++i)
    regions.push_back(region(10 + i, 45.8 + 0.035 * i, 12.9 + 0.05 * i, 6000, 3000,
                             {layer(7 + i % 3, weather::CloudType::Cumulonimbus, 0.3 + 0.05 * i)}));
  for (int round = 0; round < 6; ++round) {
    const std::string step = "round " + std::to_string(round);
    checked(cache, area, global, regions, step + " area");
    checked(cache, east, global, regions, step + " east");
    checked(cache, coarse, global, regions, step + " coarse");
    // One storm moves a cell's width, one changes, one stays.
    regions[2 + round].centerLon_deg += 0.015;
    regions[3 + 2 * round % 12].layers[0].coverage = 0.95;
  }
  EXPECT_EQ(cache.coverings(), 3u);
  EXPECT_GT(cache.tileHits(), 0u);
}

// diffBuilt skips the tiles of layers whose generation both snapshots share:
// its delta must be diffSnapshots' on the whole snapshots, at every step.
TEST_F(TileCacheTest, DiffBuiltIsTheDiffOfTheWholeSnapshots) {
  auto build = [&] { return buildSnapshotWithGenerations(area, global, 0.0, kDefaultMaxCells, regions, &cache); };
  std::vector<std::function<void()>> steps = {
      [&] {},                                                        // nothing changed
      [&] { global[1].coverage = 0.4; },                             // one layer
      [&] { regions[1].centerLon_deg += 0.01; },                     // the storm moves
      [&] { regions[1].centerLon_deg -= 0.25; },                     // far: cells reached before and now are apart
      [&] { regions[0].layers[0].coverage = 0.3; },                  // a region's layer
      [&] { global[2].base_m += 100; },                              // a uniform layer's table entry
      [&] { regions[1].centerLon_deg = 30; },                        // the storm leaves: its tiles go
      [&] { regions[1].centerLon_deg = 13.3; },                      // and comes back
      [&] { global.erase(global.begin() + 2); },                     // a layer removed
      [&] { regions.erase(regions.begin()); },                       // the clearing removed
      [&] { regions[0].centerLon_deg = 40; },                        // no region near: no tiles
  };
  BuiltSnapshot before = build();
  int skipped = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    steps[i]();
    const BuiltSnapshot after = build();
    ASSERT_EQ(after.runs.size(), after.snapshot.layers.size()) << i;
    for (std::size_t k = 0; k < after.runs.size(); ++k)
      for (std::size_t j = 0; j < before.runs.size(); ++j)
        skipped += after.runs[k].generation != 0 && after.snapshot.layers[k].id == before.snapshot.layers[j].id &&
                   after.runs[k].generation == before.runs[j].generation;
    const auto fast = diffBuilt(before, after);
    const auto whole = weather::diffSnapshots(wholeSnapshot(before), wholeSnapshot(after));
    ASSERT_EQ(fast.has_value(), whole.has_value()) << "step " << i;
    if (whole) {
      EXPECT_EQ(fast->tileLevel, whole->tileLevel) << "step " << i;
      EXPECT_EQ(fast->removedLayerIds, whole->removedLayerIds) << "step " << i;
      ASSERT_EQ(fast->layers.size(), whole->layers.size()) << "step " << i;
      for (std::size_t k = 0; k < whole->layers.size(); ++k) EXPECT_EQ(fast->layers[k].id, whole->layers[k].id);
      EXPECT_TRUE(fast->tiles == whole->tiles) << "step " << i << ": " << fast->tiles.size() << " tiles, not "
                                               << whole->tiles.size();
      // And it takes the peer to the new snapshot.
      weather::WeatherSnapshot held = wholeSnapshot(before);
      ASSERT_TRUE(weather::applyDelta(held, *fast)) << "step " << i;
      EXPECT_TRUE(held.tiles == wholeSnapshot(after).tiles) << "step " << i;
    }
    before = after;
  }
  EXPECT_GE(skipped, 8) << "untouched layers kept their generation, so their tiles were skipped";
}

// Snapshots hold the cache's tiles, not copies: subscribers' snapshots of
// one state share them. A change replaces a layer's tiles in the cache and
// leaves the ones a subscriber already holds as they were (the server diffs
// the next snapshot against them).
TEST_F(TileCacheTest, SnapshotsShareTheCachesTilesAndKeepTheirOwnAcrossAChange) {
  auto build = [&] { return buildSnapshotWithGenerations(area, global, 0.0, kDefaultMaxCells, regions, &cache); };
  const BuiltSnapshot first = build();
  const BuiltSnapshot second = build();
  ASSERT_EQ(first.runs.size(), first.snapshot.layers.size());
  EXPECT_TRUE(first.snapshot.tiles.empty()) << "tiles are in the runs";
  std::size_t shared = 0;
  for (std::size_t k = 0; k < first.runs.size(); ++k)
    if (first.runs[k].tiles) {
      EXPECT_EQ(first.runs[k].tiles.get(), second.runs[k].tiles.get()) << "layer " << first.snapshot.layers[k].id;
      ++shared;
    }
  EXPECT_GE(shared, 3u) << "layers 1, 2 and 6 vary over the area";

  const weather::WeatherSnapshot held = wholeSnapshot(first);
  regions[0].layers[1].coverage = 0.2;  // the clearing's layer 2 thins
  regions[1].centerLon_deg += 0.02;     // the storm moves
  const BuiltSnapshot after = build();
  EXPECT_TRUE(wholeSnapshot(first).tiles == held.tiles) << "a held snapshot changed under its subscriber";
  EXPECT_FALSE(wholeSnapshot(after).tiles == held.tiles);
  // And the new one is what deriving from scratch gives.
  EXPECT_TRUE(wholeSnapshot(after).tiles == buildSnapshot(area, global, 0.0, kDefaultMaxCells, regions).tiles);
}

// Issue 27: a layer only a small region reaches keeps the tiles of the
// cells it reaches, not one per cell of the area (writing every cell's tile
// for every subscriber at every change was the regional storm's largest
// cost); every other cell still reads as the layer's own value, and the
// whole snapshot still has one tile per cell, in the covering's order.
TEST_F(TileCacheTest, ALayerOnlyAStormReachesKeepsOnlyTheReachedTiles) {
  const BuiltSnapshot built = buildSnapshotWithGenerations(area, global, 0.0, kDefaultMaxCells, regions, &cache);
  const auto& layers = built.snapshot.layers;
  const auto storm = std::find_if(layers.begin(), layers.end(), [](const auto& l) { return l.id == 6; });
  ASSERT_NE(storm, layers.end());
  const LayerRun& run = built.runs[static_cast<std::size_t>(storm - layers.begin())];
  ASSERT_TRUE(run.tiles);
  const LayerTiles& t = *run.tiles;
  const std::vector<std::uint64_t> cells = coverArea(area.area, area.tileLevel, kDefaultMaxCells).cells;
  ASSERT_EQ(t.size(), cells.size());
  EXPECT_FALSE(t.dense);
  // The storm is 8 km square with a 4 km perimeter in a 60 km area.
  EXPECT_GT(t.tiles.size(), 0u);
  EXPECT_LT(t.tiles.size() * 10, cells.size()) << "a tile per reached cell only";
  EXPECT_EQ(t.tiles.size(), t.reached.size());
  std::vector<weather::CoverageTile> whole;
  t.appendTo(whole);
  ASSERT_EQ(whole.size(), cells.size());
  std::size_t covered = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    EXPECT_EQ(whole[k].cellId, cells[k]);
    EXPECT_EQ(whole[k].layerId, 6u);
    EXPECT_EQ(t.at(k), whole[k]);
    // Beyond the storm's reach: the region-only layer's own value, none.
    if (!std::binary_search(t.reached.begin(), t.reached.end(), static_cast<std::uint32_t>(k))) {
      EXPECT_EQ(whole[k].coverage, 0.0f);
      EXPECT_EQ(whole[k].density, 0.8f);
    } else if (whole[k].coverage == 1.0f) {
      ++covered;
    }
  }
  EXPECT_GT(covered, 0u) << "inside the storm its full cover";
}

}  // namespace
}  // namespace sky::server
