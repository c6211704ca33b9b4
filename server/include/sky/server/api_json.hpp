// JSON of the weather server's HTTP API. Requests are read strictly: an
// unknown key, a missing one or a wrong type is an error naming its JSON path
// ("changes[0].layer.base_m: expected a number"). Units are in the key names.
//
// POST /api/changes body:
//   {"author": "instructor",            optional
//    "changes": [                        1..256, applied all or nothing
//      {"op": "set_layer", "layer": LAYER, "ramp_s": 120, "at_s": 5000},   ramp_s, at_s optional
//      {"op": "remove_layer", "id": 2, "ramp_s": 60, "at_s": 5000},        ramp_s, at_s optional
//      {"op": "set_clock", "rate": 60, "jump_to_s": 43200},                either or both
//      {"op": "set_region", "region": REGION, "ramp_s": 300, "at_s": 5000}, ramp_s, at_s optional
//      {"op": "remove_region", "id": 7, "ramp_s": 120, "at_s": 5000}]}      ramp_s, at_s optional
//   LAYER: {"id", "type" (cumulus, stratus, ...), "base_m", "thickness_m",
//           "transition_band_m", "coverage" (0..1), "density" (0..1),
//           "wind": {"speed_mps", "from_deg", "vertical_mps"}}
//   REGION: {"id" (1..65535), "center_lat_deg", "center_lon_deg", "size_x_m",
//            "size_y_m", "corner_radius_m" (0), "rotation_deg" (0),
//            "transition_m" (0), "drifts_with_wind" (false),
//            "layers": [LAYER, ...]}   (defaults in brackets when left out)
//            A region's layer replaces the global layer of the same id inside
//            the region and blends into it across the transition perimeter;
//            a new id is a layer only the region has. A drifting region moves
//            with its first layer's wind from where it was placed.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"
#include "sky/server/lightning_service.hpp"

namespace sky::server {

// The longest author name kept, in bytes (cut on a character boundary).
inline constexpr std::size_t kMaxAuthor_bytes = 200;

// JSON text of a value that may hold text from outside: never throws; an
// invalid UTF-8 sequence that got this far is written as U+FFFD.
std::string dumpJson(const nlohmann::json& value);

// {"error": detail, "field": <detail up to its first ": ">}: the API's error
// body. The detail is made valid UTF-8 and cut to 1 KiB, so echoed input
// can neither break the JSON nor make the answer large.
std::string errorJson(std::string_view detail);

// Parses a POST /api/changes body. Malformed (not JSON, wrong shape); the
// values' ranges are the WeatherService's to check.
Result<ChangeRequest> parseChangeRequest(std::string_view body);

nlohmann::json toJson(const weather::CloudLayer& layer);
// The LAYER object above; errors name `path`. Values are not range-checked.
Result<weather::CloudLayer> layerFromJson(const nlohmann::json& object, const std::string& path);
nlohmann::json toJson(const weather::Region& region);  // with "placed_at_clock_s"
// The REGION object above; errors name `path`. With withPlacement the saved
// form's "placed_at_clock_s" is read too (the API sets it itself).
Result<weather::Region> regionFromJson(const nlohmann::json& object, const std::string& path, bool withPlacement);
nlohmann::json toJson(const WeatherView& view);
// One element of "changes" above, both ways (a scenario timeline is saved in
// this form). Errors name `path`; ranges are not checked.
nlohmann::json toJson(const WeatherChange& change);
Result<WeatherChange> changeFromJson(const nlohmann::json& object, const std::string& path);
// Author, source and summary come from outside (and from databases written
// by older versions): made valid UTF-8 here.
nlohmann::json toJson(const ChangeEvent& event);

// POST /api/events: {"lightning": {"lat_deg", "lon_deg", "kind"?
// ("cloud-to-ground", the default, or "in-cloud"), "energy_j"? (J, (0,
// 1e11], default 1e9)}}. The error names the field.
Result<FlashRequest> parseFlashRequest(std::string_view body);
nlohmann::json toJson(const weather::LightningFlash& flash);

}  // namespace sky::server
