// Air tiles of a snapshot (air_tiles.hpp).
#include "sky/server/air_tiles.hpp"

#include <algorithm>
#include <cmath>

#include "sky/server/wind_tiles.hpp"

namespace sky::server {

AirTiles deriveAirTiles(const weather::SphericalCap& cap, const LayerField* field, TileCache* cache) {
  if (!field) return {};
  const std::vector<double> heights = field->airLevels();
  if (heights.empty()) return {};
  FieldCovering covering;
  coverWithMargin(cap, kAirTileLevel, kMaxAirCells, cache, covering);
  TileCache::Entry::AirMemo* memo = covering.entry ? &covering.entry->air : nullptr;
  if (memo && memo->valid && memo->fieldKey == field->key()) return {memo->levels_m, memo->level, memo->tiles};

  AirTiles out;
  const std::size_t levels = std::min(heights.size(), weather::kMaxAirLevels);
  for (std::size_t k = 0; k < levels; ++k) out.levels_m.push_back(static_cast<float>(heights[k]));
  out.level = covering.level;
  std::vector<weather::AirValues> sampled(covering.cells.size());
  for (std::size_t k = 0; k < levels; ++k) {
    field->sampleAir(k, covering.centres, sampled);
    for (std::size_t c = 0; c < sampled.size(); ++c)
      if (std::isfinite(sampled[c].temperature_c))
        out.tiles.push_back(weather::quantizedAir({covering.cells[c], static_cast<std::uint32_t>(k),
                                                   static_cast<float>(sampled[c].temperature_c),
                                                   static_cast<float>(sampled[c].humidity_pct)}));
  }
  if (out.tiles.empty()) out = {};
  if (memo) *memo = {true, field->key(), out.levels_m, out.level, out.tiles};
  return out;
}

}  // namespace sky::server
