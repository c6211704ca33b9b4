// Scenario files on the server's side: the format and parser live in
// protocol/ (sky/weather/scenario.hpp: a headless renderer reads the same
// files); the server reads them from disk.
#pragma once

#include <filesystem>

#include "sky/weather/scenario.hpp"

namespace sky::server {

using weather::ClockSettings;
using weather::kMaxScenarioLayers;
using weather::parseScenario;
using weather::Scenario;

// Reads and parses a scenario file. Io when the file cannot be read.
Result<Scenario> loadScenario(const std::filesystem::path& path);

}  // namespace sky::server
