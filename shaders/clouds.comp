// Cloud pass: one invocation per pixel marches every cloud layer along the
// view ray (model in include/cloud_core.glsl) and writes linear radiance and
// transmittance to one storage buffer, the cloud depth to a second one.
// Uniform layout: include/sky_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

// The frame's values in a read-only storage buffer, not a uniform block:
// lavapipe inlines uniform-block values that decide branches or are copied
// into much-used variables (the layer heights, the camera radius) into the
// shader and JIT-compiles a new variant, kept forever, for every new set of
// values: 0.4-0.6 s per 320x180 frame whenever the camera moves (a glider
// flight never rendered before: ~0.5 s per frame; the same frames again,
// from Mesa's disk shader cache: ~50 ms). Storage-buffer loads are never
// inlined, so the shader is compiled once; it is 2-3x slower than a
// variant specialised on one frame's values, a gain to get back on purpose
// (specialization constants for what changes rarely), not per frame.
layout(std430, set = 0, binding = kBindingFrame) readonly buffer FrameBlock { SkyFrame frame; };
layout(set = 0, binding = kBindingNoise) uniform sampler3D noiseTex;
layout(set = 0, binding = kBindingWeather) uniform sampler2DArray weatherTex;
layout(std430, set = 0, binding = kBindingOutput) writeonly buffer OutputBlock { vec4 pixels[]; };
layout(std430, set = 0, binding = kBindingDepth) writeonly buffer DepthBlock { float depths[]; };

#define real float
#define real2 vec2
#define real3 vec3
#define SKY_CORE_CONST const

// What the texture hooks read at every step, copied from the frame buffer
// once per invocation (main) so the march does not reload it from memory:
// 25-45 % less CPU per frame on lavapipe (320x180, three views).
vec3 gCamToAnchor0, gCamToAnchor1, gCamToAnchor2, gLocalToEcef0, gLocalToEcef1, gLocalToEcef2;
vec4 gCamInAnchor, gWeatherMap;

// Weather map lookup: camera-local point -> weather anchor frame -> gnomonic
// plane of the anchor sphere (x = R q.x / q.z) -> texture coordinates.
vec2 sampleWeather(int layer, vec3 p) {
  vec3 q = vec3(dot(gCamToAnchor0, p), dot(gCamToAnchor1, p), dot(gCamToAnchor2, p)) + gCamInAnchor.xyz;
  if (q.z <= 0.0) return vec2(0.0);
  vec2 plane = q.xy * (gCamInAnchor.w / q.z) - frame.layers[layer].coverageShift.xy;
  vec2 uv = plane * gWeatherMap.x + 0.5;
  return textureLod(weatherTex, vec3(uv, frame.layers[layer].shape.y), 0.0).xy;
}

// Earth-fixed noise: rotate to ECEF axes and add the layer's origin (camera
// ECEF minus wind drift, modulo the period, computed in double on the CPU).
float sampleNoise(int layer, vec3 p) {
  vec3 e = vec3(dot(gLocalToEcef0, p), dot(gLocalToEcef1, p), dot(gLocalToEcef2, p));
  return textureLod(noiseTex, frame.layers[layer].noiseOrigin.xyz + e * gWeatherMap.z, 0.0).r;
}

// Large-scale modulation of coverage: the same noise, its own origin and period.
float sampleCloudMap(int layer, vec3 p) {
  vec3 e = vec3(dot(gLocalToEcef0, p), dot(gLocalToEcef1, p), dot(gLocalToEcef2, p));
  return textureLod(noiseTex, frame.layers[layer].cloudMapOrigin.xyz + e * gWeatherMap.w, 0.0).r;
}

#include "cloud_core.glsl"

void main() {
  // Workgroup i draws tile (i * stride) mod n: lavapipe hands each thread a
  // contiguous range of workgroup ids, and the permutation spreads every range
  // over the whole image (lavapipe.md, "static split").
  uint tile = (gl_WorkGroupID.x * frame.dispatch.x) % frame.image.w;
  uvec2 px = uvec2(tile % frame.image.z, tile / frame.image.z) * kLocalSize + gl_LocalInvocationID.xy;
  if (px.x >= frame.image.x || px.y >= frame.image.y) return;

  gCamToAnchor0 = frame.camToAnchor[0].xyz;
  gCamToAnchor1 = frame.camToAnchor[1].xyz;
  gCamToAnchor2 = frame.camToAnchor[2].xyz;
  gLocalToEcef0 = frame.localToEcef[0].xyz;
  gLocalToEcef1 = frame.localToEcef[1].xyz;
  gLocalToEcef2 = frame.localToEcef[2].xyz;
  gCamInAnchor = frame.camInAnchor;
  gWeatherMap = frame.weatherMap;

  CoreFrame f;
  f.r = frame.earth.x;
  f.cGround = frame.earth.z;
  f.sunDir = frame.sunDir.xyz;
  f.sunRadiance = frame.sunRadiance.xyz;
  f.ambient = frame.ambient.xyz;
  f.layerCount = int(frame.weatherMap.y);
  for (int i = 0; i < int(kMaxLayers); ++i) {
    SkyLayer l = frame.layers[i];
    f.layers[i] = CoreLayer(l.heights.x, l.heights.y, l.heights.z, l.heights.w, l.shape.x);
  }
  vec3 dir = cameraRay(frame.camForward.xyz, frame.camRight.xyz, frame.camDown.xyz, frame.camRight.w,
                       frame.camDown.w, float(px.x), float(px.y), float(frame.image.x), float(frame.image.y));
  PixelResult r = shadePixel(f, dir, pixelJitter(px.x, px.y));
  pixels[px.y * frame.image.x + px.x] = vec4(r.radiance, r.transmittance);
  depths[px.y * frame.image.x + px.x] = r.depth;
}
