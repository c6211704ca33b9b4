// Regional weather, as CIGI 3.3's Environmental Region Control describes a
// region: a rounded rectangle on the surface (centre, size along and across,
// rotation, corner radius) with a transition perimeter outside it in which the
// region's weather blends into the global weather. Inside the region its own
// layers replace the global layer of the same id; in the perimeter both blend.
#pragma once

#include <cstdint>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"

namespace sky::weather {

struct Region {
  std::uint32_t id = 0;          // [1, 65535] (CIGI region id is 16 bits)
  double centerLat_deg = 0;      // [-90, 90]
  double centerLon_deg = 0;      // any finite; normalised to [-180, 180)
  double sizeX_m = 1000;         // along the rotated x axis (east at rotation 0), (0, 2e6]
  double sizeY_m = 1000;         // along the rotated y axis (north at rotation 0), (0, 2e6]
  double cornerRadius_m = 0;     // [0, min(sizeX, sizeY) / 2]
  double rotation_deg = 0;       // clockwise from true north of the y axis, [-180, 180]
  double transition_m = 0;       // transition perimeter width outside the edge, [0, 2e6]
  // Whether the region moves with the wind of its first layer (a storm cell
  // drifting) on the weather clock, from where it was at placedAtClock_s.
  bool driftsWithWind = false;
  double placedAtClock_s = 0;
  // Whether the region's weather is the whole sky there (a METAR station:
  // the report says every layer): a layer it does not carry has cover 0 in
  // it, blending back across the perimeter, instead of standing unchanged.
  bool replacesAllLayers = false;
  std::vector<CloudLayer> layers;  // at most kMaxRegionLayers, distinct ids, each valid
};

inline constexpr std::size_t kMaxRegionLayers = 16;

// Checks every field; the error names the field, its value and the range
// ("region 3: size_x_m 0 outside (0, 2000000] m").
Result<void> validate(const Region& region);

// The region at weather clock clock_s: a drifting region's centre carried by
// its first layer's wind from placedAtClock_s (advect, the formula the
// renderers use), and placedAtClock_s set to clock_s. A region that does not
// drift is returned as it is.
Region regionAt(const Region& region, double clock_s);

// Signed distance (m) from a surface point to the region's edge in the
// region's own tangent plane (azimuthal equidistant about its centre, exact
// on the WGS84 ellipsoid along geodesics from the centre): negative inside,
// 0 on the edge, positive outside. Points more than a quarter of the Earth
// away are simply far outside.
double regionEdgeDistance_m(const Region& region, double lat_deg, double lon_deg);

// How much the region's weather replaces the global weather at a point:
// 1 inside, 0 beyond the transition perimeter, and between them a smooth
// (C1, smoothstep) fall-off across the perimeter.
double regionWeight(const Region& region, double lat_deg, double lon_deg);

}  // namespace sky::weather
