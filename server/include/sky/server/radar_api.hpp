// GET /api/radar: a weather radar's reflectivity picture (a plan position
// indicator, weather::radarPicture) over the tiles a renderer subscribed to
// the area holds (as GET /api/conditions), so the echoes line up with the
// shafts a channel draws.
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"

namespace sky::server {

class LiveWeather;

inline constexpr int kDefaultRadarSize = 128;
inline constexpr int kMaxRadarSize = 256;  // 65536 point queries at most

struct RadarQuery {
  double lat_deg = 0;      // the radar, [-90, 90]
  double lon_deg = 0;      // [-180, 180]
  double alt_m = 0;        // its antenna, MSL, [-500, 10000]
  double range_km = 100;   // (0, 300]
  double tilt_deg = 0.5;   // elevation of the beam, [-2, 30]
  int size = kDefaultRadarSize;  // cells a side, [16, kMaxRadarSize]
};

// "lat=..&lon=.." (or lat_deg, lon_deg) with optional range_km, tilt_deg,
// alt_m, size. Pure; an unknown, repeated, missing or out-of-range key is an
// error naming it.
Result<RadarQuery> parseRadarQuery(std::string_view query);

// The picture at the server's weather clock now (see API.md).
nlohmann::json radarJson(const LiveWeather& weather, const RadarQuery& q);

}  // namespace sky::server
