// GET /api/conditions: the weather at one point as a flight model needs it
// (wind, vertical wind, whether and how dense cloud is there), computed the
// way a renderer channel answers a CIGI Environmental Conditions Request:
// weather::weatherAt over the tiles a snapshot of the point's area carries
// (deriveTiles at the asked S2 level, with the 8-bit fractions the stream
// carries) and weather::snapshotLookup. A host
// and an operator get the same answer from the server as from a channel
// holding tiles of that level.
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {

class LiveWeather;
class TileCache;

// Tiles of this level answer by default: the level skyshell-render's
// 120 km subscription gets (cells about 4.9 km across).
inline constexpr int kDefaultConditionsLevel = 11;
inline constexpr int kMaxConditionsLevel = 20;

struct ConditionsQuery {
  double lat_deg = 0;  // [-90, 90]
  double lon_deg = 0;  // [-180, 180]
  double alt_m = 0;    // MSL, [-1000, 100000]
  int level = kDefaultConditionsLevel;  // [0, kMaxConditionsLevel]
};

// The query string of GET /api/conditions ("lat_deg=..&lon_deg=..&alt_m=..",
// optional "level="). Pure. An unknown, repeated, missing or out-of-range
// key is an error naming it.
Result<ConditionsQuery> parseConditionsQuery(std::string_view query);

// The snapshot a renderer subscribed to `cap` at tile level `level` holds at
// weather clock clock_s (its tiles' fractions quantised as the stream
// carries them): what the point answers are computed from. cache: as for
// buildSnapshot (the same tiles, fewer derived).
weather::WeatherSnapshot subscriberSnapshot(const LiveWeather& weather, double clock_s, const weather::SphericalCap& cap,
                                           int level, TileCache* cache = nullptr);

// The answer at the server's weather clock now (see API.md).
nlohmann::json conditionsJson(const LiveWeather& weather, const ConditionsQuery& q);

}  // namespace sky::server
