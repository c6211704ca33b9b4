// The advection formula: where the air (and the cloud in it) that is at a
// point at weather clock t0 is at clock t1. Server and renderers both call
// this, so every channel draws the same cloud in the same place.
#pragma once

#include "sky/weather/model.hpp"

namespace sky::weather {

struct SurfacePoint {
  double lat_deg = 0;
  double lon_deg = 0;
};

// Moves a point along the geodesic whose azimuth is the wind's downwind
// direction (fromDirection + 180) by speed * dt metres. dt may be negative
// (where did this air come from). Exact on the WGS84 ellipsoid, also across
// the antimeridian; at a pole the azimuth is taken as GeographicLib defines it.
SurfacePoint advect(const SurfacePoint& p, const LayerWind& wind, double dt_s);

// Where the air at p came from age_s seconds ago, semi-Lagrangian in one
// step: carried back along the geodesic by the wind at p itself (the
// departure point of a trajectory ending at p, with the arrival point's
// wind). Every reader of coverage tiles places them this way (the point
// query, the renderers' weather map, whose shader does the same in the map's
// plane), so a wind that varies over the area moves each part of a layer by
// its own wind and every channel agrees.
struct WindVector;
SurfacePoint upwindOf(const SurfacePoint& p, const WindVector& windAtP, double age_s);

}  // namespace sky::weather
