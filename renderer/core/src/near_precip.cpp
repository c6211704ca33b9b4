// Precipitation near the camera: the drops' laws and the streaks of one frame
// (see near_precip.hpp).
#include "near_precip.hpp"

#include <algorithm>
#include <cmath>

#include "core_common.hpp"
#include "sky/core/split_mix.hpp"
#include "sky/weather/precipitation.hpp"

namespace sky::render {

namespace {

using weather::CloudType;

constexpr double kPi = CoreCommon::kPi;

// The cube round the camera, m: where a drop of the smallest size drawn is
// still about a pixel across at full-HD resolution (rain), farther for
// flakes, which are bigger and slower.
constexpr double kRainBox_m = 3.0;
constexpr double kSnowBox_m = 5.0;
// Snow of density 0.1 g/cm^3: a flake's diameter over its melted diameter.
constexpr double kFlakeOverMelted = 2.154434690031884;  // 10^(1/3)
// Snowflakes do not fall straight: each sways round its path (amplitude and
// period chosen for the look of falling aggregates, not measured).
constexpr double kFlakeSway_m = 0.08;
constexpr double kFlakeSwayPeriod_s = 1.5;

// A drop's numbers in [0, 1) from (seed, drop, which).
double uniform(std::uint32_t seed, std::uint32_t drop, std::uint32_t which) {
  const std::uint64_t h = splitMix64((std::uint64_t(seed) << 32 | drop) * 8 + which);
  return double(h >> 11) * 0x1.0p-53;
}

bool isSnow(CloudType t) { return t == CloudType::Snow; }

}  // namespace

double raindropFallSpeed_mps(double diameter_mm) {
  return std::max(0.0, 9.65 - 10.3 * std::exp(-0.6 * diameter_mm));
}

DropPopulation dropPopulation(CloudType type, double rate_mmph) {
  DropPopulation p;
  p.type = type;
  p.rate_mmph = rate_mmph;
  if (!weather::isPrecipitation(type) || !(rate_mmph > 0)) return p;
  const double r = std::min(rate_mmph, 500.0);
  double n0 = 0;
  if (isSnow(type)) {
    n0 = 3800.0 * std::pow(r, -0.87);
    p.lambda_permm = 2.55 * std::pow(r, -0.48);
    p.box_m = kSnowBox_m;
    p.minDiameter_mm = 1.0;
    p.maxDiameter_mm = 4.0;
    p.radianceFactor = 0.9;
  } else {
    n0 = 8000.0;
    p.lambda_permm = 4.1 * std::pow(r, -0.21);
    p.box_m = kRainBox_m;
    p.minDiameter_mm = 1.0;
    p.maxDiameter_mm = 6.0;
    p.radianceFactor = type == CloudType::Rain ? 0.94 : type == CloudType::Sleet ? 0.92 : 0.9;
  }
  p.numberDensity_perm3 = n0 / p.lambda_permm * std::exp(-p.lambda_permm * p.minDiameter_mm);
  const double wanted = p.numberDensity_perm3 * p.box_m * p.box_m * p.box_m;
  p.capped = wanted > double(kMaxNearDrops);
  p.count = p.capped ? kMaxNearDrops : std::uint32_t(std::lround(wanted));
  return p;
}

std::optional<glm::dvec3> cameraVelocityEcef(const glm::dvec3& fromEcef_m, double from_s, const glm::dvec3& toEcef_m,
                                             double to_s) {
  const double dt = to_s - from_s;
  if (!(dt > 0) || dt > 1.0) return std::nullopt;
  const glm::dvec3 v = (toEcef_m - fromEcef_m) / dt;
  if (!(glm::length(v) <= 1000.0)) return std::nullopt;
  return v;
}

namespace {

struct Projected {
  glm::dvec2 px;
  double z;  // along the view axis, m
};

// A camera-local (east, north, up) offset on the image: where it lands and
// how far ahead it is.
Projected project(const NearPrecipInputs& in, const glm::dvec3& enu) {
  const double z = glm::dot(enu, in.camForward);
  const glm::dvec2 tangent(glm::dot(enu, in.camRight) / z, -glm::dot(enu, in.camDown) / z);
  return {CoreCommon{}.frustumPixel(in.frustum, tangent, double(in.width), double(in.height)), z};
}

// Distance from point p to segment ab.
double segmentDistance(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
  const glm::dvec2 ab = b - a;
  const double len2 = glm::dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

// Calls add(tx, ty) for every kNearPrecipTile tile whose centre is within
// nearEnough of segment ab, visiting only tiles along the segment: for each
// tile column (or row, whichever the segment crosses more of) the rows its
// part of the segment spans, widened by nearEnough. A long streak costs its
// length in tiles, not the area of its bounding box.
template <class Add>
void tilesAlong(glm::dvec2 a, glm::dvec2 b, double nearEnough, int tilesX, int tilesY, Add&& add) {
  constexpr double kTile = gpu::kNearPrecipTile;
  const bool xMajor = std::abs(b.x - a.x) >= std::abs(b.y - a.y);
  const int major = xMajor ? 0 : 1, minor = 1 - major;
  const int majorTiles = xMajor ? tilesX : tilesY, minorTiles = xMajor ? tilesY : tilesX;
  const double du = b[major] - a[major];
  const int c0 = std::max(0, int(std::floor((std::min(a[major], b[major]) - nearEnough) / kTile)));
  const int c1 = std::min(majorTiles - 1, int(std::floor((std::max(a[major], b[major]) + nearEnough) / kTile)));
  for (int c = c0; c <= c1; ++c) {
    // The part of the segment within nearEnough of the column.
    double t0 = 0, t1 = 1;
    if (std::abs(du) > 1e-12) {
      t0 = (c * kTile - nearEnough - a[major]) / du;
      t1 = ((c + 1) * kTile + nearEnough - a[major]) / du;
      if (t0 > t1) std::swap(t0, t1);
      t0 = std::max(t0, 0.0);
      t1 = std::min(t1, 1.0);
      if (t0 > t1) continue;
    }
    const double v0 = a[minor] + t0 * (b[minor] - a[minor]), v1 = a[minor] + t1 * (b[minor] - a[minor]);
    const int r0 = std::max(0, int(std::floor((std::min(v0, v1) - nearEnough) / kTile)));
    const int r1 = std::min(minorTiles - 1, int(std::floor((std::max(v0, v1) + nearEnough) / kTile)));
    for (int r = r0; r <= r1; ++r) {
      const int tx = xMajor ? c : r, ty = xMajor ? r : c;
      const glm::dvec2 centre((tx + 0.5) * kTile, (ty + 0.5) * kTile);
      if (segmentDistance(centre, a, b) <= nearEnough) add(tx, ty);
    }
  }
}

}  // namespace

NearPrecipFrame buildNearPrecip(const NearPrecipInputs& in) {
  NearPrecipFrame out;
  out.population = dropPopulation(in.type, in.rate_mmph);
  const DropPopulation& pop = out.population;
  constexpr std::uint32_t kTile = gpu::kNearPrecipTile;
  out.tilesX = (in.width + kTile - 1) / kTile;
  out.tilesY = (in.height + kTile - 1) / kTile;
  out.tiles.assign(std::size_t(out.tilesX) * out.tilesY, glm::uvec2(0));
  if (pop.count == 0 || in.width == 0 || in.height == 0) return out;

  const glm::dmat3 ecefToLocal = glm::transpose(in.localToEcef);
  const double box = pop.box_m;
  const double pixelsPerTangent = double(in.width) / (in.frustum.y - in.frustum.x);
  const bool snow = isSnow(pop.type);
  const double typeFall = weather::fallSpeed_mps(pop.type);
  // The camera's place in the pattern's frame, per axis in boxes (ECEF
  // metres are exact in double; only the fraction matters).
  const glm::dvec3 camBoxes = in.cameraEcef_m / box;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;  // (tile, streak)
  for (std::uint32_t i = 0; i < pop.count; ++i) {
    // The size: the exponential law cut to [min, max].
    const double u = uniform(in.seed, i, 3);
    const double d_mm = std::min(pop.minDiameter_mm - std::log1p(-u) / pop.lambda_permm, pop.maxDiameter_mm);
    const double fall = pop.type == CloudType::Rain ? raindropFallSpeed_mps(d_mm) : typeFall;
    const glm::dvec3 driftEnu = in.airEnu_mps - glm::dvec3(0, 0, fall);
    const glm::dvec3 driftEcef = in.localToEcef * driftEnu;
    // Where the drop is at the end of the exposure, relative to the camera.
    glm::dvec3 rel;
    for (int k = 0; k < 3; ++k) {
      const double w = uniform(in.seed, i, std::uint32_t(k)) + driftEcef[k] * in.clock_s / box - camBoxes[k];
      rel[k] = box * (w - std::floor(w) - 0.5);
    }
    glm::dvec3 endEnu = ecefToLocal * rel;
    // Over the exposure it moved by the air's drift less the camera's motion
    // (and a flake by its sway).
    glm::dvec3 startEnu = endEnu - (driftEnu - in.cameraEnu_mps) * in.exposure_s;
    if (snow) {
      const double phase = 2 * kPi * uniform(in.seed, i, 4);
      const double w = 2 * kPi / kFlakeSwayPeriod_s;
      const auto sway = [&](double t) {
        return kFlakeSway_m * glm::dvec3(std::sin(w * t + phase), std::cos(w * t + phase), 0);
      };
      startEnu += sway(in.clock_s - in.exposure_s) - sway(in.clock_s);
    }
    // Cut the path to the part kNearestDrop_m or more ahead.
    double z0 = glm::dot(startEnu, in.camForward), z1 = glm::dot(endEnu, in.camForward);
    if (z0 < kNearestDrop_m && z1 < kNearestDrop_m) continue;
    if (z0 < kNearestDrop_m) startEnu += (endEnu - startEnu) * ((kNearestDrop_m - z0) / (z1 - z0));
    if (z1 < kNearestDrop_m) endEnu += (startEnu - endEnu) * ((kNearestDrop_m - z1) / (z0 - z1));
    const Projected a = project(in, startEnu), b = project(in, endEnu);
    const double z = 0.5 * (a.z + b.z);
    const double diameter_m = 1e-3 * d_mm * (snow ? kFlakeOverMelted : 1.0);
    const double radius = 0.5 * diameter_m / z * pixelsPerTangent;
    const double reach = std::max(radius, 1.0);  // precip_streak.glsl: the drawn tent's half-width
    // The streak's largest coverage of a pixel: its area over the tent's
    // width across and its length along.
    const double peak = kPi * radius * radius / (reach * std::max(glm::length(b.px - a.px), reach));
    if (peak < kFaintestStreak) {
      ++out.faint;
      continue;
    }
    const glm::dvec2 lo = glm::min(a.px, b.px) - reach, hi = glm::max(a.px, b.px) + reach;
    if (hi.x <= 0 || hi.y <= 0 || lo.x >= in.width || lo.y >= in.height) continue;
    // The tiles whose square the streak's reach touches (within the
    // tile's half diagonal of its centre line).
    const auto index = std::uint32_t(out.streaks.size());
    const std::size_t before = pairs.size();
    tilesAlong(a.px, b.px, reach + 0.5 * std::sqrt(2.0) * kTile, int(out.tilesX), int(out.tilesY),
               [&](int tx, int ty) { pairs.emplace_back(std::uint32_t(ty) * out.tilesX + std::uint32_t(tx), index); });
    if (pairs.size() > kMaxNearEntries) {
      pairs.resize(before);
      out.entriesCapped = true;
      break;
    }
    if (pairs.size() == before) continue;
    gpu::SkyStreak s{};
    const double len = glm::length(b.px - a.px);
    const glm::dvec2 dir = len < 1e-3 ? glm::dvec2(1, 0) : (b.px - a.px) / len;
    s.path = gpu::vec4(float(a.px.x), float(a.px.y), float(dir.x), float(dir.y));
    s.shape = gpu::vec4(float(len), float(radius), float(z), 0.0f);
    out.streaks.push_back(s);
    out.dropArea_px2 += kPi * radius * radius;
  }
  // Counting sort by tile, streaks in drop order within a tile.
  for (const auto& [tile, streak] : pairs) ++out.tiles[tile].y;
  std::uint32_t first = 0;
  for (auto& t : out.tiles) {
    t.x = first;
    first += t.y;
    t.y = 0;
  }
  out.entries.resize(pairs.size());
  for (const auto& [tile, streak] : pairs) out.entries[out.tiles[tile].x + out.tiles[tile].y++] = streak;
  return out;
}

NearPrecipInputs NearPrecipSource::inputs(const RenderSettings& settings, const FrameInputs& frame,
                                          const FrameSetup& setup) {
  NearPrecipInputs in;
  in.clock_s = frame.weatherClock_s;
  in.exposure_s = frame.exposure_s;
  in.cameraEcef_m = setup.cameraEcef_m;
  in.localToEcef = setup.localToEcef;
  in.camForward = setup.camForward;
  in.camRight = setup.camRight;
  in.camDown = setup.camDown;
  in.frustum = setup.frustum;
  in.width = settings.width;
  in.height = settings.height;
  in.seed = settings.noiseSeed;
  const glm::dmat3 ecefToLocal = glm::transpose(setup.localToEcef);
  if (last_)
    if (auto v = cameraVelocityEcef(last_->first, last_->second, setup.cameraEcef_m, frame.weatherClock_s))
      in.cameraEnu_mps = ecefToLocal * *v;
  last_ = {setup.cameraEcef_m, frame.weatherClock_s};
  if (frame.weather == nullptr || !settings.march.nearPrecipitation) return in;
  // The lookups index every tile of the snapshot: kept for the same
  // snapshot and version, for 10 s of clock (drifting tiles are carried
  // back by their wind over the clock the lookup was made at: 10 s is 100 m
  // in a 10 m/s wind, in tiles of kilometres); every frame without a version.
  const bool same = snapshot_ == frame.weather && frame.weatherVersion.has_value() && version_ == frame.weatherVersion &&
                    std::abs(frame.weatherClock_s - lookupClock_s_) <= 10.0;
  if (!same) {
    coverage_ = weather::snapshotLookup(*frame.weather, frame.weatherClock_s);
    wind_ = weather::snapshotWindLookup(*frame.weather);
    snapshot_ = frame.weather;
    version_ = frame.weatherVersion;
    lookupClock_s_ = frame.weatherClock_s;
  }
  const geo::Geodetic& at = frame.camera.position;
  const weather::PointWeather here =
      weather::weatherAt(frame.weather->layers, coverage_, at.lat_deg, at.lon_deg, at.alt_m, wind_);
  in.type = here.precipitationType;
  in.rate_mmph = here.precipitationRate_mmph;
  // The direction the wind blows towards is 180 degrees from where it comes from.
  const double from = here.wind.fromDirection_deg * kPi / 180;
  in.airEnu_mps = glm::dvec3(-here.wind.speed_mps * std::sin(from), -here.wind.speed_mps * std::cos(from),
                             here.wind.vertical_mps);
  return in;
}

}  // namespace sky::render
