// The history of an image of another size from the last frame's full image:
// a frame budget's change of level to another resolution divisor
// (CloudRenderer::setLevel) keeps its history this way instead of drawing
// the next frame whole (divisor 1: a box of 1, the full image as it is). History pixel (i, j) is centred where the full
// image's continuous coordinate is ((i + 0.5) d, (j + 0.5) d) (frame_setup.hpp,
// FrameSetup::width): the d x d box of full pixels around it, as far as the
// image reaches. Radiance and transmittance are the box's mean; the cloud
// depth is the mean weighted by the light the clouds took out of each pixel
// (1 - transmittance), as the cloud pass weights it along a ray, and 0
// where the box saw no cloud. Layout: include/reproject_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "reproject_shared.h"

layout(local_size_x = kDownsampleLocalSize, local_size_y = kDownsampleLocalSize) in;

layout(std430, set = 0, binding = kDownsampleBindingParams) readonly buffer ParamsBlock { SkyHistoryDownsample params; };
layout(std430, set = 0, binding = kDownsampleBindingSource) readonly buffer SourceBlock { vec4 source[]; };
layout(std430, set = 0, binding = kDownsampleBindingSourceDepth) readonly buffer SourceDepthBlock { float sourceDepth[]; };
layout(set = 0, binding = kDownsampleBindingHistory, rgba32f) uniform writeonly image2D historyImage;
layout(set = 0, binding = kDownsampleBindingHistoryDepth, r32f) uniform writeonly image2D historyDepthImage;

void main() {
  const uvec2 small = params.size.xy, full = params.size.zw;
  const uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= small.x || px.y >= small.y) return;
  const uint d = params.mode.x;
  const uvec2 lo = px * d, hi = min(lo + d, full);
  vec4 sum = vec4(0.0);
  float taken = 0.0, depthSum = 0.0;
  uint count = 0u;
  for (uint y = lo.y; y < hi.y; ++y)
    for (uint x = lo.x; x < hi.x; ++x) {
      const uint i = y * full.x + x;
      const vec4 c = source[i];
      const float w = clamp(1.0 - c.w, 0.0, 1.0);
      sum += c;
      taken += w;
      depthSum += w * sourceDepth[i];
      ++count;
    }
  const vec4 mean = count > 0u ? sum / float(count) : vec4(0.0, 0.0, 0.0, 1.0);
  imageStore(historyImage, ivec2(px), mean);
  imageStore(historyDepthImage, ivec2(px), vec4(taken > 1e-6 ? depthSum / taken : 0.0));
}
