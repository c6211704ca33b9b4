// Cloud pass: one invocation per pixel marches every cloud layer and the
// clear air along the view ray (model in include/cloud_core.glsl) and writes
// linear radiance and cloud transmittance to one storage buffer, the cloud
// depth to a second one; with interleaving only one pixel of each n x n block
// (reproject.comp fills the others from earlier frames). Frame layout: include/sky_shared.h.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

#include "cloud_pass.glsl"
#include "fresh_edges.glsl"

void main() {
  // Workgroup i draws tile (i * stride) mod n: lavapipe hands each thread a
  // contiguous range of workgroup ids, and the permutation spreads every range
  // over the whole image (lavapipe.md, "static split").
  // With interleaving the first tiles cover the packed image of this frame's
  // pixels: packed pixel `sub` is pixel sub * n + phase of the full image.
  // The tiles after them draw the fresh edges (fresh_edges.glsl), kLocalSize^2
  // of their pixels each, written after the packed ones.
  uint tile = (gl_WorkGroupID.x * frame.dispatch.x) % frame.image.w;
  uint n = frame.interleave.x;
  uvec2 packed = (frame.image.xy + uvec2(n - 1u)) / n;
  uint packedTiles = frame.interleave.w;
  uvec2 px;
  uint slot;
  if (tile < packedTiles) {
    uvec2 sub = uvec2(tile % frame.image.z, tile / frame.image.z) * kLocalSize + gl_LocalInvocationID.xy;
    if (sub.x >= packed.x || sub.y >= packed.y) return;
    px = sub * n + frame.interleave.yz;
    slot = sub.y * packed.x + sub.x;
  } else {
    uint k = (tile - packedTiles) * (kLocalSize * kLocalSize) + gl_LocalInvocationIndex;
    if (k >= freshEdgeCount(frame.freshEdges, frame.image.xy)) return;
    px = uvec2(freshEdgePixel(int(k), frame.freshEdges, frame.image.xy));
    slot = packed.x * packed.y + k;
  }
  if (px.x >= frame.image.x || px.y >= frame.image.y) return;

  loadFrameGlobals();
  CoreFrame f;
  f.air = frameAir();
  f.airFromTable = kUseAirTable;
  f.clouds = kDrawClouds;
  f.layerShadows = frameLayerShadows();
  f.airTable = frameAirTable();
  f.groundIrradiance = frame.groundIrradiance.rgb;
  f.march = MarchParams(int(frame.dispatch.y), int(frame.dispatch.z), frame.weatherMap.z, frame.weatherMap.w,
                        frame.steps.x, frame.steps.y, frame.steps.z);
  f.layerCount = frameLayerCount();
  f.flashCount = int(frame.flashInfo.x);
  f.boltCount = int(frame.flashInfo.y);
  f.pixelAngle = frame.flashInfo.z;
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
  pixels[slot] = vec4(r.radiance, r.transmittance);
  depths[slot] = r.depth;
}
