// Suite and weather files from disk (see suite_loader.hpp).
#include "sky/bench/suite_loader.hpp"

#include <fstream>
#include <sstream>

#include "sky/weather/scenario.hpp"

namespace sky::bench {

namespace {

Result<std::string> readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(ErrorCode::Io, path.string() + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail(ErrorCode::Io, path.string() + ": read failed");
  return text.str();
}

}  // namespace

Result<LoadedWeather> loadWeatherFile(const std::filesystem::path& path) {
  auto text = readText(path);
  if (!text) return tl::unexpected(text.error());
  auto scenario = weather::parseScenario(*text, path.string());
  if (!scenario) return tl::unexpected(scenario.error());
  if (scenario->layers.size() > render::kMaxLayers)
    return fail(ErrorCode::InvalidArgument, path.string() + ": " + std::to_string(scenario->layers.size()) +
                                                " layers, the renderer draws at most " +
                                                std::to_string(render::kMaxLayers));
  LoadedWeather out;
  out.snapshot.weatherClock_s = scenario->clock.start_s;
  out.snapshot.layers = scenario->layers;
  out.clockStart_s = scenario->clock.start_s;
  out.clockRate = scenario->clock.rate;
  return out;
}

Result<std::vector<LoadedScene>> loadSuite(const std::filesystem::path& suiteFile,
                                           const std::vector<std::string>& names) {
  auto text = readText(suiteFile);
  if (!text) return tl::unexpected(text.error());
  auto suite = parseSuite(*text, suiteFile.string());
  if (!suite) return tl::unexpected(suite.error());
  std::vector<const Scene*> chosen;
  if (names.empty()) {
    for (const Scene& s : suite->scenes) chosen.push_back(&s);
  } else {
    for (const std::string& name : names) {
      const Scene* found = nullptr;
      for (const Scene& s : suite->scenes) found = s.name == name ? &s : found;
      if (!found) {
        std::string known;
        for (const Scene& s : suite->scenes) known += (known.empty() ? "" : ", ") + s.name;
        return fail(ErrorCode::InvalidArgument,
                    suiteFile.string() + ": no scene '" + name + "' (scenes: " + known + ")");
      }
      chosen.push_back(found);
    }
  }
  std::vector<LoadedScene> out;
  for (const Scene* s : chosen) {
    std::filesystem::path weatherPath(s->weatherFile);
    if (weatherPath.is_relative()) weatherPath = suiteFile.parent_path() / weatherPath;
    auto weather = loadWeatherFile(weatherPath);
    if (!weather) return fail(weather.error().code, "scene '" + s->name + "': " + weather.error().detail);
    out.push_back({*s, std::move(*weather)});
  }
  return out;
}

render::FrameInputs frameInputs(const LoadedScene& scene, std::uint32_t frame) {
  const double t = frameTime_s(scene.scene, frame);
  render::FrameInputs in;
  in.camera = poseAt(scene.scene, t);
  in.weather = &scene.weather.snapshot;
  in.weatherClock_s = scene.weather.clockStart_s + scene.weather.clockRate * t;
  in.sunAzimuth_deg = scene.scene.sunAzimuth_deg;
  in.sunElevation_deg = scene.scene.sunElevation_deg;
  in.frameIndex = frame;
  return in;
}

}  // namespace sky::bench
