// Everything one frame needs, derived on the CPU in double precision from the
// pose, the weather, the clock and the sun: camera axes and Earth geometry in
// the camera's local frame, per-layer heights, Earth-fixed noise origins and
// wind drift. Packed into the GPU's uniform block, or fed to the CPU reference.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "sky/render/cloud_renderer.hpp"
#include "sky_shared.h"
#include "weather_field.hpp"

namespace sky::render {

// World size of one period of the shape noise, m: with 4 Worley cells per
// period, cells are ~1.2 km, the scale of fair-weather cumulus.
inline constexpr double kNoisePeriod_m = 5000.0;
// Period of the cloud map (the same noise sampled larger), m: 23 km and 5 km
// share no small common multiple, so the pattern repeats only every 115 km.
inline constexpr double kCloudMapPeriod_m = 23000.0;

struct LayerSetup {
  double hBase_m = 0;       // camera height above the base (negative below)
  double hTop_m = 0;        // camera height above the top
  double cBase_m2 = 0;      // hBase (2r - hBase)
  double cTop_m2 = 0;       // hTop (2r - hTop)
  double thickness_m = 0;
  glm::dvec3 noiseOrigin{0};       // (camera ECEF - wind drift) mod period, in periods
  glm::dvec2 coverageShift_m{0};   // wind drift of the coverage since the snapshot, east/north
  glm::dvec3 cloudMapOrigin{0};    // as noiseOrigin, in cloud-map periods
};

struct FrameSetup {
  std::uint32_t width = 0, height = 0;
  double tanHalfFov = 0, aspect = 1;
  glm::dvec3 camForward{0}, camRight{0}, camDown{0};  // local frame: x east, y north, z up
  glm::dmat3 localToEcef{1};   // columns: the camera's east, north, up in ECEF
  glm::dmat3 camToAnchor{1};   // columns: camera east, north, up in the weather anchor's frame
  glm::dvec3 camInAnchor_m{0}; // camera relative to the anchor sphere centre, anchor frame
  double anchorRadius_m = 0;
  double mapHalfExtent_m = 0;
  double r_m = 0;              // camera distance from its local Earth centre = |camera ECEF|
  double hGround_m = 0;        // camera height above the ground sphere = altitude
  double cGround_m2 = 0;
  glm::dvec3 sunDir{0, 0, 1}, sunRadiance{0}, ambient{0};
  std::vector<LayerSetup> layers;
};

// Checks settings (size, field of view) for CloudRenderer::create.
Result<void> validateSettings(const RenderSettings& settings);
// Checks a frame's inputs: finite pose, latitude range, layer count and
// fields (weather::validate), tile values and level, sun angles.
Result<void> validateInputs(const FrameInputs& inputs);

// Derives the frame; inputs must be valid and field built for this snapshot.
FrameSetup prepareFrame(const RenderSettings& settings, const FrameInputs& inputs, const WeatherField& field);

// The uniform block, including the workgroup permutation for this image size.
gpu::SkyFrame packFrame(const FrameSetup& setup);

// Workgroups of the cloud pass for this image size (one per 8x8 tile).
std::uint32_t tileCount(std::uint32_t width, std::uint32_t height);

}  // namespace sky::render
