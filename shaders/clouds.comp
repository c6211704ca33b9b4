// Cloud pass: one invocation per pixel marches every cloud layer and the
// clear air along the view ray (model in include/cloud_core.glsl) and writes
// linear radiance and cloud transmittance to a storage buffer. Uniform
// layout: include/sky_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

// The frame's numbers in a read-only storage buffer, not a uniform block:
// lavapipe specialises a shader on the values of uniform-block members that
// decide branches (camera and layer heights here) and compiles a new variant
// whenever they change, ~1.5 s per frame under ASan with a moving camera
// (measured with MESA_SHADER_CACHE_DISABLE=true); storage buffers it leaves
// alone. std430 and std140 agree on this vec4-only layout.
layout(std430, set = 0, binding = kBindingFrame) readonly buffer FrameBlock { SkyFrame frame; };
layout(set = 0, binding = kBindingShape) uniform sampler3D shapeTex;
layout(set = 0, binding = kBindingWeather) uniform sampler2DArray weatherTex;
layout(std430, set = 0, binding = kBindingOutput) writeonly buffer OutputBlock { vec4 pixels[]; };
layout(set = 0, binding = kBindingDetail) uniform sampler3D detailTex;
layout(set = 0, binding = kBindingTransmittance) uniform sampler2D transmittanceTex;

#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define SKY_CORE_CONST const

// Weather map lookup: camera-local point -> weather anchor frame -> gnomonic
// plane of the anchor sphere (x = R q.x / q.z) -> texture coordinates.
vec3 sampleWeather(int layer, vec3 p) {
  vec3 q = vec3(dot(frame.camToAnchor[0].xyz, p), dot(frame.camToAnchor[1].xyz, p),
                dot(frame.camToAnchor[2].xyz, p)) + frame.camInAnchor.xyz;
  if (q.z <= 0.0) return vec3(0.0);
  vec2 plane = q.xy * (frame.camInAnchor.w / q.z) - frame.layers[layer].coverageShift.xy;
  vec2 uv = plane * frame.weatherMap.x + 0.5;
  return textureLod(weatherTex, vec3(uv, frame.layers[layer].shape.y), 0.0).xyz;
}

// Earth-fixed noise coordinates: rotate to ECEF axes, scale by the period and
// add the origin (camera ECEF minus wind drift, modulo the period, computed in
// double on the CPU).
vec3 noiseCoord(vec4 origin, vec3 p) {
  vec3 e = vec3(dot(frame.localToEcef[0].xyz, p), dot(frame.localToEcef[1].xyz, p),
                dot(frame.localToEcef[2].xyz, p));
  return origin.xyz + e * origin.w;
}

vec2 sampleShape(int layer, vec3 p) {
  return textureLod(shapeTex, noiseCoord(frame.layers[layer].shapeOrigin, p), 0.0).rg;
}

float sampleDetail(int layer, vec3 p) {
  return textureLod(detailTex, noiseCoord(frame.layers[layer].detailOrigin, p), 0.0).r;
}

// Large-scale cloud map: the shape texture's smooth and Worley channels at a
// larger, incommensurate period.
vec2 sampleCloudMap(int layer, vec3 p) {
  return textureLod(shapeTex, noiseCoord(frame.layers[layer].cloudMapOrigin, p), 0.0).ba;
}

vec3 sampleTransmittanceLut(vec2 uv) {
  return textureLod(transmittanceTex, uv, 0.0).rgb;
}

#include "cloud_core.glsl"

CloudType unpackType(SkyCloudType t) {
  CloudType c;
  c.extinction_perm = t.a.x;
  c.dropletDiameter_um = t.a.y;
  c.baseRound = t.a.z;
  c.topRoundStart = t.a.w;
  c.peak = t.b.x;
  c.peakVariation = t.b.y;
  c.anvil = t.b.z;
  c.densityGradient = t.b.w;
  c.densityBaseFade = t.c.x;
  c.densityTopFade = t.c.y;
  c.coverageEdge = t.c.z;
  c.fibrous = t.c.w;
  c.erosion = t.d.x;
  c.wispyHeight = t.d.y;
  c.columnFill = t.d.z;
  c.unused = 0.0;
  return c;
}

CoreLayer layerAt(int li) {
  SkyLayer l = frame.layers[li];
  return CoreLayer(l.heights.x, l.heights.y, l.heights.z, l.heights.w, l.shape.x, l.shape.z, l.shape.w > 0.5,
                   unpackType(l.primary), unpackType(l.secondary), l.ambient.rgb, l.sunDiffuse.rgb,
                   l.sunDiffuse.w);
}

void main() {
  // Workgroup i draws tile (i * stride) mod n: lavapipe hands each thread a
  // contiguous range of workgroup ids, and the permutation spreads every range
  // over the whole image (lavapipe.md, "static split").
  uint tile = (gl_WorkGroupID.x * frame.dispatch.x) % frame.image.w;
  uvec2 px = uvec2(tile % frame.image.z, tile / frame.image.z) * kLocalSize + gl_LocalInvocationID.xy;
  if (px.x >= frame.image.x || px.y >= frame.image.y) return;

  CoreFrame f;
  f.air = AirFrame(frame.earth.x, frame.earth.y, frame.earth.z, frame.earth.w, frame.sunDir.xyz,
                   frame.sunIrradiance.rgb);
  f.groundIrradiance = frame.groundIrradiance.rgb;
  f.layerCount = int(frame.weatherMap.y);
  vec3 dir = cameraRay(frame.camForward.xyz, frame.camRight.xyz, frame.camDown.xyz, frame.camRight.w,
                       frame.camDown.w, float(px.x), float(px.y), float(frame.image.x), float(frame.image.y));
  PixelResult r = shadePixel(f, dir, pixelJitter(px.x, px.y));
  pixels[px.y * frame.image.x + px.x] = vec4(r.radiance, r.transmittance);
}
