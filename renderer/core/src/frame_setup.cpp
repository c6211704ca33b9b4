// Frame derivation in double precision (see frame_setup.hpp).
#include "frame_setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "sky/core/assert.hpp"
#include "sky/render/ephemeris.hpp"
#include "sky/render/exposure.hpp"
#include "sky/render/haze.hpp"
#include "sky/weather/advection.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/wind_field.hpp"

#include "fresh_edges.hpp"
#include "sky_light_grid.hpp"

namespace sky::render {

static_assert(kMaxLayers == gpu::kMaxLayers, "cloud_renderer.hpp and sky_shared.h disagree on the layer count");

namespace {

// Largest coverage in a slice of the weather map, over all its rings, in
// [0, 1] (0: no cloud anywhere on it, so the layer is absent from the view).
double maxCoverage(const WeatherField& field, std::uint32_t slice) {
  if (slice >= field.sliceCount) return 0.0;
  const std::size_t texels = std::size_t(field.size) * field.size;
  std::uint8_t most = 0;
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring) {
    const std::size_t first = (std::size_t(ring) * field.sliceCount + slice) * texels * 4;
    if (field.texels.size() < first + texels * 4) break;
    for (std::size_t i = 0; i < texels && most < 255; ++i) most = std::max(most, field.texels[first + i * 4]);
  }
  return most / 255.0;
}

constexpr double kDegToRad = std::numbers::pi / 180.0;
// Largest image edge, pixels: keeps buffers and the tile permutation in range.
constexpr std::uint32_t kMaxImageEdge = 8192;
// Sun irradiance at the top of the atmosphere, linear units: the unit's
// definition and its physical value are in sky/render/exposure.hpp.
constexpr double kSunIrradiance = kSunIrradiance_units;
// Secondary march towards the sun: half the layer's thickness (Haggstrom 2018
// sec. 4.2, "half the layer thickness"), at least 100 m (a thin layer's light
// still crosses a few cells' edges) and at most 2 km (4 steps of 500 m keep
// a cumulonimbus tower's self-shadowing).
constexpr double kLightMarchFraction = 0.5;
constexpr double kMinLightDistance_m = 100.0;
constexpr double kMaxLightDistance_m = 2000.0;

// Tile permutation stride as a fraction of the tile count (golden ratio
// conjugate, lavapipe.md): any stride coprime to n permutes the tiles.
constexpr double kStrideFraction = 0.618;
// (id * stride) must fit 32 bits in the shader: above this count the identity
// permutation is used.
constexpr std::uint32_t kMaxPermutedTiles = 65536;

glm::dvec3 toGlm(const geo::Vec3d& v) { return {v.x, v.y, v.z}; }

glm::dvec3 inFrame(const geo::EnuFrame& f, const geo::Vec3d& v) {
  return {geo::dot(v, f.east), geo::dot(v, f.north), geo::dot(v, f.up)};
}

std::string num(double v) { return std::to_string(v); }

}  // namespace

std::vector<int> precipitationCarriers(std::span<const weather::CloudLayer> layers) {
  std::vector<int> out(layers.size(), -1);
  for (std::size_t i = 0; i < layers.size(); ++i) {
    if (!weather::isPrecipitation(layers[i].type)) continue;
    const double top_m = layers[i].base_m + layers[i].thickness_m;
    for (std::size_t j = 0; j < layers.size(); ++j) {
      const weather::CloudLayer& c = layers[j];
      if (weather::isPrecipitation(c.type) || c.type == weather::CloudType::Fog) continue;
      if (!(c.base_m < top_m && top_m <= c.base_m + c.thickness_m)) continue;
      if (out[i] < 0 || c.base_m < layers[std::size_t(out[i])].base_m) out[i] = int(j);
    }
  }
  return out;
}

LayerMeans fineRingMeans(const WeatherField& field, std::uint32_t slice) {
  if (slice >= field.sliceCount) return {0.0, 1.0};
  const std::size_t texels = std::size_t(field.size) * field.size;
  const std::size_t first = std::size_t(slice) * texels * 4;  // ring 0
  if (field.texels.size() < first + texels * 4) return {0.0, 1.0};
  std::uint64_t coverageSum = 0, coveredDensitySum = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    const std::uint64_t c = field.texels[first + i * 4], d = field.texels[first + i * 4 + 1];
    coverageSum += c;
    coveredDensitySum += c * d;
  }
  if (coverageSum == 0) return {0.0, 1.0};
  return {double(coverageSum) / (255.0 * double(texels)), double(coveredDensitySum) / (255.0 * double(coverageSum))};
}

double stepLengthFactor(double coverage, double density, double coverageStepMin, double densityStepMin) {
  // Eq. 34: the linear remap R(gc, 0.2, 0.7, multmin, 1), clamped to [multmin, 1].
  const double ramp = coverageStepMin + (coverage - kStepCoverageLow) / (kStepCoverageHigh - kStepCoverageLow) *
                                            (1.0 - coverageStepMin);
  const double coverageFactor = std::max(coverageStepMin, std::min(1.0, ramp));
  // Eq. 36.
  const double densityFactor = 1.0 / std::pow(std::max(density, densityStepMin), kStepDensityExponent);
  return coverageFactor * densityFactor;
}

std::uint32_t tileCount(std::uint32_t width, std::uint32_t height) {
  const std::uint32_t tx = (width + gpu::kLocalSize - 1) / gpu::kLocalSize;
  const std::uint32_t ty = (height + gpu::kLocalSize - 1) / gpu::kLocalSize;
  return tx * ty;
}

Result<void> validateSettings(const RenderSettings& s) {
  if (s.width == 0 || s.height == 0 || s.width > kMaxImageEdge || s.height > kMaxImageEdge)
    return fail(ErrorCode::InvalidArgument, "render settings: size " + std::to_string(s.width) + "x" +
                                                std::to_string(s.height) + " outside [1, 8192]");
  if (!(s.verticalFov_deg > 0 && s.verticalFov_deg < 179))
    return fail(ErrorCode::InvalidArgument,
                "render settings: verticalFov_deg " + num(s.verticalFov_deg) + " outside (0, 179)");
  const MarchSettings& m = s.march;
  if (m.primarySteps < 1 || m.primarySteps > 4096)
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.primarySteps " + std::to_string(m.primarySteps) + " outside [1, 4096]");
  if (m.lightSteps < 1 || (m.lightSteps > 64 && m.sunShadow.method != SunShadow::Column))
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.lightSteps " + std::to_string(m.lightSteps) + " outside [1, 64]");
  if (!(m.minTransmittance >= 0 && m.minTransmittance < 1))
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.minTransmittance " + num(m.minTransmittance) + " outside [0, 1)");
  if (m.emptyStride < 1 || m.emptyStride > 16)
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.emptyStride " + std::to_string(m.emptyStride) + " outside [1, 16]");
  if (!(m.cloudStep_m >= 0 && m.cloudStep_m <= 10000))
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.cloudStep_m " + num(m.cloudStep_m) + " outside [0, 10000]");
  if (m.cloudStep_m > 0 && !(m.emptyStep_m >= m.cloudStep_m && m.emptyStep_m <= 20000))
    return fail(ErrorCode::InvalidArgument, "render settings: march.emptyStep_m " + num(m.emptyStep_m) +
                                                " outside [cloudStep_m = " + num(m.cloudStep_m) + ", 20000]");
  if (m.airSteps > 64)
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.airSteps " + std::to_string(m.airSteps) + " outside [0, 64]");
  if (m.airTable.enabled &&
      (m.airTable.azimuths < 8 || m.airTable.azimuths > 256 || m.airTable.zeniths < 8 ||
       m.airTable.zeniths > 256 || m.airTable.zeniths % 2 != 0 || m.airTable.slices < 4 || m.airTable.slices > 64))
    return fail(ErrorCode::InvalidArgument, "render settings: march.airTable " + std::to_string(m.airTable.azimuths) +
                                                "x" + std::to_string(m.airTable.zeniths) + "x" +
                                                std::to_string(m.airTable.slices) +
                                                " outside azimuths [8, 256] x zeniths [8, 256] (even) x slices [4, 64]");
  const SunMapSettings& sun = m.sunShadow;
  if (std::uint32_t(sun.method) > std::uint32_t(SunShadow::Deep))
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.sunShadow.method " + std::to_string(std::uint32_t(sun.method)) + " outside [0, 5]");
  if (sun.method == SunShadow::Column && m.lightSteps > 1024)
    return fail(ErrorCode::InvalidArgument, "render settings: march.lightSteps " + std::to_string(m.lightSteps) +
                                                " outside [1, 1024] for the column march");
  if (sun.size < 16 || sun.size > 1024 || sun.size % 8 != 0 || sun.cascades < 1 || sun.cascades > 4 ||
      !(sun.extent_m >= 500 && sun.extent_m <= 500000) || sun.buildSteps < 1 || sun.buildSteps > 256 ||
      sun.buildFrames < 1 || sun.buildFrames > 64)
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.sunShadow size " + std::to_string(sun.size) + ", cascades " +
                    std::to_string(sun.cascades) + ", extent_m " + num(sun.extent_m) + ", buildSteps " +
                    std::to_string(sun.buildSteps) + ", buildFrames " + std::to_string(sun.buildFrames) +
                    " outside size [16, 1024] (a multiple of 8), cascades [1, 4], extent_m [500, 500000], "
                    "buildSteps [1, 256], buildFrames [1, 64]");
  if (!(m.stepGrowth >= 0 && m.stepGrowth <= 1))
    return fail(ErrorCode::InvalidArgument,
                "render settings: march.stepGrowth " + num(m.stepGrowth) + " outside [0, 1]");
  for (const auto& [field, v] :
       {std::pair{"coverageStepMin", m.coverageStepMin}, std::pair{"densityStepMin", m.densityStepMin}}) {
    if (!(v > 0 && v <= 1))
      return fail(ErrorCode::InvalidArgument,
                  std::string("render settings: march.") + field + " " + num(v) + " outside (0, 1]");
    if (v != 1 && m.cloudStep_m == 0)
      return fail(ErrorCode::InvalidArgument, std::string("render settings: march.") + field + " " + num(v) +
                                                  " scales the march in metres; even placement (cloudStep_m 0) has no "
                                                  "step length to scale");
  }
  const std::uint32_t d = s.resolution.divisor;
  if (d != 1 && d != 2 && d != 4)
    return fail(ErrorCode::InvalidArgument,
                "render settings: resolution.divisor " + std::to_string(d) + " is not 1, 2 or 4");
  const TemporalSettings& t = s.temporal;
  if (t.interleave != 1 && t.interleave != 2 && t.interleave != 4)
    return fail(ErrorCode::InvalidArgument,
                "render settings: temporal.interleave " + std::to_string(t.interleave) + " is not 1, 2 or 4");
  auto range = [](const char* field, double v, double lo, double hi, bool openLow) -> Result<void> {
    if (std::isfinite(v) && (openLow ? v > lo : v >= lo) && v <= hi) return {};
    return fail(ErrorCode::InvalidArgument, std::string("render settings: temporal.") + field + " " + num(v) +
                                                " outside " + (openLow ? "(" : "[") + num(lo) + ", " + num(hi) + "]");
  };
  for (auto ok : {range("resetDistance_m", t.resetDistance_m, 0, 1e7, true),
                  range("resetRotation_deg", t.resetRotation_deg, 0, 180, true),
                  range("resetClockStep_s", t.resetClockStep_s, 0, 1e6, false),
                  range("resetSunTurn_deg", t.resetSunTurn_deg, 0, 180, true),
                  range("depthTolerance", t.depthTolerance, 0, 1, true),
                  range("accumulation", t.accumulation, 0, 0.95, false),
                  range("historyClip", t.historyClip, 0, 4, false),
                  range("denseTurn_px", t.denseTurn_px, 0, 1000, false),
                  range("accumulationMotion_px", t.accumulationMotion_px, 0, 1000, false)})
    if (!ok) return ok;
  if (t.accumulation > 0 && t.interleave == 1)
    return fail(ErrorCode::InvalidArgument,
                "render settings: temporal.accumulation " + num(t.accumulation) + " needs temporal.interleave > 1");
  return {};
}

namespace {

// A snapshot's layers (count and fields), tile level and tile values. The
// error names the input by `which` ("" for `weather`, whose messages have
// always been unnamed; "coarseWeather: ").
Result<void> validateSnapshot(const weather::WeatherSnapshot& w, const std::string& which) {
  const std::string where = "frame inputs: " + which;
  if (w.layers.size() > gpu::kMaxLayers)
    return fail(ErrorCode::InvalidArgument, where + std::to_string(w.layers.size()) + " cloud layers, at most " +
                                                std::to_string(gpu::kMaxLayers));
  for (const auto& layer : w.layers)
    if (auto ok = weather::validate(layer); !ok)
      return fail(ErrorCode::InvalidArgument, which + ok.error().detail);
  if (w.tileLevel < 0 || w.tileLevel > 30)
    return fail(ErrorCode::InvalidArgument, where + "tileLevel " + std::to_string(w.tileLevel) + " outside [0, 30]");
  for (const auto& t : w.tiles)
    if (!(t.coverage >= 0 && t.coverage <= 1 && t.density >= 0 && t.density <= 1))
      return fail(ErrorCode::InvalidArgument,
                  where + "tile " + std::to_string(t.cellId) + " coverage/density outside [0, 1]");
  return {};
}

}  // namespace

ViewFrustum symmetricFrustum(const RenderSettings& settings) {
  const double halfV_deg = 0.5 * settings.verticalFov_deg;
  const double aspect = double(settings.width) / double(settings.height);
  const double halfH_deg = std::atan(std::tan(halfV_deg * kDegToRad) * aspect) / kDegToRad;
  return {-halfH_deg, halfH_deg, halfV_deg, -halfV_deg};
}

namespace {

Result<void> validateFrustum(const ViewFrustum& f) {
  for (double a : {f.left_deg, f.right_deg, f.up_deg, f.down_deg})
    if (!(std::abs(a) < kMaxFrustumHalfAngle_deg))
      return fail(ErrorCode::InvalidArgument, "frame inputs: frustum half-angle " + num(a) + " deg outside (-" +
                                                  num(kMaxFrustumHalfAngle_deg) + ", " +
                                                  num(kMaxFrustumHalfAngle_deg) + ")");
  if (!(f.left_deg < f.right_deg) || !(f.down_deg < f.up_deg))
    return fail(ErrorCode::InvalidArgument, "frame inputs: frustum left " + num(f.left_deg) + " right " +
                                                num(f.right_deg) + " up " + num(f.up_deg) + " down " +
                                                num(f.down_deg) + " deg: needs left < right and down < up");
  return {};
}

}  // namespace

Result<void> validateInputs(const FrameInputs& in) {
  const auto& c = in.camera;
  const auto& p = c.position;
  for (double v : {p.lat_deg, p.lon_deg, p.alt_m, c.yaw_deg, c.pitch_deg, c.roll_deg, in.weatherClock_s,
                   in.sunAzimuth_deg, in.sunElevation_deg, in.utc_s.value_or(0.0), in.moonAzimuth_deg,
                   in.moonElevation_deg, in.moonPhaseAngle_deg, in.visibility_m.value_or(1.0)})
    if (!std::isfinite(v)) return fail(ErrorCode::InvalidArgument, "frame inputs: non-finite value");
  if (in.visibility_m && !(*in.visibility_m > 0))
    return fail(ErrorCode::InvalidArgument, "frame inputs: visibility_m " + num(*in.visibility_m) + " is not > 0");
  if (in.moonPhaseAngle_deg < 0 || in.moonPhaseAngle_deg > 180)
    return fail(ErrorCode::InvalidArgument,
                "frame inputs: moonPhaseAngle_deg " + num(in.moonPhaseAngle_deg) + " outside [0, 180]");
  if (p.lat_deg < -90 || p.lat_deg > 90)
    return fail(ErrorCode::InvalidArgument, "frame inputs: camera lat_deg " + num(p.lat_deg) + " outside [-90, 90]");
  if (p.alt_m < -1000 || p.alt_m > 1e6)
    return fail(ErrorCode::InvalidArgument, "frame inputs: camera alt_m " + num(p.alt_m) + " outside [-1000, 1e6]");
  if (in.frustum)
    if (auto ok = validateFrustum(*in.frustum); !ok) return ok;
  if (in.weather == nullptr) return {};
  if (auto ok = validateSnapshot(*in.weather, ""); !ok) return ok;
  if (in.coarseWeather != nullptr)
    if (auto ok = validateSnapshot(*in.coarseWeather, "coarseWeather: "); !ok) return ok;
  return {};
}

glm::dvec3 windFlowPhases(double weatherClock_s) {
  const double period = kWindFlowPeriod_s;
  auto age = [&](double t) {
    const double m = std::fmod(t, period);
    return m < 0 ? m + period : m;
  };
  const double a = age(weatherClock_s), b = age(weatherClock_s + period / 2);
  // Phase A's weight: 0 at its reset (age 0), 1 from a quarter period on
  // until the crossfade before its next reset; B's is the rest, and B resets
  // at A's half period, where B weighs nothing.
  const double u = std::min(a, period - a) / period;  // [0, 0.5]
  const double x = std::clamp((u - (0.25 - kWindFlowCrossfade)) / (2 * kWindFlowCrossfade), 0.0, 1.0);
  return {a, b, x * x * (3 - 2 * x)};
}

FrameSetup prepareFrame(const RenderSettings& settings, const FrameInputs& in, const WeatherField& field,
                        const AtmosphereTables& tables) {
  FrameSetup s;
  const std::uint32_t d = settings.resolution.divisor;
  s.width = drawnExtent(settings.width, d);
  s.height = drawnExtent(settings.height, d);
  s.rasterWidth = double(settings.width) / d;
  s.rasterHeight = double(settings.height) / d;
  const ViewFrustum frustum = in.frustum.value_or(symmetricFrustum(settings));
  s.frustum = {std::tan(frustum.left_deg * kDegToRad), std::tan(frustum.right_deg * kDegToRad),
               std::tan(frustum.up_deg * kDegToRad), std::tan(frustum.down_deg * kDegToRad)};
  s.march = settings.march;

  const geo::EnuFrame enu = geo::enuFrameAt(in.camera.position);
  const geo::BodyAxes axes = geo::bodyAxes(in.camera);
  s.camForward = inFrame(enu, axes.forward);
  s.camRight = inFrame(enu, axes.right);
  s.camDown = inFrame(enu, axes.down);
  s.localToEcef = glm::dmat3(toGlm(enu.east), toGlm(enu.north), toGlm(enu.up));
  s.cameraEcef_m = toGlm(enu.originEcef_m);
  // A pixel's angle at the image's centre, for the width a bolt is drawn at.
  s.flashes = prepareFlashes(in.flashes, in.weatherClock_s, in.exposure_s, enu,
                             (s.frustum.y - s.frustum.x) / std::max(s.rasterWidth, 1.0));

  const geo::EnuFrame& a = field.frame;
  s.camToAnchor = glm::dmat3(inFrame(a, enu.east), inFrame(a, enu.north), inFrame(a, enu.up));
  s.camInAnchor_m = inFrame(a, enu.originEcef_m - field.centreEcef_m);
  s.anchorRadius_m = field.radius_m;
  s.mapHalfExtent_m = field.halfExtent_m[0];
  s.coarseHalfExtent_m = field.halfExtent_m[1];

  // The local sphere: centre below the camera along its up vector, radius
  // |camera ECEF|, so R_local = r - alt and heights above it are altitudes.
  const double alt_m = in.camera.position.alt_m;
  s.r_m = geo::length(enu.originEcef_m);
  // The ground is mean sea level (no terrain yet); a camera below it (the
  // Dead Sea shore at -430 m) stands on the ground instead of under it.
  s.hGround_m = std::max(alt_m, 0.0);
  s.cGround_m2 = s.hGround_m * (2 * s.r_m - s.hGround_m);
  const double hAboveTop_m = s.hGround_m - atmosphereHeight_m();
  s.cAtmosphereTop_m2 = hAboveTop_m * (2 * s.r_m - hAboveTop_m);
  const double groundRadius_m = s.r_m - s.hGround_m;

  SkyDirection sun{in.sunAzimuth_deg, in.sunElevation_deg}, moon{in.moonAzimuth_deg, in.moonElevation_deg};
  double moonPhase_deg = in.moonPhaseAngle_deg;
  if (in.utc_s) {
    const double lat = in.camera.position.lat_deg, lon = in.camera.position.lon_deg;
    sun = sunDirection(*in.utc_s, lat, lon);
    moon = moonDirection(*in.utc_s, lat, lon);
    moonPhase_deg = moonPhaseAngle_deg(*in.utc_s);
  }
  auto towards = [](const SkyDirection& d) {
    const double az = d.azimuth_deg * kDegToRad, el = d.elevation_deg * kDegToRad;
    return glm::dvec3(std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el));
  };
  s.sunDir = towards(sun);
  s.sunIrradiance = glm::dvec3(kSunIrradiance);
  s.groundIrradiance = skyLight(tables, 0.0, groundRadius_m, s.sunDir, s.sunIrradiance).irradiance;
  // One key light for the clouds, the air and the ground: the moon instead
  // of the sun when it puts more light on the ground (direct and through the
  // sky, by luminance): with a full moon from about the end of nautical
  // twilight. Its light is the sun's spectrum scaled by the illuminance
  // ratio of its phase (the moon's albedo is nearly grey; ~10 % redder,
  // ignored); twilight's glow goes when the moon takes over.
  if (sun.elevation_deg < 0 && moon.elevation_deg > -1) {
    const glm::dvec3 moonDir = towards(moon);
    const glm::dvec3 moonIrradiance(kSunIrradiance * moonToSunIlluminance(moonPhase_deg));
    const glm::dvec3 moonSky = skyLight(tables, 0.0, groundRadius_m, moonDir, moonIrradiance).irradiance;
    auto onGround = [&](const glm::dvec3& dir, const glm::dvec3& e, const glm::dvec3& sky) {
      const glm::dvec3 v = e * sunTransmittanceAt(tables, 0.0, dir.z, groundRadius_m) * std::max(dir.z, 0.0) + sky;
      return 0.2126 * v.r + 0.7152 * v.g + 0.0722 * v.b;
    };
    if (onGround(moonDir, moonIrradiance, moonSky) > onGround(s.sunDir, s.sunIrradiance, s.groundIrradiance)) {
      s.sunDir = moonDir;
      s.sunIrradiance = moonIrradiance;
      s.groundIrradiance = moonSky;
      s.moonLit = true;
    }
  }

  if (in.visibility_m) s.aerosolExcess = aerosolExcessForVisibility(*in.visibility_m);

  if (in.weather == nullptr) return s;
  const double sinceSnapshot_s = in.weatherClock_s - in.weather->weatherClock_s;
  const glm::dvec3 flow = windFlowPhases(in.weatherClock_s);
  // Indexed only when a layer's wind varies (thousands of tiles, each frame).
  const bool anyField = std::any_of(field.windVaries.begin(), field.windVaries.end(), [](bool v) { return v; });
  const weather::WindField wind = anyField ? weather::WindField(*in.weather) : weather::WindField();
  for (std::size_t slice = 0; slice < in.weather->layers.size(); ++slice) {
    const weather::CloudLayer& layer = in.weather->layers[slice];
    LayerSetup l;
    // The shell: the cloud and its transition band, which the point query's
    // answers fade the cloud over as well (layerPresence).
    const double band_m = std::max(layer.transitionBand_m, 0.0);
    const double shellBase_m = layer.base_m - band_m;
    l.thickness_m = layer.thickness_m + 2 * band_m;
    l.band = band_m / l.thickness_m;
    l.absent = maxCoverage(field, std::uint32_t(slice)) <= 0;
    // A uniform layer's own numbers; a tiled one's means over the fine ring
    // (a pass over the map, skipped when both factors are off: then it is 1).
    const MarchSettings& m = settings.march;
    if (m.coverageStepMin != 1 || m.densityStepMin != 1) {
      const LayerMeans means = field.tiled[slice] ? fineRingMeans(field, std::uint32_t(slice))
                                                  : LayerMeans{layer.coverage, layer.density};
      l.stepFactor = stepLengthFactor(means.coverage, means.density, m.coverageStepMin, m.densityStepMin);
    }
    l.lightDistance_m = std::clamp(kLightMarchFraction * layer.thickness_m, kMinLightDistance_m, kMaxLightDistance_m);
    l.primary = cloudTypeParams(layer.type);
    l.blends = field.blendType[slice] != weather::CloudType::None;
    l.secondary = l.blends ? cloudTypeParams(field.blendType[slice]) : l.primary;
    l.shapePeriod_m = l.primary.shapePeriod_m;
    l.detailPeriod_m = l.primary.detailPeriod_m;
    l.cloudMapPeriod_m = kCloudMapPeriodFactor * l.primary.shapePeriod_m;
    l.shapeStretchZ = 1.0 / l.primary.streak;
    // The diffuse light the layer's top receives, over the camera: the sky,
    // and the sun through the air (cloud_core.glsl's diffuseLight).
    const double top_m = std::max(shellBase_m + l.thickness_m, 0.0);
    l.skyTop = skyLight(tables, top_m, groundRadius_m, s.sunDir, s.sunIrradiance).meanRadiance;
    l.sunCosine = std::max(s.sunDir.z, 0.0);
    l.sunDiffuseTop = s.sunIrradiance * sunTransmittanceAt(tables, top_m, s.sunDir.z, groundRadius_m) *
                      (l.sunCosine / std::numbers::pi);
    l.hBase_m = alt_m - shellBase_m;
    l.hTop_m = alt_m - (shellBase_m + l.thickness_m);
    l.cBase_m2 = l.hBase_m * (2 * s.r_m - l.hBase_m);
    l.cTop_m2 = l.hTop_m * (2 * s.r_m - l.hTop_m);
    const weather::WindVector own = weather::toVector(layer.wind);
    const glm::dvec3 windEnu_mps(own.east_mps, own.north_mps, own.up_mps);
    // Earth-fixed noise that drifts with the wind: sampled at (x - wind t),
    // with t a flow phase's age (at most kWindFlowPeriod_s), not the weather
    // clock. The drift is along the wind at the camera, in the camera's
    // frame, which turns as the camera travels (the east by the longitude
    // flown, ~1 degree per 100 km): a drift of the whole clock would slide
    // the noise under a moving camera by the clock's drift times that angle
    // (after a day of a 10 m/s wind, 196 m per km flown east), the phases'
    // by at most 0.94 m (NoiseDrift test). Every layer with a wind flows,
    // phase to phase across the crossfade (cloud_core.glsl's cloudSample);
    // one whose wind varies over the map flows by the local wind, and its
    // tiles drift by their own (sampleWeather).
    l.windEnu_mps = windEnu_mps;
    l.windAtCamera_mps = windEnu_mps;
    // How long the layer's tiles have moved with the wind since the
    // snapshot: its age where they drift (a drifting region's), none where
    // the server holds them in place (CloudLayer::tilesDrift).
    const double tileAge_s = layer.tilesDrift ? sinceSnapshot_s : 0.0;
    l.windRef = glm::dvec4(windEnu_mps, tileAge_s);
    const bool flows = field.windVaries[slice] || glm::length(windEnu_mps) > 0;
    l.flow = flows ? glm::dvec4(flow.x, flow.y, flow.z, field.windVaries[slice] ? 1.0 : 0.0)
                   : glm::dvec4(0.0, 0.0, 1.0, 0.0);  // still air: phase A alone, never shifted
    if (field.windVaries[slice]) {
      const weather::WindVector here =
          wind.at(layer, in.camera.position.lat_deg, in.camera.position.lon_deg);
      l.windAtCamera_mps = glm::dvec3(here.east_mps, here.north_mps, here.up_mps);
    }
    const glm::dvec3 origin = toGlm(enu.originEcef_m);
    auto inPeriods = [&](double period_m, double stretchZ) {
      glm::dvec3 out;
      for (int k = 0; k < 3; ++k) {
        const double m = std::fmod(origin[k] * (k == 2 ? stretchZ : 1.0), period_m);
        out[k] = (m < 0 ? m + period_m : m) / period_m;
      }
      return out;
    };
    // Streaky types stretch the shape noise along the Earth's axis: a fixed
    // ECEF axis keeps the pattern Earth-fixed (a stretch along the local wind
    // would turn with the camera's position and slide the clouds). Streaks
    // run north-south, foreshortened towards the poles, where they end as
    // plain fibres.
    l.shapeOrigin = inPeriods(l.shapePeriod_m, l.shapeStretchZ);
    l.detailOrigin = inPeriods(l.detailPeriod_m, 1.0);
    l.cloudMapOrigin = inPeriods(l.cloudMapPeriod_m, 1.0);
    // The coverage tiles are the server's field at the snapshot's clock.
    // Where they drift, the air over the camera now was, then, where the
    // shared advection formula (weather::upwindOf, with the wind over the
    // camera) says: the map is sampled that far upwind, east/north of the
    // camera's frame, as one shift (at 100 km from the camera it parts from
    // each point's own upwind by about 1.6 % of the drift: TileDrift test);
    // where the server holds them, not at all. A layer
    // whose wind varies reads each point's own (sampleWeather), and this
    // shift only places its changed tiles for the history (history_drop).
    const weather::SurfacePoint upwind = weather::upwindOf(
        {in.camera.position.lat_deg, in.camera.position.lon_deg},
        {l.windAtCamera_mps.x, l.windAtCamera_mps.y, l.windAtCamera_mps.z}, tileAge_s);
    const geo::Vec3d upwindEcef = geo::toEcef({upwind.lat_deg, upwind.lon_deg, alt_m});
    const glm::dvec3 drift = inFrame(enu, enu.originEcef_m - upwindEcef);
    // A uniform layer is the same everywhere: it does not drift off the map
    // (an hour-old snapshot in a 150 m/s wind would otherwise be 540 km away,
    // past the map's 100 km, and empty).
    l.coverageShift_m = field.tiled[slice] ? glm::dvec2(drift.x, drift.y) : glm::dvec2(0.0);
    s.layers.push_back(l);
  }
  if (settings.march.showersUnderCells) {
    const std::vector<int> carriers = precipitationCarriers(in.weather->layers);
    for (std::size_t i = 0; i < s.layers.size(); ++i) {
      const int c = carriers[i];
      s.layers[i].carrier = c >= 0 && !s.layers[std::size_t(c)].absent ? c : -1;
    }
  }
  return s;
}

SunMapGeometry sunMapGeometry(const FrameSetup& s) {
  SunMapGeometry g;
  // Any axis across the sun: from the local up, or east with the sun overhead.
  const glm::dvec3 across = std::abs(s.sunDir.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
  g.axisU = glm::normalize(glm::cross(across, s.sunDir));
  g.axisV = glm::cross(s.sunDir, g.axisU);
  bool any = false;
  for (const LayerSetup& l : s.layers) {
    if (l.absent) continue;
    const double top = s.hGround_m - l.hTop_m, base = s.hGround_m - l.hBase_m;
    g.top_m = any ? std::max(g.top_m, top) : top;
    g.base_m = any ? std::min(g.base_m, base) : base;
    any = true;
  }
  return g;
}

const char* sunShadowName(SunShadow method) {
  switch (method) {
    case SunShadow::March: return "march";
    case SunShadow::Column: return "column";
    case SunShadow::Esm: return "esm";
    case SunShadow::Bsm: return "bsm";
    case SunShadow::Fom: return "fom";
    case SunShadow::Deep: return "deep";
  }
  return "?";
}

std::uint32_t sunMapParts(SunShadow method) {
  return method == SunShadow::Fom || method == SunShadow::Deep ? 2 : (method >= SunShadow::Esm ? 1 : 0);
}

std::uint64_t sunMapBytes(const SunMapSettings& map) {
  return 2 * std::uint64_t(map.size) * map.size * map.cascades * sunMapParts(map.method) * 16;
}

std::uint64_t sunMapUsedBytes(const SunMapSettings& map) {
  const std::uint64_t perTexel = map.method == SunShadow::Esm   ? 4
                                 : map.method == SunShadow::Bsm ? 12
                                 : map.method == SunShadow::Fom ? 28
                                 : map.method == SunShadow::Deep ? 32
                                                                 : 0;
  return 2 * std::uint64_t(map.size) * map.size * map.cascades * perTexel;
}

gpu::SkyFrame packFrame(const FrameSetup& s) {
  SKY_ASSERT(s.layers.size() <= gpu::kMaxLayers);
  gpu::SkyFrame f{};
  auto v4 = [](const glm::dvec3& v, double w = 0) { return gpu::vec4(glm::dvec4(v, w)); };
  f.camForward = v4(s.camForward);
  f.camRight = v4(s.camRight);
  f.camDown = v4(s.camDown);
  f.frustum = gpu::vec4(s.frustum);
  for (int row = 0; row < 3; ++row) {
    f.localToEcef[row] = v4(glm::dvec3(s.localToEcef[0][row], s.localToEcef[1][row], s.localToEcef[2][row]));
    f.camToAnchor[row] = v4(glm::dvec3(s.camToAnchor[0][row], s.camToAnchor[1][row], s.camToAnchor[2][row]));
  }
  f.camInAnchor = v4(s.camInAnchor_m, s.anchorRadius_m);
  f.weatherMap = gpu::vec4(float(1.0 / (2 * s.mapHalfExtent_m)), float(s.layers.size()),
                             float(s.march.minTransmittance), float(s.march.emptyStride));
  f.weatherRings = gpu::vec4(float(1.0 / (2 * s.coarseHalfExtent_m)), float(kRingBlendStart), float(kRingBlendEnd), 0.0f);
  f.earth = gpu::vec4(float(s.r_m), float(s.hGround_m), float(s.cGround_m2), float(s.cAtmosphereTop_m2));
  f.sunDir = v4(s.sunDir, s.aerosolExcess);
  f.sunIrradiance = v4(s.sunIrradiance, s.march.cloudShadows ? 1.0 : 0.0);
  f.groundIrradiance = v4(s.groundIrradiance);

  // The tiles cover the packed image of the pixels this frame draws.
  SKY_ASSERT(s.interleave >= 1 && s.phase.x < s.interleave && s.phase.y < s.interleave);
  const std::uint32_t packedW = (s.width + s.interleave - 1) / s.interleave;
  const std::uint32_t packedH = (s.height + s.interleave - 1) / s.interleave;
  const std::uint32_t tilesX = (packedW + gpu::kLocalSize - 1) / gpu::kLocalSize;
  // The fresh edges' samples follow, kLocalSize^2 to a tile.
  SKY_ASSERT(s.interleave > 1 || s.freshEdges == glm::uvec4(0));
  const std::uint32_t packedTiles = tileCount(packedW, packedH);
  const std::uint32_t edgePixels = FreshEdges{}.freshEdgeCount(s.freshEdges, glm::uvec2(s.width, s.height));
  SKY_ASSERT(edgePixels <= packedW * (s.height - packedH) || edgePixels == 0);
  const std::uint32_t tileArea = gpu::kLocalSize * gpu::kLocalSize;
  const std::uint32_t n = packedTiles + (edgePixels + tileArea - 1) / tileArea;
  std::uint32_t stride = 1;
  if (n < kMaxPermutedTiles) {
    stride = std::max<std::uint32_t>(1, std::uint32_t(std::lround(kStrideFraction * n)));
    while (std::gcd(stride, n) != 1) ++stride;
  }
  f.image = gpu::uvec4(s.width, s.height, tilesX, n);
  f.dispatch = gpu::uvec4(stride, s.march.primarySteps, s.march.lightSteps, s.march.airSteps);
  f.steps = gpu::vec4(float(s.march.cloudStep_m), float(s.march.emptyStep_m), float(s.march.stepGrowth),
                      s.march.blueNoise ? 1.0f : 0.0f);
  f.interleave = gpu::uvec4(s.interleave, s.phase.x, s.phase.y, packedTiles);
  f.freshEdges = gpu::uvec4(s.freshEdges);
  f.raster = gpu::vec4(float(s.rasterWidth), float(s.rasterHeight), float(s.jitterShift), 0.0f);
  f.pixelJitter = gpu::vec4(float(s.pixelShift.x), float(s.pixelShift.y), s.pixelJitter ? 1.0f : 0.0f, 0.0f);
  const AirTableSettings& table = s.march.airTable;
  f.airTable = table.enabled ? gpu::uvec4(table.azimuths, table.zeniths, table.slices, 0u) : gpu::uvec4(0u);
  const SunMapSettings& sun = s.march.sunShadow;
  FrameSetup::SunMapFrame plan;
  if (s.sunMapPlan) {
    plan = *s.sunMapPlan;
  } else {
    plan.read = plan.build = sunMapGeometry(s);
    plan.endCascade = sun.cascades;
    plan.rowEnd = sun.size;
  }
  const SunMapGeometry& g = plan.read;
  f.sunMap = gpu::uvec4(std::uint32_t(sun.method), sun.size, sun.cascades, sun.buildSteps);
  f.sunMapU = v4(g.axisU, sun.extent_m);
  f.sunMapV = v4(g.axisV, 0.0);
  f.sunMapShells = gpu::vec4(float(g.top_m), float(g.base_m), 0.0f, 0.0f);
  f.sunMapOrigin = v4(g.origin);
  for (std::size_t c = 0; c < plan.readOrigins.size(); ++c) f.sunMapOrigins[c] = v4(plan.readOrigins[c]);
  f.sunMapSlots = gpu::uvec4(plan.readSlots, plan.buildSlots, plan.firstCascade, plan.endCascade);
  const SunMapGeometry& b = plan.build;
  f.sunBuildU = v4(b.axisU, 0.0);
  f.sunBuildV = v4(b.axisV, 0.0);
  f.sunBuildShells = gpu::vec4(float(b.top_m), float(b.base_m), float(plan.rowBegin), float(plan.rowEnd));
  f.sunBuildOrigin = v4(b.origin);
  const FlashSetup& fl = s.flashes;
  SKY_ASSERT(fl.lights.size() <= gpu::kMaxFrameFlashes && fl.boltStart.size() <= gpu::kMaxFrameBoltSegments &&
             fl.boltEnd.size() == fl.boltStart.size());
  f.flashInfo = gpu::vec4(float(fl.lights.size()), float(fl.boltStart.size()), float(fl.pixelAngle_rad), 0.0f);
  for (std::size_t k = 0; k < fl.lights.size(); ++k) f.flashes[k] = gpu::vec4(fl.lights[k]);
  for (std::size_t k = 0; k < fl.boltStart.size(); ++k) {
    f.boltStart[k] = gpu::vec4(fl.boltStart[k]);
    f.boltEnd[k] = v4(fl.boltEnd[k]);
  }

  for (std::size_t i = 0; i < s.layers.size(); ++i) {
    const LayerSetup& l = s.layers[i];
    gpu::SkyLayer& g = f.layers[i];
    g.heights = gpu::vec4(glm::dvec4(l.hBase_m, l.hTop_m, l.cBase_m2, l.cTop_m2));
    g.shape = gpu::vec4(float(l.thickness_m), float(i), float(l.lightDistance_m), l.blends ? 1.0f : 0.0f);
    g.shapeOrigin = v4(l.shapeOrigin, 1.0 / l.shapePeriod_m);
    g.detailOrigin = v4(l.detailOrigin, 1.0 / l.detailPeriod_m);
    g.cloudMapOrigin = v4(l.cloudMapOrigin, 1.0 / l.cloudMapPeriod_m);
    g.coverageShift = gpu::vec4(float(l.coverageShift_m.x), float(l.coverageShift_m.y), float(l.stepFactor),
                                 float(l.shapeStretchZ));
    g.ambient = v4(l.skyTop, l.absent ? 1.0 : 0.0);
    g.sunDiffuse = v4(l.sunDiffuseTop, l.sunCosine);
    g.primary = packCloudType(l.primary);
    g.secondary = packCloudType(l.secondary);
    g.flow = gpu::vec4(l.flow);
    g.windRef = gpu::vec4(l.windRef);
    g.band = gpu::vec4(float(l.band), float(l.carrier), 0.0f, 0.0f);
  }
  // Unused slots keep a positive thickness and valid types so the shader's
  // per-layer setup never divides by 0.
  for (std::size_t i = s.layers.size(); i < gpu::kMaxLayers; ++i) {
    f.layers[i].shape = gpu::vec4(1.0f, float(i), 1.0f, 0.0f);
    f.layers[i].band = gpu::vec4(0.0f, -1.0f, 0.0f, 0.0f);
    f.layers[i].coverageShift.z = 1.0f;
    f.layers[i].coverageShift.w = 1.0f;
    f.layers[i].primary = f.layers[i].secondary = packCloudType(cloudTypeParams(weather::CloudType::Cumulus));
  }
  return f;
}

}  // namespace sky::render
