// A straight track for the PoseSmoother tests: due east along the parallel
// through `origin` at speed_mps (ENU displacement at origin, close enough to a
// straight line over a few km), with time injected from kT0.
#pragma once

#include <chrono>

#include "sky/app/pose_smoother.hpp"
#include "sky/geo/geodetic.hpp"

namespace sky::app::test {

using Clock = std::chrono::steady_clock;
inline const SteadyTime kT0 = SteadyTime{} + std::chrono::hours(1);

inline SteadyTime at(double t_s) {
  return kT0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(t_s));
}

struct EastTrack {
  geo::Geodetic origin{20.6, -158.3, 900};
  double speed_mps = 50;
  geo::Geodetic positionAt(double t_s) const {
    const geo::EnuFrame f = geo::enuFrameAt(origin);
    return geo::fromEcef(geo::toEcef(origin) + f.east * (speed_mps * t_s));
  }
  PoseSample sample(double t_s) const {
    PoseSample s;
    s.receivedAt = at(t_s);
    s.pose.position = positionAt(t_s);
    s.pose.yaw_deg = 90;
    s.velocityNed_mps = geo::Vec3d{0, speed_mps, 0};
    return s;
  }
};

inline double distance_m(const geo::Geodetic& a, const geo::Geodetic& b) {
  return geo::length(geo::toEcef(a) - geo::toEcef(b));
}

}  // namespace sky::app::test
