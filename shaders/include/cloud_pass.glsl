// What the cloud pass (clouds.comp) and the air-table pass (air_table.comp)
// share: one descriptor set layout, the frame's numbers, and the hooks of
// the cloud model (include/cloud_core.glsl) on the GPU's textures. Needs
// sky_shared.h, and SKY_AIR_TABLE_BUILDER defined by the table pass before
// it (air_table.glsl's builder hook).

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

// What a pipeline variant draws, fixed when it is built (specialisation
// constants, so the compiler drops what a variant does not draw; lavapipe
// runs every branch and one turn of every loop for all lanes, so code
// behind a run-time test still costs): kDrawClouds false for frames whose
// layers have no coverage anywhere (a clear sky pays only for the air);
// kUseAirTable false for the air marched per pixel.
layout(constant_id = 0) const bool kDrawClouds = true;
layout(constant_id = 1) const bool kUseAirTable = true;
// kLayersShadowLayers false for frames with at most one layer drawn: the
// layers' shadow on each other's clouds is compiled out (CoreFrame::layerShadows).
layout(constant_id = 2) const bool kLayersShadowLayers = true;

// kSunMethod: how the sun's optical depth is found (sun_map.glsl: the
// march, the column, or a map), so a frame's pipeline holds only its way.
layout(constant_id = 3) const int kSunMethod = 0;

// kWindField false for frames none of whose layers has a wind that varies
// over the map (SkyLayer::flow.w) or is in a crossfade of its flow's phases
// (flow.z strictly between 0 and 1): the wind map's reads and the second
// noise phase are compiled out (cloud_core.glsl's flowCrossfades).
layout(constant_id = 4) const bool kWindField = true;

// kLightning false for frames that light no flash (SkyFrame::flashInfo):
// the flash's light in the march and the bolt are compiled out.
layout(constant_id = 5) const bool kLightning = false;

// kShowers false for frames with no precipitation layer under a carrier
// (SkyLayer::band.y): the carrier's footprint (cloud_core.glsl's
// carrierFootprint) is compiled out. Present in the pipeline, even untaken,
// it made high's march ~20 % slower on lavapipe.
layout(constant_id = 6) const bool kShowers = false;

#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define real3x3 mat3
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

layout(set = 0, binding = kBindingAirTableOut, rgba32f) uniform writeonly image3D airTableOut;
layout(set = 0, binding = kBindingAirTable) uniform sampler3D airTable;

// The three parts are stacked in the image's depth: part p's w in [0, 1]
// is the image's (p + w) / 3.
vec4 sampleAirTable(int part, vec3 uvw) {
  return textureLod(airTable, vec3(uvw.xy, (float(part) + uvw.z) / 3.0), 0.0);
}

layout(set = 0, binding = kBindingSunMapOut, rgba32f) uniform writeonly image2DArray sunMapOut;
layout(set = 0, binding = kBindingSunMap) uniform sampler2DArray sunMapTex;

vec4 sampleSunMap(int layer, vec2 uv) {
  return textureLod(sunMapTex, vec3(uv, float(layer)), 0.0);
}

#include "cloud_core.glsl"

vec2 airCloudShadow(AirFrame a, vec3 p, float h, float muSun) {
  return airSunShadow(a, p, h, muSun);
}

#include "weather_map.glsl"

// Where the layer's tiles are read for plane point `plane`: carried back by
// the uniform drift, or (a wind that varies) by the wind there times the
// tiles' age (weather::upwindOf, in the map's plane).
vec2 tilePlane(LayerSampling s, vec2 plane) {
  if (kWindField && s.flow.w > 0.5) return plane - mapWind(s.coverageShift.z, plane) * s.windRef.w;
  return plane - s.coverageShift.xy;
}

vec3 sampleWeather(LayerSampling s, vec3 p) {
  vec2 plane;
  if (!weatherPlane(p, plane)) return vec3(0.0);
  return sampleMapLayer(tilePlane(s, plane), s.coverageShift.z).xyz;
}

vec3 sampleWindLocal(LayerSampling s, vec3 p) {
  return mapWindLocal(s.coverageShift.z, p, s.windRef.xyz);
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
  vec2 plane;
  if (!weatherPlane(p, plane)) return 0.0;
  plane = tilePlane(s, plane);
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
  vec3 e = gLocalToEcef * (p - s.flowShift);
  e.z *= s.shapeStretchZ;
  return textureLod(shapeTex, s.shapeOrigin.xyz + e * s.shapeOrigin.w, 0.0).rg;
}

float sampleDetail(LayerSampling s, vec3 p) {
  return textureLod(detailTex, noiseCoord(s.detailOrigin, p - s.flowShift), 0.0).r;
}

// Large-scale cloud map: the shape texture's smooth and Worley channels at a
// larger, incommensurate period.
vec2 sampleCloudMap(LayerSampling s, vec3 p) {
  return textureLod(shapeTex, noiseCoord(s.cloudMapOrigin, p - s.flowShift), 0.0).ba;
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

real4 flashAt(int k) { return frame.flashes[k]; }
real4 boltStartAt(int k) { return frame.boltStart[k]; }
real3 boltEndAt(int k) { return frame.boltEnd[k].xyz; }

CoreLayer layerAt(int li) {
  SkyLayer l = frame.layers[li];
  LayerSampling s = LayerSampling(l.shapeOrigin, l.detailOrigin, l.cloudMapOrigin,
                                  vec3(l.coverageShift.xy, l.shape.y), l.coverageShift.w, l.flow, l.windRef,
                                  vec3(0.0), vec3(0.0));
  return CoreLayer(l.heights.x, l.heights.y, l.heights.z, l.heights.w, l.shape.x, l.shape.z, l.shape.w > 0.5,
                   unpackType(l.primary), unpackType(l.secondary), l.ambient.rgb, l.sunDiffuse.rgb,
                   l.sunDiffuse.w, s, l.ambient.w > 0.5, l.coverageShift.z, l.band.x, int(l.band.y));
}

// Copies the frame's sampling numbers into the globals the hooks read.
void loadFrameGlobals() {
  // GLSL's mat3(a, b, c) takes columns; the frame holds rows.
  gCamToAnchor = transpose(mat3(frame.camToAnchor[0].xyz, frame.camToAnchor[1].xyz, frame.camToAnchor[2].xyz));
  gLocalToEcef = transpose(mat3(frame.localToEcef[0].xyz, frame.localToEcef[1].xyz, frame.localToEcef[2].xyz));
  gCamInAnchor = frame.camInAnchor;
  gMapScale = frame.weatherMap.x;
  gRings = frame.weatherRings;
  gSunMap = SunMap(kSunMethod, int(frame.sunMap.y), int(frame.sunMap.z), int(frame.sunMap.w), frame.sunMapU.w,
                   frame.sunMapU.xyz, frame.sunMapV.xyz, frame.sunMapShells.x, frame.sunMapShells.y,
                   frame.sunMapOrigin.xyz, frame.sunMapOrigins[0].xyz, frame.sunMapOrigins[1].xyz,
                   frame.sunMapOrigins[2].xyz, int(frame.sunMapSlots.x));
}

AirFrame frameAir() {
  return AirFrame(frame.earth.x, frame.earth.y, frame.earth.z, frame.earth.w, frame.sunDir.xyz,
                  frame.sunIrradiance.rgb, int(frame.dispatch.w), frame.sunDir.w,
                  kDrawClouds && frame.sunIrradiance.w > 0.5 ? int(frame.weatherMap.y) : 0);
}

int frameLayerCount() {
  return kDrawClouds ? int(frame.weatherMap.y) : 0;
}

int frameLayerShadows() {
  return kLayersShadowLayers && frame.sunIrradiance.w > 0.5 ? frameLayerCount() : 0;
}

AirTableShape frameAirTable() {
  if (!kUseAirTable) return AirTableShape(0, 0, 0);
  return AirTableShape(int(frame.airTable.x), int(frame.airTable.y), int(frame.airTable.z));
}
