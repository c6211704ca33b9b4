// Scenario files: the weather a server starts from (and a headless renderer
// can render without a server), as TOML (format documented
// in deploy/scenarios/skeleton-cumulus.toml). Parsing is strict: unknown keys,
// missing fields and values out of range are errors naming file, line and field.
#pragma once

#include <cstddef>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"

namespace sky::weather {

// Layers per scenario. Bounds one snapshot's size: every layer adds one tile
// per S2 cell, and a snapshot must fit one stream frame.
inline constexpr std::size_t kMaxScenarioLayers = 32;

struct ClockSettings {
  double start_s = 0;  // weather clock when the server starts, s
  double rate = 1;     // weather seconds per wall second, [0, 3600]
};

struct Scenario {
  ClockSettings clock;
  std::vector<CloudLayer> layers;  // validated, ids unique
};

// Parses scenario text. sourceName is used in error details ("a.toml:12:5:
// layer[0].coverage: ..."). Errors: Malformed (TOML syntax, wrong type,
// unknown or missing key), InvalidArgument (a value out of range).
Result<Scenario> parseScenario(std::string_view text, std::string_view sourceName);

}  // namespace sky::weather
