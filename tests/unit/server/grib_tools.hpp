// Helpers of the GRIB tests: the shared samples, and ecCodes' own
// grib_get_data as the independent decode.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
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

inline double lonDiff(double a, double b) {
  double d = std::fmod(a - b, 360.0);
  if (d > 180) d -= 360;
  if (d < -180) d += 360;
  return std::abs(d);
}

}  // namespace sky::server
