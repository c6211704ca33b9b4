// The bench's physical ground truth (--truth path): a still scene's frame
// path-traced (sky/render/path_tracer.hpp) at the output size, in passes
// that each halve its noise (1, 4, 16, ... samples per pixel up to the
// asked count), the sums saved after each pass so a stopped run resumes
// where it was (outDir/truth/<scene>-<size>.state), with progress lines
// (samples, rate, time left).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sky/bench/configurations.hpp"
#include "sky/bench/suite_loader.hpp"
#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/cpu_reference.hpp"

namespace sky::bench {

struct TruthOptions {
  std::uint32_t samplesPerPixel = 0;  // 0: no truth
  std::uint32_t threads = 0;          // 0: every hardware thread
  std::uint32_t maxEvents = 0;        // 0: every order of scattering
  std::string stateDir;               // where the resumable sums go; empty: not saved
  // Octave weights b to measure besides the model's (a variant "octaves b=X" each).
  std::vector<double> octaveWeights;
  // The model with each of its parts off (octaves, ambient, scattered sun,
  // Mie phase): false measures the model and the variants asked for only.
  bool parts = true;
  // Other models to measure, each a variant named by its spec (parseModelSpec).
  std::vector<std::pair<std::string, render::ModelSwitches>> models;
};

// A model to measure from its spec "b=0.35:c=0.8:sd=0.5": the octaves'
// weight b (0-1), extinction a (0-1] and eccentricity c (0-1), and the gain
// on the scattered sun's diffuse light sd (0-2), any of them in any order. Errors: InvalidArgument naming the bad part.
Result<render::ModelSwitches> parseModelSpec(std::string_view spec);

struct TruthImage {
  render::Image image;             // the mean (rgba linear)
  std::vector<float> error;        // per pixel, the standard error of the rgb mean
  std::uint64_t samples = 0;       // per pixel
  std::uint64_t violations = 0;    // density lookups above the majorant (0: unbiased)
  double meanRelativeError = 0;    // mean over pixels of error / max(mean, 1e-3)
  double seconds = 0;              // spent by this run (not by resumed passes)
};

// An image against the truth by the mean of its rgb, with the truth's own
// noise taken out: RMSE = sqrt(max(0, mean((a - t)^2) - mean(se^2))) (the
// truth's standard error se squared is what its noise adds to the squared
// difference on average), and the image's mean over the truth's.
struct TruthDistance {
  double rmse = 0;
  double meanRatio = 0;
};
TruthDistance truthDistance(const std::vector<float>& rgba, const TruthImage& truth);

// Path-traces frame 0 of a still scene with the reference configuration's
// settings at width x height. Errors: the path tracer's; Io for the state.
Result<TruthImage> pathTruth(const LoadedScene& scene, const Configuration& reference, std::uint32_t width,
                             std::uint32_t height, const TruthOptions& options,
                             const std::function<void(const std::string&)>& log);

}  // namespace sky::bench
