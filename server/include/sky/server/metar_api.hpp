// POST /api/metar: raw METAR reports become station regions (metar_changes.hpp),
// previewed or applied. Stations accumulate: each request adds to (or
// replaces, station by station) the regions of the ones before.
//
// Body: {"reports": ["METAR LJLJ 221150Z ...", ...],           0..kMaxMetarReports reports
//        "remove": ["LJLJ", ...],  optional: stations whose regions go (0..kMaxMetarReports)
//        "stations": [{"icao", "lat_deg", "lon_deg", "elevation_m"}],  optional:
//                     the server's own table (--metar-stations) otherwise
//        "radius_m": 60000,   optional: how far a station's weather reaches
//        "ramp_s": 300, "at_s": ...,  optional timing, as for changes
//        "apply": false,      true applies (needs the token), false previews
//        "author": "..."}     optional
// At least one report or removal. The route's body limit (64 KiB) holds
// about 500 reports without a station table.
// Reply 200: {"reports": [{"index": 1, "icao": "LJLJ", "ok": true, "sky":
//             "read" or "not_observed", "region_id": 40123 (when it sets one),
//             "layers": [LAYER...], "skipped": [{"group": 5, "text":
//             "-VCTSRA", "reason": "unrecognised group"}], "skipped_count": 1,
//             "joined": [...]} or {"index": 2, "ok": false, "error": "report 2:
//             group 2 'K1': station is not a four-character ICAO code"}],
//             "stations": {"set": n, "replaced": n, "reshaped": n, "removed": n},
//             "remove_errors": ["remove LJLJ: ..."],
//             "changes": [{"op": "set_region", "region": REGION} or
//                         {"op": "remove_region", "id": N}...],
//             "applied": null or {"sequence", "first_sequence", "submits",
//                                 "clock_s", "summary"}}
// The changes are submitted kMaxChangesPerSubmit at a time (LiveWeather's
// cap), each an event of its own. A bad report does not stop the others. 400
// when the body is malformed, when applying with nothing to change, or when
// the model refuses a submit (then that submit and the ones after it are not
// applied; "applied" says how far it got).
#pragma once

#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"
#include "sky/server/metar_changes.hpp"

namespace sky::server {

// Reports (and removals) per request: at most what the route's 64 KiB body
// limit can hold (a report is ~60-130 bytes).
inline constexpr std::size_t kMaxMetarReports = 1024;
// Changes per submit: LiveWeather refuses more than 256 in one request.
inline constexpr std::size_t kMaxChangesPerSubmit = 256;

struct MetarRequest {
  std::vector<std::string> reports;
  std::vector<std::string> remove;  // ICAO codes
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
