// Builds the Snapshot a subscriber gets: every layer, plus coverage tiles on
// the S2 cells covering its area of interest at a level whose cell count (and
// so the frame) stays bounded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "sky/stream/messages.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {

// Cells per snapshot. 20000 cells at the ~1 km tiles DESIGN.md asks for cover
// a cap of roughly 80 km radius, more than a renderer sees through cloud, and
// one cloud layer's tiles then take ~480 kB of a frame.
inline constexpr std::size_t kDefaultMaxCells = 20000;

// Bytes one CoverageTile takes on the wire, used to keep a snapshot under
// sky::stream::kMaxFrameBytes (the schema's size, pinned in protocol/).
inline constexpr std::size_t kTileWireBytes = stream::kTileWireBytes;

// Cells allowed for `layerCount` layers: maxCells, lowered so that cells ×
// layers tiles still fit one stream frame (with room for the layer table).
std::size_t cellBudget(std::size_t maxCells, std::size_t layerCount);

struct Covering {
  int level = 0;                     // S2 level actually used, <= the wanted one
  std::vector<std::uint64_t> cells;  // S2CellIds of exactly `level`, size <= maxCells
};

// S2 covering of `cap` at `wantedLevel` ([0, 30]) or, when that takes more than
// maxCells (>= 6, one cell per cube face) cells, at the finest coarser level
// that does not.
Covering coverArea(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells);

// One tile per (cell, layer). Layers are global in this version, so each tile
// carries its layer's coverage and density; regional weather replaces this.
std::vector<weather::CoverageTile> deriveTiles(std::span<const std::uint64_t> cells,
                                               std::span<const weather::CloudLayer> layers);

// The snapshot answering `request` at weather clock clock_s.
weather::WeatherSnapshot buildSnapshot(const stream::Subscribe& request,
                                       std::span<const weather::CloudLayer> layers,
                                       double clock_s, std::size_t maxCells);

}  // namespace sky::server
