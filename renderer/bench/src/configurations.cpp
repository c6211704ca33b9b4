// The bench's configurations (see configurations.hpp).
#include "sky/bench/configurations.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sky/render/presets.hpp"

namespace sky::bench {

std::vector<Configuration> builtInConfigurations() {
  // The renderer's presets (sky/render/presets.hpp), `reference` first,
  // then the resolution-only trades of the default preset.
  std::vector<Configuration> all;
  for (const render::Preset& p : render::presets()) {
    Configuration c{p.name, "preset: " + p.description, 1.0, false, {}};
    c.settings.march = p.march;
    all.push_back(c);
  }
  all.push_back({"half-res", "preset high at 1/2 the width and height, bilinear upscale (bench-side)", 0.5, false, {}});
  all.push_back({"quarter-res", "preset high at 1/4 the width and height, bilinear upscale (bench-side)", 0.25, false, {}});
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
