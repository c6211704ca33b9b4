// The bench's configurations (see configurations.hpp).
#include "sky/bench/configurations.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace sky::bench {

std::vector<Configuration> builtInConfigurations() {
  // PRESETS PLUG IN HERE. The renderer has no quality presets yet: its only
  // knobs are resolution, field of view and the noise seed, and its march
  // (steps, light steps) is fixed in shaders/include/cloud_core.glsl. So today
  // `reference` is simply the renderer as it is, and the other entries trade
  // resolution only. When presets land, each becomes one entry here
  // ({"medium", "...", 1.0, true, render::presetSettings(Preset::Medium)}
  // or the like), `reference` takes the reference preset, and the seeds'
  // configurations (Haggstrom's and Ford's final settings) become entries too.
  std::vector<Configuration> all;
  all.push_back({kReferenceName, "the renderer's only quality today: full resolution, fixed march", 1.0, false, {}});
  all.push_back({"half-res", "renders at 1/2 the width and height, bilinear upscale (bench-side)", 0.5, false, {}});
  all.push_back({"quarter-res", "renders at 1/4 the width and height, bilinear upscale (bench-side)", 0.25, false, {}});
  return all;
}

Result<std::vector<Configuration>> selectConfigurations(const std::string& names) {
  const std::vector<Configuration> all = builtInConfigurations();
  if (names.empty() || names == "all") return all;
  std::vector<Configuration> chosen{all.front()};
  std::stringstream in(names);
  std::string name;
  while (std::getline(in, name, ',')) {
    if (name.empty() || name == kReferenceName) continue;
    auto it = std::find_if(all.begin(), all.end(), [&](const Configuration& c) { return c.name == name; });
    if (it == all.end()) {
      std::string known;
      for (const auto& c : all) known += (known.empty() ? "" : ", ") + c.name;
      return fail(ErrorCode::InvalidArgument, "unknown configuration '" + name + "' (known: " + known + ")");
    }
    if (std::none_of(chosen.begin(), chosen.end(), [&](const Configuration& c) { return c.name == name; }))
      chosen.push_back(*it);
  }
  return chosen;
}

render::RenderSettings settingsFor(const Configuration& config, std::uint32_t outWidth, std::uint32_t outHeight,
                                   double verticalFov_deg) {
  render::RenderSettings s = config.settings;
  s.width = std::max<std::uint32_t>(1, std::uint32_t(std::lround(outWidth * config.renderScale)));
  s.height = std::max<std::uint32_t>(1, std::uint32_t(std::lround(outHeight * config.renderScale)));
  s.verticalFov_deg = verticalFov_deg;
  return s;
}

}  // namespace sky::bench
