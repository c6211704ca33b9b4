// The air tiles of a snapshot: a forecast's temperature and humidity at its
// levels on the S2 cells of the subscriber's area (two cell edges past it,
// as the wind tiles). Without a forecast that gives them, none: readers take
// the standard atmosphere (and a CIGI host's Atmosphere Control).
#pragma once

#include <cstddef>
#include <vector>

#include "sky/server/snapshot_builder.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {

// Temperature varies over tens of kilometres in a forecast (NAM's grid is
// 40 km, GFS's 28-280): cells of level 9 (about 16 km), coarser for larger
// areas, at most kMaxAirCells a level (a 300 km area at level 8: about 300).
inline constexpr int kAirTileLevel = 9;
inline constexpr std::size_t kMaxAirCells = 512;

struct AirTiles {
  std::vector<float> levels_m;  // heights of the tiles' levels, m MSL, ascending
  int level = 0;                // S2 level; 0 when there are no tiles
  std::vector<weather::AirTile> tiles;
};

// The field's air over the area `cap`, quantised as on the wire (tiles only
// where the field has a temperature). With a cache, the covering comes from
// it and the tiles are kept with it for the field's key.
AirTiles deriveAirTiles(const weather::SphericalCap& cap, const LayerField* field, TileCache* cache = nullptr);

}  // namespace sky::server
