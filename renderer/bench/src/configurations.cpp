// The bench's configurations (see configurations.hpp).
#include "sky/bench/configurations.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

#include "sky/render/frame_budget.hpp"
#include "sky/render/presets.hpp"

namespace sky::bench {

std::vector<Configuration> builtInConfigurations() {
  // The renderer's presets (sky/render/presets.hpp), `reference` first,
  // then the resolution-only trades of the default preset.
  std::vector<Configuration> all;
  for (const render::Preset& p : render::presets()) {
    Configuration c{p.name, "preset: " + p.description, 1.0, {}};
    c.settings.march = p.march;
    c.settings.temporal = p.temporal;
    c.settings.resolution = p.resolution;
    all.push_back(c);
  }
  // The seeds' final settings in our march, as far as it has them (each
  // description says what is left out).
  auto metres = [](std::string name, std::string description, double cloud_m, double empty_m, double growth,
                   double minTransmittance) {
    Configuration c{std::move(name), std::move(description), 1.0, {}};
    render::MarchSettings& m = c.settings.march;  // high's, but for the placement and the exit
    m.primarySteps = 4096;
    m.cloudStep_m = cloud_m;
    m.emptyStep_m = empty_m;
    m.stepGrowth = growth;
    m.minTransmittance = minTransmittance;
    return c;
  };
  all.push_back(metres("haggstrom-2018",
                       "Haggstrom 2018's final march: 14 m steps growing by 0.04 m per metre (eq. 20, sec. 4.2.1), "
                       "longer steps outside cloud (2x here: the thesis gives no factor), 4 sun steps, stop at full "
                       "opacity (T < 0.001 here); no 4x4 reprojection",
                       14, 28, 0.04, 0.001));
  all.back().settings.march.lightSteps = 4;
  all.push_back(metres("ford-2024",
                       "Ford 2024's final march: step 100 (m here), large steps twice the small (sec. 4.6.2), early "
                       "exit at transmittance 0.075 (sec. 5.4.1); no 8-frame TAA window, no skipping below density 0.01",
                       100, 200, 0, 0.075));
  // The 1-of-4 interleave (presets use 1 of 16): medium's march, each
  // pixel redrawn every 4 frames instead of 16 (less to reproject under motion).
  if (const auto medium = render::findPreset("medium")) {
    Configuration c{"medium-2x2", "preset medium drawing 1 pixel of 4 per frame (2x2) instead of 1 of 16", 1.0, {}};
    c.settings.march = medium->march;
    c.settings.temporal = medium->temporal;
    c.settings.temporal.interleave = 2;
    all.push_back(c);
  }
  // The renderer's own resolution scale (realtime has it): high's march
  // with the clouds drawn at 1/2 the width and height, brought to full size
  // by the depth-aware upscale, next to the bench-side bilinear half-res.
  // Each carries high's settings whole (its sun map included), so it
  // differs from high only in size.
  if (const auto high = render::findPreset("high")) {
    auto sized = [&high](std::string name, std::string description, double scale) {
      Configuration c{std::move(name), std::move(description), scale, {}};
      c.settings.march = high->march;
      c.settings.temporal = high->temporal;
      c.settings.resolution = high->resolution;
      return c;
    };
    Configuration half = sized(
        "high-half", "preset high with the clouds drawn at 1/2 the width and height (the renderer's depth-aware upscale)",
        1.0);
    half.settings.resolution.divisor = 2;
    all.push_back(half);
    all.push_back(sized("half-res", "preset high at 1/2 the width and height, bilinear upscale (bench-side)", 0.5));
    all.push_back(sized("quarter-res", "preset high at 1/4 the width and height, bilinear upscale (bench-side)", 0.25));
  }
  return all;
}

Result<Configuration> customConfiguration(const std::string& spec) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos || colon == 0)
    return fail(ErrorCode::InvalidArgument, "custom configuration '" + spec + "': want NAME:key=value,...");
  Configuration c;
  c.name = spec.substr(0, colon);
  if (!std::all_of(c.name.begin(), c.name.end(), [](char ch) {
        return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-';
      }) || c.name == kReferenceName)
    return fail(ErrorCode::InvalidArgument, "custom configuration '" + spec + "': name must be [a-z0-9-], not reference");
  c.description = "custom: " + spec.substr(colon + 1);
  std::stringstream in(spec.substr(colon + 1));
  std::optional<render::Preset> base;  // the base= preset, for budget=
  for (std::string item; std::getline(in, item, ',');) {
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    const bool number = !value.empty() && end != value.c_str() && *end == '\0' && std::isfinite(v) && v >= 0;
    render::MarchSettings& m = c.settings.march;
    if (key == "base") {
      auto preset = render::findPreset(value);
      if (!preset) return fail(ErrorCode::InvalidArgument, "custom configuration '" + spec + "': " + preset.error().detail);
      m = preset->march;
      c.settings.temporal = preset->temporal;
      c.settings.resolution = preset->resolution;
      base = *preset;
      continue;
    }
    if (!number) return fail(ErrorCode::InvalidArgument, "custom configuration '" + spec + "': '" + item + "' is not key=number");
    if (key == "primary") m.primarySteps = std::uint32_t(v);
    else if (key == "light") m.lightSteps = std::uint32_t(v);
    else if (key == "exit") m.minTransmittance = v;
    else if (key == "stride") m.emptyStride = std::uint32_t(v);
    else if (key == "cloud") m.cloudStep_m = v;
    else if (key == "empty") m.emptyStep_m = v;
    else if (key == "growth") m.stepGrowth = v;
    else if (key == "air") m.airSteps = std::uint32_t(v);
    else if (key == "multmin") m.coverageStepMin = v;
    else if (key == "divmin") m.densityStepMin = v;
    else if (key == "scale" && v > 0 && v <= 1) c.renderScale = v;
    else if (key == "interleave" && (v == 1 || v == 2 || v == 4)) c.settings.temporal.interleave = std::uint32_t(v);
    else if (key == "divisor" && (v == 1 || v == 2 || v == 4)) c.settings.resolution.divisor = std::uint32_t(v);
    else if (key == "depth-aware" && (v == 0 || v == 1)) c.settings.resolution.depthAware = v == 1;
    else if (key == "blue" && (v == 0 || v == 1)) m.blueNoise = v == 1;
    else if (key == "cloud-shadows" && (v == 0 || v == 1)) m.cloudShadows = v == 1;
    else if (key == "near-precip" && (v == 0 || v == 1)) m.nearPrecipitation = v == 1;
    else if (key == "shower-cells" && (v == 0 || v == 1)) m.showersUnderCells = v == 1;
    else if (key == "budget" && base && v == std::floor(v)) {
      // Level v of the base preset's frame-budget ladder (frame_budget.hpp).
      auto ladder = render::budgetLadder(*base);
      if (!ladder) return fail(ErrorCode::InvalidArgument, "custom configuration '" + spec + "': " + ladder.error().detail);
      if (std::size_t(v) >= ladder->size())
        return fail(ErrorCode::InvalidArgument, "custom configuration '" + spec + "': " + base->name + "'s ladder has " +
                                                    std::to_string(ladder->size()) + " levels");
      const render::BudgetLevel& level = (*ladder)[std::size_t(v)];
      m = level.march;
      c.settings.temporal = level.temporal;
      c.settings.resolution = level.resolution;
    }
    else if (key == "air-table" && (v == 0 || v == 1)) m.airTable.enabled = v == 1;
    else if (key == "air-azimuths") m.airTable.azimuths = std::uint32_t(v);
    else if (key == "air-zeniths") m.airTable.zeniths = std::uint32_t(v);
    else if (key == "air-slices") m.airTable.slices = std::uint32_t(v);
    else if (key == "shadow" && v <= 5 && v == std::floor(v)) m.sunShadow.method = render::SunShadow(std::uint32_t(v));
    else if (key == "shadow-size") m.sunShadow.size = std::uint32_t(v);
    else if (key == "shadow-cascades") m.sunShadow.cascades = std::uint32_t(v);
    else if (key == "shadow-extent") m.sunShadow.extent_m = v;
    else if (key == "shadow-steps") m.sunShadow.buildSteps = std::uint32_t(v);
    else if (key == "shadow-frames") m.sunShadow.buildFrames = std::uint32_t(v);
    else if (key == "accumulate" && v <= 0.95) c.settings.temporal.accumulation = v;
    else if (key == "pixel-jitter" && (v == 0 || v == 1)) c.settings.temporal.pixelJitter = v == 1;
    else if (key == "clip" && v >= 0 && v <= 4) c.settings.temporal.historyClip = v;
    else if (key == "dense-turn" && v >= 0 && v <= 1000) c.settings.temporal.denseTurn_px = v;
    else if (key == "acc-motion" && v >= 0 && v <= 1000) c.settings.temporal.accumulationMotion_px = v;
    else if (key == "edges" && (v == 0 || v == 1)) c.settings.temporal.freshEdges = v == 1;
    else if (key == "sharp" && (v == 0 || v == 1)) c.settings.temporal.sharpHistory = v == 1;
    else if (key == "horizon" && (v == 0 || v == 1)) c.settings.temporal.horizonSides = v == 1;
    else if (key == "region-drop" && (v == 0 || v == 1)) c.settings.temporal.regionDrop = v == 1;
    else
      return fail(ErrorCode::InvalidArgument,
                  "custom configuration '" + spec + "': unknown key '" + key +
                      "' (base, primary, light, exit, stride, cloud, empty, growth, air, multmin, divmin, scale, "
                      "interleave 1|2|4, divisor 1|2|4, depth-aware 0|1, blue 0|1, cloud-shadows 0|1, near-precip 0|1, shower-cells 0|1, "
                      "air-table 0|1, "
                      "air-azimuths, air-zeniths, air-slices, budget (a level of the base preset's ladder, after base), accumulate 0..0.95, "
                      "pixel-jitter 0|1, clip 0..4, dense-turn (px, 0 never), acc-motion (px, 0 off), edges 0|1, sharp 0|1, horizon 0|1, region-drop 0|1, shadow 0..5 (march, column, esm, bsm, fom, deep), shadow-size, "
                      "shadow-cascades, shadow-extent (m), shadow-steps, shadow-frames)");
  }
  // Accumulation blends redraws with the history: without interleaving
  // there is none (a base preset's accumulation goes with its interleave).
  if (c.settings.temporal.interleave == 1) c.settings.temporal.accumulation = 0;
  return c;
}

Result<Configuration> referenceConfiguration(const std::string& keys) {
  auto c = customConfiguration("ground-truth:" + keys);
  if (!c) return tl::unexpected(c.error());
  if (c->reusesHistory() || c->renderScale != 1.0 || c->settings.resolution.divisor != 1)
    return fail(ErrorCode::InvalidArgument, "--reference '" + keys +
                                                "': the ground truth draws every pixel of every frame at full size "
                                                "(no interleave, no scale, no divisor)");
  c->name = kReferenceName;
  c->description = "ground truth for this run: " + keys;
  return c;
}

Result<std::vector<Configuration>> selectConfigurations(const std::string& names) {
  const std::vector<Configuration> all = builtInConfigurations();
  if (names.empty() || names == "all") return all;
  std::vector<Configuration> chosen{all.front()};
  std::stringstream in(names);
  std::string name;
  // With a custom spec (it has ':' and may have commas) the list separator is ';'.
  const char separator = names.find(':') != std::string::npos ? ';' : ',';
  while (std::getline(in, name, separator)) {
    if (name.empty() || name == kReferenceName) continue;
    if (name.find(':') != std::string::npos) {
      auto custom = customConfiguration(name);
      if (!custom) return tl::unexpected(custom.error());
      chosen.push_back(*custom);
      continue;
    }
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
