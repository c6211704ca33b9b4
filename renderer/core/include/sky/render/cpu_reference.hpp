// CPU reference: the same cloud and sky model as the GPU pass (shaders/include/
// cloud_core.glsl compiled as C++), evaluated in double precision with
// emulated texture filtering, for image tests and numerical checks. It reads
// the same noise and atmosphere tables the GPU uploads, built the same way.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

namespace cpu_core {
struct CoreTables;  // the noise and atmosphere tables the CPU core reads (cpu_core.hpp)
}

struct PixelCoord {
  std::uint32_t x = 0, y = 0;  // column, row (top row 0)
};

// Parts of the light model (cloud_core.glsl's SKY_MODEL_CONST switches),
// each on by default: off, the reference shows what that part brings
// (measured against the path-traced truth, skyshell-bench --truth path).
struct ModelSwitches {
  bool octaves = true;   // Wrenninge's multiple-scattering octaves beyond the first
  // When set, the octaves' contribution b (kOctaveContribution) instead of
  // the model's: a measurement of what another weight would do.
  std::optional<double> octaveContribution;
  // When set, the octaves' extinction a (kOctaveExtinction) and eccentricity
  // c (kOctaveEccentricity) instead of the model's.
  std::optional<double> octaveExtinction;
  std::optional<double> octaveEccentricity;
  bool ambient = true;   // the sky's and the scattered sun's diffuse light
  // The scattered sun's part of the diffuse light alone (the octaves stand
  // for the sun's multiple scattering too).
  bool scatteredSun = true;
  // When set, the scattered sun's diffuse light times this (kSunDiffuseGain).
  std::optional<double> sunDiffuseGain;
  bool miePhase = true;  // the droplets' Mie fit; false: one HG lobe (g 0.85)
};

class CpuReference {
 public:
  // Builds the shape and detail noise (from settings.noiseSeed) and the
  // atmosphere tables once. Errors: InvalidArgument for bad settings.
  static Result<CpuReference> create(const RenderSettings& settings);

  // Every pixel of the frame. Same contract and errors as
  // CloudRenderer::render (no Device errors). Slow: meant for small images.
  // densityLookups, when given, receives the frame's texture lookups of
  // the cloud model (weather map, cloud map, shape and detail noise; primary
  // march, light march and ground shadows): what the march costs.
  Result<Image> render(const FrameInputs& inputs, std::uint64_t* densityLookups = nullptr) const;

  // Only the listed pixels, rgba each (a = cloud transmittance), in the
  // order given. InvalidArgument for a pixel outside the image.
  Result<std::vector<std::array<float, 4>>> renderPixels(const FrameInputs& inputs,
                                                         std::span<const PixelCoord> pixels) const;

  const RenderSettings& settings() const { return settings_; }
  // The model the next renders draw (all of it by default).
  void setModel(const ModelSwitches& model) { model_ = model; }

 private:
  CpuReference(RenderSettings settings, std::shared_ptr<const cpu_core::CoreTables> tables);
  RenderSettings settings_;
  ModelSwitches model_;
  std::shared_ptr<const cpu_core::CoreTables> tables_;
};

// One-shot convenience: create() then render() (rebuilds the tables each call).
Result<Image> renderCpuReference(const RenderSettings& settings, const FrameInputs& inputs);

}  // namespace sky::render
