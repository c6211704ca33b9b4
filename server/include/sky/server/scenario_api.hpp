// POST /api/scenario: a scenario (TOML, the format of --scenario files)
// replaces the weather with its start and schedules its timeline
// (LiveWeather::loadScenario). The body is the TOML text itself, or JSON
//   {"toml": "...", "name": "storm.toml", "author": "instructor"}
// (name and author optional; the name labels errors and the timeline's
// events). Errors come back as
//   {"error": "storm.toml:12:1: timeline[3].layer.coverage: ...",
//    "file": "storm.toml", "line": 12, "column": 1, "field": "timeline[3].layer.coverage"}
// (file, line, column and field when the error names them).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"

namespace sky::server {

// The name a scenario sent as bare TOML goes by.
inline constexpr const char* kDefaultScenarioName = "scenario.toml";

struct ScenarioUpload {
  std::string toml;
  std::string name = kDefaultScenarioName;
  std::string author;
};

// Strict like the other bodies: JSON with unknown keys or wrong types is an
// error naming the key; anything not starting with '{' is TOML text.
Result<ScenarioUpload> parseScenarioUpload(std::string_view body);

// The 400 body for a scenario error detail of the form "name:line:col: field: what".
nlohmann::json scenarioErrorJson(const std::string& detail, const std::string& name);

}  // namespace sky::server
