// See sun_map_plan.hpp.
#include "sun_map_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core_common.hpp"

namespace sky::render {

namespace {

constexpr double kCascadeRatio = CoreCommon::kSunCascadeRatio;

bool sameMap(const SunMapSettings& a, const SunMapSettings& b) {
  return a.method == b.method && a.size == b.size && a.cascades == b.cascades && a.extent_m == b.extent_m &&
         a.buildSteps == b.buildSteps && a.buildFrames == b.buildFrames;
}

}  // namespace

SunMapPlanner::Staleness SunMapPlanner::staleness(const Front& f, const FrameSetup& s, double weatherClock_s,
                                                  std::uint64_t weatherUploads) {
  const SunMapSettings& settings = s.march.sunShadow;
  const double turned_deg =
      std::acos(std::clamp(glm::dot(s.localToEcef * s.sunDir, f.frame.sun), -1.0, 1.0)) * 180 / std::numbers::pi;
  // The clouds drift with the fastest layer's wind; half a texel of the
  // first cascade is what the map resolves. Every cascade by the first's:
  // a coarse cascade kept until the clouds drifted half of its own texel
  // (4^c times more) changed the picture at once when it was rebuilt, by
  // 3x a frame's motion (HeadlessReconnect.ServerKilledAndRestartedMidReplayCausesNoJump),
  // where rebuilt with the first it moves on in small steps.
  double wind = 1.0;
  for (const LayerSetup& l : s.layers)
    if (!l.absent)
      wind = std::max({wind, glm::length(glm::dvec2(l.windEnu_mps.x, l.windEnu_mps.y)),
                       glm::length(glm::dvec2(l.windAtCamera_mps.x, l.windAtCamera_mps.y))});
  const double halfTexel = settings.extent_m / settings.size;
  const auto drift = [&](const Anchor& a) { return std::abs(weatherClock_s - a.weatherClock_s) * wind; };
  const auto moved = [&](const Anchor& a) { return glm::length(s.cameraEcef_m - a.ecef); };
  const std::uint32_t n = settings.cascades;
  // A jump first, by the finest cascade: it decides how the new map is built.
  if (turned_deg > kSunMapJumpTurn_deg) return {"sun turned", true, 0, n};
  if (drift(f.anchors[0]) > kSunMapJumpTexels * halfTexel) return {"clouds drifted", true, 0, n};
  if (moved(f.anchors[0]) > settings.extent_m) return {"camera moved", true, 0, n};
  Staleness stale;
  double scale = 1.0;  // cascade c's extent over cascade 0's
  for (std::uint32_t c = 0; c < n; ++c, scale *= kCascadeRatio) {
    const Anchor& a = f.anchors[c];
    const char* why = weatherUploads != a.weatherUploads         ? "tiles changed"
                      : turned_deg > kSunMapRebuildTurn_deg      ? "sun turned"
                      : drift(a) > halfTexel                     ? "clouds drifted"
                      : moved(a) > 0.25 * settings.extent_m * scale ? "camera moved"
                                                                 : nullptr;
    if (why == nullptr) continue;
    if (stale.reason.empty()) {
      stale.reason = why;
      stale.first = c;
    }
    stale.end = c + 1;
  }
  return stale;
}

SunMapGeometry SunMapPlanner::inFrame(const Frame& f, const Anchor& a, const FrameSetup& s) {
  // The map's axes and the cascade's place in this frame's local frame (its
  // rotation is orthonormal: the inverse is the transpose).
  const glm::dmat3 toLocal = glm::transpose(s.localToEcef);
  SunMapGeometry g;
  g.axisU = toLocal * f.axisU;
  g.axisV = toLocal * f.axisV;
  g.origin = toLocal * (a.ecef - s.cameraEcef_m);
  g.top_m = f.top_m;
  g.base_m = f.base_m;
  return g;
}

SunMapPlan SunMapPlanner::plan(const FrameSetup& s, double weatherClock_s, std::uint64_t weatherUploads,
                               bool weatherJumped) {
  const SunMapSettings& settings = s.march.sunShadow;
  const std::uint32_t n = settings.cascades;
  SunMapPlan p;
  FrameSetup::SunMapFrame& f = p.frame;
  const bool drawsLayers = std::any_of(s.layers.begin(), s.layers.end(), [](const LayerSetup& l) { return !l.absent; });
  const Anchor here{s.cameraEcef_m, weatherClock_s, weatherUploads};
  const auto frameHere = [&] {
    const SunMapGeometry fresh = sunMapGeometry(s);
    return Frame{s.localToEcef * fresh.axisU, s.localToEcef * fresh.axisV, fresh.top_m, fresh.base_m,
                 s.localToEcef * s.sunDir, settings};
  };
  const auto readFront = [&] {
    f.read = inFrame(front_->frame, front_->anchors[0], s);
    for (std::uint32_t c = 1; c < kMaxCascades; ++c)
      f.readOrigins[c - 1] = c < n ? inFrame(front_->frame, front_->anchors[c], s).origin : f.read.origin;
    f.readSlots = front_->slots;
  };
  // Nothing (of use) to read: the whole map now, into the slots read, and
  // read at once; whatever was being built is dropped.
  const auto wholeNow = [&](std::string reason) {
    pending_.reset();
    const std::uint32_t slots = front_ ? front_->slots : 0;
    front_ = Front{frameHere(), {}, slots};
    front_->anchors.fill(here);
    p.reason = std::move(reason);
    f.build = sunMapGeometry(s);
    readFront();
    f.buildSlots = f.readSlots;
    f.firstCascade = 0;
    f.endCascade = n;
    f.rowEnd = settings.size;
    p.completes = true;
    return p;
  };
  if (!drawsLayers) {
    if (front_) {
      readFront();
    } else {
      f.read = sunMapGeometry(s);
      f.readOrigins.fill(f.read.origin);
    }
    return p;
  }
  if (!front_) return wholeNow("first frame");
  if (!sameMap(front_->frame.settings, settings)) return wholeNow("settings changed");
  const bool olderWeather = std::any_of(front_->anchors.begin(), front_->anchors.begin() + n,
                                        [&](const Anchor& a) { return a.weatherUploads != weatherUploads; });
  if (weatherJumped && olderWeather) return wholeNow("weather changed");
  // Moved on by a jump (a host setting the time of day, a teleport): the
  // old map is of no use either.
  if (Staleness stale = staleness(*front_, s, weatherClock_s, weatherUploads); stale.jumped) {
    return wholeNow(std::move(stale.reason));
  } else if (!pending_ && !stale.reason.empty()) {
    // Some cascades: on the axes and shells the others were built on (the
    // sun turning or the tiles changing make every cascade stale).
    const bool every = stale.first == 0 && stale.end == n;
    pending_ = Pending{every ? frameHere() : front_->frame, here, stale.first, stale.end, 0, std::move(stale.reason)};
  }
  if (pending_) {
    const std::uint32_t band = (settings.size + settings.buildFrames - 1) / settings.buildFrames;
    const std::uint32_t rebuilt = ((1u << pending_->end) - 1) & ~((1u << pending_->first) - 1);
    p.reason = pending_->reason;
    f.build = inFrame(pending_->frame, pending_->anchor, s);
    f.buildSlots = front_->slots ^ rebuilt;
    f.firstCascade = pending_->first;
    f.endCascade = pending_->end;
    f.rowBegin = pending_->rowsDone;
    f.rowEnd = std::min(settings.size, f.rowBegin + band);
    pending_->rowsDone = f.rowEnd;
    if (f.rowEnd == settings.size) {
      for (std::uint32_t c = pending_->first; c < pending_->end; ++c) front_->anchors[c] = pending_->anchor;
      if (pending_->first == 0 && pending_->end == n) front_->frame = pending_->frame;
      front_->slots ^= rebuilt;
      pending_.reset();
      p.completes = true;
    }
  }
  readFront();
  return p;
}

}  // namespace sky::render
