// Density-lookup throughput probe (tests/bench/lookup_bench.cpp): one camera
// ray per pixel through a tiled 128^3 volume, exactly one filtered 3D texture
// lookup per step and nothing else (a position add and a sum that keeps the
// lookups alive). The machine's ceiling for the cloud pass's inner loop.
#version 450

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform sampler3D volume;
layout(std430, set = 0, binding = 1) writeonly buffer Sums { float sums[]; };

layout(push_constant) uniform Push {
  uvec4 image;   // width, height, tiles per row, tile count
  uvec4 march;   // steps, permutation stride, 0, 0
  vec4 origin;   // ray origin in texture coordinates (xyz), step length in texture coordinates (w)
  vec4 lens;     // tan(half horizontal fov), tan(half vertical fov), 0, 0
} pc;

void main() {
  // Workgroup i draws tile (i * stride) mod n: lavapipe gives each worker a
  // contiguous range of workgroup ids, the permutation spreads it over the
  // image (reference/lavapipe.md, "static split").
  uint tile = (gl_WorkGroupID.x * pc.march.y) % pc.image.w;
  uvec2 px = uvec2(tile % pc.image.z, tile / pc.image.z) * 8u + gl_LocalInvocationID.xy;
  if (px.x >= pc.image.x || px.y >= pc.image.y) return;
  vec2 ndc = (vec2(px) + 0.5) / vec2(pc.image.xy) * 2.0 - 1.0;
  vec3 dir = normalize(vec3(ndc.x * pc.lens.x, 1.0, -ndc.y * pc.lens.y));
  vec3 p = pc.origin.xyz;
  vec3 stepVec = dir * pc.origin.w;
  float sum = 0.0;
  for (uint i = 0u; i < pc.march.x; ++i) {
    sum += textureLod(volume, p, 0.0).r;
    p += stepVec;
  }
  sums[px.y * pc.image.x + px.x] = sum;
}
