// Layout of the cloud pass's frame block and its binding numbers, shared by
// C++ (renderer/core) and GLSL (shaders/clouds.comp). Only vec4/uvec4 members,
// so std430, std140 and C++ agree without hidden padding; the C++ side pins
// sizes and offsets with static_assert below.
#ifndef SKY_SHARED_H
#define SKY_SHARED_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/vec4.hpp>
namespace sky::gpu {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
#define SKY_SHARED_CONST static constexpr std::uint32_t
#else
#define SKY_SHARED_CONST const uint
#endif

// Descriptor set 0 bindings of the cloud pass.
SKY_SHARED_CONST kBindingFrame = 0u;          // read-only storage buffer holding one SkyFrame
SKY_SHARED_CONST kBindingShape = 1u;          // sampler3D, tileable shape noise (RGBA8, repeat):
                                              // billowy Perlin-Worley, fibrous, smooth fBm, Worley
SKY_SHARED_CONST kBindingWeather = 2u;        // sampler2DArray, RGBA8 = coverage, density, type blend;
                                              // one slice per layer and ring: layer ring * kMaxLayers + slice;
                                              // then the wind map, layer kWindMapLayers + ring * kMaxLayers +
                                              // slice: RGBA8 = east high, east low, north high, north low byte
SKY_SHARED_CONST kBindingOutput = 3u;         // storage buffer of vec4 radiance (rgb) + transmittance (a)
SKY_SHARED_CONST kBindingDetail = 4u;         // sampler3D, tileable Worley detail noise (R8, repeat)
SKY_SHARED_CONST kBindingTransmittance = 5u;  // sampler2D, atmosphere transmittance table (RGBA16F, clamp)
SKY_SHARED_CONST kBindingMultipleScattering = 6u;  // sampler2D, atmosphere multiple scattering (RGBA16F, clamp)
SKY_SHARED_CONST kBindingDepth = 7u;               // storage buffer of float cloud depth (m, 0 = no cloud) per pixel
SKY_SHARED_CONST kBindingCoverageMip = 10u;        // read-only storage buffer of float: the weather map's max-coverage
                                                   // mip, rings x kMaxLayers x kCoverageMipSize^2 (ring, slice, row north, column east)
SKY_SHARED_CONST kBindingBlueNoise = 11u;          // read-only storage buffer of float: the blue-noise tile,
                                                   // kBlueNoiseSize^2 values in [0, 1), row-major
SKY_SHARED_CONST kBindingAirTableOut = 12u;        // storage image3D (RGBA32F): the air table the table pass
                                                   // writes (air_table.glsl), its three parts stacked in depth
SKY_SHARED_CONST kBindingAirTable = 13u;           // sampler3D of the same image, read by the cloud pass
                                                   // (linear; u repeats, v and w clamp to the edge)
SKY_SHARED_CONST kBindingSunMapOut = 14u;          // storage image2DArray (RGBA32F): the sun map the map pass
                                                   // writes (sun_map.glsl), cascade c's part j in layer c * parts + j
SKY_SHARED_CONST kBindingSunMap = 15u;             // sampler2DArray of the same image (linear, clamped to the edge)
// Pixels per edge of the blue-noise tile (renderer/core/src/blue_noise.hpp).
SKY_SHARED_CONST kBlueNoiseSize = 64u;
// Cells per edge of the max-coverage mip (renderer/core/src/coverage_mip.hpp).
SKY_SHARED_CONST kCoverageMipSize = 32u;

// Workgroup edge of the cloud pass, pixels (8x8 = 64 invocations = 8 lavapipe
// subgroups of 8 lanes).
SKY_SHARED_CONST kLocalSize = 8u;
// Cloud layers the pass draws; also the slice count of the weather texture.
SKY_SHARED_CONST kMaxLayers = 4u;
// The weather texture's first wind layer (after the two rings' cover), and
// the wind it encodes: each component (m/s, +-kWindMapScale_mps) in 16 bits
// as a high and a low byte, q = (v / scale + 1) / 2 * 65535, so the texture
// filter (linear in each byte) filters the wind itself.
SKY_SHARED_CONST kWindMapLayers = 2u * kMaxLayers;
SKY_SHARED_CONST kWindMapScale_mps = 150u;

// Lightning a frame draws (lightning.glsl): flashes lighting their clouds,
// and the segments of one cloud-to-ground channel (the protocol's
// weather::kMaxBoltSegments).
SKY_SHARED_CONST kMaxFrameFlashes = 4u;
SKY_SHARED_CONST kMaxFrameBoltSegments = 48u;

// A cloud type's 15 numbers (cloud_density.glsl's CloudType, in its order,
// four per vec4; the last one unused).
struct SkyCloudType {
  vec4 a;  // extinction (1/m), droplet diameter (um, <= 0 ice), baseRound, topRoundStart
  vec4 b;  // peak, peakVariation, anvil, densityGradient
  vec4 c;  // densityBaseFade, densityTopFade, coverageEdge, fibrous
  vec4 d;  // erosion, wispyHeight, columnFill, unused
};

// One cloud layer as the GPU sees it. Heights are computed on the CPU in double
// from altitudes, because r - R of two Earth-sized radii cancels in float.
struct SkyLayer {
  vec4 heights;        // x: camera height above base (m), y: camera height above top (m),
                       // z: hBase (2r - hBase), w: hTop (2r - hTop) (m^2, r = camera radius)
  vec4 shape;          // x: thickness (m), y: weather slice index, z: light march distance (m),
                       // w: 1 when tiles blend towards the secondary type, else 0
  vec4 shapeOrigin;    // xyz: camera ECEF minus wind drift, modulo the shape period, in periods;
                       // w: 1 / shape period (1/m)
  vec4 detailOrigin;   // the same for the detail noise and its period
  vec4 cloudMapOrigin; // the same for the cloud map (the shape texture at a larger period)
  vec4 coverageShift;  // xy: coverage drift east/north in the weather map plane (m), z: the march in
                       // metres' step-length factor (> 0; 1: off), w: the shape noise's ECEF z scale
                       // (1, or < 1 for streaks)
  vec4 ambient;        // rgb: mean sky radiance at the layer top (linear units); w: 1 when the layer
                       // has no coverage anywhere on the weather map (not marched), else 0
  vec4 sunDiffuse;     // rgb: sunlight at the layer top as diffuse radiance, E T mu / pi; w: mu of the sun
  SkyCloudType primary;    // the layer's own type
  SkyCloudType secondary;  // the type its tiles blend towards
  vec4 flow;           // the layer's wind field (wind map): x, y: the two flow phases' ages (s), z: phase A's
                       // weight, w: 1 when the layer's wind varies over the map (its wind slice is read), else 0
  vec4 windRef;        // xyz: the layer's own wind, camera-local (m/s), which the noise origins drift with;
                       // w: the age of the map's tiles, weather clock minus the snapshot's (s)
  vec4 band;           // x: the transition band's fraction of the shell at each end (heights and
                       // thickness above are the shell's: the cloud with its band); y: the index of
                       // the layer that carries this precipitation layer, or -1; zw: unused
};

struct SkyFrame {
  vec4 camForward;      // xyz: camera forward in the local frame (x east, y north, z up)
  vec4 camRight;        // xyz: camera right; w: unused
  vec4 camDown;         // xyz: camera down; w: unused
  vec4 localToEcef[3];  // rows of the rotation local -> ECEF
  vec4 camToAnchor[3];  // rows of the rotation camera-local -> weather-anchor-local
  vec4 camInAnchor;     // xyz: camera relative to the anchor sphere centre, anchor frame (m);
                        // w: anchor sphere radius (m)
  vec4 weatherMap;      // x: 1 / (2 half extent) (1/m), y: layer count, z: the march's minimum
                        // transmittance, w: its empty stride (RenderSettings::march)
  vec4 earth;           // x: camera radius r (m), y: camera height above ground (m),
                        // z: hGround (2r - hGround) (m^2), w: the same for the atmosphere top (m^2)
  vec4 sunDir;          // xyz: unit vector towards the sun, local frame; w: the view ray's aerosol
                        // excess (AirFrame::aerosolExcess, 0: the standard haze)
  vec4 sunIrradiance;   // rgb: sun irradiance at the top of the atmosphere (linear units); w: 1 when the
                        // air and the lower layers see the clouds' shadow (MarchSettings::cloudShadows), else 0
  vec4 groundIrradiance;  // rgb: sky irradiance on horizontal ground (linear units); w: unused
  uvec4 image;          // x: width, y: height, z: tiles per row, w: tile count
  uvec4 dispatch;       // x: tile permutation stride (coprime to the tile count), y: primary steps per
                        // layer span, z: light steps, w: clear-air steps (0: the default, kAirSteps)
  SkyLayer layers[kMaxLayers];
  vec4 weatherRings;    // x: 1 / (2 half extent) of the coarse ring (1/m); y, z: the blend band's start and
                        // end in fractions of the fine ring's half extent (max norm); w: unused
  vec4 steps;           // the march in metres (RenderSettings::march): x: step inside cloud (m; 0: even
                        // placement), y: step through clear air (m), z: step growth per metre, w: 1 when the
                        // step offsets come from the blue-noise tile, 0 from the pixel hash
  uvec4 interleave;     // x: n, the pass draws 1 pixel of each n x n block (1: every pixel); y, z: this
                        // frame's pixel in the block (column, row); w: the tiles of those pixels (the
                        // tiles after them draw the fresh edges). The output holds the drawn pixels
                        // packed, ceil(width / n) per row, then the fresh edges' (reproject.comp reads them).
  vec4 raster;          // xy: the image's extent in its own pixels for the camera rays: the full size over the
                        // resolution divisor (image.xy rounds it up); z: added (mod 1) to every pixel's step
                        // offset (TemporalSettings::accumulation); w: unused
  vec4 pixelJitter;     // xy: added (mod 1) to the pixel's two blue-noise values for where in the pixel
                        // its ray goes; z: 1 to jitter (TemporalSettings::pixelJitter), 0 for the centre
  vec4 frustum;         // tangents of the view's left, right, up and down half-angles (left and down
                        // negative; core_common.glsl, frustumPoint)
  uvec4 airTable;       // the air table (air_table.glsl, AirTableShape): x azimuths (0: the air is marched
                        // per pixel, no table pass), y zeniths, z slices per part; w unused
  uvec4 sunMap;         // the sun's shadow (sun_map.glsl, SunMap): x method (SunShadow; >= 2 a map and its
                        // pass), y texels per cascade edge, z cascades, w samples per layer along a texel's line
  vec4 sunMapU;         // xyz: the map's first axis, local frame; w: cascade 0's half extent (m)
  vec4 sunMapV;         // xyz: its second axis; w: unused (the rows this frame builds: sunBuildShells)
  vec4 sunMapShells;    // x: the highest drawn layer's top, y: the lowest one's base, m above the ground
                        // sphere (as the map read was built); z, w: unused
  vec4 sunMapOrigin;    // xyz: the centre of the map's cascade 0, local frame (m; 0 when built this frame);
                        // w: unused
  uvec4 freshEdges;     // with interleaving, the widths (px) of the bands at the left, right, top and bottom
                        // edges drawn at every pixel as well (fresh_edges.glsl); 0 none
  vec4 sunBuildU;       // the map this frame builds rows of, as sunMapU: xyz its first axis; w unused
  vec4 sunBuildV;       // xyz: its second axis; w unused
  vec4 sunBuildShells;  // x, y: its top and base shells as sunMapShells; z: the first texel row built this
                        // frame, w: one past the last (of every cascade)
  vec4 sunBuildOrigin;  // xyz: its centre, local frame (m); w unused
  vec4 sunMapOrigins[3];  // xyz: the centres of the map's cascades 1-3 as sunMapOrigin (a camera that
                          // moved rebuilds a cascade by its own extent: sun_map_plan.hpp); w unused
  uvec4 sunMapSlots;    // the image holds two maps, one read while the other is built over several
                        // frames: x bit c, the map cascade c is read from; y bit c, the map it is built
                        // into; z, w: the cascades built this frame, [z, w)
  vec4 flashInfo;       // x: flashes lit this frame, y: bolt segments drawn, z: a pixel's angle (rad); w unused
  vec4 flashes[kMaxFrameFlashes];        // xyz: a flash's light centre, local frame (m); w: its intensity
                                         // (linear units x m^2: the irradiance at 1 m)
  vec4 boltStart[kMaxFrameBoltSegments]; // xyz: a channel segment's start, local frame (m); w: the
                                         // channel's intensity per metre (linear units x m, per sr)
  vec4 boltEnd[kMaxFrameBoltSegments];   // xyz: its end; w unused
};

#ifdef __cplusplus
static_assert(sizeof(vec4) == 16 && sizeof(uvec4) == 16);
static_assert(sizeof(SkyCloudType) == 64);
static_assert(sizeof(SkyLayer) == 304);
static_assert(offsetof(SkyLayer, shapeOrigin) == 32);
static_assert(offsetof(SkyLayer, ambient) == 96);
static_assert(offsetof(SkyLayer, sunDiffuse) == 112);
static_assert(offsetof(SkyLayer, primary) == 128);
static_assert(offsetof(SkyLayer, secondary) == 192);
static_assert(offsetof(SkyFrame, localToEcef) == 48);
static_assert(offsetof(SkyFrame, camToAnchor) == 96);
static_assert(offsetof(SkyFrame, camInAnchor) == 144);
static_assert(offsetof(SkyFrame, image) == 240);
static_assert(offsetof(SkyFrame, dispatch) == 256);
static_assert(offsetof(SkyFrame, layers) == 272);
static_assert(offsetof(SkyLayer, cloudMapOrigin) == 64);
static_assert(offsetof(SkyLayer, flow) == 256);
static_assert(offsetof(SkyLayer, band) == 288);
static_assert(offsetof(SkyFrame, weatherRings) == 272 + 304 * kMaxLayers);
static_assert(offsetof(SkyFrame, steps) == 272 + 304 * kMaxLayers + 16);
static_assert(offsetof(SkyFrame, interleave) == 272 + 304 * kMaxLayers + 32);
static_assert(offsetof(SkyFrame, raster) == 272 + 304 * kMaxLayers + 48);
static_assert(offsetof(SkyFrame, frustum) == 272 + 304 * kMaxLayers + 80);
static_assert(offsetof(SkyFrame, airTable) == 272 + 304 * kMaxLayers + 96);
static_assert(offsetof(SkyFrame, sunMap) == 272 + 304 * kMaxLayers + 112);
static_assert(offsetof(SkyFrame, flashInfo) == 272 + 304 * kMaxLayers + 336);
static_assert(sizeof(SkyFrame) == 272 + 304 * kMaxLayers + 352 + 16 * (kMaxFrameFlashes + 2 * kMaxFrameBoltSegments));
}  // namespace sky::gpu
#endif
#undef SKY_SHARED_CONST

#endif  // SKY_SHARED_H
