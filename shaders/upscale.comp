// Upscale pass: brings the image the cloud pass (and the reprojection) drew
// at 1/d of the size each way to the full size. Each output pixel is the
// bilinear blend of the four small-image pixels around it, depth-aware: the
// scene's depth at full size decides which of them may be blended. Here
// the scene is the Earth: each output pixel's ray hits the ground or goes
// to the sky, known exactly at full size, and a small pixel on the other
// side of the horizon is left out, so the horizon stays as sharp as at full
// size. The cloud depth is the nearest kept pixel's: a blend of a near and
// a far cloud's depth would be a point on neither. When all four lie across
// the horizon (a sliver of it), the nearest pixel is taken.
// One invocation per cell between four small pixels' centres: it reads the
// four once and writes the d x d full-size pixels inside the cell (read per
// output pixel they would cost 4 d^2 reads per cell instead of 4).
// Layout: include/upscale_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "upscale_shared.h"

layout(local_size_x = kUpscaleLocalSizeX, local_size_y = kUpscaleLocalSizeY) in;

layout(std430, set = 0, binding = kUpscaleBindingParams) readonly buffer ParamsBlock { SkyUpscale params; };
// The small image in storage images (renderer/core/src/pixel_mirror.hpp).
layout(set = 0, binding = kUpscaleBindingSource, rgba32f) uniform readonly image2D sourceImage;
layout(set = 0, binding = kUpscaleBindingSourceDepth, r32f) uniform readonly image2D sourceDepthImage;
layout(std430, set = 0, binding = kUpscaleBindingOut) writeonly buffer OutBlock { vec4 outPixels[]; };
layout(std430, set = 0, binding = kUpscaleBindingOutDepth) writeonly buffer OutDepthBlock { float outDepth[]; };

#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define real3x3 mat3
#define SKY_CORE_CONST const
#include "core_common.glsl"

// The block's numbers, read once (storage loads are gathers on lavapipe).
vec3 gForward, gRight, gDown;
vec4 gFrustum;
float gRadius, gGroundC;
vec2 gRaster;  // the small image's extent for the camera rays

// Whether the ray through pixel (x, y) of a width x height image hits the
// ground: the cloud pass's test (cloud_core.glsl, shadePixel: the ground
// sphere's far root ahead), in the form without roots (rayMeetsSphere),
// as it runs for every pixel of the full size.
bool seesGround(vec2 px, vec2 size) {
  vec2 s = frustumPoint(gFrustum, px.x + 0.5, px.y + 0.5, size.x, size.y);
  return rayMeetsSphere(gForward + gRight * s.x - gDown * s.y, gRadius, gGroundC);
}

void main() {
  gForward = params.camForward.xyz;
  gRight = params.camRight.xyz;
  gDown = params.camDown.xyz;
  gFrustum = params.frustum;
  gRadius = params.earth.x;
  gGroundC = params.earth.y;
  gRaster = params.earth.zw;
  ivec2 small = ivec2(params.size.xy);
  ivec2 full = ivec2(params.size.zw);
  int d = int(params.mode.x);
  bool depthAware = params.mode.y != 0u;
  // Cell (cx, cy) lies between the centres of small pixels cx and cx + 1 (and
  // rows cy, cy + 1), from -1 to the last: the cells at the edges hold the
  // full-size pixels outside the outermost centres, their missing pixels
  // clamped to the edge.
  ivec2 cell = ivec2(gl_GlobalInvocationID.xy) - 1;
  if (cell.x >= small.x || cell.y >= small.y) return;
  vec4 tapColour[4];
  float tapDepth[4];
  bool tapGround[4];
  for (int k = 0; k < 4; ++k) {
    ivec2 c = clamp(cell + ivec2(k & 1, k >> 1), ivec2(0), small - 1);
    tapColour[k] = imageLoad(sourceImage, c);
    tapDepth[k] = imageLoad(sourceDepthImage, c).x;
    tapGround[k] = depthAware && seesGround(vec2(c), gRaster);
  }
  // Full-size pixel x sits at (x + 0.5) / d - 0.5 in the small image: in
  // cell cx for x from cx d + d/2 to cx d + d/2 + d - 1.
  ivec2 first = cell * d + d / 2;
  for (int oy = 0; oy < d; ++oy) {
    for (int ox = 0; ox < d; ++ox) {
      ivec2 px = first + ivec2(ox, oy);
      if (px.x < 0 || px.y < 0 || px.x >= full.x || px.y >= full.y) continue;
      vec2 f = (vec2(px) + 0.5) / float(d) - 0.5 - vec2(cell);
      bool ground = depthAware && seesGround(vec2(px), vec2(full));
      vec4 colour = vec4(0.0);
      float depth = 0.0, wsum = 0.0, best = -1.0;
      int nearest = (f.x < 0.5 ? 0 : 1) + (f.y < 0.5 ? 0 : 2);
      for (int k = 0; k < 4; ++k) {
        float w = ((k & 1) == 1 ? f.x : 1.0 - f.x) * ((k >> 1) == 1 ? f.y : 1.0 - f.y);
        w = tapGround[k] == ground ? w : 0.0;
        colour += w * tapColour[k];
        wsum += w;
        depth = w > best ? tapDepth[k] : depth;
        best = max(best, w);
      }
      if (wsum > 0.0) {
        colour /= wsum;
      } else {
        colour = tapColour[nearest];
        depth = tapDepth[nearest];
      }
      uint o = uint(px.y * full.x + px.x);
      outPixels[o] = colour;
      outDepth[o] = depth;
    }
  }
}
