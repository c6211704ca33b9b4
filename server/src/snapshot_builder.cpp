// Snapshot building (see snapshot_builder.hpp).
#include "sky/server/snapshot_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
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

std::vector<weather::CloudLayer> snapshotLayers(std::span<const weather::CloudLayer> layers,
                                                std::span<const weather::Region> regions) {
  std::vector<weather::CloudLayer> table(layers.begin(), layers.end());
  std::map<std::uint32_t, weather::CloudLayer> regionOnly;
  std::vector<const weather::Region*> byId;
  for (const auto& r : regions) byId.push_back(&r);
  std::sort(byId.begin(), byId.end(), [](const auto* a, const auto* b) { return a->id < b->id; });
  for (const weather::Region* r : byId)
    for (const weather::CloudLayer& l : r->layers) {
      const bool global = std::any_of(layers.begin(), layers.end(), [&](const auto& g) { return g.id == l.id; });
      if (!global && !regionOnly.count(l.id)) {
        weather::CloudLayer absent = l;
        absent.coverage = 0;
        regionOnly[l.id] = absent;
      }
    }
  for (const auto& [id, l] : regionOnly) table.push_back(l);
  return table;
}

namespace {

// Great-circle distance on the mean sphere, m: a cheap bound to skip regions
// far from a cell before the exact geodesic measure.
double sphereDistance_m(double lat1, double lon1, double lat2, double lon2) {
  constexpr double d2r = std::numbers::pi / 180.0;
  const double s1 = std::sin((lat2 - lat1) * d2r / 2), s2 = std::sin((lon2 - lon1) * d2r / 2);
  const double h = s1 * s1 + std::cos(lat1 * d2r) * std::cos(lat2 * d2r) * s2 * s2;
  return 2 * kMeanEarthRadius_m * std::asin(std::min(1.0, std::sqrt(h)));
}

struct Reach {
  const weather::Region* region;
  double reach_m;  // beyond this (sphere distance from the centre) its weight is 0
};

// Half diagonal plus perimeter, with 1 % and 1 km for the ellipsoid and the
// sphere bound's own error.
double reachOf(const weather::Region& r) {
  return 1.01 * (std::hypot(r.sizeX_m, r.sizeY_m) / 2 + r.transition_m) + 1000.0;
}

}  // namespace

namespace {

std::uint64_t shapeKey(const weather::Region& r) {
  std::uint64_t h = 1469598103934665603ull;
  for (double v : {r.centerLat_deg, r.centerLon_deg, r.sizeX_m, r.sizeY_m, r.cornerRadius_m, r.rotation_deg,
                   r.transition_m}) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &v, sizeof bits);
    for (int i = 0; i < 8; ++i) {
      h ^= (bits >> (8 * i)) & 0xffu;
      h *= 1099511628211ull;
    }
  }
  return h;
}

// Bounds of the cache: areas (renderers re-subscribe as they move) and
// region shapes (a drifting region has a new shape at every change).
constexpr std::size_t kMaxCachedCoverings = 256;
constexpr std::size_t kMaxCachedShapes = 64;

}  // namespace

const TileCache::Entry& TileCache::covering(const weather::SphericalCap& cap, int wantedLevel,
                                            std::size_t maxCells) {
  const auto key = std::tuple{cap.centerLat_deg, cap.centerLon_deg, cap.radius_m, wantedLevel, maxCells};
  if (auto it = coverings_.find(key); it != coverings_.end()) return it->second;
  if (coverings_.size() >= kMaxCachedCoverings) coverings_.clear();
  Entry e{coverArea(cap, wantedLevel, maxCells), {}};
  e.centres.reserve(e.covering.cells.size());
  for (std::uint64_t c : e.covering.cells) e.centres.push_back(weather::cellCentre(c));
  return coverings_.emplace(key, std::move(e)).first->second;
}

double TileCache::weight(const weather::Region& region, std::uint64_t cell, const weather::CellCentre& centre) {
  const std::uint64_t key = shapeKey(region);
  auto shape = weights_.find(key);
  if (shape == weights_.end()) {
    if (weights_.size() >= kMaxCachedShapes) weights_.clear();
    shape = weights_.emplace(key, std::unordered_map<std::uint64_t, double>{}).first;
  }
  if (auto it = shape->second.find(cell); it != shape->second.end()) return it->second;
  const double w = weather::regionWeight(region, centre.lat_deg, centre.lon_deg);
  shape->second.emplace(cell, w);
  return w;
}

std::vector<weather::CoverageTile> deriveTiles(std::span<const std::uint64_t> cells,
                                               std::span<const weather::CloudLayer> layers,
                                               std::span<const weather::Region> regions, TileCache* cache,
                                               std::span<const weather::CellCentre> centres) {
  std::vector<weather::CoverageTile> tiles;
  tiles.reserve(cells.size() * layers.size());
  std::vector<Reach> reaches;
  for (const auto& r : regions) reaches.push_back({&r, reachOf(r)});
  // Every region's weight at every cell centre (none when no region is near).
  std::vector<std::vector<double>> weights(regions.empty() ? 0 : cells.size());
  for (std::size_t ci = 0; ci < weights.size(); ++ci) {
    const weather::CellCentre c = ci < centres.size() ? centres[ci] : weather::cellCentre(cells[ci]);
    std::vector<double> w(reaches.size(), 0.0);
    bool any = false;
    for (std::size_t k = 0; k < reaches.size(); ++k) {
      const weather::Region& r = *reaches[k].region;
      if (sphereDistance_m(c.lat_deg, c.lon_deg, r.centerLat_deg, r.centerLon_deg) > reaches[k].reach_m) continue;
      w[k] = cache ? cache->weight(r, cells[ci], c) : weather::regionWeight(r, c.lat_deg, c.lon_deg);
      any = any || w[k] > 0;
    }
    if (any) weights[ci] = std::move(w);
  }
  std::vector<weather::CoverageTile> layerTiles;
  for (const weather::CloudLayer& layer : layers) {
    layerTiles.clear();
    bool varies = false;
    for (std::size_t ci = 0; ci < cells.size(); ++ci) {
      weather::CoverageTile t{cells[ci], layer.id, static_cast<float>(layer.coverage),
                              static_cast<float>(layer.density)};
      if (ci < weights.size() && !weights[ci].empty()) {
        double sumW = 0, coverage = 0, density = 0, heaviest = 0;
        weather::CloudType heaviestType = layer.type;
        for (std::size_t k = 0; k < reaches.size(); ++k) {
          const double w = weights[ci][k];
          if (w <= 0) continue;
          for (const weather::CloudLayer& rl : reaches[k].region->layers) {
            if (rl.id != layer.id) continue;
            sumW += w;
            coverage += w * rl.coverage;
            density += w * rl.density;
            if (w > heaviest) {
              heaviest = w;
              heaviestType = rl.type;
            }
          }
        }
        if (sumW > 0) {
          const double w = std::min(sumW, 1.0);
          t.coverage = static_cast<float>(layer.coverage + w * (coverage / sumW - layer.coverage));
          t.density = static_cast<float>(layer.density + w * (density / sumW - layer.density));
          if (heaviestType != layer.type) {
            t.blendType = heaviestType;
            t.blend = static_cast<float>(w);
          }
        }
      }
      varies = varies || t.coverage != static_cast<float>(layer.coverage) ||
               t.density != static_cast<float>(layer.density) || t.blendType != weather::CloudType::None;
      layerTiles.push_back(t);
    }
    // A layer the same everywhere in the area needs no tiles: a renderer
    // takes a layer without tiles as uniform (its own coverage and density).
    if (varies) tiles.insert(tiles.end(), layerTiles.begin(), layerTiles.end());
  }
  return tiles;
}

weather::WeatherSnapshot buildSnapshot(const stream::Subscribe& request,
                                       std::span<const weather::CloudLayer> layers,
                                       double clock_s, std::size_t maxCells,
                                       std::span<const weather::Region> regions, TileCache* cache) {
  const std::vector<weather::CloudLayer> table = snapshotLayers(layers, regions);
  const std::size_t budget = cellBudget(maxCells, table.size());
  weather::WeatherSnapshot snapshot;
  snapshot.weatherClock_s = clock_s;
  snapshot.layers = table;
  // No region reaches the area: the weather there is uniform and needs no
  // tiles, so no covering either (the level is the one the budget allows).
  const auto& cap = request.area;
  const bool regional = std::any_of(regions.begin(), regions.end(), [&](const weather::Region& r) {
    return sphereDistance_m(cap.centerLat_deg, cap.centerLon_deg, r.centerLat_deg, r.centerLon_deg) <=
           cap.radius_m + reachOf(r);
  });
  if (!regional) {
    int level = request.tileLevel;
    while (level > 0 && estimatedCells(cap, level) > static_cast<double>(budget)) --level;
    snapshot.tileLevel = level;
    return snapshot;
  }
  if (cache) {
    const TileCache::Entry& e = cache->covering(cap, request.tileLevel, budget);
    snapshot.tileLevel = e.covering.level;
    snapshot.tiles = deriveTiles(e.covering.cells, table, regions, cache, e.centres);
    return snapshot;
  }
  const Covering covering = coverArea(cap, request.tileLevel, budget);
  snapshot.tileLevel = covering.level;
  snapshot.tiles = deriveTiles(covering.cells, table, regions);
  return snapshot;
}

}  // namespace sky::server
