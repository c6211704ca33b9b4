// Helpers of the GRIB tests: the shared samples, ecCodes' own
// grib_get_data as the independent decode, and a decoder behind a gate.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace sky::server {

inline const std::string kGfs = std::string(SKY_SOURCE_DIR) + "/tests/data/grib/gfs-2p5deg-2011011012-f120-cloud-layers-10m-wind.grib2";
inline const std::string kNam = std::string(SKY_SOURCE_DIR) + "/tests/data/grib/nam212-lambert-2004120812-f24.grib2";

inline std::vector<std::byte> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> out(chars.size());
  std::memcpy(out.data(), chars.data(), chars.size());
  return out;
}

struct Point {
  double lat = 0, lon = 0, value = 0;
};

// grib_get_data's points of one message, in the message's order.
inline std::vector<Point> gribGetData(const std::string& path, std::size_t message) {
  const std::string cmd = std::string(SKY_GRIB_GET_DATA) + " -m 1e30 -F %.6f -w count=" + std::to_string(message) +
                          " '" + path + "'";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::vector<Point> points;
  if (!pipe) return points;
  char line[256];
  while (std::fgets(line, sizeof line, pipe.get())) {
    Point p;
    if (std::sscanf(line, "%lf %lf %lf", &p.lat, &p.lon, &p.value) == 3) points.push_back(p);
  }
  return points;
}

// The real decoder behind a gate, for what happens while a forecast
// decodes: a script (executable()) that writes its pid to `dir`/started when
// it starts, waits until open(), then is the decoder (exec keeps its pid and
// the pipe on fd 3). "A decode is under way" is then a state a test holds,
// not a race against the machine's load.
class GatedDecoder {
 public:
  GatedDecoder(std::filesystem::path dir, const std::string& decoder) : dir_(std::move(dir)) {
    std::filesystem::create_directories(dir_);
    const std::string tmp = (dir_ / "started.tmp").string();
    std::ofstream(executable()) << "#!/bin/sh\n"
                                << "echo $$ > '" << tmp << "' && mv '" << tmp << "' '" << (dir_ / "started").string()
                                << "'\n"
                                << "while [ ! -e '" << (dir_ / "go").string() << "' ]; do sleep 0.02; done\n"
                                << "exec '" << decoder << "' \"$@\"\n";
    std::filesystem::permissions(executable(), std::filesystem::perms::owner_all);
  }
  std::filesystem::path executable() const { return dir_ / "gated-decoder"; }
  // Lets every decoder through, the waiting ones and those to come.
  void open() const { std::ofstream(dir_ / "go") << "go\n"; }
  // The pid of the first decoder, once it has started; 0 if none did
  // within `timeout`.
  pid_t waitUntilStarted(std::chrono::milliseconds timeout) const {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!std::filesystem::exists(dir_ / "started") && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    pid_t pid = 0;
    std::ifstream(dir_ / "started") >> pid;
    return pid;
  }

 private:
  std::filesystem::path dir_;
};

inline double lonDiff(double a, double b) {
  double d = std::fmod(a - b, 360.0);
  if (d > 180) d -= 360;
  if (d < -180) d += 360;
  return std::abs(d);
}

}  // namespace sky::server
