// Snapshot building (see snapshot_builder.hpp).
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/air_tiles.hpp"
#include "sky/server/wind_tiles.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <numbers>

#include "sky/core/assert.hpp"
#include "sky/stream/framing.hpp"
#include "sky/weather/precipitation.hpp"

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
// The most of a frame wind and air tiles take from cover tiles (under a fifth of it).
constexpr std::size_t kMaxFieldFrameTiles = kMaxWindLayers * kMaxWindCells + weather::kMaxAirLevels * kMaxAirCells;

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

double sphereDistance_m(double lat1, double lon1, double lat2, double lon2) {
  constexpr double kDegToRad = std::numbers::pi / 180.0;
  const double s1 = std::sin((lat2 - lat1) * kDegToRad / 2), s2 = std::sin((lon2 - lon1) * kDegToRad / 2);
  const double h = s1 * s1 + std::cos(lat1 * kDegToRad) * std::cos(lat2 * kDegToRad) * s2 * s2;
  return 2 * kMeanEarthRadius_m * std::asin(std::min(1.0, std::sqrt(h)));
}

// Half diagonal plus perimeter, with 1 % and 1 km for the ellipsoid and the
// sphere bound's own error.
double reachOf(const weather::Region& r) {
  return 1.01 * (std::hypot(r.sizeX_m, r.sizeY_m) / 2 + r.transition_m) + 1000.0;
}

// fieldTiles: the snapshot's wind and air tiles, which take a cover tile's room each.
std::size_t cellBudget(std::size_t maxCells, std::size_t layerCount, std::size_t fieldTiles) {
  static_assert(stream::kWindTileWireBytes == kTileWireBytes, "a wind tile takes a cover tile's room");
  static_assert(stream::kAirTileWireBytes == kTileWireBytes, "an air tile takes a cover tile's room");
  const std::size_t tilesPerFrame =
      (stream::kMaxFrameBytes - kFrameHeadroomBytes) / kTileWireBytes - std::min(fieldTiles, kMaxFieldFrameTiles);
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
                                                std::span<const weather::Region> regions, const weather::CellCentre* at,
                                                double radius_m) {
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
  if (at && !regionOnly.empty()) {
    // The regions round `at` (cheap distance bound first), heaviest first.
    std::vector<std::pair<double, const weather::Region*>> near;
    for (const weather::Region* r : byId)
      if (sphereDistance_m(at->lat_deg, at->lon_deg, r->centerLat_deg, r->centerLon_deg) <= reachOf(*r))
        if (const double w = weather::regionWeight(*r, at->lat_deg, at->lon_deg); w > 0) near.emplace_back(w, r);
    std::stable_sort(near.begin(), near.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::set<std::uint32_t> done;
    for (const auto& [w, r] : near)
      for (const weather::CloudLayer& l : r->layers)
        if (auto it = regionOnly.find(l.id); it != regionOnly.end() && done.insert(l.id).second) {
          it->second = l;
          it->second.coverage = 0;
        }
  }
  if (at) {
    // Fog and precipitation (both from the ground up): every region's in
    // reach of the area, from the lowest base to the highest top.
    std::map<std::uint32_t, std::pair<double, double>> fog;  // id -> base, top
    for (const weather::Region* r : byId) {
      if (sphereDistance_m(at->lat_deg, at->lon_deg, r->centerLat_deg, r->centerLon_deg) > radius_m + reachOf(*r)) continue;
      for (const weather::CloudLayer& l : r->layers) {
        if ((l.type != weather::CloudType::Fog && !weather::isPrecipitation(l.type)) || !regionOnly.count(l.id)) continue;
        auto& span = fog.try_emplace(l.id, l.base_m, l.base_m + l.thickness_m).first->second;
        span = {std::min(span.first, l.base_m), std::max(span.second, l.base_m + l.thickness_m)};
      }
    }
    for (const auto& [id, span] : fog) {
      weather::CloudLayer& l = regionOnly[id];
      l.base_m = span.first;
      l.thickness_m = span.second - span.first;
    }
  }
  for (const auto& [id, l] : regionOnly) table.push_back(l);
  return table;
}

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// A region's reach as a bound on the dot product of unit vectors: a cell
// whose centre has dot(centre, region centre) below it is out of reach.
struct ReachBound {
  UnitVector centre;
  double minDot = -2;  // a reach past the antipode reaches everything
  double angle_rad = 0;
};

ReachBound reachBound(const weather::Region& r) {
  const double angle_rad = reachOf(r) / kMeanEarthRadius_m;
  return {unitVector(r.centerLat_deg, r.centerLon_deg), angle_rad >= std::numbers::pi ? -2.0 : std::cos(angle_rad),
          angle_rad};
}

double dot(const UnitVector& a, const UnitVector& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

std::uint64_t bitsOf(double v) { return std::bit_cast<std::uint64_t>(v); }

TileCache::ShapeKey shapeKey(const weather::Region& r) {
  return {bitsOf(r.centerLat_deg), bitsOf(r.centerLon_deg), bitsOf(r.sizeX_m), bitsOf(r.sizeY_m),
          bitsOf(r.cornerRadius_m), bitsOf(r.rotation_deg), bitsOf(r.transition_m)};
}

// Bounds of the cache (besides its areas, TileCache::maxCoverings_): region
// shapes (a drifting or moving region has a new shape at every change) across
// coverings, and shapes per covering.
constexpr std::size_t kMaxCachedShapes = 64;
// Cell weights kept across coverings, ~60 bytes each in the hash maps: 1M is
// ~60 MB, and a storm cell 60 km across reaches ~400 cells of each of 64
// subscribers' level 11 coverings (the bench), mostly the same ones.
constexpr std::size_t kMaxCachedCellWeights = 1'000'000;
constexpr std::size_t kMaxShapesPerCovering = 8;

// Cells per group of a covering (TileCache::Entry::groups): a parent this
// many levels coarser has up to 4^3 = 64 children, so a 120 km area at
// level 11 (~2900 cells) is ~50 groups, and a storm cell 60 km across
// tests ~10 groups' cells instead of all of them.
constexpr int kGroupLevels = 3;
// Rounding in the group test (acos near 0 and 1 loses ~1e-8 rad).
constexpr double kGroupSlack_rad = 1e-6;

// The parent of S2 cell `id` at `level` (<= its own): S2CellId::parent,
// whose lowest set bit marks a cell's level (s2cellid.h).
std::uint64_t parentCell(std::uint64_t id, int level) {
  const std::uint64_t lsb = std::uint64_t{1} << (2 * (30 - level));
  return (id & (~lsb + 1)) | lsb;
}

std::vector<TileCache::Entry::CellGroup> cellGroups(std::span<const std::uint64_t> cells, int level,
                                                    std::span<const UnitVector> units) {
  std::vector<TileCache::Entry::CellGroup> groups;
  const int parentLevel = std::max(0, level - kGroupLevels);
  std::uint64_t parent = 0;
  for (std::size_t ci = 0; ci < cells.size(); ++ci) {
    const std::uint64_t p = parentCell(cells[ci], parentLevel);
    if (groups.empty() || p != parent) {
      groups.push_back({static_cast<std::uint32_t>(ci), static_cast<std::uint32_t>(ci), {0, 0, 0}, 0});
      parent = p;
    }
    groups.back().end = static_cast<std::uint32_t>(ci + 1);
  }
  for (auto& g : groups) {
    UnitVector sum{0, 0, 0};
    for (std::size_t ci = g.begin; ci < g.end; ++ci) {
      sum.x += units[ci].x;
      sum.y += units[ci].y;
      sum.z += units[ci].z;
    }
    const double norm = std::sqrt(sum.x * sum.x + sum.y * sum.y + sum.z * sum.z);
    // Centres spread over more than a hemisphere (only at level 0-2): the
    // whole sphere is the group's cap.
    if (!(norm > 1e-9)) {
      g.centre = units[g.begin];
      g.radius_rad = std::numbers::pi;
      continue;
    }
    g.centre = {sum.x / norm, sum.y / norm, sum.z / norm};
    for (std::size_t ci = g.begin; ci < g.end; ++ci)
      g.radius_rad = std::max(g.radius_rad, std::acos(std::clamp(dot(g.centre, units[ci]), -1.0, 1.0)));
  }
  return groups;
}

// A region's layer of the layer being derived, with that region's weight at
// the cells it reaches.
struct Contribution {
  const TileCache::Weights* weights;
  const weather::CloudLayer* layer;
};

// The weights kept: every one not <= 0 (a NaN too, as the sums below would
// take it).
void keepWeight(TileCache::Weights& out, std::size_t cell, double w) {
  if (w <= 0) return;
  out.cells.push_back(static_cast<std::uint32_t>(cell));
  out.weights.push_back(w);
}

// One layer's tiles over `shared` cells: the global value blended towards
// the weighted mean of the contributing regions' values; none when the layer
// comes out the same everywhere. Only the cells a region reaches are
// blended (a storm cell reaches a few hundred of an area's thousands), and
// without a field only their tiles are kept (LayerTiles' sparse form).
LayerTiles layerTiles(const std::shared_ptr<const std::vector<std::uint64_t>>& shared,
                      const weather::CloudLayer& layer, std::span<const Contribution> contributions,
                      std::span<const weather::CoverageTile> field = {}) {
  LayerTiles out;
  if (contributions.empty() && field.empty()) return out;
  const std::span<const std::uint64_t> cells(*shared);
  // Per reached cell, the sums over the contributions in their order.
  struct Sum {
    std::uint32_t cell;
    double w = 0, cov = 0, den = 0, heaviest = 0;
    weather::CloudType heaviestType;
  };
  std::vector<Sum> sums;
  constexpr std::uint32_t kNone = ~0u;
  std::vector<std::uint32_t> slot(contributions.size() > 1 ? cells.size() : 0, kNone);  // cell -> sums index
  for (const Contribution& c : contributions) {
    const auto& ws = *c.weights;
    for (std::size_t n = 0; n < ws.cells.size(); ++n) {
      const std::uint32_t ci = ws.cells[n];
      const double w = ws.weights[n];
      std::size_t at = sums.size();
      if (slot.empty() || slot[ci] == kNone) {
        if (!slot.empty()) slot[ci] = static_cast<std::uint32_t>(at);
        sums.push_back({ci, 0, 0, 0, 0, layer.type});
      } else {
        at = slot[ci];
      }
      Sum& s = sums[at];
      s.w += w;
      s.cov += w * c.layer->coverage;
      s.den += w * c.layer->density;
      if (w > s.heaviest) {
        s.heaviest = w;
        s.heaviestType = c.layer->type;
      }
    }
  }
  const auto coverage = static_cast<float>(layer.coverage), density = static_cast<float>(layer.density);
  // The value a cell has before regions blend in: the field's where it has
  // one, else the layer's own.
  auto baseAt = [&](std::size_t ci) {
    weather::CoverageTile t{cells[ci], layer.id, coverage, density};
    if (!field.empty() && !std::isnan(field[ci].coverage)) {
      t = field[ci];
      t.cellId = cells[ci];
      t.layerId = layer.id;
    }
    return t;
  };
  auto differs = [&](const weather::CoverageTile& t) {
    return t.coverage != coverage || t.density != density || t.blendType != weather::CloudType::None;
  };
  std::vector<std::pair<std::uint32_t, weather::CoverageTile>> blended;
  bool varies = false;
  for (const Sum& s : sums) {
    if (!(s.w > 0)) continue;
    weather::CoverageTile t = baseAt(s.cell);
    const double w = std::min(s.w, 1.0);
    t.coverage = static_cast<float>(t.coverage + w * (s.cov / s.w - t.coverage));
    t.density = static_cast<float>(t.density + w * (s.den / s.w - t.density));
    if (s.heaviestType != layer.type && w >= t.blend) {
      t.blendType = s.heaviestType;
      t.blend = static_cast<float>(w);
    }
    varies = varies || differs(t);
    blended.emplace_back(s.cell, t);
  }
  // (Several contributions list their cells in the order each first reached them.)
  std::sort(blended.begin(), blended.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  out.cells = shared;
  out.layerId = layer.id;
  out.reached.reserve(blended.size());
  for (const auto& b : blended) out.reached.push_back(b.first);
  if (field.empty()) {
    // Every cell no region reaches has the layer's own value.
    if (!varies) return LayerTiles{};
    out.coverage = coverage;
    out.density = density;
    out.tiles.reserve(blended.size());
    for (const auto& b : blended) out.tiles.push_back(b.second);
    return out;
  }
  out.dense = true;
  out.tiles.reserve(cells.size());
  for (std::size_t ci = 0; ci < cells.size(); ++ci) {
    out.tiles.push_back(baseAt(ci));
    varies = varies || differs(out.tiles.back());
  }
  // A layer the same everywhere in the area needs no tiles: a renderer takes
  // a layer without tiles as uniform (its own coverage and density).
  if (!varies) return LayerTiles{};
  // With a field every tile may differ from the layer's own value, and a
  // diff compares them all (NaN never equals the next snapshot's).
  out.coverage = std::numeric_limits<float>::quiet_NaN();
  out.density = density;
  for (const auto& [ci, t] : blended) out.tiles[ci] = t;
  return out;
}

// A region's layer of this id, if it has one (a region's layer ids are distinct).
const weather::CloudLayer* layerOf(const weather::Region& r, std::uint32_t id) {
  for (const auto& l : r.layers)
    if (l.id == id) return &l;
  return nullptr;
}

// The layer at cover 0: what a region that replaces every layer has of a
// layer it does not carry.
weather::CloudLayer clearedOf(const weather::CloudLayer& layer) {
  weather::CloudLayer l = layer;
  l.coverage = 0;
  return l;
}

// What region r contributes to layer `id`: its own layer of that id, or
// `cleared` when it replaces every layer, or nothing.
const weather::CloudLayer* regionLayer(const weather::Region& r, std::uint32_t id, const weather::CloudLayer& cleared) {
  if (const auto* own = layerOf(r, id)) return own;
  return r.replacesAllLayers ? &cleared : nullptr;
}

// Every layer's tiles from every region's weight per cell (weights[k] for
// region k; null where it reaches no cell).
std::vector<weather::CoverageTile> tilesFromWeights(const std::shared_ptr<const std::vector<std::uint64_t>>& cells,
                                                    std::span<const weather::CloudLayer> layers,
                                                    std::span<const weather::Region> regions,
                                                    std::span<const TileCache::Weights* const> weights,
                                                    const LayerField* field, std::span<const weather::CellCentre> centres) {
  std::vector<weather::CoverageTile> tiles;
  std::vector<Contribution> contributions;
  std::vector<weather::CoverageTile> base;
  for (const weather::CloudLayer& layer : layers) {
    contributions.clear();
    const weather::CloudLayer cleared = clearedOf(layer);
    for (std::size_t k = 0; k < regions.size(); ++k)
      if (const auto* rl = regionLayer(regions[k], layer.id, cleared); rl && weights[k])
        contributions.push_back({weights[k], rl});
    base.clear();
    if (field && field->gives(layer.id)) {
      base.resize(cells->size());
      field->sample(layer.id, centres, base);
    }
    layerTiles(cells, layer, contributions, base).appendTo(tiles);
  }
  return tiles;
}

}  // namespace

UnitVector unitVector(double lat_deg, double lon_deg) {
  const double lat = lat_deg * kDegToRad, lon = lon_deg * kDegToRad;
  return {std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)};
}

TileCache::Entry& TileCache::covering(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells) {
  const auto key = std::tuple{cap.centerLat_deg, cap.centerLon_deg, cap.radius_m, wantedLevel, maxCells};
  if (auto it = coverings_.find(key); it != coverings_.end()) return it->second;
  if (coverings_.size() >= std::max<std::size_t>(maxCoverings_, 1)) coverings_.clear();
  Entry e;
  e.serial = ++coveringSerials_;
  e.cap = cap;
  e.covering = coverArea(cap, wantedLevel, maxCells);
  e.cells = std::make_shared<const std::vector<std::uint64_t>>(e.covering.cells);
  e.centres.reserve(e.covering.cells.size());
  e.units.reserve(e.covering.cells.size());
  for (std::uint64_t c : e.covering.cells) {
    e.centres.push_back(weather::cellCentre(c));
    e.units.push_back(unitVector(e.centres.back().lat_deg, e.centres.back().lon_deg));
  }
  e.groups = cellGroups(e.covering.cells, e.covering.level, e.units);
  return coverings_.emplace(key, std::move(e)).first->second;
}

std::size_t TileCache::ShapeKeyHash::operator()(const ShapeKey& k) const {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the words
  for (std::uint64_t v : k) {
    h ^= v;
    h *= 1099511628211ull;
  }
  return static_cast<std::size_t>(h ^ (h >> 32));
}

double TileCache::cellWeight(const ShapeKey& shape, const weather::Region& region, std::uint64_t cell,
                             const weather::CellCentre& centre) {
  auto it = cellWeights_.find(shape);
  if (it == cellWeights_.end() || cellWeightCount_ >= kMaxCachedCellWeights) {
    if (cellWeights_.size() >= kMaxCachedShapes || cellWeightCount_ >= kMaxCachedCellWeights) {
      cellWeights_.clear();
      cellWeightCount_ = 0;
    }
    it = cellWeights_.try_emplace(shape).first;
  }
  auto& cells = it->second;
  if (auto w = cells.find(cell); w != cells.end()) return w->second;
  const double w = weather::regionWeight(region, centre.lat_deg, centre.lon_deg);
  cells.emplace(cell, w);
  ++cellWeightCount_;
  return w;
}

TileCache::ShapeKey TileCache::shapeOf(const weather::Region& region) { return shapeKey(region); }

void TileCache::makeRoomForShapes(Entry& entry, std::size_t regions) {
  if (entry.shapeWeights.size() + regions > kMaxShapesPerCovering) entry.shapeWeights.clear();
}

const TileCache::Weights& TileCache::weights(Entry& entry, const weather::Region& region) {
  // (Never erases: the caller bounds entry.shapeWeights before asking.)
  const ShapeKey shape = shapeKey(region);
  if (auto it = entry.shapeWeights.find(shape); it != entry.shapeWeights.end()) return it->second;
  Weights w;
  const ReachBound reach = reachBound(region);
  for (const Entry::CellGroup& g : entry.groups) {
    // (A bound past the antipode takes every group.)
    if (reach.minDot > -1 &&
        std::acos(std::clamp(dot(g.centre, reach.centre), -1.0, 1.0)) > reach.angle_rad + g.radius_rad + kGroupSlack_rad)
      continue;
    for (std::size_t ci = g.begin; ci < g.end; ++ci)
      if (dot(entry.units[ci], reach.centre) >= reach.minDot)
        keepWeight(w, ci, cellWeight(shape, region, entry.covering.cells[ci], entry.centres[ci]));
  }
  return entry.shapeWeights.emplace(shape, std::move(w)).first->second;
}

std::vector<weather::CoverageTile> deriveTiles(std::span<const std::uint64_t> cells,
                                               std::span<const weather::CloudLayer> layers,
                                               std::span<const weather::Region> regions, const LayerField* field) {
  std::vector<TileCache::Weights> weights(regions.size());
  std::vector<const TileCache::Weights*> byRegion(regions.size(), nullptr);
  std::vector<UnitVector> units;
  std::vector<weather::CellCentre> centres;
  if (field) {
    centres.reserve(cells.size());
    for (std::uint64_t c : cells) centres.push_back(weather::cellCentre(c));
  }
  if (!regions.empty()) {
    units.reserve(cells.size());
    for (std::uint64_t c : cells) {
      const weather::CellCentre centre = weather::cellCentre(c);
      units.push_back(unitVector(centre.lat_deg, centre.lon_deg));
    }
  }
  for (std::size_t k = 0; k < regions.size(); ++k) {
    const ReachBound reach = reachBound(regions[k]);
    for (std::size_t ci = 0; ci < cells.size(); ++ci) {
      if (dot(units[ci], reach.centre) < reach.minDot) continue;
      const weather::CellCentre centre = weather::cellCentre(cells[ci]);
      keepWeight(weights[k], ci, weather::regionWeight(regions[k], centre.lat_deg, centre.lon_deg));
    }
    if (!weights[k].cells.empty()) byRegion[k] = &weights[k];
  }
  return tilesFromWeights(std::make_shared<const std::vector<std::uint64_t>>(cells.begin(), cells.end()), layers,
                          regions, byRegion, field, centres);
}

std::vector<LayerRun> deriveRuns(TileCache& cache, TileCache::Entry& entry,
                                 std::span<const weather::CloudLayer> layers,
                                 std::span<const weather::Region> regions, const LayerField* field) {
  // Room for every region's weights first: the pointers below must stay valid.
  TileCache::makeRoomForShapes(entry, regions.size());
  // The regions that can reach a cell of this covering (its cells reach past
  // the cap by up to a cell: S2 cells are at most about twice the average
  // edge across); the others change nothing here.
  const auto& cap = entry.cap;
  const double margin_m = 2 * weather::averageCellEdge_m(entry.covering.level);
  std::vector<bool> reaches(regions.size());
  for (std::size_t k = 0; k < regions.size(); ++k)
    reaches[k] = sphereDistance_m(cap.centerLat_deg, cap.centerLon_deg, regions[k].centerLat_deg,
                                  regions[k].centerLon_deg) <= cap.radius_m + reachOf(regions[k]) + margin_m;
  std::vector<LayerRun> runs;
  runs.reserve(layers.size());
  std::vector<Contribution> contributions;
  std::vector<std::uint64_t> inputs;
  for (const weather::CloudLayer& layer : layers) {
    // A layer's tiles depend on its own values and, for each region that
    // reaches here and has it (in order: the sums run in it), that region's
    // shape and layer values: equal inputs give equal tiles (their bit
    // patterns compared exactly, not hashed).
    inputs = {static_cast<std::uint64_t>(layer.type), bitsOf(layer.coverage), bitsOf(layer.density)};
    const bool fromField = field && field->gives(layer.id);
    if (fromField) inputs.insert(inputs.end(), {~0ull, field->key()});
    const weather::CloudLayer cleared = clearedOf(layer);
    for (std::size_t k = 0; k < regions.size(); ++k) {
      const auto* rl = reaches[k] ? regionLayer(regions[k], layer.id, cleared) : nullptr;
      if (!rl) continue;
      const TileCache::ShapeKey shape = shapeKey(regions[k]);
      inputs.push_back(k);
      inputs.insert(inputs.end(), shape.begin(), shape.end());
      inputs.insert(inputs.end(), {static_cast<std::uint64_t>(rl->type), bitsOf(rl->coverage), bitsOf(rl->density)});
    }
    TileCache::LayerMemo& memo = entry.layers[layer.id];
    const bool hit = memo.valid && memo.inputs == inputs;
    cache.countTiles(hit);
    if (!hit) {
      contributions.clear();
      for (std::size_t k = 0; k < regions.size(); ++k)
        if (const auto* rl = reaches[k] ? regionLayer(regions[k], layer.id, cleared) : nullptr)
          contributions.push_back({&cache.weights(entry, regions[k]), rl});
      std::vector<weather::CoverageTile> base;
      if (fromField) {
        base.resize(entry.covering.cells.size());
        field->sample(layer.id, entry.centres, base);
      }
      auto tiles = layerTiles(entry.cells, layer, contributions, base);
      tiles.covering = entry.serial;
      // New tiles, not the old ones overwritten: snapshots sent before still
      // hold the old.
      memo.tiles = tiles.cells ? std::make_shared<const LayerTiles>(std::move(tiles)) : nullptr;
      memo.inputs = inputs;
      memo.generation = cache.nextGeneration();
      memo.valid = true;
    }
    runs.push_back({memo.generation, memo.tiles});
  }
  // Layers gone from the table take their memo with them.
  for (auto it = entry.layers.begin(); it != entry.layers.end();)
    it = std::any_of(layers.begin(), layers.end(), [&](const auto& l) { return l.id == it->first; })
             ? std::next(it)
             : entry.layers.erase(it);
  return runs;
}

weather::CoverageTile LayerTiles::at(std::size_t k) const {
  SKY_ASSERT(k < size());
  if (dense) return tiles[k];
  const auto it = std::lower_bound(reached.begin(), reached.end(), static_cast<std::uint32_t>(k));
  if (it != reached.end() && *it == k) return tiles[static_cast<std::size_t>(it - reached.begin())];
  return {(*cells)[k], layerId, coverage, density};
}

void LayerTiles::appendTo(std::vector<weather::CoverageTile>& out) const {
  if (dense) {
    out.insert(out.end(), tiles.begin(), tiles.end());
    return;
  }
  out.reserve(out.size() + size());
  std::size_t next = 0;  // into reached / tiles
  for (std::size_t k = 0; k < size(); ++k) {
    if (next < reached.size() && reached[next] == k)
      out.push_back(tiles[next++]);
    else
      out.push_back({(*cells)[k], layerId, coverage, density});
  }
}

weather::WeatherSnapshot wholeSnapshot(const BuiltSnapshot& built) {
  weather::WeatherSnapshot whole = built.snapshot;
  if (built.runs.empty()) return whole;
  whole.tiles.reserve(tileCount(built));
  for (const LayerRun& run : built.runs)
    if (run.tiles) run.tiles->appendTo(whole.tiles);
  return whole;
}

std::size_t tileCount(const BuiltSnapshot& built) {
  std::size_t n = built.snapshot.tiles.size();
  for (const LayerRun& run : built.runs) n += run.size();
  return n;
}

namespace {

// Which of the table's layers have tiles that move with the wind after the
// snapshot's clock (CloudLayer::tilesDrift): those only drifting regions in
// reach of the area give. A region that does not drift, a METAR station
// (it replaces every layer round it) or the forecast's field holds its
// tiles where they are; where both kinds give one layer it is held, and a
// drifting region's part of it moves when the server sends it again.
void markDriftingTiles(std::vector<weather::CloudLayer>& table, std::span<const weather::Region> regions,
                       const weather::SphericalCap& cap, const LayerField* field) {
  std::set<std::uint32_t> drifts, holds;
  for (const weather::Region& r : regions) {
    if (sphereDistance_m(cap.centerLat_deg, cap.centerLon_deg, r.centerLat_deg, r.centerLon_deg) >
        cap.radius_m + reachOf(r))
      continue;
    std::set<std::uint32_t>& into = r.driftsWithWind ? drifts : holds;
    if (r.replacesAllLayers)
      for (const weather::CloudLayer& l : table) into.insert(l.id);
    for (const weather::CloudLayer& l : r.layers) into.insert(l.id);
  }
  for (weather::CloudLayer& l : table)
    l.tilesDrift = drifts.count(l.id) && !holds.count(l.id) && !(field && field->gives(l.id));
}

}  // namespace

BuiltSnapshot buildSnapshotWithGenerations(const stream::Subscribe& request,
                                           std::span<const weather::CloudLayer> layers, double clock_s,
                                           std::size_t maxCells, std::span<const weather::Region> regions,
                                           TileCache* cache, const LayerField* field) {
  const weather::CellCentre centre{request.area.centerLat_deg, request.area.centerLon_deg};
  std::vector<weather::CloudLayer> table = snapshotLayers(layers, regions, &centre, request.area.radius_m);
  markDriftingTiles(table, regions, request.area, field);
  BuiltSnapshot built;
  weather::WeatherSnapshot& snapshot = built.snapshot;
  snapshot.weatherClock_s = clock_s;
  snapshot.layers = table;
  snapshot.areaIndex = request.areaIndex;
  WindTiles wind = deriveWindTiles(request.area, table, regions, field, cache);
  snapshot.windTileLevel = wind.level;
  snapshot.windTiles = std::move(wind.tiles);
  AirTiles air = deriveAirTiles(request.area, field, cache);
  snapshot.airLevels_m = std::move(air.levels_m);
  snapshot.airTileLevel = air.level;
  snapshot.airTiles = std::move(air.tiles);
  const std::size_t budget =
      cellBudget(maxCells, table.size(), snapshot.windTiles.size() + snapshot.airTiles.size());
  // No region reaches the area: the weather there is uniform and needs no
  // tiles, so no covering either (the level is the one the budget allows).
  const auto& cap = request.area;
  const bool regional =
      std::any_of(regions.begin(), regions.end(),
                  [&](const weather::Region& r) {
                    return sphereDistance_m(cap.centerLat_deg, cap.centerLon_deg, r.centerLat_deg, r.centerLon_deg) <=
                           cap.radius_m + reachOf(r);
                  }) ||
      (field && std::any_of(table.begin(), table.end(), [&](const auto& l) { return field->gives(l.id); }));
  if (!regional) {
    int level = request.tileLevel;
    while (level > 0 && estimatedCells(cap, level) > static_cast<double>(budget)) --level;
    snapshot.tileLevel = level;
    built.runs.assign(table.size(), LayerRun{});
    return built;
  }
  if (cache) {
    TileCache::Entry& e = cache->covering(cap, request.tileLevel, budget);
    snapshot.tileLevel = e.covering.level;
    built.runs = deriveRuns(*cache, e, table, regions, field);
    return built;
  }
  const Covering covering = coverArea(cap, request.tileLevel, budget);
  snapshot.tileLevel = covering.level;
  snapshot.tiles = deriveTiles(covering.cells, table, regions, field);
  return built;  // runs not known
}

weather::WeatherSnapshot buildSnapshot(const stream::Subscribe& request,
                                       std::span<const weather::CloudLayer> layers,
                                       double clock_s, std::size_t maxCells,
                                       std::span<const weather::Region> regions, TileCache* cache,
                                       const LayerField* field) {
  return wholeSnapshot(buildSnapshotWithGenerations(request, layers, clock_s, maxCells, regions, cache, field));
}

}  // namespace sky::server
