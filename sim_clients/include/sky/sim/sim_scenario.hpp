// skyshell-scenario's input: a flight plus timed weather actions, as TOML.
//
//   [flight]
//   file = "../flights/climb-through-layers.csv"  # .csv/.igc/.gpx, relative to this file
//   speed = 4.0      # optional, flight seconds per wall second, [0.05, 100] (default 1)
//   start_s = 0.0    # optional, offset into the flight, s (default 0)
//   end_s = 600.0    # optional, offset into the flight, s (default: its end)
//
//   [[action]]       # zero or more, sent when the flight reaches at_s
//   at_s = 30.0      # flight time, s (>= start_s)
//   what = "..."     # required: one line for the log
//   api = "changes"  # optional: "changes" (default) or "metar", the endpoint
//   request = { author = "...", changes = [ ... ] }
//                    # the body of the weather server's POST /api/changes
//                    # (or POST /api/metar: reports, apply), written as TOML
//                    # (converted to JSON as it stands; the server checks it
//                    # and says what is wrong)
//
// Strict: an unknown key, a missing key or a value out of range is an error
// naming the file, line and field.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "sky/core/result.hpp"

namespace sky::sim {

struct ScenarioAction {
  double at_s = 0;
  std::string what;
  nlohmann::json request;  // an object
  std::string target = "/api/changes";  // the endpoint it is POSTed to: /api/changes or /api/metar
  std::size_t line = 0;    // where it was written, for messages
};

struct SimScenario {
  std::filesystem::path flightFile;  // resolved against the scenario's folder
  double speed = 1;
  double start_s = 0;
  double end_s = -1;  // < 0: the flight's end
  std::vector<ScenarioAction> actions;  // sorted by at_s (stable)
};

// Parses scenario text; relative flight paths resolve against baseDir.
Result<SimScenario> parseSimScenario(std::string_view text, std::string_view sourceName,
                                     const std::filesystem::path& baseDir);
Result<SimScenario> loadSimScenario(const std::filesystem::path& path);

}  // namespace sky::sim
