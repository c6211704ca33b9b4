// The sky light the frame setup hands the clouds and the ground, from a grid
// over (ground radius, height, sun cosine) filled on first use: the direct
// integral (skyDomeAt, 128 air marches) at the grid's nodes, interpolated in
// height and sun cosine between them. A frame asks for it once for the
// ground and once per layer; with the direct integral, the host's share of
// a 320x180 `realtime` frame (sky_render_bench: wall minus the passes'
// timestamps) was ~2.4 ms, with the grid ~0.7 ms.
#pragma once

#include <cstdint>
#include <mutex>
#include <unordered_map>

#include <glm/vec3.hpp>

#include "atmosphere_tables.hpp"

namespace sky::render {

// Node spacing in height, m: a small part of the air's scale heights (8 km
// Rayleigh, 1.2 km Mie). With the nodes per sun cosine below and geometric
// interpolation the grid is within 0.2 % of the direct integral by day and
// 2.5 % in twilight (Atmosphere.SkyLightGridFollowsTheDirectIntegral), less
// than the direct integral's own dependence on the sun's azimuth (2.9 %).
inline constexpr double kSkyGridHeightStep_m = 250.0;
// Nodes per unit of sun cosine (0.45 degrees of sun elevation at the horizon,
// where the light changes fastest: twilight).
inline constexpr double kSkyGridPerSunCosine = 128.0;
// The ground radius is taken to the nearest km (it varies by 21 km between
// the equator and the poles; 500 m of it changes the light by < 1e-5).
inline constexpr double kSkyGridRadiusStep_m = 1000.0;

class SkyLightGrid {
 public:
  // The sky light from height h_m (clamped to >= 0) above a ground sphere of
  // radius groundRadius_m, the sun towards sunDir (unit, local frame, z up)
  // with irradiance sunIrradiance at the top. Thread-safe. The value depends
  // only on the arguments and the tables (each node is a pure function of
  // its key), never on what was asked before.
  SkyLight at(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir,
              const glm::dvec3& sunIrradiance);

  // Nodes computed so far.
  std::size_t nodes() const;

 private:
  // Beyond this many nodes the grid starts again (a day's sun and a few
  // layers' tops need a few thousand).
  static constexpr std::size_t kMaxNodes = 1u << 16;

  SkyDome node(const AtmosphereTables& tables, std::int64_t radiusKey, std::int64_t hIndex, std::int64_t muIndex);

  mutable std::mutex mutex_;
  std::unordered_map<std::uint64_t, SkyDome> nodes_;
};

// The frame setup's sky light: the tables' grid (AtmosphereTables::skyLight),
// or the direct integral for tables built without one.
SkyLight skyLight(const AtmosphereTables& tables, double h_m, double groundRadius_m, const glm::dvec3& sunDir,
                  const glm::dvec3& sunIrradiance);

}  // namespace sky::render
