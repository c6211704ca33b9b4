// Near-precipitation pass, second step: the streaks of the drops or flakes
// within a few metres of the camera (renderer/core/src/near_precip.cpp lists
// them by screen tile), drawn over the frame's image in place. Each covers
// a pixel for a share of the exposure (precip_streak.glsl) with its own
// radiance, the image's mean radiance times the type's factor; the drops
// are nearer than anything else the frame draws, so they are in front.
// One workgroup a tile. Layout: include/near_precip_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "near_precip_shared.h"

layout(local_size_x = kNearPrecipTile, local_size_y = kNearPrecipTile) in;

layout(std430, set = 0, binding = kNearPrecipBindingParams) readonly buffer ParamsBlock { SkyNearPrecip params; };
layout(std430, set = 0, binding = kNearPrecipBindingImage) buffer ImageBlock { vec4 pixels[]; };
layout(std430, set = 0, binding = kNearPrecipBindingMean) readonly buffer MeanBlock { vec4 mean; };
layout(std430, set = 0, binding = kNearPrecipBindingTiles) readonly buffer TilesBlock { uvec2 tiles[]; };
layout(std430, set = 0, binding = kNearPrecipBindingEntries) readonly buffer EntriesBlock { uint entries[]; };
layout(std430, set = 0, binding = kNearPrecipBindingStreaks) readonly buffer StreaksBlock { SkyStreak streaks[]; };

#define real float
#define real2 vec2
#include "precip_streak.glsl"

void main() {
  uvec2 size = params.size.xy;
  uvec2 px = gl_GlobalInvocationID.xy;
  if (px.x >= size.x || px.y >= size.y) return;
  uvec2 range = tiles[gl_WorkGroupID.y * params.size.z + gl_WorkGroupID.x];
  if (range.y == 0u) return;
  vec2 p = vec2(px) + 0.5;
  // The share of the pixel the drops leave uncovered: each covers its share
  // of what the ones behind it left (their order does not change the product).
  float open = 1.0;
  for (uint k = range.x; k < range.x + range.y; ++k) {
    SkyStreak s = streaks[entries[k]];
    open *= 1.0 - streakCoverageAlong(p, s.path.xy, s.path.zw, s.shape.x, s.shape.y);
  }
  uint o = px.y * size.x + px.x;
  vec4 c = pixels[o];
  vec3 drop = params.radiance.x * mean.rgb;
  pixels[o] = vec4(c.rgb * open + drop * (1.0 - open), c.a);
}
