// Unit tests of PoseSmoother against the FlightGear feed's known quirks
// (../shared/data/README.md): start-up repeats, stalls, a stray first packet,
// outliers, teleports, and the seams (antimeridian, heading wrap). Time is
// injected; tracks are straight lines built with sky::geo, so the truth at
// any time is a closed form.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>

#include <gtest/gtest.h>

#include "sky/app/pose_smoother.hpp"
#include "east_track.hpp"

namespace sky::app {
namespace {

using test::at;
using test::distance_m;
using test::EastTrack;
using test::kT0;

TEST(PoseSmoother, NothingBeforeAPositionIsConfirmed) {
  PoseSmoother s;
  EXPECT_FALSE(s.poseAt(at(0)));
  s.add(EastTrack{}.sample(0));
  EXPECT_FALSE(s.poseAt(at(0.1))) << "a single packet may be FlightGear's stray first one";
  s.add(EastTrack{}.sample(0.2));
  EXPECT_TRUE(s.poseAt(at(0.3)));
}

// FlightGear repeats the start position with airspeed 0 for ~15 s while the
// flight model starts, then flies off: the camera sits still exactly at the
// start, then moves off without a jump.
TEST(PoseSmoother, StartUpRepeatsHoldTheStartThenMoveOffSmoothly) {
  EastTrack track;
  PoseSmoother s;
  PoseSample still = track.sample(0);
  still.velocityNed_mps = geo::Vec3d{0, 0, 0};
  std::optional<geo::Geodetic> previous;
  double maxStep_m = 0;
  for (int i = 0; i < 500; ++i) {  // 25 s in 50 ms render steps
    const double t = i * 0.05;
    if (i % 4 == 0) {  // packets at 5 Hz
      if (t < 15) {
        still.receivedAt = at(t);
        s.add(still);
      } else {
        PoseSample moving = track.sample(t - 15);
        moving.receivedAt = at(t);
        s.add(moving);
      }
    }
    const auto p = s.poseAt(at(t));
    if (!p) continue;
    if (t < 15) {
      EXPECT_EQ(p->pose.position.lat_deg, still.pose.position.lat_deg) << t;
      EXPECT_EQ(p->pose.position.lon_deg, still.pose.position.lon_deg) << t;
      EXPECT_EQ(p->pose.position.alt_m, still.pose.position.alt_m) << t;
    }
    if (previous) maxStep_m = std::max(maxStep_m, distance_m(*previous, p->pose.position));
    previous = p->pose.position;
  }
  // 50 m/s for 50 ms is 2.5 m; allow the start of the motion some slack.
  EXPECT_LT(maxStep_m, 4.0);
  EXPECT_GT(distance_m(*previous, track.origin), 8.0 * track.speed_mps) << "the camera did not fly off";
}

// A 3 s stall: the camera keeps flying for maxExtrapolation_s on the packet's
// velocity, then holds; when packets resume it converges without a jump.
TEST(PoseSmoother, StallExtrapolatesForABoundedTimeThenHoldsThenConverges) {
  EastTrack track;
  PoseSmoother s;
  const PoseSmootherConfig& c = s.config();
  const double stallFrom = 5.0, stallTo = 8.0;
  std::optional<geo::Geodetic> previous;
  double maxStep_m = 0;
  for (int i = 0; i <= 240; ++i) {  // 12 s in 50 ms steps
    const double t = i * 0.05;
    if (i % 4 == 0 && (t <= stallFrom || t >= stallTo)) s.add(track.sample(t));
    const auto p = s.poseAt(at(t));
    if (!p) continue;
    const double r = t - c.renderDelay_s;
    if (previous) maxStep_m = std::max(maxStep_m, distance_m(*previous, p->pose.position));
    previous = p->pose.position;
    if (r < stallFrom + c.maxExtrapolation_s && t < stallTo) {
      // interpolation, then extrapolation on the true velocity: on the track
      EXPECT_LT(distance_m(p->pose.position, track.positionAt(r)), 0.5) << "t=" << t;
      if (r > stallFrom + 0.01) {
        EXPECT_EQ(p->mode, SmoothingMode::Extrapolated) << t;
      }
    } else if (t < stallTo && r > stallFrom + c.maxExtrapolation_s + 0.01) {
      EXPECT_EQ(p->mode, SmoothingMode::Held) << t;
      EXPECT_LT(distance_m(p->pose.position, track.positionAt(stallFrom + c.maxExtrapolation_s)), 0.5)
          << "held at the end of the bounded extrapolation, t=" << t;
    } else if (r > stallTo + 5 * c.convergenceTimeConstant_s) {
      EXPECT_LT(distance_m(p->pose.position, track.positionAt(r)), 1.0) << "converged, t=" << t;
    }
  }
  // Normal motion is 2.5 m per step; the catch-up after the stall covers the
  // held 50 m within a few time constants, never in one step.
  EXPECT_LT(maxStep_m, 12.0);
}

// FlightGear's very first packet can carry the default airport's position
// (KSFO) before the requested one applies: it is never shown.
TEST(PoseSmoother, StrayFirstPacketIsDiscarded) {
  EastTrack track;
  PoseSmoother s;
  PoseSample stray = track.sample(0);
  stray.pose.position = {37.6188, -122.3754, 4};
  s.add(stray);
  for (int i = 1; i <= 20; ++i) {
    s.add(track.sample(i * 0.2));
    const auto p = s.poseAt(at(i * 0.2));
    if (i == 1) {
      EXPECT_FALSE(p) << "one packet of the real track is not yet confirmed";
      continue;
    }
    ASSERT_TRUE(p);
    EXPECT_LT(distance_m(p->pose.position, track.positionAt(i * 0.2 - s.config().renderDelay_s)), 12.0);
  }
  EXPECT_EQ(s.outliersDropped(), 1u);
  EXPECT_EQ(s.teleports(), 0u);
}

TEST(PoseSmoother, SingleOutlierIsDiscarded) {
  EastTrack track;
  PoseSmoother s;
  double worst_m = 0;
  for (int i = 0; i <= 50; ++i) {
    PoseSample x = track.sample(i * 0.2);
    if (i == 20) x.pose.position.lat_deg += 0.5;  // ~55 km in 0.2 s
    s.add(x);
    if (const auto p = s.poseAt(at(i * 0.2)))
      worst_m = std::max(worst_m, distance_m(p->pose.position, track.positionAt(i * 0.2 - s.config().renderDelay_s)));
  }
  EXPECT_LT(worst_m, 12.0);
  EXPECT_EQ(s.outliersDropped(), 1u);
  EXPECT_EQ(s.teleports(), 0u);
}

// A repositioned aircraft: the jump is confirmed by the following packets and
// the camera goes there at once (no slow blend across 100 km).
TEST(PoseSmoother, TeleportConfirmedByFollowingPacketsIsAccepted) {
  EastTrack before, after;
  after.origin = {21.3, -157.9, 1500};
  PoseSmoother s;
  for (int i = 0; i <= 20; ++i) {
    s.add(before.sample(i * 0.2));
    s.poseAt(at(i * 0.2));
  }
  for (int i = 21; i <= 40; ++i) {
    s.add(after.sample(i * 0.2));
    const auto p = s.poseAt(at(i * 0.2));
    ASSERT_TRUE(p);
    if (i == 21) {
      EXPECT_LT(distance_m(p->pose.position, before.positionAt(4.2)), 20.0) << "one packet is not a teleport yet";
    } else {
      EXPECT_LT(distance_m(p->pose.position, after.positionAt(i * 0.2 - s.config().renderDelay_s)), 12.0) << i;
    }
  }
  EXPECT_EQ(s.teleports(), 1u);
  EXPECT_EQ(s.outliersDropped(), 0u);
}

// Irregular packets (jittered, with bursts), render calls at an irregular
// rate and one clock reading that goes back: render time never decreases and
// the camera never moves backwards along the track.
TEST(PoseSmoother, InterpolationIsMonotonicInTime) {
  EastTrack track;
  PoseSmoother s;
  const double packetTimes[] = {0.0, 0.11, 0.13, 0.35, 0.36, 0.52, 0.9, 0.95, 1.2, 1.21, 1.22, 1.6, 2.4, 2.5, 2.7};
  std::size_t next = 0;
  std::optional<SmoothedPose> previous;
  for (double t = 0; t < 3.0; t += 0.017) {
    while (next < std::size(packetTimes) && packetTimes[next] <= t) s.add(track.sample(packetTimes[next++]));
    for (double q : {t, t - 0.01}) {  // the second reading is earlier than the first
      const auto p = s.poseAt(at(q));
      if (!p) continue;
      if (previous) {
        EXPECT_GE(p->renderTime, previous->renderTime);
        const geo::EnuFrame f = geo::enuFrameAt(track.origin);
        const double along = geo::dot(geo::toEcef(p->pose.position) - f.originEcef_m, f.east);
        const double alongBefore = geo::dot(geo::toEcef(previous->pose.position) - f.originEcef_m, f.east);
        EXPECT_GE(along, alongBefore - 1e-6) << "t=" << t;
      }
      previous = p;
    }
  }
}

TEST(PoseSmoother, CrossesTheAntimeridianTheShortWay) {
  EastTrack track;
  track.origin = {-16.5, 179.995, 3000};  // Fiji, 530 m west of the antimeridian
  PoseSmoother s;
  std::optional<geo::Geodetic> previous;
  bool crossed = false;
  for (int i = 0; i <= 100; ++i) {  // 50 m/s for 20 s: 1 km each side
    const double t = i * 0.2;
    s.add(track.sample(t));
    for (double dt : {0.0, 0.05, 0.1, 0.15}) {
      const auto p = s.poseAt(at(t + dt));
      if (!p) continue;
      EXPECT_GT(std::abs(p->pose.position.lon_deg), 179.97) << "went the long way round, t=" << t;
      if (previous) {
        EXPECT_LT(distance_m(*previous, p->pose.position), 5.0) << t;
      }
      crossed = crossed || p->pose.position.lon_deg < 0;
      previous = p->pose.position;
    }
  }
  EXPECT_TRUE(crossed);
}

TEST(PoseSmoother, HeadingInterpolatesAlongTheShortestArc) {
  EastTrack track;
  track.speed_mps = 0;
  PoseSmoother s;
  PoseSample a = track.sample(0), b = track.sample(1.0);
  a.pose.yaw_deg = 359;
  b.pose.yaw_deg = 1;
  a.pose.roll_deg = -179;
  b.pose.roll_deg = 179;
  s.add(a);
  s.add(b);
  const auto p = s.poseAt(at(0.5 + s.config().renderDelay_s));
  ASSERT_TRUE(p);
  EXPECT_NEAR(std::abs(geo::angleDiff_deg(0, p->pose.yaw_deg)), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(p->pose.roll_deg), 180.0, 1e-9);
}

}  // namespace
}  // namespace sky::app
