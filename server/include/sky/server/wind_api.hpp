// GET /api/wind: the wind field over an area at one height, as the operator
// console draws it (an arrow per cell): each point's wind through the same
// point query and wind tiles (deriveWindTiles, weather::WindField) a renderer
// subscribed to the area answers its host with.
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"

namespace sky::server {

class LiveWeather;

// At most this many arrows: S2 cells of the area at the finest level (up to
// the wind tiles' own) whose covering stays within it.
inline constexpr std::size_t kMaxWindArrows = 400;

struct WindQuery {
  double lat_deg = 0;        // [-90, 90]
  double lon_deg = 0;        // [-180, 180]
  double radius_m = 100000;  // [1000, 2000000]
  double alt_m = 1000;       // MSL, [-1000, 20000]
};

// "lat_deg=..&lon_deg=..&alt_m=.." with optional "radius_m=". Pure; an
// unknown, repeated, missing or out-of-range key is an error naming it.
Result<WindQuery> parseWindQuery(std::string_view query);

// The arrows at the server's weather clock now (see API.md).
nlohmann::json windJson(const LiveWeather& weather, const WindQuery& q);

}  // namespace sky::server
