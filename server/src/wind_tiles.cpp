// Wind tiles of a snapshot (wind_tiles.hpp).
#include "sky/server/wind_tiles.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>

#include "sky/weather/wind_field.hpp"

namespace sky::server {

namespace {

const weather::CloudLayer* ownLayer(const weather::Region& r, std::uint32_t id) {
  for (const auto& l : r.layers)
    if (l.id == id) return &l;
  return nullptr;
}

bool sameOnTheWire(const weather::WindVector& a, const weather::WindVector& b) {
  const weather::WindTile qa = weather::quantized({0, 0, float(a.east_mps), float(a.north_mps), float(a.up_mps)});
  const weather::WindTile qb = weather::quantized({0, 0, float(b.east_mps), float(b.north_mps), float(b.up_mps)});
  return qa == qb;
}

// The cells of the area and what the wind of a layer needs of them.
struct WindCells {
  std::span<const std::uint64_t> cells;
  std::span<const weather::CellCentre> centres;
  int level = 0;
};

}  // namespace

void coverWithMargin(const weather::SphericalCap& cap, int wantedLevel, std::size_t maxCells, TileCache* cache,
                     FieldCovering& out) {
  // Two cell edges past the area, at the level the budget allows, found
  // from the wanted one down (coarser cells: a wider margin at that level).
  for (int level = wantedLevel;;) {
    const weather::SphericalCap wider{cap.centerLat_deg, cap.centerLon_deg,
                                      cap.radius_m + 2 * weather::averageCellEdge_m(level)};
    if (cache) {
      out.entry = &cache->covering(wider, level, maxCells);
      out.cells = out.entry->covering.cells;
      out.centres = out.entry->centres;
      out.level = out.entry->covering.level;
    } else {
      out.local = coverArea(wider, level, maxCells);
      out.cells = out.local.cells;
      out.level = out.local.level;
    }
    if (out.level == level || out.level == 0) break;
    level = out.level;
  }
  if (!cache) {
    out.localCentres.clear();
    for (std::uint64_t c : out.local.cells) out.localCentres.push_back(weather::cellCentre(c));
    out.centres = out.localCentres;
  }
}

WindTiles deriveWindTiles(const weather::SphericalCap& cap, std::span<const weather::CloudLayer> table,
                          std::span<const weather::Region> regions, const LayerField* field, TileCache* cache) {
  // The regions near the area, and for each layer whether anything can make
  // its wind differ from its own: a field's wind, or a region's layer of its
  // id with another wind.
  std::vector<const weather::Region*> near;
  for (const auto& r : regions)
    if (sphereDistance_m(cap.centerLat_deg, cap.centerLon_deg, r.centerLat_deg, r.centerLon_deg) <=
        cap.radius_m + reachOf(r) + 2 * weather::averageCellEdge_m(kWindTileLevel))
      near.push_back(&r);
  std::vector<bool> varies(table.size(), false);
  std::vector<std::pair<double, std::size_t>> byBase;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const weather::WindVector own = weather::toVector(table[i].wind);
    varies[i] = field && field->givesWind(table[i].id);
    for (const weather::Region* r : near)
      if (const auto* rl = ownLayer(*r, table[i].id); rl && !sameOnTheWire(weather::toVector(rl->wind), own))
        varies[i] = true;
    if (varies[i]) byBase.emplace_back(table[i].base_m, i);
  }
  if (byBase.empty()) return {};
  std::sort(byBase.begin(), byBase.end());
  for (std::size_t n = kMaxWindLayers; n < byBase.size(); ++n) varies[byBase[n].second] = false;

  // The covering, and each near region's weight at its cells.
  FieldCovering covering;
  coverWithMargin(cap, kWindTileLevel, kMaxWindCells, cache, covering);
  TileCache::Entry* entry = covering.entry;
  if (cache) TileCache::makeRoomForShapes(*entry, near.size());
  const WindCells at{covering.cells, covering.centres, covering.level};
  std::vector<std::vector<double>> weightOf(near.size());
  auto weights = [&](std::size_t k) -> const std::vector<double>& {
    std::vector<double>& w = weightOf[k];
    if (!w.empty()) return w;
    w.assign(at.cells.size(), 0.0);
    if (entry) {
      const TileCache::Weights& cached = cache->weights(*entry, *near[k]);
      for (std::size_t n = 0; n < cached.cells.size(); ++n) w[cached.cells[n]] = cached.weights[n];
    } else {
      for (std::size_t c = 0; c < at.cells.size(); ++c)
        if (sphereDistance_m(at.centres[c].lat_deg, at.centres[c].lon_deg, near[k]->centerLat_deg,
                             near[k]->centerLon_deg) <= reachOf(*near[k]))
          w[c] = weather::regionWeight(*near[k], at.centres[c].lat_deg, at.centres[c].lon_deg);
    }
    return w;
  };

  WindTiles out;
  out.level = at.level;
  std::vector<weather::WindVector> base, sum;
  std::vector<double> total;
  std::vector<std::uint64_t> inputs;
  auto bits = [](double v) { return std::bit_cast<std::uint64_t>(v); };
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (!varies[i]) continue;
    const weather::CloudLayer& layer = table[i];
    const weather::WindVector own = weather::toVector(layer.wind);
    const bool fromField = field && field->givesWind(layer.id);
    // What this layer's tiles come from, exactly (as the cover's memo).
    inputs = {bits(own.east_mps), bits(own.north_mps), bits(own.up_mps)};
    if (fromField) inputs.insert(inputs.end(), {~0ull, field->key(), bits(layer.base_m), bits(layer.thickness_m)});
    for (std::size_t k = 0; k < near.size(); ++k)
      if (const auto* rl = ownLayer(*near[k], layer.id)) {
        const TileCache::ShapeKey shape = TileCache::shapeOf(*near[k]);
        const weather::WindVector v = weather::toVector(rl->wind);
        inputs.push_back(k);
        inputs.insert(inputs.end(), shape.begin(), shape.end());
        inputs.insert(inputs.end(), {bits(v.east_mps), bits(v.north_mps), bits(v.up_mps)});
      }
    if (entry) {
      const auto memo = entry->windLayers.find(layer.id);
      if (memo != entry->windLayers.end() && memo->second.inputs == inputs) {
        out.tiles.insert(out.tiles.end(), memo->second.tiles.begin(), memo->second.tiles.end());
        continue;
      }
    }
    base.assign(at.cells.size(), own);
    if (fromField) {
      std::vector<weather::WindVector> sampled(at.cells.size());
      field->sampleWind(layer.id, at.centres, sampled);
      for (std::size_t c = 0; c < sampled.size(); ++c)
        if (std::isfinite(sampled[c].east_mps) && std::isfinite(sampled[c].north_mps)) {
          base[c] = sampled[c];
          if (!std::isfinite(base[c].up_mps)) base[c].up_mps = own.up_mps;
        }
    }
    // Regions blend in as they do for cover: towards their weighted mean by
    // their summed weight, at most 1.
    sum.assign(at.cells.size(), {});
    total.assign(at.cells.size(), 0.0);
    for (std::size_t k = 0; k < near.size(); ++k) {
      const auto* rl = ownLayer(*near[k], layer.id);
      if (!rl) continue;
      const weather::WindVector v = weather::toVector(rl->wind);
      const std::vector<double>& w = weights(k);
      for (std::size_t c = 0; c < w.size(); ++c)
        if (w[c] > 0) {
          sum[c].east_mps += w[c] * v.east_mps;
          sum[c].north_mps += w[c] * v.north_mps;
          sum[c].up_mps += w[c] * v.up_mps;
          total[c] += w[c];
        }
    }
    std::vector<weather::WindTile> tiles;
    tiles.reserve(at.cells.size());
    bool differs = false;
    for (std::size_t c = 0; c < at.cells.size(); ++c) {
      weather::WindVector v = base[c];
      if (total[c] > 0) {
        const double f = std::min(1.0, total[c]);
        v.east_mps += f * (sum[c].east_mps / total[c] - v.east_mps);
        v.north_mps += f * (sum[c].north_mps / total[c] - v.north_mps);
        v.up_mps += f * (sum[c].up_mps / total[c] - v.up_mps);
      }
      differs = differs || !sameOnTheWire(v, own);
      tiles.push_back(weather::quantized({at.cells[c], layer.id, float(v.east_mps), float(v.north_mps), float(v.up_mps)}));
    }
    if (!differs) tiles.clear();
    out.tiles.insert(out.tiles.end(), tiles.begin(), tiles.end());
    if (entry) entry->windLayers[layer.id] = {inputs, std::move(tiles)};
  }
  // Layers gone from the table take their memo with them.
  if (entry)
    for (auto it = entry->windLayers.begin(); it != entry->windLayers.end();)
      it = std::any_of(table.begin(), table.end(), [&](const auto& l) { return l.id == it->first; })
               ? std::next(it)
               : entry->windLayers.erase(it);
  if (out.tiles.empty()) out.level = 0;
  return out;
}

}  // namespace sky::server
