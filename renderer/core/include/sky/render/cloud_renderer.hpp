// The headless cloud renderer's public face: settings, one frame's inputs (a
// CIGI camera pose, the weather, the weather clock, the sun and the moon), the linear image
// it returns, and PNG output. The Vulkan machinery stays behind a pimpl.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/render/gpu_options.hpp"
#include "sky/weather/lightning.hpp"
#include "sky/weather/model.hpp"

namespace sky::render {

// Cloud layers one frame can draw (the shaders' kMaxLayers, checked there).
inline constexpr std::size_t kMaxLayers = 4;

// The sky and the aerial perspective from a table built once per frame
// (shaders/include/air_table.glsl; Hillaire 2020's sky-view table and
// aerial-perspective volume in one) instead of a clear-air march per pixel:
// for azimuths x zeniths directions around the camera, the air's light and
// transmittance at `slices` distances along each, with the clouds' shadow.
// Its image takes 3 x azimuths x zeniths x slices x 16 bytes (RGBA32F; 6 MiB
// at the defaults). The pixel then reads the air in front of each cloud layer
// and the ground from it; its error against the march: docs/light-transport.md.
struct AirTableSettings {
  bool enabled = true;
  std::uint32_t azimuths = 64;  // [8, 256]
  std::uint32_t zeniths = 64;   // even, [8, 256]
  std::uint32_t slices = 32;    // [4, 64] (at most 192 MiB)
};

// How a cloud sample finds the sun's optical depth above it
// (shaders/include/sun_map.glsl). March: Haggstrom's secondary march over
// the layer's light distance, lightSteps samples of the shape noise (the
// other layers' shadow from cloudShadow). Column: every layer's whole
// column above the sample marched, lightSteps samples per layer crossed,
// with the detail noise, and above the air and the ground with
// SunMapSettings::buildSteps (with many steps the ground truth of the maps).
// The maps, built once per frame in sun space over cascades around the
// camera and read by the clouds, the ground and the air (light shafts):
// Esm, Bsm, Fom (Wang's three) and Deep (the optical depth at 8 knots).
enum class SunShadow : std::uint32_t { March = 0, Column = 1, Esm = 2, Bsm = 3, Fom = 4, Deep = 5 };

// The sun-space map of SunShadow's map methods: `cascades` square grids of
// size x size texels, cascade 0 covering extent_m either side of the
// camera and each next one 4x that; each texel marches its sun line with
// buildSteps samples per layer crossed. A map is rebuilt when what it holds
// has moved, over buildFrames frames (a band of rows per frame) into a
// second map while frames read the first (renderer/core/src/sun_map_plan.hpp).
// Memory: 2 maps x size^2 x cascades x parts x 16 bytes (RGBA32F; parts: 1
// for ESM and BSM, 2 for FOM and deep), of which ESM uses 4 bytes a texel,
// BSM 12, FOM 28, deep 32.
struct SunMapSettings {
  SunShadow method = SunShadow::March;
  std::uint32_t size = 128;        // [16, 1024], a multiple of 8
  std::uint32_t cascades = 4;      // [1, 4]
  double extent_m = 4000;          // [500, 500000]
  std::uint32_t buildSteps = 16;   // [1, 256]
  std::uint32_t buildFrames = 1;   // [1, 64]: the frames a rebuild is spread over
};

// The name of a sun shadow method ("march", "column", "esm", "bsm", "fom", "deep").
const char* sunShadowName(SunShadow method);
// RGBA32F parts a cascade of the method's map takes (0: no map).
std::uint32_t sunMapParts(SunShadow method);
// The bytes the image of the two maps takes (0 without a map), and the bytes
// of it the method's values fill (ESM 4, BSM 12, FOM 28, deep 32 a texel).
std::uint64_t sunMapBytes(const SunMapSettings& map);
std::uint64_t sunMapUsedBytes(const SunMapSettings& map);

// The cloud march's cost knobs (shaders/include/cloud_core.glsl), carried
// in the frame block as run-time numbers. The defaults are the `high`
// preset's march (presets.hpp) with the secondary sun march, which `high`
// replaces with a deep shadow map.
struct MarchSettings {
  std::uint32_t primarySteps = 48;  // samples per layer span, evenly spaced, [1, 4096]
  std::uint32_t lightSteps = 4;     // samples towards the sun per lit sample, [1, 64]; [1, 1024] for
                                    // the column march (sunShadow.method Column)
  double minTransmittance = 0.01;   // stop the view ray once it keeps less, [0, 1); 0: never
  // Samples advanced after one that met no cloud: long strides through empty
  // air, single ones inside cloud. 1 marches every sample. [1, 16].
  std::uint32_t emptyStride = 1;
  // The march in metres instead of evenly placed samples (cloud_core.glsl,
  // MarchParams): cloudStep_m > 0 steps cloudStep_m inside cloud and
  // emptyStep_m (>= cloudStep_m) through clear air, judged there by the
  // cheap density (shape without the detail noise), both growing by
  // stepGrowth metres per metre of distance from the camera; primarySteps
  // then caps the samples of a layer span. cloudStep_m 0: even placement.
  double cloudStep_m = 0;  // [0, 10000]
  double emptyStep_m = 0;  // [cloudStep_m, 20000] when cloudStep_m > 0
  double stepGrowth = 0;   // [0, 1]
  // Haggstrom 2018's step lengths per layer (sec. 4.2.2-4.2.3), for the march
  // in metres only (refused with even placement: validateSettings): both
  // steps times max(m, min(1, R(gc, 0.2, 0.7, m, 1))) with m = coverageStepMin
  // (eq. 34; shorter steps where the layer's mean coverage gc is low, so
  // small clouds are not stepped over) and times 1 / max(gd, d)^0.8 with
  // d = densityStepMin (eq. 36; longer steps where its mean density gd is
  // low). gc and gd: frame_setup.cpp, layerMeans. 1 turns a factor off; he
  // found 0.4 best for both.
  double coverageStepMin = 1;  // (0, 1]
  double densityStepMin = 1;   // (0, 1]
  // Steps of the clear-air march along each view ray (aerial perspective and
  // the sky; atmosphere_core.glsl) where it is marched per pixel (without the
  // air table); 0: its default, 16. [0, 64].
  std::uint32_t airSteps = 0;
  AirTableSettings airTable;
  SunMapSettings sunShadow;
  // The clouds' shadow at the weather map's scale (cloud_core.glsl,
  // cloudShadow) in the clear-air march's sunlight (the shade under an
  // overcast, light shafts between regions of cloud) and on the clouds of
  // the layers below (cirrus over cumulus, a deck over a layer): one weather
  // lookup per layer above each air step and each cloud sample. false: only
  // the ground is shadowed.
  bool cloudShadows = true;
  // The drops or flakes within a few metres of a camera that is in
  // precipitation, drawn as the streaks their motion leaves over the
  // exposure (renderer/core/src/near_precip.hpp); false: only the
  // precipitation's medium (its extinction and light) is drawn there.
  bool nearPrecipitation = true;
  // A precipitation layer whose top is inside a cloud layer falls only
  // under that layer's cells (cloud_core.glsl's carrierFootprint: showers
  // under their cumulus); false: its shafts follow its own noise, falling
  // from the clear sky between the cells as often as under them.
  bool showersUnderCells = true;
  // Where along its first step each pixel's samples sit (a fraction of the
  // step, fixed per pixel): false, a white-noise hash of the pixel; true, a
  // 64x64 blue-noise tile repeated over the image (renderer/core/src/blue_noise.hpp),
  // so neighbouring pixels sample far apart and the march's error is noise
  // of high spatial frequency instead of clumps.
  bool blueNoise = false;
};

// Interleaved rendering with reprojection (shaders/reproject.comp,
// renderer/core/src/temporal_plan.hpp): each frame the cloud pass draws one
// pixel of every n x n block, in a fixed order that visits each pixel once
// every n^2 frames, and every other pixel comes from the previous frame
// through the camera's motion and the wind, at its cloud depth. A still view
// converges in n^2 frames to exactly the image drawn whole.
struct TemporalSettings {
  std::uint32_t interleave = 1;  // n: 1 (every pixel, no history), 2 (1 of 4) or 4 (1 of 16)
  // The history is dropped, and the frame drawn whole, when since the previous
  // frame the camera moved further than resetDistance_m (a teleport), the view
  // turned further than resetRotation_deg, the weather clock stepped further
  // than resetClockStep_s (either way), the key light turned further than
  // resetSunTurn_deg, the camera crossed a layer's base or top, or the weather
  // (layers, tiles) changed.
  double resetDistance_m = 1000;    // (0, 1e7]
  double resetRotation_deg = 30;    // (0, 180]
  double resetClockStep_s = 10;     // [0, 1e6]
  double resetSunTurn_deg = 1;      // (0, 180]
  // A history pixel is reused where its cloud depth is within this fraction
  // (plus 20 m) of where the pixel's point was; else the pixel is upscaled
  // from this frame's drawn pixels (disocclusion). (0, 1].
  double depthTolerance = 0.1;
  // Temporal accumulation: a redrawn pixel keeps this share of what the
  // history held there (where the history holds), an exponential mean over
  // its redraws; and every n^2 frames each pixel's step offset moves on by
  // the golden ratio (mod 1), so the redraws sample new places along the ray
  // and the mean tends to the march with steps many times shorter. 0: a
  // redrawn pixel is taken as drawn, and a still view converges exactly to
  // the image drawn whole. [0, 0.95]; > 0 needs interleave > 1.
  double accumulation = 0;
  // With accumulation, also jitter where in its pixel each ray goes: a 2D
  // offset in [-0.5, 0.5) pixels from the blue-noise tile (two of its
  // values, the pixel's and one 32 texels away), moved on each cycle by the
  // R2 sequence, so the redraws average over the pixel's area (anti-aliased
  // edges) instead of sampling its centre. Ignored without accumulation.
  bool pixelJitter = false;
  // Clipping of the history in motion (shaders/include/history_clip.glsl):
  // a pixel taken from the history, and the history a redraw is blended
  // with, are clipped to the box of the four pixels drawn this frame round
  // it (the corners of its cell of the interleave's grid) when the
  // history's transmittance lies outside theirs: cloud where all four show
  // sky, sky inside cloud, or the blend of both that each frame's
  // resampling makes at an edge (which, left alone, streaked along the rows
  // not drawn that frame in a banked turn; docs/motion.md). The box is their
  // mean +- this many standard deviations, within their range, in a
  // compressed YCoCg space with the transmittance; with four samples 4 is
  // their range. Not applied to a still view (the camera and every layer's
  // air unmoved), which keeps converging to the image drawn whole. 0: off.
  // [0, 4].
  double historyClip = 0;
  // A fast turn with interleave 4: when the view turned since the previous
  // frame by more than this many of the cloud pass's pixels (at the image's
  // centre, roll included), the frame draws 1 pixel of 4 per block instead
  // of 1 of 16, so what comes into view is drawn at half the spacing rather
  // than upscaled from a quarter of it; the cloud pass costs ~4x that frame.
  // 0: never. [0, 1000].
  double denseTurn_px = 2;
  // Accumulation in motion: a redrawn pixel's history share falls linearly
  // with how far its point moved in the image since the previous frame
  // (camera, parallax and wind alike), from `accumulation` at rest to half
  // of it at this many pixels and beyond: a history that was resampled, or
  // upscaled where it came into view, would otherwise hold a fresh sample
  // back for many frames (a lag that reads as ghosting). Half, not none:
  // inside a cloud the single march's noise that the mean averages away
  // costs more than the lag (docs/motion.md). 0: the share does not fall.
  // [0, 1000].
  double accumulationMotion_px = 1;
  // Fresh edges: in a turn, the bands at the image's edges that came into
  // view since the previous frame (their rays fell outside the previous
  // image) are drawn at every pixel, not upscaled from 1 pixel of each
  // block; the planner measures them each frame (shaders/include/fresh_edges.glsl).
  // Off in every preset: on the bench's camera paths they cost up to half
  // again the frame (fast turns) for at most +0.003 SSIM (docs/motion.md).
  bool freshEdges = false;
  // The history, where a pixel takes it from between the previous frame's
  // pixels, resampled with Catmull-Rom weights over 4 x 4 of them (held
  // within the four nearest) instead of bilinearly over 2 x 2: in a long
  // turn each frame resamples what the last one resampled, and bilinear
  // weights blur it a little more every time.
  bool sharpHistory = false;
  // Ground and sky have the same cloud depth (none), so the depth test alone
  // lets a pixel near the horizon take history or blend drawn pixels from
  // the other side of it, and a banked turn smears the one into the other
  // (streaks along the horizon). On: a pixel takes only what lies on its own
  // side, judged by the ground sphere along each pixel's ray (the previous
  // camera's for the history), as the upscale pass already does.
  bool horizonSides = true;
  // A change of only the weather's tiles (a region's or a station's
  // coverage ramping) keeps the history; in the cells of the image the
  // changed tiles' volume and shadow may show in (history_drop.hpp) a
  // redrawn pixel replaces its history instead of accumulating into it, so
  // the image follows the weather within one cycle of n^2 frames. A step
  // (over 16 of the map's 1/255 steps at a texel) redraws the frame whole,
  // as does every change of tiles with this off.
  bool regionDrop = true;
};

// Frames of a still view after which an interleaved renderer's history is
// full: the first, drawn whole, then one cycle of n^2 frames (with
// accumulation, enough cycles that the first frame's share of the mean is
// under 5 %: ceil(ln 0.05 / ln accumulation)); 0 without interleaving. What
// the bench renders before it times a configuration.
constexpr std::uint32_t historyWarmupFrames(const TemporalSettings& t) {
  if (t.interleave <= 1) return 0;
  std::uint32_t cycles = 1;
  for (double share = t.accumulation; share >= 0.05 && cycles < 64; share *= t.accumulation) ++cycles;
  return t.interleave * t.interleave * cycles + 1;
}

// A render-resolution scale (shaders/upscale.comp, renderer/core/src/upscale_pass.hpp):
// the cloud pass and the reprojection work on an image `divisor` times
// smaller each way, and an upscale pass brings it to the full size. The
// upscale is guided by the scene's depth at full size: each output pixel
// knows from its own ray whether it sees the ground or the sky, and takes
// only the low-resolution pixels on its side of the horizon, so the horizon
// stays sharp and sky does not bleed into the ground (or the reverse); the
// cloud depth is the nearest of those pixels' (never a blend of two depths).
struct ResolutionSettings {
  // 1 (full size), 2 or 4. The small image is the size over d rounded up;
  // its pixels are d x d pixels of the full image wherever the size is not
  // a multiple of d, the last column and row reaching past its edge.
  std::uint32_t divisor = 1;
  bool depthAware = true;     // false: plain bilinear over the four nearest pixels
};

// A view frustum by the angles of the image's four edges from the view axis,
// deg: CIGI 3.3 View Definition's half-angles, left and down negative (an
// off-axis channel of a multi-channel display has, e.g., left -10, right 50).
// Each in (-kMaxFrustumHalfAngle_deg, kMaxFrustumHalfAngle_deg), left < right,
// down < up. The rays: core_common.glsl, frustumPoint and cameraRay.
struct ViewFrustum {
  double left_deg = -30, right_deg = 30, up_deg = 30, down_deg = -30;
  bool operator==(const ViewFrustum&) const = default;
};
// Past 89 deg the tangent grows past 57 and the edge pixels' rays cover tens
// of degrees each; no display channel is that wide.
inline constexpr double kMaxFrustumHalfAngle_deg = 89;

struct RenderSettings {
  std::uint32_t width = 320, height = 180;  // pixels, [1, 8192]
  double verticalFov_deg = 60;              // (0, 179); a symmetric frustum (symmetricFrustum)
  std::uint32_t noiseSeed = 1;              // shape noise; same seed, same clouds
  // Where noise textures are cached between starts (noise_cache.hpp);
  // empty: generated at every start.
  std::string noiseCacheDir;
  MarchSettings march;
  TemporalSettings temporal;
  ResolutionSettings resolution;
};

// The symmetric frustum of the settings: verticalFov_deg up and down, the
// horizontal half-angle from it and the aspect width / height.
ViewFrustum symmetricFrustum(const RenderSettings& settings);

// A frame's exposure of lightning, s: a 30 Hz frame's (a flash's stroke
// lasts tens of milliseconds, so a frame sees it when its exposure holds it).
inline constexpr double kDefaultExposure_s = 1.0 / 30.0;

struct FrameInputs {
  geo::GeodeticPose camera;  // CIGI pose: lat/lon/alt (m above the ellipsoid, >= 0), yaw/pitch/roll deg
  const weather::WeatherSnapshot* weather = nullptr;  // layers + coverage tiles; nullptr = clear sky.
                                                      // Up to kMaxLayers layers. A layer with no
                                                      // tiles is uniform (its own coverage and
                                                      // density); with tiles, a missing cell is empty.
  // The answer to a second, wider and coarser subscription (its own
  // tileLevel). When set, the weather map's coarse ring (ring 1, 1200 km)
  // takes its tiles from it: a layer of `weather` with tiles here takes
  // them (empty where a cell has none), one without is uniform there at
  // `weather`'s own coverage and density; its tiles of layer ids `weather`
  // lacks are ignored, and its layers' own numbers are not used (the layers
  // drawn are `weather`'s, in its order). nullptr: ring 1 is filled from
  // `weather`. Ignored without `weather`.
  const weather::WeatherSnapshot* coarseWeather = nullptr;
  // The caller's version of *weather and *coarseWeather together: a value
  // seen before promises the same content as then, so the renderer reuses
  // what it derived from them (the weather map, the history's scene key)
  // without comparing tens of thousands of tiles; a new value makes it
  // compare. Unset: it compares every frame.
  std::optional<std::uint64_t> weatherVersion;
  double weatherClock_s = 0;  // clouds advect with each layer's wind by this clock
  // Lightning flashes (the server's events; kept by the caller while they
  // give light): those giving light over the exposure before weatherClock_s
  // light their clouds, the brightest cloud-to-ground one draws its channel.
  std::span<const weather::LightningFlash> flashes;
  double exposure_s = kDefaultExposure_s;
  double sunAzimuth_deg = 135, sunElevation_deg = 40;  // in the camera's local ENU frame
  // When set (UTC, s since 1970), the sun is where it is at that instant seen
  // from the camera (ephemeris.hpp), and the two angles above are ignored.
  std::optional<double> utc_s;
  // The moon, when utc_s is unset (with utc_s the ephemeris places it and
  // gives its phase): direction in the camera's local ENU frame and phase
  // angle, 0 full to 180 new. The clouds are lit by one key light: the sun,
  // or the moon when it lights the ground more (frame_setup.cpp).
  double moonAzimuth_deg = 0, moonElevation_deg = -90, moonPhaseAngle_deg = 180;
  // Sea-level visibility of the clear air (m, > 0), from a host (CIGI
  // Atmosphere Control, FlightGear): the haze of the view ray's air,
  // Koschmieder's range at 550 nm (haze.hpp). nullopt: the standard aerosol
  // (Bruneton 2017's profile, 218 km).
  std::optional<double> visibility_m;
  // This frame's view frustum (a channel's View Definition); unset: the
  // settings' symmetric one (symmetricFrustum).
  std::optional<ViewFrustum> frustum;
  // The frame's place in the interleave and accumulation cycles
  // (TemporalSettings): channels of one display that draw the same host
  // frame pass its number, so they draw the same pixels of each block with
  // the same offsets. Unset: the frames this renderer has planned so far.
  std::optional<std::uint64_t> patternIndex;
  std::uint64_t frameIndex = 0;  // the caller's frame number, for its metadata; the image does not depend on it
};

// What the reprojection did with the last frame (all zero without
// interleaving): whether the frame was drawn whole and why, and how many
// pixels were drawn, reused from the history, or upscaled from the drawn
// ones because their point was outside the previous view or the history
// there showed something else (disocclusion).
// What became of the sun map in the last frame (sun_map_plan.hpp): rebuilt
// (and why) or read as an earlier frame built it; no map: method "march" or
// "column", rebuilt false.
struct SunMapReport {
  bool rebuilt = false;  // this frame built rows of a new map
  std::string reason;    // "first frame", "weather changed", "sun turned", "clouds drifted", "camera moved", ...
  std::uint32_t rowBegin = 0, rowEnd = 0;  // the rows it built of each cascade it rebuilds
  // The cascades it rebuilds, [first, end): every one, or those the camera
  // left by a quarter of their extent (the coarse ones less often).
  std::uint32_t firstCascade = 0, endCascade = 0;
  bool completed = false;  // it built the last rows, and read the new map
};

// The precipitation near the camera in the last frame
// (MarchSettings::nearPrecipitation): what the point query answered at the
// camera, how many drops were drawn and how many reached the image.
struct NearPrecipReport {
  weather::CloudType type = weather::CloudType::None;  // None: dry at the camera, or not drawn
  double rate_mmph = 0;
  std::uint32_t drops = 0;    // in the cube round the camera
  bool capped = false;        // the rate asked for more drops, or they for more tile entries, than are drawn (near_precip.hpp)
  std::uint32_t streaks = 0;  // of them, those whose path reached the image
  std::uint32_t faint = 0;    // and those left out as too faint to change a pixel (near_precip.hpp)
  double dropArea_px2 = 0;    // their image area, sum of pi r^2
  double cameraSpeed_mps = 0; // the camera's speed the streaks were drawn with
};

struct TemporalReport {
  bool drawnWhole = false;
  std::string reason;  // why it was drawn whole ("first frame", "teleport 2.1 km", ...); empty otherwise
  // The frame's interleave: the settings', 2 in a fast turn (TemporalSettings::denseTurn_px), 1 drawn whole.
  std::uint32_t interleave = 0;
  // The fresh edges (TemporalSettings::freshEdges): the widths of the bands
  // the frame drew at every pixel at the left, right, top and bottom edges,
  // and their pixels (counted in `drawn` as well).
  std::array<std::uint32_t, 4> freshEdges{};
  std::uint64_t freshEdgePixels = 0;
  // Pixels of the image the cloud pass works on: with a resolution divisor d,
  // (width / d) x (height / d).
  std::uint64_t drawn = 0, reused = 0, offscreen = 0, disoccluded = 0;
  // The share of the image where the weather's tiles changed since the
  // previous frame (history_drop.hpp; there a redraw replaces its history
  // rather than accumulating into it), 0 without such a change.
  double weatherChangedFraction = 0;
};

// What the weather map's update did for the last frame: nothing (same
// weather, same anchor), rewrote the texels of the tiles that changed or
// came (a snapshot that differs only in tiles) and uploaded the rectangles
// around them, or rebuilt and uploaded the whole map (and why).
struct WeatherMapReport {
  bool rebuilt = false;
  std::string reason;                 // why it was rebuilt ("anchor moved", ...); empty otherwise
  std::uint64_t texelsRewritten = 0;  // RGBA8 texels written, over all rings and slices
  std::uint64_t bytesUploaded = 0;    // bytes copied into the GPU's weather image
  // With only tiles rewritten: the largest change of a texel's coverage,
  // density or blend, in the map's 1/255 steps.
  std::uint32_t largestStep = 0;
};

// Linear radiance, rgba per pixel (a = view-ray transmittance through the
// clouds), row-major, top row first; and per pixel the cloud depth: the
// distance along the view ray to where the clouds took the light out of it,
// weighted by how much they took (m; 0 where the ray met no cloud, i.e.
// a = 1). Images that are not renders (contact sheets) leave it empty.
struct Image {
  std::uint32_t width = 0, height = 0;
  std::vector<float> rgba;
  std::vector<float> cloudDepth_m;  // width * height, or empty
};

// GPU time of one pass, from timestamps written before and after its commands.
struct PassTime {
  std::string pass;   // "weather_upload", "clouds", "present", ...
  double gpu_ms = 0;  // ms
};

struct ImageStats {
  std::size_t nonFinite = 0;  // pixels with any NaN or Inf channel
  double meanLuminance = 0;   // Rec. 709 luminance of the finite pixels' rgb
};

class CloudRenderer {
 public:
  // Picks a Vulkan device with a compute queue (SKY_VULKAN_DEVICE=<substring>
  // chooses by name), loads the SPIR-V and builds the pass. Errors: Unsupported
  // when there is no Vulkan driver or device, Io when the shader is missing,
  // Device for any other Vulkan failure, InvalidArgument for bad settings.
  // `gpu` adds Khronos validation and, for a windowed front end, the window
  // surface (then present() shows frames in it).
  static Result<std::unique_ptr<CloudRenderer>> create(const RenderSettings& settings, const GpuOptions& gpu = {});

  // Renders one frame (blocking). Errors: InvalidArgument for out-of-range
  // inputs (more than kMaxLayers layers, bad pose), Device/Timeout from the GPU.
  Result<Image> render(const FrameInputs& inputs);

  // Builds every variant of the cloud pass's shaders that a frame may need
  // (with and without a wind field or a crossfade of the clouds' flow,
  // lightning, one or several layers) instead of at the first frame that
  // needs it: a live channel calls it once at start, so that a flow's first
  // crossfade or the first flash does not stall a frame (measured on
  // lavapipe: 0.45-0.55 s longer than the next frame). Returns how many it
  // built. Errors: Io/Malformed for the SPIR-V, Device from Vulkan.
  Result<std::size_t> buildAllVariants();
  // How many variants of the cloud pass's shaders are built.
  std::size_t variantsBuilt() const;

  // Shows a rendered image in the window (created with GpuOptions::window),
  // with the PNG's display transform at `exposure` (writePng). Returns false
  // when the window could not take a frame this time (minimised, being
  // resized). Errors: InvalidArgument without a window or for an image of
  // another size, Device/Timeout from the GPU.
  Result<bool> present(const Image& image, double exposure = 1.0);

  // The passes the GPU ran for the last render() (and a present() after it),
  // in submission order; empty when the device's queue has no timestamps.
  const std::vector<PassTime>& lastPassTimes() const;
  // The sun map of the last frame: rebuilt or reused.
  const SunMapReport& lastSunMap() const;
  // What the reprojection did with the last render().
  const TemporalReport& lastTemporal() const;
  // What the weather map's update did for the last render().
  const WeatherMapReport& lastWeatherMap() const;
  // The drops drawn near the camera in the last render().
  const NearPrecipReport& lastNearPrecip() const;
  // Drops the temporal history: the next render() is drawn whole, with
  // `reason` in its TemporalReport (a host's IG reset).
  void resetHistory(const std::string& reason);

  // Validation messages since the last call, and the totals (nothing
  // without GpuOptions::validation).
  std::vector<std::string> takeValidationMessages();
  ValidationCounts validationCounts();

  // How the noise textures were obtained at create(): "shape noise 64^3 seed
  // 1: loaded from <file>" (or generated, regenerated and why).
  const std::string& noiseReport() const;

  std::string deviceName() const;
  const RenderSettings& settings() const;
  // Changes the march for the frames from the next on, keeping how the
  // image is drawn (setLevel with the current temporal and resolution).
  Result<void> setMarch(const MarchSettings& march);
  // Changes how the frames from the next on are drawn (a frame budget's
  // levels, frame_budget.hpp): the march (the air table's size with it),
  // the interleave and its history, the resolution divisor. What the
  // renderer was built with stays: whether there is an air table, the sun
  // map's method and size, and the most pixels the cloud pass draws (a
  // level may divide the image further than the renderer's settings, not
  // less). The passes after the clouds for each way of drawing are built at
  // its first frame and kept. At a change of the way of drawing the history
  // carries over: copied from the last frame's image at the new way's size
  // (the upscaled image for a way at full size), or boxed down from its
  // full image for a way that draws a smaller one. After a frame that drew
  // drops near the camera over its image the next frame is drawn whole
  // (TemporalReport::reason "drawn another way, after drops near the camera").
  // Errors: InvalidArgument for settings validateSettings refuses or any of
  // those fixed ones changed; the settings are then as they were.
  Result<void> setLevel(const MarchSettings& march, const TemporalSettings& temporal,
                        const ResolutionSettings& resolution);

  CloudRenderer(CloudRenderer&&) noexcept;
  CloudRenderer& operator=(CloudRenderer&&) noexcept;
  ~CloudRenderer();

 private:
  struct Impl;
  explicit CloudRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

ImageStats computeStats(const Image& image);

// Writes an 8-bit sRGB PNG (rgb only): the radiance times `exposure` (the
// multiplier of the renderer's radiance units, > 0: displayExposure of an
// EV100, sky/render/exposure.hpp; the default, 1, is the fixed exposure the
// PNGs had before the camera's, kFixedDisplayExposure), ACES filmic tonemap
// (Narkowicz 2015 fit; curve and white point in image_output.cpp), sRGB
// transfer. Errors: InvalidArgument for an empty or inconsistent image, Io
// when the file cannot be written.
Result<void> writePng(const Image& image, const std::string& path, double exposure = 1.0);
// Writes 8-bit RGB pixels as they are (rows top to bottom, width x height x
// 3 bytes): pictures that are not radiance (a radar's false colours).
Result<void> writeRgbPng(const std::vector<std::uint8_t>& rgb, std::uint32_t width, std::uint32_t height,
                         const std::string& path);

}  // namespace sky::render
