// A weather radar's picture (plan position indicator) of the weather: over a
// square grid round the radar, the beam's height at each cell's range (a
// beam at a tilt over the standard 4/3-Earth refraction) and the point
// query's precipitation there, as dBZ (precipitation.hpp). One function for
// the server's GET /api/radar and a renderer's headless replay, so both
// show what the renderers draw.
#pragma once

#include <span>
#include <vector>

#include "sky/weather/model.hpp"
#include "sky/weather/query.hpp"

namespace sky::weather {

struct RadarSite {
  double lat_deg = 0;
  double lon_deg = 0;
  double alt_m = 0;        // antenna, MSL
  double range_m = 100000; // half the picture's side, and the farthest echo
  double tilt_deg = 0.5;   // beam elevation
  int size = 128;          // cells a side, >= 1
};

// The beam's height above the antenna at slant range r (4/3 effective Earth
// radius), m, and the ground distance it has covered, m.
double radarBeamHeight_m(double slantRange_m, double tilt_deg);
double radarGroundDistance_m(double slantRange_m, double tilt_deg);

// dBZ per cell, size x size, rows from north to south and columns from west
// to east (cell (i, j) centred (j + 0.5 - size / 2) x side east and
// (size / 2 - i - 0.5) x side north of the radar in its tangent plane);
// kNoEcho_dBZ where no precipitation echoes or past the range. Only
// precipitation layers echo.
std::vector<float> radarPicture(std::span<const CloudLayer> layers, const CoverageLookup& lookup, const RadarSite& site);

}  // namespace sky::weather
