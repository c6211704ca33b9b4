// Lightning for one frame (see flash_setup.hpp).
#include "flash_setup.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "sky_shared.h"

namespace sky::render {

namespace {

static_assert(gpu::kMaxFrameBoltSegments == weather::kMaxBoltSegments, "a frame draws a whole bolt");

glm::dvec3 toLocal(const geo::EnuFrame& camera, const geo::Vec3d& ecef) {
  const geo::Vec3d d = ecef - camera.originEcef_m;
  return {geo::dot(d, camera.east), geo::dot(d, camera.north), geo::dot(d, camera.up)};
}

struct Lit {
  const weather::LightningFlash* flash;
  double power_w;
  glm::dvec3 local;
  double atCamera;  // intensity / distance^2: how bright it is here
};

}  // namespace

FlashSetup prepareFlashes(std::span<const weather::LightningFlash> flashes, double clock_s, double exposure_s,
                          const geo::EnuFrame& camera, double pixelAngle_rad) {
  FlashSetup out;
  out.pixelAngle_rad = pixelAngle_rad;
  if (!(exposure_s > 0)) return out;
  std::vector<Lit> lit;
  for (const weather::LightningFlash& f : flashes) {
    const double p = weather::flashPower_w(f, clock_s - exposure_s, clock_s);
    if (!(p >= kMinFlashPower_w)) continue;
    const double height = f.kind == weather::FlashKind::CloudToGround ? f.top_m : 0.5 * (f.bottom_m + f.top_m);
    const glm::dvec3 local = toLocal(camera, geo::toEcef({f.lat_deg, f.lon_deg, height}));
    const double d2 = glm::dot(local, local);
    if (d2 > kMaxFlashDistance_m * kMaxFlashDistance_m) continue;
    lit.push_back({&f, p, local, p / std::max(d2, 1.0)});
  }
  std::sort(lit.begin(), lit.end(), [](const Lit& a, const Lit& b) { return a.atCamera > b.atCamera; });
  if (lit.size() > gpu::kMaxFrameFlashes) lit.resize(gpu::kMaxFrameFlashes);
  const double perSteradian = 1.0 / (4.0 * std::numbers::pi * kLinearUnitIrradiance_Wpm2);
  for (const Lit& l : lit) out.lights.push_back(glm::dvec4(l.local, l.power_w * perSteradian));

  const auto bolt = std::find_if(lit.begin(), lit.end(), [](const Lit& l) {
    return l.flash->kind == weather::FlashKind::CloudToGround;
  });
  if (bolt == lit.end()) return out;
  const weather::LightningFlash& f = *bolt->flash;
  const std::vector<weather::BoltSegment> segments = weather::boltSegments(f);
  double weightedLength = 0;
  for (const auto& s : segments)
    weightedLength += s.weight * std::hypot(s.b[0] - s.a[0], s.b[1] - s.a[1], s.b[2] - s.a[2]);
  if (!(weightedLength > 0)) return out;
  // The channel's frame: east, north, up at its ground point.
  const geo::EnuFrame ground = geo::enuFrameAt({f.lat_deg, f.lon_deg, f.bottom_m});
  auto at = [&](const double (&v)[3]) {
    return toLocal(camera, ground.originEcef_m + ground.east * v[0] + ground.north * v[1] + ground.up * v[2]);
  };
  const double perMetre = bolt->power_w * perSteradian / weightedLength;
  for (const auto& s : segments) {
    out.boltStart.push_back(glm::dvec4(at(s.a), perMetre * s.weight));
    out.boltEnd.push_back(at(s.b));
  }
  return out;
}

}  // namespace sky::render
