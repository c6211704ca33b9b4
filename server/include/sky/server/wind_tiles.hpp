// The wind tiles of a snapshot: each layer's wind on the S2 cells of the
// subscriber's area where it differs over the area: a forecast's winds at
// the layer's height, and regions' own winds blended into the layer's across
// their transition perimeter (the same weights as their cover). A layer whose
// wind is its own everywhere gets none; uniform weather costs nothing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "sky/server/snapshot_builder.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/region.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {

// Wind varies over tens of kilometres (a forecast's grid, a front, a region's
// perimeter): cells of level 10 (about 8 km) where the area allows, coarser
// for larger areas so that one layer's wind takes at most kMaxWindCells
// tiles (16 bytes each: 32 KiB a layer).
inline constexpr int kWindTileLevel = 10;
inline constexpr std::size_t kMaxWindCells = 2048;
// Layers with wind tiles in one snapshot, the lowest first; any more keep
// their own wind (a quarter of a frame at most goes to wind).
inline constexpr std::size_t kMaxWindLayers = 16;

// The cells a field's tiles (wind, air) are given on: the area widened by
// two cell edges, so that a point anywhere in it has every cell the fields'
// kernel weighs (an area of one metre, as the point query's, would otherwise
// be one cell with no neighbours), at `wantedLevel` or coarser within
// maxCells. With a cache the cells and centres are its entry's (`entry`),
// else this object's own; not copyable (the spans point into it).
struct FieldCovering {
  FieldCovering() = default;
  FieldCovering(const FieldCovering&) = delete;
  FieldCovering& operator=(const FieldCovering&) = delete;
  std::span<const std::uint64_t> cells;
  std::span<const weather::CellCentre> centres;
  int level = 0;
  TileCache::Entry* entry = nullptr;
  Covering local;
  std::vector<weather::CellCentre> localCentres;
};
void coverWithMargin(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells, TileCache* cache,
                     FieldCovering& out);

struct WindTiles {
  int level = 0;  // 0 when there are no tiles
  std::vector<weather::WindTile> tiles;
};

// The wind tiles of `table` (the snapshot's layers) over the area `cap`,
// quantised as on the wire. `regions` as they stand at the snapshot's clock.
// With a cache, the covering and the regions' weights come from it.
WindTiles deriveWindTiles(const weather::SphericalCap& cap, std::span<const weather::CloudLayer> table,
                          std::span<const weather::Region> regions, const LayerField* field, TileCache* cache = nullptr);

}  // namespace sky::server
