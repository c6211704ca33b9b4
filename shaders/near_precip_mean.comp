// Near-precipitation pass, first step: the mean radiance of the frame's
// image, which a drop near the camera takes its own from (near_precip.hpp).
// One workgroup sums a grid of pixels spread evenly over the image: a fixed
// order of sums, so the same image gives the same mean bit for bit.
// Layout: include/near_precip_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "near_precip_shared.h"

layout(local_size_x = kNearPrecipMeanLocalSize) in;

layout(std430, set = 0, binding = kNearPrecipBindingParams) readonly buffer ParamsBlock { SkyNearPrecip params; };
layout(std430, set = 0, binding = kNearPrecipBindingImage) readonly buffer ImageBlock { vec4 pixels[]; };
layout(std430, set = 0, binding = kNearPrecipBindingMean) writeonly buffer MeanBlock { vec4 mean; };

shared vec3 sums[kNearPrecipMeanLocalSize];

void main() {
  uvec2 size = params.size.xy;
  uint n = kNearPrecipMeanGrid * kNearPrecipMeanGrid;
  vec3 sum = vec3(0.0);
  for (uint i = gl_LocalInvocationID.x; i < n; i += kNearPrecipMeanLocalSize) {
    uvec2 cell = uvec2(i % kNearPrecipMeanGrid, i / kNearPrecipMeanGrid);
    uvec2 px = min((2u * cell + 1u) * size / (2u * kNearPrecipMeanGrid), size - 1u);
    vec3 c = pixels[px.y * size.x + px.x].rgb;
    // A non-finite pixel (there should be none) would make every drop one.
    sum += all(lessThan(abs(c), vec3(3.0e38))) ? c : vec3(0.0);
  }
  sums[gl_LocalInvocationID.x] = sum;
  barrier();
  for (uint stride = kNearPrecipMeanLocalSize / 2u; stride > 0u; stride /= 2u) {
    if (gl_LocalInvocationID.x < stride) sums[gl_LocalInvocationID.x] += sums[gl_LocalInvocationID.x + stride];
    barrier();
  }
  if (gl_LocalInvocationID.x == 0u) mean = vec4(sums[0] / float(n), 1.0);
}
