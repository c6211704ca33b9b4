// What the tests of the SQLite store share: one scenario of a single layer,
// a wall-clock origin, and a database path with no file (nor WAL, SHM or
// journal) left from an earlier run.
#pragma once

#include <chrono>
#include <filesystem>

#include "sky/server/live_weather.hpp"

namespace sky::server::test {

inline const WallClock::time_point kStoreT0{std::chrono::hours(1000)};

// One cumulus-like layer at 1500-2500 m, coverage 0.3, clock at 1000 s, rate 1.
inline Scenario oneLayerScenario() {
  Scenario s;
  s.clock = {1000.0, 1.0};
  weather::CloudLayer l;
  l.id = 1;
  l.base_m = 1500;
  l.thickness_m = 1000;
  l.coverage = 0.3;
  l.density = 1;
  s.layers = {l};
  return s;
}

// <temp>/<folder>/<name>, with no database files of that name in it.
inline std::filesystem::path freshDatabase(const char* folder, const char* name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / folder;
  std::filesystem::create_directories(dir);
  const std::filesystem::path p = dir / name;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) std::filesystem::remove(p.string() + suffix);
  return p;
}

}  // namespace sky::server::test
