// PoseSmoother under hostile or broken feeds (issue 18: no input can stop a
// channel): NaN, infinite and absurd positions, attitudes and velocities, and
// time stamps that go backwards or jump into the future. None may poison the
// smoother: the camera stays finite and on the good track, and recovers.
#include <array>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "sky/app/pose_smoother.hpp"
#include "east_track.hpp"

namespace sky::app {
namespace {

using test::at;
using test::distance_m;
using test::EastTrack;
using test::kT0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool finitePose(const geo::GeodeticPose& p) {
  return std::isfinite(p.position.lat_deg) && std::isfinite(p.position.lon_deg) && std::isfinite(p.position.alt_m) &&
         std::isfinite(p.yaw_deg) && std::isfinite(p.pitch_deg) && std::isfinite(p.roll_deg);
}

// Flies the track at 5 Hz for `seconds`, with `spoil` applied to sample i;
// returns the worst distance of the camera from the truth at render time.
template <class Spoil>
double flyWith(PoseSmoother& s, const EastTrack& track, int samples, Spoil spoil) {
  double worst_m = 0;
  for (int i = 0; i < samples; ++i) {
    PoseSample x = track.sample(i * 0.2);
    spoil(i, x);
    s.add(x);
    const auto p = s.poseAt(at(i * 0.2));
    if (!p) continue;
    EXPECT_TRUE(finitePose(p->pose)) << "sample " << i;
    worst_m = std::max(worst_m, distance_m(p->pose.position, track.positionAt(i * 0.2 - s.config().renderDelay_s)));
  }
  return worst_m;
}

// Each kind of garbage a decoder might let through, or a caller might hand
// in: dropped and counted, changing nothing.
TEST(PoseSmootherHostile, NonFiniteAndAbsurdValuesAreDroppedAndCounted) {
  const auto spoilers = std::to_array<void (*)(geo::GeodeticPose&)>({
      [](geo::GeodeticPose& p) { p.position.lat_deg = kNaN; },
      [](geo::GeodeticPose& p) { p.position.lat_deg = 1e30; },  // the example
      [](geo::GeodeticPose& p) { p.position.lon_deg = kInf; },
      [](geo::GeodeticPose& p) { p.position.lon_deg = -1e30; },
      [](geo::GeodeticPose& p) { p.position.alt_m = kNaN; },
      [](geo::GeodeticPose& p) { p.position.alt_m = 1e12; },
      [](geo::GeodeticPose& p) { p.yaw_deg = kNaN; },
      [](geo::GeodeticPose& p) { p.pitch_deg = -kInf; },
      [](geo::GeodeticPose& p) { p.pitch_deg = 91; },
      [](geo::GeodeticPose& p) { p.roll_deg = 1e30; },
  });
  for (std::size_t k = 0; k < spoilers.size(); ++k) {
    EastTrack track;
    PoseSmoother s;
    // Every fifth sample spoiled, including the very first one.
    const double worst_m = flyWith(s, track, 50, [&](int i, PoseSample& x) {
      if (i % 5 == 0) spoilers[k](x.pose);
    });
    EXPECT_EQ(s.invalidDropped(), 10u) << "spoiler " << k;
    EXPECT_EQ(s.outliersDropped(), 0u) << "spoiler " << k << ": garbage is not an outlier candidate";
    EXPECT_EQ(s.teleports(), 0u) << "spoiler " << k;
    EXPECT_LT(worst_m, 12.0) << "spoiler " << k;
  }
}

// A garbage-only feed never yields a pose (and never a NaN one).
TEST(PoseSmootherHostile, OnlyGarbageGivesNoPose) {
  PoseSmoother s;
  for (int i = 0; i < 20; ++i) {
    PoseSample x = EastTrack{}.sample(i * 0.1);
    x.pose.position.lat_deg = kNaN;
    EXPECT_FALSE(s.add(x));
    EXPECT_FALSE(s.poseAt(at(i * 0.1)));
  }
  EXPECT_EQ(s.invalidDropped(), 20u);
}

// A velocity that is NaN, infinite or faster than any aircraft is ignored
// (the track's own motion is used): the extrapolated camera stays finite and
// on the line instead of flying off.
TEST(PoseSmootherHostile, AbsurdVelocitiesAreIgnoredNotExtrapolated) {
  for (const double v : {kNaN, kInf, -kInf, 1e30, 5000.0}) {
    EastTrack track;
    PoseSmoother s;
    for (int i = 0; i < 10; ++i) {
      PoseSample x = track.sample(i * 0.2);
      x.velocityNed_mps = geo::Vec3d{v, v, v};
      EXPECT_TRUE(s.add(x));
      s.poseAt(at(i * 0.2));
    }
    // A stall: 1 s past the newest sample, extrapolated from the track (50 m/s east).
    const auto p = s.poseAt(at(1.8 + 1.0 + s.config().renderDelay_s));
    ASSERT_TRUE(p) << v;
    EXPECT_TRUE(finitePose(p->pose)) << v;
    EXPECT_LT(distance_m(p->pose.position, track.positionAt(2.8)), 5.0) << v;
    EXPECT_EQ(s.invalidDropped(), 0u);
  }
}

// Stamps a little out of order (reordered packets) are moved after the
// newest; the render time never goes back and the camera stays on the line.
TEST(PoseSmootherHostile, SlightlyBackwardsStampsKeepTheTrack) {
  EastTrack track;
  PoseSmoother s;
  std::optional<SteadyTime> lastRender;
  for (int i = 0; i < 40; ++i) {
    PoseSample x = track.sample(i * 0.2);
    if (i % 4 == 3) x.receivedAt = at(i * 0.2 - 0.5);  // 0.3 s before the previous one
    s.add(x);
    const auto p = s.poseAt(at(i * 0.2));
    if (!p) continue;
    EXPECT_TRUE(finitePose(p->pose));
    if (lastRender) {
      EXPECT_GE(p->renderTime, *lastRender);
    }
    lastRender = p->renderTime;
    EXPECT_LT(distance_m(p->pose.position, track.positionAt(i * 0.2 - s.config().renderDelay_s)), 40.0) << i;
  }
  EXPECT_EQ(s.teleports(), 0u);
}

// One stamp an hour in the future, then the clock carries on as before: the
// bogus stamp must not freeze the camera until that hour has passed. The
// samples in the old time base confirm a new track (a teleport in time) and
// the camera moves with them again.
TEST(PoseSmootherHostile, AFutureStampThenTimeGoingBackwardsRecovers) {
  EastTrack track;
  PoseSmoother s;
  for (int i = 0; i < 10; ++i) {
    s.add(track.sample(i * 0.2));
    s.poseAt(at(i * 0.2));
  }
  PoseSample bogus = track.sample(2.0);
  bogus.receivedAt = at(3600);
  s.add(bogus);
  s.poseAt(at(2.0));
  double lastError_m = 1e9;
  for (int i = 11; i < 30; ++i) {
    s.add(track.sample(i * 0.2));
    const auto p = s.poseAt(at(i * 0.2));
    ASSERT_TRUE(p);
    EXPECT_TRUE(finitePose(p->pose));
    lastError_m = distance_m(p->pose.position, track.positionAt(i * 0.2 - s.config().renderDelay_s));
  }
  EXPECT_LT(lastError_m, 12.0) << "the camera follows the track again";
  EXPECT_EQ(s.teleports(), 1u);
}

// A single stamp far in the past (a bogus clock) is a candidate that the next
// good sample shows to be an outlier; the track goes on undisturbed.
TEST(PoseSmootherHostile, ASinglePastStampIsAnOutlier) {
  EastTrack track;
  PoseSmoother s;
  const double worst_m = flyWith(s, track, 40, [](int i, PoseSample& x) {
    if (i == 20) x.receivedAt = at(-3600);
  });
  EXPECT_LT(worst_m, 12.0);
  EXPECT_EQ(s.outliersDropped(), 1u);
  EXPECT_EQ(s.teleports(), 0u);
}

// The render clock going backwards (a caller's bug, or a steady clock of
// another process) never moves the render time back nor yields NaN.
TEST(PoseSmootherHostile, RenderTimeGoingBackwardsHolds) {
  EastTrack track;
  PoseSmoother s;
  for (int i = 0; i < 10; ++i) s.add(track.sample(i * 0.2));
  const auto a = s.poseAt(at(1.8));
  const auto b = s.poseAt(at(0.5));
  const auto c = s.poseAt(at(-3600));
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(b->renderTime, a->renderTime);
  EXPECT_EQ(c->renderTime, a->renderTime);
  EXPECT_TRUE(finitePose(c->pose));
  EXPECT_LT(distance_m(c->pose.position, a->pose.position), 1e-6);
}

}  // namespace
}  // namespace sky::app
