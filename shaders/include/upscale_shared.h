// Layout of the upscale pass's parameter block and its binding numbers,
// shared by C++ (renderer/core/src/upscale_pass.cpp) and GLSL
// (shaders/upscale.comp). vec4/uvec4 members only, as sky_shared.h.
#ifndef SKY_UPSCALE_SHARED_H
#define SKY_UPSCALE_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/vec4.hpp>
namespace sky::gpu {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
#define SKY_UPSCALE_CONST static constexpr std::uint32_t
#else
#define SKY_UPSCALE_CONST const uint
#endif

// Descriptor set 0 bindings of the upscale pass; every image a storage
// buffer, row-major, top row first.
SKY_UPSCALE_CONST kUpscaleBindingParams = 0u;    // read-only: one SkyUpscale
SKY_UPSCALE_CONST kUpscaleBindingSource = 1u;    // rgba32f storage image, read: the small image, radiance + transmittance
SKY_UPSCALE_CONST kUpscaleBindingSourceDepth = 2u;  // r32f storage image, read: its cloud depth (m, 0 none)
SKY_UPSCALE_CONST kUpscaleBindingOut = 3u;       // vec4: the full-size image
SKY_UPSCALE_CONST kUpscaleBindingOutDepth = 4u;  // float: its cloud depth

// Workgroup: cells between four small pixels' centres, rows of 32 (as the
// reprojection, reproject_shared.h); the grid has (small width + 1) x
// (small height + 1) cells.
SKY_UPSCALE_CONST kUpscaleLocalSizeX = 32u;
SKY_UPSCALE_CONST kUpscaleLocalSizeY = 2u;

struct SkyUpscale {
  vec4 camForward;  // xyz: camera axes in the local frame (x east, y north, z up); w: unused
  vec4 camRight;    // w: unused
  vec4 camDown;     // w: unused
  vec4 earth;       // x: camera radius r (m), y: hGround (2r - hGround) (m^2), as the cloud pass's;
                    // zw: the small image's extent for the camera rays (SkyFrame::raster)
  uvec4 size;       // x, y: the small image's width and height (the full size / divisor, rounded up);
                    // z, w: the full image's
  uvec4 mode;       // x: divisor (full / small), y: 1 depth-aware, 0 plain bilinear; zw: unused
  vec4 frustum;     // the view frustum (SkyFrame::frustum), the same for both sizes
};

#ifdef __cplusplus
static_assert(sizeof(SkyUpscale) == 16 * 7);
static_assert(offsetof(SkyUpscale, size) == 64);
}  // namespace sky::gpu
#endif
#undef SKY_UPSCALE_CONST

#endif  // SKY_UPSCALE_SHARED_H
