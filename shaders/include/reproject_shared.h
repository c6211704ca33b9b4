// Layout of the reprojection pass's parameter block and its binding numbers,
// shared by C++ (renderer/core/src/reproject_pass.cpp, temporal_plan.cpp) and
// GLSL (shaders/reproject.comp). vec4/uvec4 members only, as sky_shared.h.
#ifndef SKY_REPROJECT_SHARED_H
#define SKY_REPROJECT_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/vec4.hpp>
namespace sky::gpu {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
#define SKY_REPROJECT_CONST static constexpr std::uint32_t
#else
#define SKY_REPROJECT_CONST const uint
#endif

// Descriptor set 0 bindings of the reprojection pass. Every image is a
// storage buffer, row-major, top row first.
SKY_REPROJECT_CONST kReprojectBindingParams = 0u;        // read-only: one SkyReproject
SKY_REPROJECT_CONST kReprojectBindingFresh = 1u;         // rgba32f storage image, read: this frame's drawn pixels, packed
SKY_REPROJECT_CONST kReprojectBindingFreshDepth = 2u;    // r32f storage image, read: their cloud depth (m, 0 none)
SKY_REPROJECT_CONST kReprojectBindingHistory = 3u;       // rgba32f storage image, read: the previous frame's full image
SKY_REPROJECT_CONST kReprojectBindingHistoryDepth = 4u;  // r32f storage image, read: its cloud depth
SKY_REPROJECT_CONST kReprojectBindingOut = 5u;           // vec4: this frame's full image (the next history)
SKY_REPROJECT_CONST kReprojectBindingOutDepth = 6u;      // float: its cloud depth
SKY_REPROJECT_CONST kReprojectBindingOutcomes = 7u;      // uint per pixel: what became of it (below)
SKY_REPROJECT_CONST kReprojectBindingDrop = 8u;          // read-only uint per cell of the history-drop
                                                          // mask (SkyReproject::drop): 1 = the weather changed there
SKY_REPROJECT_CONST kReprojectBindingWeather = 9u;       // sampler2DArray: the cloud pass's weather texture
                                                          // (sky_shared.h), for the wind of layers whose wind varies

// What became of each pixel (the values of the outcome buffer).
SKY_REPROJECT_CONST kStatFresh = 0u;       // drawn this frame
SKY_REPROJECT_CONST kStatReused = 1u;      // taken from the history through the motion
SKY_REPROJECT_CONST kStatOffscreen = 2u;   // its point was outside the previous view: upscaled
SKY_REPROJECT_CONST kStatDisoccluded = 3u; // the history there shows something else (depth): upscaled
SKY_REPROJECT_CONST kStatNoHistory = 4u;   // no history to take (a reset frame is drawn whole instead)
SKY_REPROJECT_CONST kReprojectStatCount = 5u;

// Workgroup of the pass: 32x2 pixels, rows of 32 so the history reads of a
// subgroup lie along a row (faster than 8x8 on lavapipe; time it with
// `sky_render_bench --preset realtime`, which prints the pass).
SKY_REPROJECT_CONST kReprojectLocalSizeX = 32u;
SKY_REPROJECT_CONST kReprojectLocalSizeY = 2u;
SKY_REPROJECT_CONST kReprojectMaxLayers = 4u;  // = kMaxLayers of sky_shared.h

struct SkyReproject {
  vec4 camForward;   // xyz: this frame's camera axes in its local frame (x east, y north, z up);
                     // w: the ground sphere's c = hGround (2r - hGround) (m^2, SkyFrame::earth.z)
  vec4 camRight;     // w: 1 when a pixel takes only history and drawn pixels on its side of the
                     // horizon (TemporalSettings::horizonSides), else 0
  vec4 camDown;      // w: unused
  vec4 prevForward;  // xyz: the previous frame's camera axes, in this frame's local frame
  vec4 prevRight;
  vec4 prevDown;
  vec4 prevPosition; // xyz: the previous camera in this frame's local frame (m); w: camera radius r (m)
  uvec4 image;       // x: width, y: height, z: n (interleave), w: 1 when there is a history, else 0
  uvec4 phase;       // xy: this frame's drawn pixel in each n x n block; z: packed width; w: layer count
  vec4 layerBand[kReprojectMaxLayers];    // x: layer base, y: top, as heights above the camera (m)
  vec4 layerMotion[kReprojectMaxLayers];  // xyz: how far the layer's air moved since the previous
                                          // frame, this frame's local frame (m)
  vec4 tolerance;    // x: relative cloud-depth difference a reused pixel may have, y: the same in m
                     // (added), z: margin around a layer band its wind applies in (m), w: the history's
                     // share of a redrawn pixel (TemporalSettings::accumulation; 0: none)
  vec4 raster;       // xy: the image's extent in its pixels for the camera rays (SkyFrame::raster);
                     // z: the history clip's gamma (TemporalSettings::historyClip; 0: off); w: the
                     // motion in pixels at which a redraw keeps half its history's share
                     // (TemporalSettings::accumulationMotion_px; 0: the share does not fall)
  vec4 frustum;      // this frame's view frustum (SkyFrame::frustum)
  vec4 prevFrustum;  // the previous frame's, which the history was drawn with
  uvec4 freshEdges;  // widths (px) of the bands at the left, right, top and bottom edges drawn at every
                     // pixel this frame (fresh_edges.glsl), their samples after the packed pixels; 0 none
  uvec4 drop;        // the history-drop mask (history_drop.hpp): x, y: cells across and down, z: log2 of a
                     // cell's edge in pixels, w: 1 when the mask is set this frame (else it is not read)
  // The weather map, as the cloud pass reads it (SkyFrame's fields of the
  // same names): for a layer whose wind varies, each pixel's point moves by
  // the wind there.
  vec4 camToAnchor[3];  // rows of the rotation camera-local -> weather-anchor-local
  vec4 camInAnchor;     // xyz: camera relative to the anchor sphere centre, anchor frame (m); w: its radius
  vec4 weatherMap;      // x: 1 / the fine ring's edge (1/m); y, z: the rings' blend band; w: 1 / the coarse ring's edge
  vec4 layerWind[kReprojectMaxLayers];  // x: the layer's weather-map slice, y: 1 when its wind varies (the wind
                                        // map then moves it, layerMotion.z its vertical), z: seconds since the
                                        // previous frame; w: unused
};

// The history from an image of another size (shaders/history_downsample.comp):
// a frame budget's change of level to another resolution divisor
// (CloudRenderer::setLevel) boxes the last frame's full image into the
// history images (a box of 1 at full size). Bindings
// of its own set; workgroup 8x8 history pixels.
SKY_REPROJECT_CONST kDownsampleBindingParams = 0u;      // read-only: one SkyHistoryDownsample
SKY_REPROJECT_CONST kDownsampleBindingSource = 1u;      // read-only vec4: the full image, radiance + transmittance
SKY_REPROJECT_CONST kDownsampleBindingSourceDepth = 2u; // read-only float: its cloud depth
SKY_REPROJECT_CONST kDownsampleBindingHistory = 3u;     // rgba32f storage image, written: the history
SKY_REPROJECT_CONST kDownsampleBindingHistoryDepth = 4u; // r32f storage image, written: its cloud depth
SKY_REPROJECT_CONST kDownsampleLocalSize = 8u;

struct SkyHistoryDownsample {
  uvec4 size;  // x, y: the history's width and height; z, w: the full image's
  uvec4 mode;  // x: the box's side (full pixels per history pixel each way); yzw: unused
};

#ifdef __cplusplus
static_assert(sizeof(SkyHistoryDownsample) == 32);
static_assert(sizeof(SkyReproject) == 16 * (9 + 2 * kReprojectMaxLayers + 6 + 5 + kReprojectMaxLayers));
static_assert(offsetof(SkyReproject, image) == 112);
static_assert(offsetof(SkyReproject, layerBand) == 144);
}  // namespace sky::gpu
#endif
#undef SKY_REPROJECT_CONST

#endif  // SKY_REPROJECT_SHARED_H
