// See sun_map_plan.hpp.
#include "sun_map_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace sky::render {

SunMapPlan SunMapPlanner::plan(const FrameSetup& s, double weatherClock_s, std::uint64_t weatherUploads) {
  const SunMapSettings& settings = s.march.sunShadow;
  const SunMapGeometry fresh = sunMapGeometry(s);
  const glm::dvec3 sunEcef = s.localToEcef * s.sunDir;
  SunMapPlan p;
  p.geometry = fresh;
  if (!anchor_) {
    p.reason = "first frame";
  } else if (weatherUploads != anchor_->weatherUploads) {
    p.reason = "weather changed";
  } else if (settings.extent_m != anchor_->settings.extent_m || settings.buildSteps != anchor_->settings.buildSteps) {
    p.reason = "settings changed";
  } else if (std::acos(std::clamp(glm::dot(sunEcef, anchor_->sun), -1.0, 1.0)) >
             kSunMapRebuildTurn_deg * std::numbers::pi / 180) {
    p.reason = "sun turned";
  } else {
    // The clouds drift with the fastest layer's wind; half a texel of the
    // first cascade is what the map resolves.
    double wind = 1.0;
    for (const LayerSetup& l : s.layers)
      if (!l.absent) wind = std::max(wind, glm::length(glm::dvec2(l.windEnu_mps.x, l.windEnu_mps.y)));
    const double halfTexel = settings.extent_m / settings.size;
    const glm::dvec3 moved = s.cameraEcef_m - anchor_->ecef;
    if (std::abs(weatherClock_s - anchor_->weatherClock_s) * wind > halfTexel)
      p.reason = "clouds drifted";
    else if (glm::length(moved) > 0.25 * settings.extent_m)
      p.reason = "camera moved";
  }
  p.rebuild = !p.reason.empty();
  if (p.rebuild) {
    anchor_ = Anchor{s.cameraEcef_m, s.localToEcef * fresh.axisU, s.localToEcef * fresh.axisV, sunEcef,
                     weatherClock_s, weatherUploads, settings};
    return p;
  }
  // Reused: the anchor's axes and place in this frame's local frame (its
  // rotation is orthonormal: the inverse is the transpose).
  const glm::dmat3 toLocal = glm::transpose(s.localToEcef);
  p.geometry.axisU = toLocal * anchor_->axisU;
  p.geometry.axisV = toLocal * anchor_->axisV;
  p.geometry.origin = toLocal * (anchor_->ecef - s.cameraEcef_m);
  return p;
}

}  // namespace sky::render
