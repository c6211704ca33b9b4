// Lightning for one frame: the server's flashes (sky/weather/lightning.hpp)
// as the lights and the channel lightning.glsl draws, in the camera's local
// frame and the renderer's linear units.
#pragma once

#include <span>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "sky/geo/geodetic.hpp"
#include "sky/render/exposure.hpp"
#include "sky/weather/lightning.hpp"

namespace sky::render {

// The renderer's linear unit of irradiance in W/m^2: the sun's 20 units
// stand for the solar constant, 1361 W/m^2 (sky/render/exposure.hpp).
inline constexpr double kLinearUnitIrradiance_Wpm2 = kSolarConstant_Wpm2 / kSunIrradiance_units;
// Flashes farther than this from the camera light nothing drawn (below the
// horizon from any height a simulator flies at, or lost in the haze).
inline constexpr double kMaxFlashDistance_m = 300e3;
// A flash whose mean power over the exposure is under this lights nothing:
// a stroke's light seven decays on (strokes peak near 1e8-1e9 W), which ends
// the frames a flash redraws whole (temporal_plan.cpp).
inline constexpr double kMinFlashPower_w = 1e5;

struct FlashSetup {
  std::vector<glm::dvec4> lights;     // xyz: camera-local (m), w: intensity (linear units x m^2), brightest first
  std::vector<glm::dvec4> boltStart;  // xyz: camera-local (m), w: intensity per metre (linear units x m)
  std::vector<glm::dvec3> boltEnd;
  double pixelAngle_rad = 0;
};

// The flashes giving light over the exposure [clock_s - exposure_s, clock_s]
// (at most gpu::kMaxFrameFlashes, those brightest at the camera), each a
// point light at the cloud base a bolt leaves (cloud-to-ground) or at the
// middle of an in-cloud flash, with the flash's mean power over the
// exposure; and the channel of the brightest cloud-to-ground flash among
// them (its radiated power spread over the channel's length, branches by
// their weight). camera: the local frame's origin and axes.
FlashSetup prepareFlashes(std::span<const weather::LightningFlash> flashes, double clock_s, double exposure_s,
                          const geo::EnuFrame& camera, double pixelAngle_rad);

}  // namespace sky::render
