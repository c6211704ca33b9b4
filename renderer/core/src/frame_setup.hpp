// Everything one frame needs, derived on the CPU in double precision from the
// pose, the weather, the clock and the sun: camera axes and Earth geometry in
// the camera's local frame, per-layer heights, cloud types, Earth-fixed noise
// origins and wind drift, and the sky's light on the layers and the ground.
// Packed into the GPU's uniform block, or fed to the CPU reference.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "atmosphere_tables.hpp"
#include "cloud_types.hpp"
#include "flash_setup.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky_shared.h"
#include "weather_field.hpp"

namespace sky::render {

// Period of the cloud map (the shape texture sampled larger) relative to the
// layer type's shape period: for cumulus 23 km against 5 km, which share no
// small common multiple, so the pattern repeats only every 115 km.
inline constexpr double kCloudMapPeriodFactor = 4.6;

struct LayerSetup {
  double hBase_m = 0;       // camera height above the base (negative below)
  double hTop_m = 0;        // camera height above the top
  double cBase_m2 = 0;      // hBase (2r - hBase)
  double cTop_m2 = 0;       // hTop (2r - hTop)
  // The heights above and thickness_m are the layer's shell: its cloud from
  // base to top with the transition band below and above (band: the band's
  // fraction of the shell at each end; layer_presence.glsl).
  double thickness_m = 0;
  double band = 0;
  double lightDistance_m = 0;      // what the secondary march towards the sun covers
  CloudTypeParams primary;         // the layer's type
  CloudTypeParams secondary;       // the type its tiles blend towards (= primary when none)
  bool blends = false;             // tiles carry a blend towards `secondary`
  double shapePeriod_m = 0, detailPeriod_m = 0, cloudMapPeriod_m = 0;
  double shapeStretchZ = 1;        // the shape noise's ECEF z scale (1 / the type's streak length)
  glm::dvec3 shapeOrigin{0};       // (camera ECEF - wind drift) mod shape period, in periods
  glm::dvec3 detailOrigin{0};      // the same for the detail period
  glm::dvec3 cloudMapOrigin{0};    // the same for the cloud-map period
  glm::dvec2 coverageShift_m{0};   // wind drift of the coverage since the snapshot, east/north
  glm::dvec3 windEnu_mps{0};       // the layer's own air velocity (where it blows to), local frame
  // The layer's wind field (cloud_core.glsl's LayerSampling::flow, windRef):
  // x, y the two flow phases' ages (s), z phase A's weight, w 1 when the wind
  // varies over the map (WeatherField::windVaries); and the own wind with the
  // map tiles' age (s) in w.
  glm::dvec4 flow{0};
  glm::dvec4 windRef{0};
  // The air's velocity over the camera (the wind field's there, or the own
  // wind): what moves the layer's clouds near the camera, local frame.
  glm::dvec3 windAtCamera_mps{0};
  glm::dvec3 skyTop{0};            // mean sky radiance at the layer top, linear units
  glm::dvec3 sunDiffuseTop{0};     // sunlight at the layer top as diffuse radiance, E T mu / pi
  double sunCosine = 0;            // mu of the sun at the layer top over the camera, >= 0
  // The march in metres' step lengths times this (stepLengthFactor), > 0; 1
  // with the factors off.
  double stepFactor = 1;
  // No coverage anywhere on the weather map (the whole view: the map reaches
  // past the march's 150 km): the layer is not marched and casts no shadow.
  bool absent = false;
  // A precipitation layer: the index of the layer whose cells drop it (its
  // shafts fall under them; cloud_core.glsl's carrierFootprint), or -1.
  int carrier = -1;
};

// The sun-space map's frame (sun_map.glsl, SunMap): two unit axes across the
// sun in the camera's local frame, and the heights above the ground sphere
// of the highest drawn layer's top and the lowest one's base (0, 0 with no
// layer drawn: the map's lines then miss every shell).
// The noise's flow with a wind that varies (cloud_core.glsl, cloudSample):
// each phase carries the noise for up to this long, then the other takes
// over. A shear of 1e-3 /s (10 m/s across 10 km) stretches a cloud by 60 %
// at most before its phase fades; a forecast's shear (1e-5 /s) by 1 %.
inline constexpr double kWindFlowPeriod_s = 600;
// Half the crossfade, in fractions of the period: both phases are read for
// 2 x 2 x 0.05 = 20 % of the time (a minute of each ten).
inline constexpr double kWindFlowCrossfade = 0.05;
// At weather clock t: the ages (s) of flow phases A and B and A's weight.
glm::dvec3 windFlowPhases(double weatherClock_s);

struct SunMapGeometry {
  glm::dvec3 axisU{1, 0, 0};
  glm::dvec3 axisV{0, 1, 0};
  double top_m = 0;
  double base_m = 0;
  glm::dvec3 origin{0};  // the map's centre, camera-local (0: built around the camera)
};

struct FrameSetup {
  // The image the cloud pass draws: the settings' size over the resolution
  // divisor, rounded up. Its pixel (i, j) is centred where the full image's
  // continuous coordinate is ((i + 0.5) d, (j + 0.5) d); rays take the
  // full image's frustum, rasterWidth x rasterHeight of these pixels (the
  // settings' size / d, not whole when the size is not a multiple of d).
  std::uint32_t width = 0, height = 0;
  double rasterWidth = 0, rasterHeight = 0;
  // The full image's view frustum: tangents of its left, right, up and down
  // half-angles (core_common.glsl, frustumPoint).
  glm::dvec4 frustum{-1, 1, 1, -1};
  glm::dvec3 camForward{0}, camRight{0}, camDown{0};  // local frame: x east, y north, z up
  glm::dmat3 localToEcef{1};   // columns: the camera's east, north, up in ECEF
  glm::dvec3 cameraEcef_m{0};  // the local frame's origin
  glm::dmat3 camToAnchor{1};   // columns: camera east, north, up in the weather anchor's frame
  glm::dvec3 camInAnchor_m{0}; // camera relative to the anchor sphere centre, anchor frame
  double anchorRadius_m = 0;
  double mapHalfExtent_m = 0;        // the fine ring's
  double coarseHalfExtent_m = 0;     // the coarse ring's
  double r_m = 0;              // camera distance from its local Earth centre = |camera ECEF|
  double hGround_m = 0;        // camera height above the ground sphere = altitude
  double cGround_m2 = 0;
  double cAtmosphereTop_m2 = 0;  // the same for the top of the atmosphere
  // The key light (the sun, or the moon at night: moonLit); the model calls it the sun.
  glm::dvec3 sunDir{0, 0, 1};
  glm::dvec3 sunIrradiance{0};     // at the top of the atmosphere, linear units
  bool moonLit = false;
  // The view ray's aerosol beyond the standard profile (AirFrame::aerosolExcess):
  // from FrameInputs::visibility_m, 0 without it.
  double aerosolExcess = 0;
  glm::dvec3 groundIrradiance{0};  // sky irradiance on the ground, linear units
  std::vector<LayerSetup> layers;
  MarchSettings march;  // the march's cost knobs, as set
  // The pixels the cloud pass draws: one of each interleave x interleave
  // block, the one at `phase` in it (TemporalPlanner); 1, {0, 0}: all.
  std::uint32_t interleave = 1;
  glm::uvec2 phase{0};
  // With interleaving, the bands at the image's edges drawn at every pixel
  // as well (left, right, top, bottom widths; fresh_edges.glsl).
  glm::uvec4 freshEdges{0};
  // Added (mod 1) to every pixel's step offset: TemporalSettings::accumulation's
  // per-cycle shift; 0 otherwise.
  double jitterShift = 0;
  // TemporalSettings::pixelJitter's per-cycle shift of the ray positions in
  // their pixels (R2 sequence, each in [0, 1)); applied when pixelJitter.
  glm::dvec2 pixelShift{0};
  bool pixelJitter = false;
  // The sun map this frame reads and the rows of the one it builds, each
  // around its anchor (the renderer's plan, sun_map_plan.hpp), and the slot
  // of the image's two each lies in. Unset: the whole map built around this
  // frame's camera (sunMapGeometry) into slot 0 and read, as the CPU
  // reference builds it.
  struct SunMapFrame {
    SunMapGeometry read, build;  // read.origin is cascade 0's centre
    std::array<glm::dvec3, 3> readOrigins{};  // the centres of cascades 1-3 read, local frame
    std::uint32_t readSlots = 0, buildSlots = 0;  // bit c: the image's map cascade c is read from, built into
    std::uint32_t firstCascade = 0, endCascade = 0;  // the cascades built, [first, end)
    std::uint32_t rowBegin = 0, rowEnd = 0;  // rows of those cascades built; none when equal
  };
  std::optional<SunMapFrame> sunMapPlan;
  // The lightning this frame draws (flash_setup.hpp).
  FlashSetup flashes;
};

// Haggstrom 2018's coverage ramp of the step length (sec. 4.2.2, eq. 34):
// full steps from mean coverage 0.7 up, coverageStepMin times them at 0.2 and
// below, linear between; his values, kept (he tuned multmin with them).
inline constexpr double kStepCoverageLow = 0.2;
inline constexpr double kStepCoverageHigh = 0.7;
// The exponent of his density factor 1 / max(gd, divmin)^0.8 (sec. 4.2.3,
// eq. 36): under 1, so halving the density less than doubles the steps.
inline constexpr double kStepDensityExponent = 0.8;

// The step-length factor of a layer with mean coverage `coverage` and mean
// density where covered `density` (both [0, 1]): eq. 34 times eq. 36, with
// coverageStepMin and densityStepMin in (0, 1] (MarchSettings; 1, 1: 1).
// Result in [coverageStepMin, densityStepMin^-0.8].
double stepLengthFactor(double coverage, double density, double coverageStepMin, double densityStepMin);

// A layer's mean coverage and mean density where covered, [0, 1] each.
struct LayerMeans {
  double coverage = 0;
  double density = 1;
};

// The mean coverage and the mean density where covered of a slice over the
// weather map's fine ring (the 200 km square around the anchor, a lattice
// point a few km from the camera): the density weighted by the coverage, as a
// texel's density matters to the march as much as it holds cloud. {0, 1}
// for a slice with no cloud in it. prepareFrame uses it for tiled layers
// (a uniform layer has its own coverage and density).
LayerMeans fineRingMeans(const WeatherField& field, std::uint32_t slice);

// Per layer: for a precipitation layer, the index of the layer whose cells
// drop it, the cloud layer (not fog, not precipitation) whose cloud holds
// the precipitation's top (METAR's and the console's precipitation reaches
// a few hundred metres into its carrier; metar_layers.cpp), the lowest of
// several; -1 for the others and for precipitation from no cloud.
std::vector<int> precipitationCarriers(std::span<const weather::CloudLayer> layers);

// Pixels along one edge of the image the cloud pass draws: a full edge of
// `full` pixels over the resolution divisor, rounded up (FrameSetup::width).
constexpr std::uint32_t drawnExtent(std::uint32_t full, std::uint32_t divisor) { return (full + divisor - 1) / divisor; }

// Checks settings (size, field of view) for CloudRenderer::create.
Result<void> validateSettings(const RenderSettings& settings);
// Checks a frame's inputs: finite pose, latitude range, layer count and
// fields (weather::validate), tile values and level, sun angles.
Result<void> validateInputs(const FrameInputs& inputs);

// Derives the frame; inputs must be valid and field built for this snapshot;
// tables give the sky's light.
FrameSetup prepareFrame(const RenderSettings& settings, const FrameInputs& inputs, const WeatherField& field,
                        const AtmosphereTables& tables);

// The sun map of frame `setup` built around its camera.
SunMapGeometry sunMapGeometry(const FrameSetup& setup);

// The uniform block, including the workgroup permutation for this image size.
gpu::SkyFrame packFrame(const FrameSetup& setup);

// Workgroups of the cloud pass for this image size (one per 8x8 tile).
std::uint32_t tileCount(std::uint32_t width, std::uint32_t height);

}  // namespace sky::render
