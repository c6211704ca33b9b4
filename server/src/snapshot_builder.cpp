// Snapshot building (see snapshot_builder.hpp).
#include "sky/server/snapshot_builder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sky/core/assert.hpp"
#include "sky/stream/framing.hpp"

namespace sky::server {

namespace {

// Room in a frame for everything but the tiles: the layer table (~60 bytes a
// layer, kMaxScenarioLayers of them at most) and FlatBuffers' own overhead.
constexpr std::size_t kFrameHeadroomBytes = 64 * 1024;

// Mean Earth radius (IUGG R1), the sphere tiling.hpp measures caps on.
constexpr double kMeanEarthRadius_m = 6371008.8;

// Cube faces: no covering of anything has fewer cells per level than this
// bound allows for, so it is the smallest budget that can always be met.
constexpr std::size_t kMinCells = 6;

// Upper estimate of the cells covering `cap` at `level`: its area in cells plus
// a ring of boundary cells. Only used to avoid asking S2 for a covering that
// would be far too large (at level 20 a continent is billions of cells); the
// real count is then checked.
double estimatedCells(const weather::SphericalCap& cap, int level) {
  const double edge_m = weather::averageCellEdge_m(level);
  const double angle_rad = std::min(cap.radius_m / kMeanEarthRadius_m, std::numbers::pi);
  const double area_m2 =
      2 * std::numbers::pi * kMeanEarthRadius_m * kMeanEarthRadius_m * (1 - std::cos(angle_rad));
  const double perimeter_m = 2 * std::numbers::pi * kMeanEarthRadius_m * std::sin(angle_rad);
  // Factor 2 on the ring: S2 cells vary in size about their mean by ~2x.
  return area_m2 / (edge_m * edge_m) + 2 * perimeter_m / edge_m + 4;
}

}  // namespace

std::size_t cellBudget(std::size_t maxCells, std::size_t layerCount) {
  const std::size_t tilesPerFrame =
      (stream::kMaxFrameBytes - kFrameHeadroomBytes) / kTileWireBytes;
  const std::size_t byFrame = tilesPerFrame / std::max<std::size_t>(layerCount, 1);
  return std::max(kMinCells, std::min(maxCells, byFrame));
}

Covering coverArea(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells) {
  SKY_ASSERT(wantedLevel >= 0 && wantedLevel <= 30);
  SKY_ASSERT(maxCells >= kMinCells);
  int level = wantedLevel;
  while (level > 0 && estimatedCells(cap, level) > 4.0 * static_cast<double>(maxCells)) --level;
  for (;; --level) {
    Covering c{level, weather::coverCap(cap, level, maxCells)};
    if (c.cells.size() <= maxCells || level == 0) return c;
  }
}

std::vector<weather::CoverageTile> deriveTiles(std::span<const std::uint64_t> cells,
                                               std::span<const weather::CloudLayer> layers) {
  std::vector<weather::CoverageTile> tiles;
  tiles.reserve(cells.size() * layers.size());
  for (const weather::CloudLayer& layer : layers)
    for (const std::uint64_t cell : cells)
      tiles.push_back({cell, layer.id, static_cast<float>(layer.coverage),
                       static_cast<float>(layer.density)});
  return tiles;
}

weather::WeatherSnapshot buildSnapshot(const stream::Subscribe& request,
                                       std::span<const weather::CloudLayer> layers,
                                       double clock_s, std::size_t maxCells) {
  const Covering covering =
      coverArea(request.area, request.tileLevel, cellBudget(maxCells, layers.size()));
  weather::WeatherSnapshot snapshot;
  snapshot.weatherClock_s = clock_s;
  snapshot.layers.assign(layers.begin(), layers.end());
  snapshot.tileLevel = covering.level;
  snapshot.tiles = deriveTiles(covering.cells, layers);
  return snapshot;
}

}  // namespace sky::server
