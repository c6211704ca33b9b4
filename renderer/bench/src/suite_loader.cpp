// Suite and weather files from disk (see suite_loader.hpp).
#include "sky/bench/suite_loader.hpp"

#include <algorithm>
#include <fstream>
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

float ChangeTiles::coverageAt(double done) const {
  return from + (to - from) * float(std::clamp(done, 0.0, 1.0));
}

Result<ChangeTiles> changeTiles(const weather::WeatherSnapshot& before, const WeatherChange& change,
                                const geo::GeodeticPose& centre) {
  if (change.layer >= before.layers.size())
    return fail(ErrorCode::InvalidArgument, "change.layer " + std::to_string(change.layer) + ": the weather has " +
                                                std::to_string(before.layers.size()) + " layers");
  // Cells of ~2.2 km (S2 level 12): about 15000 over the tiled cap, a few
  // dozen in a disc of 8 km.
  constexpr int kLevel = 12;
  const weather::CloudLayer& layer = before.layers[change.layer];
  ChangeTiles out;
  out.tiled = before;
  out.tiled.tileLevel = kLevel;
  out.tiled.tiles.clear();
  out.from = float(layer.coverage);
  out.to = float(change.coverage);
  for (std::uint64_t cell :
       weather::coverCap({centre.position.lat_deg, centre.position.lon_deg, kChangeTiledRadius_m}, kLevel, 100000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    if (geo::geodesicDistance_m(c.lat_deg, c.lon_deg, change.lat_deg, change.lon_deg) <= change.radius_m)
      out.disc.push_back(out.tiled.tiles.size());
    out.tiled.tiles.push_back({cell, layer.id, out.from, float(layer.density)});
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
    LoadedScene loaded{*s, std::move(*weather), std::nullopt, {}, {}};
    if (s->change) {
      auto tiles = changeTiles(loaded.weather.snapshot, *s->change, s->keys.front().pose);
      if (!tiles) return fail(tiles.error().code, "scene '" + s->name + "': " + tiles.error().detail);
      loaded.changing = tiles->tiled;
      loaded.change = std::move(*tiles);
    }
    out.push_back(std::move(loaded));
  }
  return out;
}

render::FrameInputs frameInputs(const LoadedScene& scene, std::uint32_t frame) {
  const double t = frameTime_s(scene.scene, frame);
  render::FrameInputs in;
  in.camera = poseAt(scene.scene, t);
  in.weather = &scene.weather.snapshot;
  if (scene.change) {
    const WeatherChange& c = *scene.scene.change;
    const double done = t < c.t_s ? 0.0 : c.ramp_s > 0 ? (t - c.t_s) / c.ramp_s : 1.0;
    const float coverage = scene.change->coverageAt(done);
    for (const std::size_t i : scene.change->disc) scene.changing.tiles[i].coverage = coverage;
    in.weather = &scene.changing;
  }
  in.weatherClock_s = scene.weather.clockStart_s + scene.weather.clockRate * t;
  if (scene.scene.flash) {
    weather::LightningFlash f = *scene.scene.flash;
    f.time_s = in.weatherClock_s - scene.scene.flash->time_s;  // the scene's time_s: seconds before the frame
    scene.flashes = {f};
    in.flashes = scene.flashes;
  }
  in.sunAzimuth_deg = scene.scene.sunAzimuth_deg;
  in.sunElevation_deg = scene.scene.sunElevation_deg;
  in.frameIndex = frame;
  return in;
}

}  // namespace sky::bench
