// Scenes shared by the GPU tests: camera poses and weather snapshots (uniform
// layers, and layers made of S2 coverage tiles around the camera).
#pragma once

#include <memory>
#include <string>

#include "sky/render/cloud_renderer.hpp"
#include "sky/weather/model.hpp"

namespace sky::test {

geo::GeodeticPose pose(double lat_deg, double lon_deg, double alt_m, double yaw_deg, double pitch_deg);

weather::CloudLayer layer(std::uint32_t id, double base_m, double thickness_m, double coverage, double density);

// A snapshot whose layer is given by S2 tiles (level 8, ~36 km cells) covering
// 200 km around the point, each with this coverage and density; the layer's
// own coverage is 0, so only the tiles make cloud.
weather::WeatherSnapshot tiledSnapshot(const geo::Geodetic& around, weather::CloudLayer layer, float coverage,
                                       float density);

// Mean |a - b| over rgb, max |a - b|, RMSE over rgb.
struct Diff {
  double meanAbs = 0, maxAbs = 0, rmse = 0;
};
Diff diff(const render::Image& a, const render::Image& b);

// Writes a PNG into the test output folder (for looking at failures).
void savePng(const render::Image& image, const std::string& name);

}  // namespace sky::test
