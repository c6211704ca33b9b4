// Cloud pass: one invocation per pixel marches every cloud layer along the
// view ray (model in include/cloud_core.glsl) and writes linear radiance and
// transmittance to one storage buffer, the cloud depth to a second one.
// Uniform layout: include/sky_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

layout(std140, set = 0, binding = kBindingFrame) uniform FrameBlock { SkyFrame frame; };
layout(set = 0, binding = kBindingNoise) uniform sampler3D noiseTex;
layout(set = 0, binding = kBindingWeather) uniform sampler2DArray weatherTex;
layout(std430, set = 0, binding = kBindingOutput) writeonly buffer OutputBlock { vec4 pixels[]; };
layout(std430, set = 0, binding = kBindingDepth) writeonly buffer DepthBlock { float depths[]; };

#define real float
#define real2 vec2
#define real3 vec3
#define SKY_CORE_CONST const

// Weather map lookup: camera-local point -> weather anchor frame -> gnomonic
// plane of the anchor sphere (x = R q.x / q.z) -> texture coordinates.
vec2 sampleWeather(int layer, vec3 p) {
  vec3 q = vec3(dot(frame.camToAnchor[0].xyz, p), dot(frame.camToAnchor[1].xyz, p),
                dot(frame.camToAnchor[2].xyz, p)) + frame.camInAnchor.xyz;
  if (q.z <= 0.0) return vec2(0.0);
  vec2 plane = q.xy * (frame.camInAnchor.w / q.z) - frame.layers[layer].coverageShift.xy;
  vec2 uv = plane * frame.weatherMap.x + 0.5;
  return textureLod(weatherTex, vec3(uv, frame.layers[layer].shape.y), 0.0).xy;
}

// Earth-fixed noise: rotate to ECEF axes and add the layer's origin (camera
// ECEF minus wind drift, modulo the period, computed in double on the CPU).
float sampleNoise(int layer, vec3 p) {
  vec3 e = vec3(dot(frame.localToEcef[0].xyz, p), dot(frame.localToEcef[1].xyz, p),
                dot(frame.localToEcef[2].xyz, p));
  return textureLod(noiseTex, frame.layers[layer].noiseOrigin.xyz + e * frame.weatherMap.z, 0.0).r;
}

// Large-scale modulation of coverage: the same noise, its own origin and period.
float sampleCloudMap(int layer, vec3 p) {
  vec3 e = vec3(dot(frame.localToEcef[0].xyz, p), dot(frame.localToEcef[1].xyz, p),
                dot(frame.localToEcef[2].xyz, p));
  return textureLod(noiseTex, frame.layers[layer].cloudMapOrigin.xyz + e * frame.weatherMap.w, 0.0).r;
}

#include "cloud_core.glsl"

void main() {
  // Workgroup i draws tile (i * stride) mod n: lavapipe hands each thread a
  // contiguous range of workgroup ids, and the permutation spreads every range
  // over the whole image (lavapipe.md, "static split").
  uint tile = (gl_WorkGroupID.x * frame.dispatch.x) % frame.image.w;
  uvec2 px = uvec2(tile % frame.image.z, tile / frame.image.z) * kLocalSize + gl_LocalInvocationID.xy;
  if (px.x >= frame.image.x || px.y >= frame.image.y) return;

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
