// Test builder shared by the server's region and tile-cache tests: a square
// region (CIGI Environmental Region Control shape, no rotation or rounding).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "sky/weather/region.hpp"

namespace sky::server::test {

inline weather::Region squareRegion(std::uint32_t id, double lat, double lon, double size_m, double transition_m,
                                    std::vector<weather::CloudLayer> layers) {
  weather::Region r;
  r.id = id;
  r.centerLat_deg = lat;
  r.centerLon_deg = lon;
  r.sizeX_m = size_m;
  r.sizeY_m = size_m;
  r.transition_m = transition_m;
  r.layers = std::move(layers);
  return r;
}

}  // namespace sky::server::test
