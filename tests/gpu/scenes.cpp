// Scene helpers for the GPU tests (see scenes.hpp).
#include "scenes.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "sky/weather/tiling.hpp"

namespace sky::test {

geo::GeodeticPose pose(double lat_deg, double lon_deg, double alt_m, double yaw_deg, double pitch_deg) {
  geo::GeodeticPose p;
  p.position = {lat_deg, lon_deg, alt_m};
  p.yaw_deg = yaw_deg;
  p.pitch_deg = pitch_deg;
  return p;
}

weather::CloudLayer layer(std::uint32_t id, double base_m, double thickness_m, double coverage, double density) {
  weather::CloudLayer l;
  l.id = id;
  l.type = weather::CloudType::Cumulus;
  l.base_m = base_m;
  l.thickness_m = thickness_m;
  l.coverage = coverage;
  l.density = density;
  return l;
}

weather::WeatherSnapshot tiledSnapshot(const geo::Geodetic& around, weather::CloudLayer l, float coverage,
                                       float density) {
  constexpr int kLevel = 8;
  weather::WeatherSnapshot s;
  s.tileLevel = kLevel;
  l.coverage = 0;
  s.layers.push_back(l);
  for (std::uint64_t cell : weather::coverCap({around.lat_deg, around.lon_deg, 200000.0}, kLevel, 4000))
    s.tiles.push_back({cell, l.id, coverage, density});
  return s;
}

Diff diff(const render::Image& a, const render::Image& b) {
  Diff d;
  double sum = 0, sum2 = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < std::min(a.rgba.size(), b.rgba.size()); ++i) {
    if (i % 4 == 3) continue;
    const double e = std::abs(double(a.rgba[i]) - double(b.rgba[i]));
    sum += e;
    sum2 += e * e;
    d.maxAbs = std::max(d.maxAbs, e);
    ++n;
  }
  d.meanAbs = n ? sum / double(n) : 0;
  d.rmse = n ? std::sqrt(sum2 / double(n)) : 0;
  return d;
}

void savePng(const render::Image& image, const std::string& name) {
  std::filesystem::create_directories(SKY_GPU_TEST_OUTPUT_DIR);
  (void)render::writePng(image, std::string(SKY_GPU_TEST_OUTPUT_DIR) + "/" + name + ".png");
}

}  // namespace sky::test
