// Render configurations the bench measures: a named RenderSettings plus what
// the bench itself varies. `reference` is the ground truth every other
// configuration is compared with. builtInConfigurations() (configurations.cpp)
// is where the renderer's presets (sky/render/presets.hpp) plug in.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::bench {

inline constexpr const char* kReferenceName = "reference";

struct Configuration {
  std::string name;         // [a-z0-9-], what --configs selects and the report shows
  std::string description;  // what it changes against reference, one line
  // Fraction of the output resolution the renderer draws at; the bench
  // resizes the image bilinearly to the output size before comparing
  // (display.hpp). The renderer has no render scale of its own yet; when it
  // does, a preset sets it in RenderSettings and this stays 1. (0, 1].
  double renderScale = 1.0;
  // The renderer's settings for this configuration; width, height and
  // verticalFov_deg are overwritten per scene and resolution by settingsFor.
  render::RenderSettings settings;

  // Whether frames reuse earlier frames (settings.temporal.interleave > 1).
  // Only such a configuration can ghost: for the others the bench measures
  // ghosting against the configuration's own frames (0); for one that does,
  // against the same configuration drawing every pixel of every frame
  // (runner.cpp, temporalBaseline). It also starts each case with its
  // history full (render::historyWarmupFrames).
  bool reusesHistory() const { return settings.temporal.interleave > 1; }
};

// Every configuration the bench knows, `reference` first.
std::vector<Configuration> builtInConfigurations();

// The configurations named (comma-separated names or "all"), `reference`
// always first, whether named or not. Errors: InvalidArgument naming an
// unknown configuration and listing the known ones.
Result<std::vector<Configuration>> selectConfigurations(const std::string& names);

// A configuration from a spec NAME:key=value,... (keys: base = a preset
// whose march, interleave and divisor it starts from, else high's; primary, light, exit, stride,
// cloud, empty, growth, air = the MarchSettings fields; multmin, divmin =
// coverageStepMin, densityStepMin (Haggstrom 2018 eq. 34, 36); scale = the bench-side render scale
// (bilinear resize of the output); interleave = TemporalSettings::interleave, 1, 2 or 4;
// divisor = ResolutionSettings::divisor, 1, 2 or 4 (the renderer's own upscale);
// depth-aware = ResolutionSettings::depthAware, 0 or 1; blue = MarchSettings::blueNoise, 0 or 1;
// accumulate = TemporalSettings::accumulation, 0 to 0.95, off with interleave 1).
// --configs takes such specs next to names; a list with a spec in it is
// separated by ';' (a spec has commas). Errors: InvalidArgument naming the bad part.
Result<Configuration> customConfiguration(const std::string& spec);

// A ground truth other than the `reference` preset, from custom-configuration
// keys ("base=reference,light=64"): named `reference`, it replaces the first
// configuration of a run (a sweep against 64 light steps compares with that).
// Errors: InvalidArgument as customConfiguration, and for an interleave > 1,
// a scale or a divisor (the ground truth draws every pixel of every frame).
Result<Configuration> referenceConfiguration(const std::string& keys);

// The RenderSettings a configuration renders a scene with at an output size.
render::RenderSettings settingsFor(const Configuration& config, std::uint32_t outWidth, std::uint32_t outHeight,
                                   double verticalFov_deg);

}  // namespace sky::bench
