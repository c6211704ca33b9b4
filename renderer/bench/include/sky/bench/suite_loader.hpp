// Reading the scene suite and its weather files from disk, and a scene frame
// as the renderer's FrameInputs.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "sky/bench/suite.hpp"
#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/weather/model.hpp"

namespace sky::bench {

struct LoadedWeather {
  weather::WeatherSnapshot snapshot;  // the file's layers, uniform (no tiles)
  double clockStart_s = 0;            // weather clock of a scene's first frame
  double clockRate = 1;               // weather seconds per second of path time
};

// Reads a scenario file (deploy/scenarios format). Errors: Io when it cannot
// be read, the scenario parser's errors (naming file, line and field), and
// InvalidArgument for more layers than the renderer draws (kMaxLayers).
Result<LoadedWeather> loadWeatherFile(const std::filesystem::path& path);

struct LoadedScene {
  Scene scene;
  LoadedWeather weather;
  // With Scene::change: each frame's weather (the changed layer tiled).
  std::vector<weather::WeatherSnapshot> frameWeather;
};

// A scene's change (Scene::change) over `before`'s layers, one snapshot
// per fraction of `done` ([0, 1] of the way): the layer tiled round
// `centre` at its own coverage, the disc's tiles that fraction of the way
// to the change's. Errors: InvalidArgument (no such layer).
Result<std::vector<weather::WeatherSnapshot>> changedSnapshots(const weather::WeatherSnapshot& before,
                                                                const WeatherChange& change,
                                                                const geo::GeodeticPose& centre,
                                                                std::span<const double> done);

// Reads the suite and each chosen scene's weather (relative paths from the
// suite's folder). `names` empty = every scene, in file order; otherwise these
// scenes in this order. Errors: Io, the parsers' errors, InvalidArgument for
// an unknown scene name (listing the known ones).
Result<std::vector<LoadedScene>> loadSuite(const std::filesystem::path& suiteFile, const std::vector<std::string>& names);

// The renderer's inputs for frame `frame` of a scene: the pose on its path,
// the weather clock advanced by the path time at the file's rate, the sun.
// The returned inputs point into `scene` (its weather snapshot).
render::FrameInputs frameInputs(const LoadedScene& scene, std::uint32_t frame);

}  // namespace sky::bench
