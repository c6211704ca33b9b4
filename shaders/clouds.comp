// Cloud pass: one invocation per pixel marches every cloud layer and the
// clear air along the view ray (model in include/cloud_core.glsl) and writes
// linear radiance and cloud transmittance to one storage buffer, the cloud
// depth to a second one; with interleaving only one pixel of each n x n block
// (reproject.comp fills the others from earlier frames). Frame layout: include/sky_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

// The frame's numbers in a read-only storage buffer, not a uniform block:
// lavapipe specialises a shader on uniform-block values that decide branches
// and compiles a new variant whenever they change (with a moving camera ~1.5
// s per frame under ASan, measured with MESA_SHADER_CACHE_DISABLE=true);
// storage buffers it leaves alone. std430 and std140 agree on this vec4-only
// layout. Storage loads are gathers on lavapipe, so what a sample needs is
// read once: the frame's into the globals below, a layer's into its
// CoreLayer (layerAt, once per span).
layout(std430, set = 0, binding = kBindingFrame) readonly buffer FrameBlock { SkyFrame frame; };
layout(set = 0, binding = kBindingShape) uniform sampler3D shapeTex;
layout(set = 0, binding = kBindingWeather) uniform sampler2DArray weatherTex;
layout(std430, set = 0, binding = kBindingOutput) writeonly buffer OutputBlock { vec4 pixels[]; };
layout(set = 0, binding = kBindingDetail) uniform sampler3D detailTex;
layout(set = 0, binding = kBindingTransmittance) uniform sampler2D transmittanceTex;
layout(set = 0, binding = kBindingMultipleScattering) uniform sampler2D multipleScatteringTex;
layout(std430, set = 0, binding = kBindingDepth) writeonly buffer DepthBlock { float depths[]; };
layout(std430, set = 0, binding = kBindingCoverageMip) readonly buffer CoverageMipBlock { float coverageMip[]; };
layout(std430, set = 0, binding = kBindingBlueNoise) readonly buffer BlueNoiseBlock { float blueNoise[]; };

#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define SKY_CORE_CONST const

// Copies of the frame's sampling numbers, set at the start of main.
mat3 gCamToAnchor;     // camera-local -> weather-anchor-local
vec4 gCamInAnchor;     // xyz: camera in the anchor frame (m); w: anchor sphere radius (m)
float gMapScale;       // 1 / (2 half extent) of the weather map's fine ring (1/m)
vec4 gRings;           // the frame's weatherRings
mat3 gLocalToEcef;     // camera-local -> ECEF axes

vec3 sampleTransmittanceLut(vec2 uv) {
  return textureLod(transmittanceTex, uv, 0.0).rgb;
}

vec3 sampleMultipleScatteringLut(vec2 uv) {
  return textureLod(multipleScatteringTex, uv, 0.0).rgb;
}

#include "cloud_core.glsl"

vec2 airCloudShadow(AirFrame a, vec3 p, float h, float muSun) {
  return cloudShadow(a, a.shadowLayers, -1, p, h, muSun);
}

// Weather map lookup: camera-local point -> weather anchor frame -> gnomonic
// plane of the anchor sphere (x = R q.x / q.z) -> texture coordinates of the
// rings: the fine ring inside its blend band, the coarse ring beyond, linear
// in the max norm between (WeatherField::sample, ringBlendWeight).
vec3 sampleWeather(LayerSampling s, vec3 p) {
  vec3 q = gCamToAnchor * p + gCamInAnchor.xyz;
  if (q.z <= 0.0) return vec3(0.0);
  vec2 plane = q.xy * (gCamInAnchor.w / q.z) - s.coverageShift.xy;
  float e = 2.0 * max(abs(plane.x), abs(plane.y)) * gMapScale;
  float w = clamp((e - gRings.y) / (gRings.z - gRings.y), 0.0, 1.0);
  vec3 v = vec3(0.0);
  if (w < 1.0) v = textureLod(weatherTex, vec3(plane * gMapScale + 0.5, s.coverageShift.z), 0.0).xyz;
  if (w > 0.0)
    v = mix(v, textureLod(weatherTex, vec3(plane * gRings.x + 0.5, s.coverageShift.z + float(kMaxLayers)), 0.0).xyz, w);
  return v;
}

// The max-coverage mip of a camera-local point: the weather lookup's plane
// coordinates and ring weight, then each ring's cell it reads (nearest; 0
// outside a ring), the larger of the two across the blend band
// (sampleCoverageMip on the CPU).
float mipCell(uint ring, uint slice, vec2 uv) {
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThanEqual(uv, vec2(1.0)))) return 0.0;
  uvec2 cell = uvec2(uv * float(kCoverageMipSize));
  return coverageMip[((ring * kMaxLayers + slice) * kCoverageMipSize + cell.y) * kCoverageMipSize + cell.x];
}

float sampleMaxCoverage(LayerSampling s, vec3 p) {
  vec3 q = gCamToAnchor * p + gCamInAnchor.xyz;
  if (q.z <= 0.0) return 0.0;
  vec2 plane = q.xy * (gCamInAnchor.w / q.z) - s.coverageShift.xy;
  float e = 2.0 * max(abs(plane.x), abs(plane.y)) * gMapScale;
  float w = clamp((e - gRings.y) / (gRings.z - gRings.y), 0.0, 1.0);
  uint slice = uint(s.coverageShift.z);
  float most = 0.0;
  if (w < 1.0) most = mipCell(0u, slice, plane * gMapScale + 0.5);
  if (w > 0.0) most = max(most, mipCell(1u, slice, plane * gRings.x + 0.5));
  return most;
}

// Earth-fixed noise coordinates: rotate to ECEF axes, scale by the period and
// add the origin (camera ECEF minus wind drift, modulo the period, computed in
// double on the CPU).
vec3 noiseCoord(vec4 origin, vec3 p) {
  return origin.xyz + (gLocalToEcef * p) * origin.w;
}

// The shape noise, stretched along ECEF z for streaky types (the origin is
// stretched the same way on the CPU, so the pattern stays Earth-fixed).
vec2 sampleShape(LayerSampling s, vec3 p) {
  vec3 e = gLocalToEcef * p;
  e.z *= s.shapeStretchZ;
  return textureLod(shapeTex, s.shapeOrigin.xyz + e * s.shapeOrigin.w, 0.0).rg;
}

float sampleDetail(LayerSampling s, vec3 p) {
  return textureLod(detailTex, noiseCoord(s.detailOrigin, p), 0.0).r;
}

// Large-scale cloud map: the shape texture's smooth and Worley channels at a
// larger, incommensurate period.
vec2 sampleCloudMap(LayerSampling s, vec3 p) {
  return textureLod(shapeTex, noiseCoord(s.cloudMapOrigin, p), 0.0).ba;
}

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
  LayerSampling s = LayerSampling(l.shapeOrigin, l.detailOrigin, l.cloudMapOrigin,
                                  vec3(l.coverageShift.xy, l.shape.y), l.coverageShift.w);
  return CoreLayer(l.heights.x, l.heights.y, l.heights.z, l.heights.w, l.shape.x, l.shape.z, l.shape.w > 0.5,
                   unpackType(l.primary), unpackType(l.secondary), l.ambient.rgb, l.sunDiffuse.rgb,
                   l.sunDiffuse.w, s, l.ambient.w > 0.5, l.coverageShift.z);
}

void main() {
  // Workgroup i draws tile (i * stride) mod n: lavapipe hands each thread a
  // contiguous range of workgroup ids, and the permutation spreads every range
  // over the whole image (lavapipe.md, "static split").
  // With interleaving the tiles cover the packed image of this frame's
  // pixels: packed pixel `sub` is pixel sub * n + phase of the full image.
  uint tile = (gl_WorkGroupID.x * frame.dispatch.x) % frame.image.w;
  uvec2 sub = uvec2(tile % frame.image.z, tile / frame.image.z) * kLocalSize + gl_LocalInvocationID.xy;
  uint n = frame.interleave.x;
  uvec2 packed = (frame.image.xy + uvec2(n - 1u)) / n;
  if (sub.x >= packed.x || sub.y >= packed.y) return;
  uvec2 px = sub * n + frame.interleave.yz;
  if (px.x >= frame.image.x || px.y >= frame.image.y) return;

  // GLSL's mat3(a, b, c) takes columns; the frame holds rows.
  gCamToAnchor = transpose(mat3(frame.camToAnchor[0].xyz, frame.camToAnchor[1].xyz, frame.camToAnchor[2].xyz));
  gLocalToEcef = transpose(mat3(frame.localToEcef[0].xyz, frame.localToEcef[1].xyz, frame.localToEcef[2].xyz));
  gCamInAnchor = frame.camInAnchor;
  gMapScale = frame.weatherMap.x;
  gRings = frame.weatherRings;

  CoreFrame f;
  f.air = AirFrame(frame.earth.x, frame.earth.y, frame.earth.z, frame.earth.w, frame.sunDir.xyz,
                   frame.sunIrradiance.rgb, int(frame.dispatch.w), frame.sunDir.w,
                   frame.sunIrradiance.w > 0.5 ? int(frame.weatherMap.y) : 0);
  f.groundIrradiance = frame.groundIrradiance.rgb;
  f.march = MarchParams(int(frame.dispatch.y), int(frame.dispatch.z), frame.weatherMap.z, frame.weatherMap.w,
                        frame.steps.x, frame.steps.y, frame.steps.z);
  f.layerCount = int(frame.weatherMap.y);
  // The pixel's step offset: the blue-noise tile's, or the hash's (SkyFrame::steps.w).
  uint tileIndex = (px.y & (kBlueNoiseSize - 1u)) * kBlueNoiseSize + (px.x & (kBlueNoiseSize - 1u));
  // Where in the pixel the ray goes: its centre, or with pixelJitter an
  // offset from two blue-noise values (the pixel's, and the one half a tile
  // away), moved on by the cycle's shift.
  vec2 at = vec2(px);
  if (frame.pixelJitter.z > 0.5) {
    uvec2 q = (px + uvec2(kBlueNoiseSize / 2u)) & (kBlueNoiseSize - 1u);
    vec2 noise = vec2(blueNoise[tileIndex], blueNoise[q.y * kBlueNoiseSize + q.x]);
    at += fract(noise + frame.pixelJitter.xy) - 0.5;
  }
  vec3 dir = cameraRay(frame.camForward.xyz, frame.camRight.xyz, frame.camDown.xyz, frame.frustum, at.x, at.y,
                       frame.raster.x, frame.raster.y);
  float jitter = frame.steps.w > 0.5 ? blueNoise[tileIndex] : pixelJitter(px.x, px.y);
  jitter = fract(jitter + frame.raster.z);
  PixelResult r = shadePixel(f, dir, jitter);
  pixels[sub.y * packed.x + sub.x] = vec4(r.radiance, r.transmittance);
  depths[sub.y * packed.x + sub.x] = r.depth;
}
