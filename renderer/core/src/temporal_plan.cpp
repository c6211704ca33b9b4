// Interleave order, history rules and reprojection parameters (see temporal_plan.hpp).
#include "temporal_plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <sstream>

#include "sky/core/assert.hpp"

#include "core_common.hpp"
#include "fresh_edges.hpp"
#include "weather_field.hpp"

namespace sky::render {

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

// Bayer matrices (ordered dither): entry = the frame of the cycle that draws
// that pixel of the block (row, column).
constexpr std::array<std::array<std::uint32_t, 2>, 2> kBayer2{{{0, 2}, {3, 1}}};
constexpr std::array<std::array<std::uint32_t, 4>, 4> kBayer4{{{0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}}};

double angleBetween_deg(const glm::dvec3& a, const glm::dvec3& b) {
  const double c = glm::dot(a, b) / std::max(glm::length(a) * glm::length(b), 1e-300);
  return std::acos(std::clamp(c, -1.0, 1.0)) * kRadToDeg;
}

std::string rounded(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

gpu::vec4 v4(const glm::dvec3& v, double w = 0) { return gpu::vec4(glm::dvec4(v, w)); }

}  // namespace

glm::uvec2 interleavePhase(std::uint32_t n, std::uint32_t cycleIndex) {
  SKY_ASSERT(n == 1 || n == 2 || n == 4);
  if (n == 1) return {0, 0};
  const std::uint32_t k = cycleIndex % (n * n);
  for (std::uint32_t y = 0; y < n; ++y)
    for (std::uint32_t x = 0; x < n; ++x)
      if ((n == 2 ? kBayer2[y][x] : kBayer4[y][x]) == k) return {x, y};
  SKY_ASSERT(false);
  return {0, 0};
}

double TemporalPlanner::turn_deg(const Remembered& prev, const Remembered& now) {
  // The rotation taking one camera's axes (in ECEF) to the other's.
  const glm::dmat3 a = prev.localToEcef * glm::dmat3(prev.forward, prev.right, prev.down);
  const glm::dmat3 b = now.localToEcef * glm::dmat3(now.forward, now.right, now.down);
  const glm::dmat3 r = glm::transpose(b) * a;
  return std::acos(std::clamp((r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0, -1.0, 1.0)) * kRadToDeg;
}

glm::uvec4 TemporalPlanner::freshEdges(const Remembered& prev, const FrameSetup& setup, std::uint32_t n) {
  // The previous camera's axes in this frame's local frame. A point's
  // direction stands for the point: the clouds lie far beyond one frame's
  // camera motion (a near cloud the motion uncovers is the reprojection's
  // disocclusion, upscaled as before).
  const glm::dmat3 prevToLocal = glm::transpose(setup.localToEcef) * prev.localToEcef;
  const glm::dvec3 pf = prevToLocal * prev.forward, pr = prevToLocal * prev.right, pd = prevToLocal * prev.down;
  const double rw = setup.rasterWidth, rh = setup.rasterHeight;
  const int w = int(setup.width), h = int(setup.height);
  if (w < 2 || h < 2 || !(rw > 0) || !(rh > 0)) return glm::uvec4(0);
  CoreCommon shared;
  // Where pixel (x, y)'s ray was in the previous image (continuous pixels;
  // far outside when it was behind that camera). The history's bilinear
  // lookup holds from 0 to the image's extent; past it on one side, the
  // pixel came into view through that side's edge.
  auto previous = [&](int x, int y) {
    const glm::dvec3 dir = shared.cameraRay(setup.camForward, setup.camRight, setup.camDown, setup.frustum, double(x),
                                            double(y), rw, rh);
    const double z = glm::dot(dir, pf);
    if (z <= 1e-9) return glm::dvec2(-1e30);
    return shared.frustumPixel(prev.frustum, glm::dvec2(glm::dot(dir, pr), -glm::dot(dir, pd)) / z, rw, rh);
  };
  // Each edge walked inwards along every `step`-th row (column) and the
  // last; a band one pixel wider covers the rows between.
  const int rowStep = std::max(1, h / 64), columnStep = std::max(1, w / 64);
  auto inward = [&](int along, int step, int limit, auto outsideAt) {
    int width = 0;
    for (int a = 0;; a = std::min(a + step, along - 1)) {
      int d = 0;
      while (d < limit && outsideAt(a, d)) ++d;
      width = std::max(width, d);
      if (a == along - 1) break;
    }
    return width > 0 && step > 1 ? std::min(width + 1, limit) : width;
  };
  // A ray from behind the previous camera counts as outside every side.
  glm::uvec4 e(std::uint32_t(inward(h, rowStep, w / 2, [&](int y, int d) { return previous(d, y).x < 0; })),
               std::uint32_t(inward(h, rowStep, w / 2, [&](int y, int d) {
                 const glm::dvec2 p = previous(w - 1 - d, y);
                 return p.x > rw || p.x < -1e29;
               })),
               std::uint32_t(inward(w, columnStep, h / 2, [&](int x, int d) { return previous(x, d).y < 0; })),
               std::uint32_t(inward(w, columnStep, h / 2, [&](int x, int d) {
                 const glm::dvec2 p = previous(x, h - 1 - d);
                 return p.y > rh || p.y < -1e29;
               })));
  // The cloud pass writes the bands' samples after the packed pixels, in
  // the rows of its output the packed image leaves free (reproject.comp
  // reads them there): the widest band gives way until they fit.
  const std::uint32_t packedW = (setup.width + n - 1) / n, packedH = (setup.height + n - 1) / n;
  const std::uint32_t capacity = packedW * (setup.height - packedH);
  const glm::uvec2 size(setup.width, setup.height);
  while (FreshEdges{}.freshEdgeCount(e, size) > capacity) {
    std::uint32_t* widest = &e.x;
    for (std::uint32_t* c : {&e.y, &e.z, &e.w})
      if (*c > *widest) widest = c;
    --*widest;
  }
  return e;
}

std::string TemporalPlanner::resetReason(const Remembered& prev, const Remembered& now) const {
  if (now.structureKey != prev.structureKey) return "weather changed";
  const double moved_m = glm::length(now.cameraEcef_m - prev.cameraEcef_m);
  if (moved_m > settings_.resetDistance_m) return "camera moved " + rounded(moved_m, 0) + " m";
  const double turned_deg = turn_deg(prev, now);
  if (turned_deg > settings_.resetRotation_deg) return "view turned " + rounded(turned_deg, 1) + " deg";
  const double step_s = now.clock_s - prev.clock_s;
  if (std::abs(step_s) > settings_.resetClockStep_s) return "weather clock stepped " + rounded(step_s, 1) + " s";
  // A flash's light comes and goes within a few frames: no history holds it.
  if (now.flashLit || prev.flashLit) return "lightning";
  if (now.moonLit != prev.moonLit) return now.moonLit ? "the moon took over the light" : "the sun took over the light";
  const double sunTurn_deg = angleBetween_deg(now.keyLightEcef, prev.keyLightEcef);
  if (sunTurn_deg > settings_.resetSunTurn_deg) return "key light moved " + rounded(sunTurn_deg, 2) + " deg";
  if (now.layerSide.size() != prev.layerSide.size()) return "weather changed";
  for (std::size_t i = 0; i < now.layerSide.size(); ++i)
    if (now.layerSide[i] != prev.layerSide[i])
      return std::string("camera ") + (now.layerSide[i] == 0 ? "entered" : "left") + " cloud layer " +
             std::to_string(i);
  return {};
}

TemporalPlan TemporalPlanner::plan(const FrameSetup& setup, const FrameInputs& inputs, const WeatherEdit& edit) {
  Remembered now;
  now.cameraEcef_m = setup.cameraEcef_m;
  now.localToEcef = setup.localToEcef;
  now.forward = setup.camForward;
  now.right = setup.camRight;
  now.down = setup.camDown;
  now.frustum = setup.frustum;
  now.keyLightEcef = setup.localToEcef * setup.sunDir;
  now.moonLit = setup.moonLit;
  now.flashLit = !setup.flashes.lights.empty();
  now.clock_s = inputs.weatherClock_s;
  if (!inputs.weatherVersion || inputs.weatherVersion != keyVersion_) {
    versionStructureKey_ = weatherStructureKey(inputs.weather, inputs.coarseWeather);
    versionContentKey_ = weatherContentKey(inputs.weather, inputs.coarseWeather);
    keyVersion_ = inputs.weatherVersion;
  }
  now.structureKey = versionStructureKey_;
  now.contentKey = versionContentKey_;
  for (const LayerSetup& l : setup.layers) now.layerSide.push_back(l.hTop_m > 0 ? 1 : l.hBase_m < 0 ? -1 : 0);

  TemporalPlan plan;
  const std::uint32_t n = settings_.interleave;
  std::string reason = previous_ ? resetReason(*previous_, now) : forgottenBecause_;
  // Only tiles changed, a few of the map's steps at a time (a ramp): the
  // history stays, redrawn without accumulation where they show. A step
  // change, or one the map does not know in tiles, redraws the frame whole:
  // kept, the history would dissolve into the new weather over a cycle.
  const bool tilesChanged = reason.empty() && now.contentKey != previous_->contentKey;
  if (tilesChanged && (!settings_.regionDrop || !edit.rects || edit.field == nullptr ||
                       edit.largestStep > kMaxRampStep))
    reason = "weather changed";
  // The changes of the last cycle of n^2 frames: each pixel is redrawn
  // once a cycle, and until then its history shows the old weather, so a
  // redraw replaces it wherever one of them shows in this frame's view. In
  // the map's texels, so only while the map keeps its anchor.
  if (!reason.empty() || edit.field == nullptr || !sameAnchor(edit.field->anchor, recentAnchor_)) recent_.clear();
  if (edit.field != nullptr) recentAnchor_ = edit.field->anchor;
  if (reason.empty() && tilesChanged && !edit.rects->empty()) recent_.push_back({frames_, *edit.rects});
  while (!recent_.empty() && frames_ - recent_.front().frame >= std::uint64_t(n) * n) recent_.pop_front();
  if (!recent_.empty()) {
    std::vector<TexelRect> rects;
    for (const RecentEdit& e : recent_) rects.insert(rects.end(), e.rects.begin(), e.rects.end());
    plan.drop = historyDrop(setup, *edit.field, rects);
    if (plan.drop.marked == 0) plan.drop = {};
  }
  plan.drawWhole = !reason.empty();
  plan.reason = reason;
  plan.interleave = plan.drawWhole ? 1 : n;
  // A fast turn: what comes into view would be upscaled from 1 pixel of 16
  // and stay that coarse until each pixel's turn to be drawn comes, so the
  // frame draws 1 of 4 instead (TemporalSettings::denseTurn_px).
  if (!plan.drawWhole && n == 4 && settings_.denseTurn_px > 0) {
    // One pixel's angle at the image's centre: the frustum's vertical angle
    // over its rows.
    const double pixel_deg = (std::atan(setup.frustum.z) - std::atan(setup.frustum.w)) * kRadToDeg /
                             double(std::max<std::uint32_t>(setup.height, 1));
    plan.turned_px = turn_deg(*previous_, now) / pixel_deg;
    if (plan.turned_px > settings_.denseTurn_px) plan.interleave = 2;
  }
  const std::uint32_t drawnN = plan.interleave;
  if (!plan.drawWhole && drawnN > 1 && settings_.freshEdges) {
    plan.freshEdges = freshEdges(*previous_, setup, drawnN);
    plan.freshEdgePixels = FreshEdges{}.freshEdgeCount(plan.freshEdges, glm::uvec2(setup.width, setup.height));
  }
  const std::uint64_t index = inputs.patternIndex.value_or(frames_);
  plan.phase = plan.drawWhole ? glm::uvec2(0) : interleavePhase(drawnN, std::uint32_t(index % (drawnN * drawnN)));
  // With accumulation each cycle of n^2 frames shifts the step offsets by
  // the golden ratio: the additive recurrence spreads any number of
  // consecutive cycles' offsets evenly over [0, 1).
  if (settings_.accumulation > 0) {
    const double cycle = double(index / (std::uint64_t(n) * n));
    plan.jitterShift = cycle * kGoldenRatioConjugate - std::floor(cycle * kGoldenRatioConjugate);
    // Roberts' R2 sequence (the plastic number's generalised golden ratio):
    // consecutive cycles' 2D shifts cover the pixel evenly.
    if (settings_.pixelJitter) {
      constexpr double kR2x = 0.7548776662466927, kR2y = 0.5698402909980532;
      plan.pixelShift = {cycle * kR2x - std::floor(cycle * kR2x), cycle * kR2y - std::floor(cycle * kR2y)};
      plan.pixelJitter = true;
    }
  }
  ++frames_;

  gpu::SkyReproject& p = plan.params;
  p.camForward = v4(setup.camForward, setup.cGround_m2);
  p.camRight = v4(setup.camRight, settings_.horizonSides ? 1.0 : 0.0);
  p.camDown = v4(setup.camDown);
  p.frustum = gpu::vec4(setup.frustum);
  p.prevFrustum = p.frustum;
  p.image = gpu::uvec4(setup.width, setup.height, plan.interleave, plan.drawWhole ? 0u : 1u);
  p.raster = gpu::vec4(float(setup.rasterWidth), float(setup.rasterHeight), float(settings_.historyClip),
                       float(settings_.accumulationMotion_px));
  const std::uint32_t packedW = (setup.width + plan.interleave - 1) / plan.interleave;
  p.phase = gpu::uvec4(plan.phase.x, plan.phase.y, packedW, std::uint32_t(setup.layers.size()));
  p.freshEdges = gpu::uvec4(plan.freshEdges);
  if (!plan.drop.cells.empty())
    p.drop = gpu::uvec4(plan.drop.cellsX, plan.drop.cellsY, kHistoryDropCellShift, 1u);
  p.tolerance = gpu::vec4(float(settings_.depthTolerance), float(kDepthToleranceSlack_m), float(kLayerWindMargin_m),
                          float(settings_.accumulation));
  p.prevPosition = v4(glm::dvec3(0), setup.r_m);
  if (!plan.drawWhole) {
    // The previous camera in this frame's local frame: ECEF differences in
    // double, rotated by this frame's local axes (transpose = inverse).
    const Remembered& prev = *previous_;
    const glm::dmat3 toLocal = glm::transpose(setup.localToEcef);
    const glm::dmat3 prevToLocal = toLocal * prev.localToEcef;
    p.prevForward = v4(prevToLocal * prev.forward);
    p.prevRight = v4(prevToLocal * prev.right);
    p.prevDown = v4(prevToLocal * prev.down);
    p.prevFrustum = gpu::vec4(prev.frustum);
    p.prevPosition = v4(toLocal * (prev.cameraEcef_m - setup.cameraEcef_m), setup.r_m);
    const double step_s = now.clock_s - prev.clock_s;
    SKY_ASSERT(setup.layers.size() <= gpu::kReprojectMaxLayers);
    for (std::size_t i = 0; i < setup.layers.size(); ++i) {
      const LayerSetup& l = setup.layers[i];
      p.layerBand[i] = gpu::vec4(float(-l.hBase_m), float(-l.hTop_m), 0.0f, 0.0f);
      // The air over the camera; a layer whose wind varies moves each
      // pixel's point by the wind there instead (reproject.comp, the same
      // weather map as the cloud pass), and by this one's vertical part.
      p.layerMotion[i] = v4(l.windAtCamera_mps * step_s);
      p.layerWind[i] = gpu::vec4(float(i), l.flow.w > 0.5 ? 1.0f : 0.0f, float(step_s), 0.0f);
    }
  }
  for (int row = 0; row < 3; ++row)
    p.camToAnchor[row] =
        v4(glm::dvec3(setup.camToAnchor[0][row], setup.camToAnchor[1][row], setup.camToAnchor[2][row]));
  p.camInAnchor = v4(setup.camInAnchor_m, setup.anchorRadius_m);
  p.weatherMap = gpu::vec4(float(1.0 / (2 * setup.mapHalfExtent_m)), float(kRingBlendStart), float(kRingBlendEnd),
                           float(1.0 / (2 * setup.coarseHalfExtent_m)));
  previous_ = now;
  return plan;
}

}  // namespace sky::render
