// Reading the scene suite and its weather files from disk, and a scene frame
// as the renderer's FrameInputs.
#pragma once

#include <filesystem>
#include <optional>
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

// A scene's change (Scene::change) as tiles: `before`'s layers with the
// changed layer tiled round the path's first pose at its own coverage, and
// the tiles that lie in the disc.
struct ChangeTiles {
  weather::WeatherSnapshot tiled;
  std::vector<std::size_t> disc;  // indices into tiled.tiles
  float from = 0, to = 0;         // the disc's coverage before and after the change
  // The disc's coverage `done` ([0, 1]) of the way.
  float coverageAt(double done) const;
};

// Errors: InvalidArgument (no such layer).
Result<ChangeTiles> changeTiles(const weather::WeatherSnapshot& before, const WeatherChange& change,
                                const geo::GeodeticPose& centre);

struct LoadedScene {
  Scene scene;
  LoadedWeather weather;
  std::optional<ChangeTiles> change;  // with Scene::change
  // What frameInputs hands out for a scene with a change: change->tiled
  // with the disc at that frame's coverage. One snapshot per scene,
  // rewritten by each call, so the memory does not grow with the frames
  // (a path may have 600 of ~15000 tiles each).
  mutable weather::WeatherSnapshot changing;
  // The still's flash at the frame's clock (Scene::flash), for frameInputs.
  mutable std::vector<weather::LightningFlash> flashes;
};

// Reads the suite and each chosen scene's weather (relative paths from the
// suite's folder). `names` empty = every scene, in file order; otherwise these
// scenes in this order. Errors: Io, the parsers' errors, InvalidArgument for
// an unknown scene name (listing the known ones).
Result<std::vector<LoadedScene>> loadSuite(const std::filesystem::path& suiteFile, const std::vector<std::string>& names);

// The renderer's inputs for frame `frame` of a scene: the pose on its path,
// the weather clock advanced by the path time at the file's rate, the sun.
// The returned inputs point into `scene` (its weather snapshot; with a
// change scene.changing, valid until the next call for that scene).
render::FrameInputs frameInputs(const LoadedScene& scene, std::uint32_t frame);

}  // namespace sky::bench
