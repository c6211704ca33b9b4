// The physical ground truth: a Monte Carlo path tracer of the medium the
// renderer marches (the same density function, compiled from the same
// GLSL as the CPU reference), with every order of scattering, the cloud
// types' own phase functions, the sun through the same atmosphere, the
// clear sky's light and a Lambertian ground. What it leaves to the model
// it measures: the air along the view ray is the reference's march (with
// its cloud shadow), and the air along a path's other rays is clear sky
// (scattering, no cloud shadow); lightning is not traced.
// Progressive and resumable: render() adds samples to a PathTraceState,
// which can be saved and loaded; each pixel keeps its sample count's
// mean and standard error. Slow by design: small images, on the CPU.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

namespace cpu_core {
struct CoreTables;  // the noise and atmosphere tables the CPU core reads (cpu_core.hpp)
}

struct PathTraceOptions {
  std::uint32_t samplesPerPixel = 4;  // added by this call, >= 1
  std::uint32_t threads = 0;          // 0: every hardware thread
  // Scattering events a path may have (in clouds or on the ground); 0: any
  // number (Russian roulette ends paths). 1: single scattering.
  std::uint32_t maxEvents = 0;
  // The clear sky's light on the clouds and the ground (and the air's own
  // along a path's rays after the view ray); false: the sun alone.
  bool skyLight = true;
  // Rays through random points of each pixel (its area's mean), or
  // through its centre as the renderer's presets draw them.
  bool pixelArea = false;
  // The droplets' diffraction peak (the Mie fit's HG lobe, g > 0.95) traced
  // as scattering; by default it is taken as unscattered (delta-M scaling:
  // path_tracer.cpp, kPeakAsymmetry), which removes most of the noise.
  bool exactPeak = false;
  std::uint64_t seed = 1;
  // Called from one thread as rows finish: rows done, rows in all.
  std::function<void(std::uint32_t, std::uint32_t)> progress;
};

// Sums over a frame's samples so far, per pixel.
struct PathTraceState {
  std::uint32_t width = 0, height = 0;
  std::uint64_t samples = 0;      // per pixel
  std::uint64_t violations = 0;   // density lookups above the majorant (0 for an unbiased image)
  std::uint64_t lookups = 0;      // density lookups so far
  std::string key;                // what the sums are of (the caller's; checked on resume)
  std::vector<double> sum;        // rgb, then cloud transmittance: 4 per pixel
  std::vector<double> sumSquares; // rgb: 3 per pixel
  std::vector<double> depthSum;   // per pixel: the distances where samples met cloud, m
  std::vector<std::uint32_t> depthCount;

  // The mean radiance (alpha: the mean cloud transmittance) and the cloud
  // depth where a sample met cloud (0 elsewhere).
  Image mean() const;
  // Per pixel, the standard error of the mean of the rgb's mean, in the
  // radiance's units.
  std::vector<float> standardError() const;

  // The state as bytes (host byte order: a run resumes on the machine that
  // wrote it), and back: decode refuses bytes that are not a state, of
  // another key, or whose sums do not fill exactly the rest (InvalidArgument).
  std::vector<std::uint8_t> encode() const;
  static Result<PathTraceState> decode(std::span<const std::uint8_t> bytes, const std::string& key);
  // The same through a file (written to a temporary name, then renamed).
  // Errors: Io, and decode's.
  Result<void> save(const std::string& path) const;
  static Result<PathTraceState> load(const std::string& path, const std::string& key);
};

class PathTracer {
 public:
  // As CpuReference::create (the same noise and atmosphere tables).
  static Result<PathTracer> create(const RenderSettings& settings);
  // Adds options.samplesPerPixel samples to every pixel of `state` (an
  // empty state is sized here; one of another size is InvalidArgument).
  Result<void> render(const FrameInputs& inputs, const PathTraceOptions& options, PathTraceState& state) const;
  const RenderSettings& settings() const { return settings_; }

 private:
  PathTracer(RenderSettings settings, std::shared_ptr<const cpu_core::CoreTables> tables);
  RenderSettings settings_;
  std::shared_ptr<const cpu_core::CoreTables> tables_;
};

}  // namespace sky::render
