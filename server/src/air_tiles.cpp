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
  out.level = covering.level;
  std::vector<weather::AirValues> sampled(covering.cells.size());
  for (std::size_t k = 0; k < heights.size() && out.levels_m.size() < weather::kMaxAirLevels; ++k) {
    // On the wire the heights are floats, strictly ascending and within
    // the decoder's range: a level that would break that (two pressures a
    // float apart, a height past it) is left out rather than have every
    // subscriber refuse the snapshot.
    const auto h = static_cast<float>(heights[k]);
    if (!(h >= -1000.0f && h <= 100000.0f) || (!out.levels_m.empty() && !(h > out.levels_m.back()))) continue;
    const auto index = static_cast<std::uint32_t>(out.levels_m.size());
    out.levels_m.push_back(h);
    field->sampleAir(k, covering.centres, sampled);
    for (std::size_t c = 0; c < sampled.size(); ++c)
      if (std::isfinite(sampled[c].temperature_c))
        out.tiles.push_back(weather::quantizedAir({covering.cells[c], index, static_cast<float>(sampled[c].temperature_c),
                                                   static_cast<float>(sampled[c].humidity_pct)}));
  }
  if (out.tiles.empty()) out = {};
  if (memo) *memo = {true, field->key(), out.levels_m, out.level, out.tiles};
  return out;
}

}  // namespace sky::server
