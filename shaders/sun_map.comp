// Sun-map pass: one invocation per texel of each cascade of the frame's sun
// map (include/sun_map.glsl) marches the texel's sun line through every
// layer and stores the method's encoding of it; the air-table and cloud
// passes that follow read it. Frame layout and bindings:
// include/sky_shared.h (the cloud pass's set).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

#define SKY_SUN_MAP_BUILDER
#include "cloud_pass.glsl"

// The cascade this invocation builds: the frame builds cascades
// [sunMapSlots.z, sunMapSlots.w) (sun_map_plan.hpp: a camera that moved
// rebuilds a cascade by its own extent, so the coarse ones less often).
int builtCascade() {
  return int(gl_GlobalInvocationID.z) + int(frame.sunMapSlots.z);
}

void storeSunMap(vec4 part0, vec4 part1) {
  int c = builtCascade();
  ivec3 at = ivec3(gl_GlobalInvocationID.x, int(gl_GlobalInvocationID.y) + int(frame.sunBuildShells.z),
                   sunMapLayer(gSunMap, c, int(frame.sunMapSlots.y >> uint(c)) & 1));
  imageStore(sunMapOut, at, part0);
  if (sunMapParts(kSunMethod) > 1) imageStore(sunMapOut, at + ivec3(0, 0, 1), part1);
}

// This frame builds rows [sunBuildShells.z, sunBuildShells.w) of those
// cascades of the map being built (its geometry: sunBuild*), which frames
// read once its last row is done (renderer/core/src/sun_map_plan.hpp).
void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.x, int(gl_GlobalInvocationID.y) + int(frame.sunBuildShells.z));
  if (texel.x >= int(frame.sunMap.y) || texel.y >= int(frame.sunBuildShells.w)) return;
  loadFrameGlobals();
  gSunMap.axisU = frame.sunBuildU.xyz;
  gSunMap.axisV = frame.sunBuildV.xyz;
  gSunMap.topHeight = frame.sunBuildShells.x;
  gSunMap.baseHeight = frame.sunBuildShells.y;
  gSunMap.origin = frame.sunBuildOrigin.xyz;
  buildSunMapTexel(frameAir(), gSunMap, frameLayerCount(), builtCascade(), texel.x, texel.y);
}
