// Scenario files: the weather a server starts from (and a headless renderer
// can render without a server), and a timeline of changes the server makes
// as its weather clock passes their times, as TOML (format documented in
// deploy/scenarios/skeleton-cumulus.toml and deploy/scenarios/storm-timeline.toml).
// Parsing is strict: unknown keys, missing fields and values out of range are
// errors naming file, line and field.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/weather/model.hpp"
#include "sky/weather/region.hpp"

namespace sky::weather {

// Layers per scenario. Bounds one snapshot's size: every layer adds one tile
// per S2 cell, and a snapshot must fit one stream frame.
inline constexpr std::size_t kMaxScenarioLayers = 32;

struct ClockSettings {
  double start_s = 0;  // weather clock when the server starts, s
  double rate = 1;     // weather seconds per wall second, [0, 3600]
};

// Entries in one timeline: bounds the work of checking a scenario and the
// size of the saved state.
inline constexpr std::size_t kMaxTimelineEntries = 1024;
// Longest ramp, s: a day, as the server's API allows.
inline constexpr double kMaxRamp_s = 86400;

// One timed change of a scenario's timeline, in the vocabulary of the
// server's POST /api/changes: made when the weather clock reaches at_s.
struct TimelineEntry {
  enum class Op { SetLayer, RemoveLayer, SetRegion, RemoveRegion, SetClock };
  double at_s = 0;              // weather clock, >= the scenario's clock.start_s
  Op op = Op::SetLayer;
  double ramp_s = 0;            // [0, kMaxRamp_s]; not for set_clock
  CloudLayer layer;             // SetLayer: validated
  Region region;                // SetRegion: validated
  std::uint32_t id = 0;         // RemoveLayer, RemoveRegion
  std::optional<double> rate;      // SetClock: [0, 3600]
  std::optional<double> jumpTo_s;  // SetClock: finite; at least one of the two
  std::string where;            // "file:line:col: timeline[i]", for errors found when it is applied
};

struct Scenario {
  ClockSettings clock;
  std::vector<CloudLayer> layers;  // validated, ids unique
  // Ordered by at_s (entries of equal at_s in file order): what a server
  // does as its clock runs. A renderer reading the file uses only `layers`.
  std::vector<TimelineEntry> timeline;
};

// Parses scenario text. sourceName is used in error details ("a.toml:12:5:
// layer[0].coverage: ..."). Errors: Malformed (TOML syntax, wrong type,
// unknown or missing key), InvalidArgument (a value out of range).
Result<Scenario> parseScenario(std::string_view text, std::string_view sourceName);

}  // namespace sky::weather
