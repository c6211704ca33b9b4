// See sun_map_plan.hpp.
#include "sun_map_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace sky::render {

namespace {

bool sameMap(const SunMapSettings& a, const SunMapSettings& b) {
  return a.method == b.method && a.size == b.size && a.cascades == b.cascades && a.extent_m == b.extent_m &&
         a.buildSteps == b.buildSteps && a.buildFrames == b.buildFrames;
}

}  // namespace

SunMapPlanner::Staleness SunMapPlanner::staleness(const Anchor& a, const FrameSetup& s, double weatherClock_s,
                                                  std::uint64_t weatherUploads) {
  const SunMapSettings& settings = s.march.sunShadow;
  const double turned_deg =
      std::acos(std::clamp(glm::dot(s.localToEcef * s.sunDir, a.sun), -1.0, 1.0)) * 180 / std::numbers::pi;
  // The clouds drift with the fastest layer's wind; half a texel of the
  // first cascade is what the map resolves.
  double wind = 1.0;
  for (const LayerSetup& l : s.layers)
    if (!l.absent)
      wind = std::max({wind, glm::length(glm::dvec2(l.windEnu_mps.x, l.windEnu_mps.y)),
                       glm::length(glm::dvec2(l.windAtCamera_mps.x, l.windAtCamera_mps.y))});
  const double halfTexel = settings.extent_m / settings.size;
  const double drift = std::abs(weatherClock_s - a.weatherClock_s) * wind;
  const double moved = glm::length(s.cameraEcef_m - a.ecef);
  // A jump first: it decides how the new map is built.
  if (turned_deg > kSunMapJumpTurn_deg) return {"sun turned", true};
  if (drift > kSunMapJumpTexels * halfTexel) return {"clouds drifted", true};
  if (moved > settings.extent_m) return {"camera moved", true};
  if (weatherUploads != a.weatherUploads) return {"tiles changed", false};
  if (turned_deg > kSunMapRebuildTurn_deg) return {"sun turned", false};
  if (drift > halfTexel) return {"clouds drifted", false};
  if (moved > 0.25 * settings.extent_m) return {"camera moved", false};
  return {};
}

SunMapGeometry SunMapPlanner::inFrame(const Anchor& a, const FrameSetup& s) {
  // The anchor's axes and place in this frame's local frame (its rotation is
  // orthonormal: the inverse is the transpose).
  const glm::dmat3 toLocal = glm::transpose(s.localToEcef);
  SunMapGeometry g;
  g.axisU = toLocal * a.axisU;
  g.axisV = toLocal * a.axisV;
  g.origin = toLocal * (a.ecef - s.cameraEcef_m);
  g.top_m = a.top_m;
  g.base_m = a.base_m;
  return g;
}

SunMapPlan SunMapPlanner::plan(const FrameSetup& s, double weatherClock_s, std::uint64_t weatherUploads,
                               bool weatherJumped) {
  const SunMapSettings& settings = s.march.sunShadow;
  SunMapPlan p;
  FrameSetup::SunMapFrame& f = p.frame;
  const bool drawsLayers = std::any_of(s.layers.begin(), s.layers.end(), [](const LayerSetup& l) { return !l.absent; });
  const auto anchorHere = [&] {
    const SunMapGeometry fresh = sunMapGeometry(s);
    return Anchor{s.cameraEcef_m, s.localToEcef * fresh.axisU, s.localToEcef * fresh.axisV, fresh.top_m,
                  fresh.base_m,   s.localToEcef * s.sunDir,    weatherClock_s,              weatherUploads,
                  settings};
  };
  // Nothing (of use) to read: the whole map now, into the slot read, and
  // read at once; whatever was being built is dropped.
  const auto wholeNow = [&](std::string reason) {
    pending_.reset();
    front_ = anchorHere();
    p.reason = std::move(reason);
    f.read = f.build = sunMapGeometry(s);
    f.readSlot = f.buildSlot = frontSlot_;
    f.rowEnd = settings.size;
    p.completes = true;
    return p;
  };
  if (!drawsLayers) {
    f.read = front_ ? inFrame(*front_, s) : sunMapGeometry(s);
    f.readSlot = frontSlot_;
    return p;
  }
  if (!front_) return wholeNow("first frame");
  if (!sameMap(front_->settings, settings)) return wholeNow("settings changed");
  if (weatherJumped && weatherUploads != front_->weatherUploads) return wholeNow("weather changed");
  // Moved on by a jump (a host setting the time of day, a teleport): the
  // old map is of no use either.
  if (Staleness stale = staleness(*front_, s, weatherClock_s, weatherUploads); stale.jumped) {
    return wholeNow(std::move(stale.reason));
  } else if (!pending_ && !stale.reason.empty()) {
    pending_ = Pending{anchorHere(), 0, std::move(stale.reason)};
  }
  if (pending_) {
    const std::uint32_t band = (settings.size + settings.buildFrames - 1) / settings.buildFrames;
    p.reason = pending_->reason;
    f.build = inFrame(pending_->anchor, s);
    f.buildSlot = 1 - frontSlot_;
    f.rowBegin = pending_->rowsDone;
    f.rowEnd = std::min(settings.size, f.rowBegin + band);
    pending_->rowsDone = f.rowEnd;
    if (f.rowEnd == settings.size) {
      front_ = pending_->anchor;
      frontSlot_ = f.buildSlot;
      pending_.reset();
      p.completes = true;
    }
  }
  f.read = inFrame(*front_, s);
  f.readSlot = frontSlot_;
  return p;
}

}  // namespace sky::render
