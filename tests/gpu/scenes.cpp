// Scene helpers for the GPU tests (see scenes.hpp).
#include "scenes.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "sky/geo/geodetic.hpp"
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

weather::WeatherSnapshot discSnapshot(const weather::CloudLayer& layer, const geo::Geodetic& around, double radius_m,
                                      double discLat_deg, double discLon_deg, double discRadius_m, float inside,
                                      float outside) {
  weather::WeatherSnapshot w;
  w.tileLevel = 12;
  w.layers.push_back(layer);
  for (std::uint64_t c : weather::coverCap({around.lat_deg, around.lon_deg, radius_m}, 12, 100000)) {
    const weather::CellCentre at = weather::cellCentre(c);
    const bool in = geo::geodesicDistance_m(at.lat_deg, at.lon_deg, discLat_deg, discLon_deg) <= discRadius_m;
    w.tiles.push_back({c, 1, in ? inside : outside, 1.0f});
  }
  return w;
}

weather::WeatherSnapshot stormCell(weather::CloudLayer l, double lat_deg, double lon_deg, double core_m,
                                   double radius_m, float coreCoverage, float edgeCoverage) {
  constexpr int kLevel = 13;
  constexpr double kEarth_m = 6371000.0, kDeg = 3.14159265358979323846 / 180.0;
  weather::WeatherSnapshot s;
  s.tileLevel = kLevel;
  l.coverage = 0;
  s.layers.push_back(l);
  for (std::uint64_t cell : weather::coverCap({lat_deg, lon_deg, radius_m}, kLevel, 4000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    const double dLat = (c.lat_deg - lat_deg) * kDeg;
    const double dLon = (c.lon_deg - lon_deg) * kDeg * std::cos(lat_deg * kDeg);
    const double d = kEarth_m * std::sqrt(dLat * dLat + dLon * dLon);
    float coverage = 0;
    if (d < core_m)
      coverage = coreCoverage;
    else if (d < radius_m)
      coverage = coreCoverage + (edgeCoverage - coreCoverage) * float((d - core_m) / (radius_m - core_m));
    s.tiles.push_back({cell, l.id, coverage, 1.0f});
  }
  return s;
}

render::FrameInputs Scene::inputs() const {
  render::FrameInputs in;
  in.camera = camera;
  in.weather = &weather;
  in.sunAzimuth_deg = sunAzimuth_deg;
  in.sunElevation_deg = sunElevation_deg;
  return in;
}

std::vector<Scene> issueScenes() {
  using T = weather::CloudType;
  auto typed = [](std::uint32_t id, T type, double base_m, double thickness_m, double coverage) {
    weather::CloudLayer l = layer(id, base_m, thickness_m, coverage, 1.0);
    l.type = type;
    return l;
  };
  auto uniform = [](std::vector<weather::CloudLayer> layers) {
    weather::WeatherSnapshot s;
    s.layers = std::move(layers);
    return s;
  };
  std::vector<Scene> scenes;
  // Fair-weather cumulus at midday, looking up from 500 m.
  scenes.push_back({"midday_cumulus_below", pose(47.0, 8.0, 500.0, 0.0, 25.0),
                    uniform({typed(1, T::Cumulus, 1200.0, 1500.0, 0.45)}), 135.0, 60.0});
  // Cumulus between the camera and a sun 4 degrees up: silver linings, red light.
  scenes.push_back({"sunset_backlit", pose(47.0, 8.0, 800.0, 270.0, 8.0),
                    uniform({typed(1, T::Cumulus, 1500.0, 1200.0, 0.4)}), 272.0, 4.0});
  // A closed stratus deck 400 m above a camera near the ground.
  scenes.push_back({"overcast_stratus_below", pose(47.0, 8.0, 100.0, 0.0, 20.0),
                    uniform({typed(1, T::Stratus, 500.0, 600.0, 1.0)}), 135.0, 40.0});
  // A broken stratocumulus deck seen from 10 km.
  scenes.push_back({"deck_from_10km", pose(47.0, 8.0, 10000.0, 30.0, -20.0),
                    uniform({typed(1, T::Stratocumulus, 1500.0, 900.0, 0.8)}), 135.0, 35.0});
  // One storm cell 35 km north, 1 to 11 km: tower and anvil.
  scenes.push_back({"cumulonimbus", pose(47.0, 8.0, 800.0, 0.0, 12.0),
                    stormCell(typed(1, T::Cumulonimbus, 1000.0, 10000.0, 0.0), 47.0 + 35000.0 / 111195.0, 8.0,
                              3000.0, 14000.0, 0.9f, 0.15f),
                    250.0, 35.0});
  // Cirrus at 9-10 km over scattered cumulus.
  scenes.push_back({"cirrus_over_cumulus", pose(47.0, 8.0, 500.0, 0.0, 35.0),
                    uniform({typed(1, T::Cumulus, 1200.0, 1500.0, 0.35), typed(2, T::Cirrus, 9000.0, 1000.0, 0.6)}),
                    150.0, 50.0});
  return scenes;
}

Diff diff(const render::Image& a, const render::Image& b) {
  Diff d;
  double sum = 0, sum2 = 0, shown2 = 0, shown = 0;
  std::size_t n = 0;
  auto display = [](float v) { return std::isfinite(v) && v > 0 ? double(v) / (1.0 + double(v)) : 0.0; };
  for (std::size_t i = 0; i < std::min(a.rgba.size(), b.rgba.size()); ++i) {
    if (i % 4 == 3) continue;
    const double e = std::abs(double(a.rgba[i]) - double(b.rgba[i]));
    sum += e;
    sum2 += e * e;
    const double es = display(a.rgba[i]) - display(b.rgba[i]);
    shown2 += es * es;
    shown += display(b.rgba[i]);
    d.maxAbs = std::max(d.maxAbs, e);
    ++n;
  }
  d.meanAbs = n ? sum / double(n) : 0;
  d.rmse = n ? std::sqrt(sum2 / double(n)) : 0;
  d.displayedRmse = n ? std::sqrt(shown2 / double(n)) : 0;
  d.displayedMean = n ? shown / double(n) : 0;
  return d;
}

void savePng(const render::Image& image, const std::string& name) {
  std::filesystem::create_directories(SKY_GPU_TEST_OUTPUT_DIR);
  (void)render::writePng(image, std::string(SKY_GPU_TEST_OUTPUT_DIR) + "/" + name + ".png");
}

}  // namespace sky::test
