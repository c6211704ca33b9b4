// Suite and weather files from disk (see suite_loader.hpp).
#include "sky/bench/suite_loader.hpp"

#include <algorithm>
#include <fstream>
#include <span>
#include <sstream>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/scenario.hpp"
#include "sky/weather/tiling.hpp"

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

Result<std::vector<weather::WeatherSnapshot>> changedSnapshots(const weather::WeatherSnapshot& before,
                                                                const WeatherChange& change,
                                                                const geo::GeodeticPose& centre,
                                                                std::span<const double> done) {
  if (change.layer >= before.layers.size())
    return fail(ErrorCode::InvalidArgument, "change.layer " + std::to_string(change.layer) + ": the weather has " +
                                                std::to_string(before.layers.size()) + " layers");
  // Cells of ~2.2 km (S2 level 12): about 15000 over the tiled cap, a few
  // dozen in a disc of 8 km.
  constexpr int kLevel = 12;
  const weather::CloudLayer& layer = before.layers[change.layer];
  weather::WeatherSnapshot base = before;
  base.tileLevel = kLevel;
  base.tiles.clear();
  std::vector<std::size_t> inDisc;
  for (std::uint64_t cell :
       weather::coverCap({centre.position.lat_deg, centre.position.lon_deg, kChangeTiledRadius_m}, kLevel, 100000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    if (geo::geodesicDistance_m(c.lat_deg, c.lon_deg, change.lat_deg, change.lon_deg) <= change.radius_m)
      inDisc.push_back(base.tiles.size());
    base.tiles.push_back({cell, layer.id, float(layer.coverage), float(layer.density)});
  }
  std::vector<weather::WeatherSnapshot> out;
  for (const double d : done) {
    out.push_back(base);
    const float coverage = float(layer.coverage + (change.coverage - layer.coverage) * std::clamp(d, 0.0, 1.0));
    for (const std::size_t i : inDisc) out.back().tiles[i].coverage = coverage;
  }
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
    LoadedScene loaded{*s, std::move(*weather), {}};
    if (const auto& change = s->change) {
      std::vector<double> done;
      for (std::uint32_t f = 0; f < s->frames; ++f) {
        const double t = frameTime_s(*s, f);
        done.push_back(t < change->t_s ? 0.0 : change->ramp_s > 0 ? (t - change->t_s) / change->ramp_s : 1.0);
      }
      auto w = changedSnapshots(loaded.weather.snapshot, *change, s->keys.front().pose, done);
      if (!w) return fail(w.error().code, "scene '" + s->name + "': " + w.error().detail);
      loaded.frameWeather = std::move(*w);
    }
    out.push_back(std::move(loaded));
  }
  return out;
}

render::FrameInputs frameInputs(const LoadedScene& scene, std::uint32_t frame) {
  const double t = frameTime_s(scene.scene, frame);
  render::FrameInputs in;
  in.camera = poseAt(scene.scene, t);
  in.weather = frame < scene.frameWeather.size() ? &scene.frameWeather[frame] : &scene.weather.snapshot;
  in.weatherClock_s = scene.weather.clockStart_s + scene.weather.clockRate * t;
  in.sunAzimuth_deg = scene.scene.sunAzimuth_deg;
  in.sunElevation_deg = scene.scene.sunElevation_deg;
  in.frameIndex = frame;
  return in;
}

}  // namespace sky::bench
