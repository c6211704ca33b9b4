// Scenes shared by the GPU tests: camera poses and weather snapshots (uniform
// layers, and layers made of S2 coverage tiles around the camera).
#pragma once

#include <memory>
#include <string>
#include <vector>

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

// A storm cell: one layer given by level-13 tiles (~1 km) around a point,
// coverage coreCoverage out to core_m, falling linearly to edgeCoverage at
// radius_m, none beyond; the layer's own coverage is 0.
weather::WeatherSnapshot stormCell(weather::CloudLayer layer, double lat_deg, double lon_deg, double core_m,
                                   double radius_m, float coreCoverage, float edgeCoverage);

// A layer given by level-12 tiles (~2 km) covering radius_m round `around`
// at coverage `outside`, and `inside` on those within discRadius_m of
// (discLat_deg, discLon_deg), density 1 (a cell growing in a tiled field);
// the layer as given (its id on the tiles is 1).
weather::WeatherSnapshot discSnapshot(const weather::CloudLayer& layer, const geo::Geodetic& around, double radius_m,
                                      double discLat_deg, double discLon_deg, double discRadius_m, float inside,
                                      float outside);

// The six scenes of issue 5's correctness suite, with their weather and sun.
struct Scene {
  std::string name;
  geo::GeodeticPose camera;
  weather::WeatherSnapshot weather;
  double sunAzimuth_deg = 0, sunElevation_deg = 0;
  // Inputs pointing at this scene's weather (valid while the scene lives).
  render::FrameInputs inputs() const;
};
std::vector<Scene> issueScenes();

// Mean |a - b| over rgb, max |a - b|, RMSE over rgb; and the RMSE of the
// displayed value x / (1 + x) (the compression any tonemap applies) with b's
// mean displayed value, for comparing images whose cloud edges in the sun's
// forward lobe reach radiance ~1000 (a linear RMSE is then those few pixels).
struct Diff {
  double meanAbs = 0, maxAbs = 0, rmse = 0;
  double displayedRmse = 0, displayedMean = 0;
};
Diff diff(const render::Image& a, const render::Image& b);

// Writes a PNG into the test output folder (for looking at failures).
void savePng(const render::Image& image, const std::string& name);

}  // namespace sky::test
