// POST /api/metar: raw METAR reports become station regions (metar_changes.hpp),
// previewed or applied.
//
// Body: {"reports": ["METAR LJLJ 221150Z ...", ...],           1..64 reports
//        "stations": [{"icao", "lat_deg", "lon_deg", "elevation_m"}],  optional:
//                     the server's own table (--metar-stations) otherwise
//        "radius_m": 60000,   optional: how far a station's weather reaches
//        "ramp_s": 300, "at_s": ...,  optional timing, as for changes
//        "apply": false,      true applies (needs the token), false previews
//        "author": "..."}     optional
// Reply 200: {"reports": [{"index": 1, "icao": "LJLJ", "ok": true,
//             "layers": [LAYER...]} or {"index": 2, "ok": false, "error": "report 2:
//             group 5 'BKN0x5': height is not three digits"}],
//             "changes": [{"op": "set_region", "region": REGION}...],
//             "applied": null or {"sequence", "clock_s", "summary"}}
// A bad report does not stop the others. 400 when the body is malformed, when
// applying with no report that maps, or when the model refuses the changes
// (then nothing is applied).
#pragma once

#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"
#include "sky/server/metar_changes.hpp"

namespace sky::server {

struct MetarRequest {
  std::vector<std::string> reports;
  std::optional<std::vector<Station>> stations;
  MetarOptions options;
  bool apply = false;
  std::string author;
};

// Strict, like the other API bodies: unknown keys and wrong types name their path.
Result<MetarRequest> parseMetarRequest(std::string_view body);

struct MetarReply {
  int status = 200;
  nlohmann::json body;
};

// Plans the request and, when it asks to apply, submits the changes as one
// batch (source "metar"). `authorized`: the caller had the token.
MetarReply handleMetar(const MetarRequest& request, std::span<const Station> serverStations,
                       WeatherService& weather);

}  // namespace sky::server
