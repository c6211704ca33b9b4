// The clear-sky atmosphere on the CPU: the transmittance and
// multiple-scattering tables the GPU pass and the CPU reference both sample
// (built once, in double precision, from shaders/include/atmosphere_core.glsl),
// and the sky's light that the frame setup hands the clouds and the ground
// each frame (mean sky radiance and irradiance, integrated over the sky with
// the same model).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace sky::render {

// One RGBA16F table: half floats, RGBA per texel, row-major.
struct AtmosphereTable {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint16_t> texels;

  // Bilinear with clamp-to-edge and texel centres at (i + 0.5) / size, as
  // Vulkan's linear sampler on the RGBA16F upload; uv in [0, 1].
  glm::dvec3 sample(const glm::dvec2& uv) const;
};

class SkyLightGrid;

struct AtmosphereTables {
  AtmosphereTable transmittance;        // (mu, height): transmittance to the top
  AtmosphereTable multipleScattering;   // (sun cosine, height): Hillaire 2020's multiple scattering
  // The sky light over (height, sun cosine), filled on first use from the two
  // tables above (sky_light_grid.hpp); copies of these tables share it.
  std::shared_ptr<SkyLightGrid> skyLight;

  glm::dvec3 sampleTransmittance(const glm::dvec2& uv) const { return transmittance.sample(uv); }
  glm::dvec3 sampleMultipleScattering(const glm::dvec2& uv) const { return multipleScattering.sample(uv); }
};

// Steps of the direct integral each table texel holds: 500 midpoint steps
// keep the error of exp(-tau) under 1e-5 on a vertical path (tested against
// the closed form), far below the table's interpolation error.
inline constexpr int kTransmittanceTableSteps = 500;

// Height of the atmosphere's top above the ground, m (atmosphere_core.glsl).
double atmosphereHeight_m();

// Builds the tables (deterministic; ~16k direct integrals for the
// transmittance, then 1024 x 256 directions of 20 steps for the multiple scattering).
AtmosphereTables buildAtmosphereTables();

// The tables, built once per process on first use (thread-safe): they depend
// on nothing, and building them takes ~0.5 s of a renderer's start (Release),
// which a bench creating a renderer per case paid every time.
const AtmosphereTables& sharedAtmosphereTables();

// Sunlight reaching height h_m (sun at cosine muSun from the vertical) per
// unit irradiance at the top: the table's transmittance times the visible
// part of the sun's disc (atmosphere_core.glsl's sunTransmittance).
glm::dvec3 sunTransmittanceAt(const AtmosphereTables& tables, double h_m, double muSun, double groundRadius_m);

struct SkyLight {
  glm::dvec3 meanRadiance{0};  // mean sky radiance over the upper hemisphere, linear units
  glm::dvec3 irradiance{0};    // on a horizontal surface, linear units
};

// The sky seen from height h_m above a ground sphere of radius
// groundRadius_m, the sun towards sunDir (unit, local frame, z up): its two
// parts, the light the sun's scattering gives per unit irradiance at the top
// of the atmosphere (single-scattered sky with its multiple scattering), and
// the night-sky floor seen through the air; over 8 x 16 equal-solid-angle
// directions: 128 air marches.
struct SkyDome {
  SkyLight perSun;
  SkyLight night;

  // The sky light with the sun's irradiance sunIrradiance at the top.
  SkyLight lit(const glm::dvec3& sunIrradiance) const;
};
SkyDome skyDomeAt(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir);

// skyDomeAt(...).lit(sunIrradiance): the direct integral.
SkyLight skyLightAt(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir,
                    const glm::dvec3& sunIrradiance);

}  // namespace sky::render
