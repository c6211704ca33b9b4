// JSON of the weather server's HTTP API. Requests are read strictly: an
// unknown key, a missing one or a wrong type is an error naming its JSON path
// ("changes[0].layer.base_m: expected a number"). Units are in the key names.
//
// POST /api/changes body:
//   {"author": "instructor",            optional
//    "changes": [                        1..256, applied all or nothing
//      {"op": "set_layer", "layer": LAYER, "ramp_s": 120, "at_s": 5000},   ramp_s, at_s optional
//      {"op": "remove_layer", "id": 2, "ramp_s": 60, "at_s": 5000},        ramp_s, at_s optional
//      {"op": "set_clock", "rate": 60, "jump_to_s": 43200}]}               either or both
//   LAYER: {"id", "type" (cumulus, stratus, ...), "base_m", "thickness_m",
//           "transition_band_m", "coverage" (0..1), "density" (0..1),
//           "wind": {"speed_mps", "from_deg", "vertical_mps"}}
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"
#include "sky/server/change.hpp"

namespace sky::server {

// Parses a POST /api/changes body. Malformed (not JSON, wrong shape); the
// values' ranges are the WeatherService's to check.
Result<ChangeRequest> parseChangeRequest(std::string_view body);

nlohmann::json toJson(const weather::CloudLayer& layer);
// The LAYER object above; errors name `path`. Values are not range-checked.
Result<weather::CloudLayer> layerFromJson(const nlohmann::json& object, const std::string& path);
nlohmann::json toJson(const WeatherView& view);
nlohmann::json toJson(const ChangeEvent& event);

}  // namespace sky::server
