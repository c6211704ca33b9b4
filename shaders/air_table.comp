// Air-table pass: one invocation per direction of the frame's air table
// (include/air_table.glsl) marches the clear air along it, with the clouds'
// shadow, and writes its light and transmittance at every slice; the cloud
// pass that follows reads the sky and the aerial perspective from it.
// Frame layout and bindings: include/sky_shared.h (the cloud pass's set).
#version 450
#extension GL_GOOGLE_include_directive : require

#include "sky_shared.h"

layout(local_size_x = kLocalSize, local_size_y = kLocalSize) in;

#define SKY_AIR_TABLE_BUILDER
#include "cloud_pass.glsl"

void storeAirTable(int slice, vec4 part0, vec4 part1, vec4 part2) {
  ivec2 column = ivec2(gl_GlobalInvocationID.xy);
  int slices = int(frame.airTable.z);
  imageStore(airTableOut, ivec3(column, slice), part0);
  imageStore(airTableOut, ivec3(column, slices + slice), part1);
  imageStore(airTableOut, ivec3(column, 2 * slices + slice), part2);
}

void main() {
  AirTableShape t = frameAirTable();
  ivec2 column = ivec2(gl_GlobalInvocationID.xy);
  if (column.x >= t.azimuths || column.y >= t.zeniths) return;
  loadFrameGlobals();
  AirFrame a = frameAir();
  buildAirTableColumn(a, t, airTableDirection(a, t, column.x, column.y));
}
