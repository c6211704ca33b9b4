// Layout of the near-precipitation pass (shaders/near_precip_mean.comp and
// near_precip.comp): its parameter block, the streaks it draws and their
// tile lists, with the binding numbers; shared by C++ (renderer/core/src/
// near_precip_pass.cpp) and GLSL. vec4/uvec4 members only, as sky_shared.h.
#ifndef SKY_NEAR_PRECIP_SHARED_H
#define SKY_NEAR_PRECIP_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/vec4.hpp>
namespace sky::gpu {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
#define SKY_NEAR_PRECIP_CONST static constexpr std::uint32_t
#else
#define SKY_NEAR_PRECIP_CONST const uint
#endif

// Descriptor set 0 bindings; the image is the frame's last (the buffer the
// renderer reads back), changed in place.
SKY_NEAR_PRECIP_CONST kNearPrecipBindingParams = 0u;   // read-only: one SkyNearPrecip
SKY_NEAR_PRECIP_CONST kNearPrecipBindingImage = 1u;    // vec4 per pixel, row-major: radiance + transmittance
SKY_NEAR_PRECIP_CONST kNearPrecipBindingMean = 2u;     // vec4: the image's mean radiance (written by the mean pass)
SKY_NEAR_PRECIP_CONST kNearPrecipBindingTiles = 3u;    // uvec2 per tile: first entry, entry count
SKY_NEAR_PRECIP_CONST kNearPrecipBindingEntries = 4u;  // uint per entry: a streak's index
SKY_NEAR_PRECIP_CONST kNearPrecipBindingStreaks = 5u;  // SkyStreak per streak

// Square screen tiles the streaks are listed by; one workgroup a tile. A
// pixel tests every streak of its tile: at 16 px a flake of snow was tested
// by 2.7 times as many pixels as at 8 (snow-hover, realtime, 320x180: the
// pass took 6.4 ms against 2.4), while 4 px tiles multiply the CPU's
// entries for a long streak for a further 0.5 ms.
SKY_NEAR_PRECIP_CONST kNearPrecipTile = 8u;
// The mean pass: one workgroup of this many invocations over a grid of
// kNearPrecipMeanGrid x kNearPrecipMeanGrid pixels spread over the image.
SKY_NEAR_PRECIP_CONST kNearPrecipMeanLocalSize = 256u;
SKY_NEAR_PRECIP_CONST kNearPrecipMeanGrid = 64u;

struct SkyNearPrecip {
  uvec4 size;      // x, y: the image's width and height; z, w: tiles across and down
  vec4 radiance;   // x: the drops' radiance over the image's mean radiance (near_precip.hpp); yzw: unused
};

// One drop's path on the image over the exposure: from a, in the unit
// direction dir, len long (pixels, continuous, pixel centres at +0.5;
// precip_streak.glsl's streakCoverageAlong), and its image radius.
struct SkyStreak {
  vec4 path;   // xy: a, zw: dir (a unit vector; (1, 0) for a path under 1e-3 px)
  vec4 shape;  // x: len (px); y: radius (px); z: distance from the camera (m); w: unused
};

#ifdef __cplusplus
static_assert(sizeof(SkyNearPrecip) == 32);
static_assert(sizeof(SkyStreak) == 32);
}  // namespace sky::gpu
#endif
#undef SKY_NEAR_PRECIP_CONST

#endif  // SKY_NEAR_PRECIP_SHARED_H
