// The eyepoint of a CIGI View Control composed onto an entity's pose
// (protocol/geo eyepoint.hpp), against geometry worked out by hand: offsets
// along the body axes, yaw/pitch/roll relative to the nose, and the inverse
// of bodyAxes.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "sky/geo/eyepoint.hpp"

namespace sky::geo {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Angle between two ECEF directions, deg.
double angle_deg(const Vec3d& a, const Vec3d& b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0, 1.0)) / kDeg;
}

TEST(Eyepoint, NoOffsetIsTheEntity) {
  const GeodeticPose entity{{47, 8, 1000}, 123, 7, -11};
  const GeodeticPose eye = eyepointPose(entity, {});
  EXPECT_NEAR(eye.position.lat_deg, 47, 1e-12);
  EXPECT_NEAR(eye.position.lon_deg, 8, 1e-12);
  EXPECT_NEAR(eye.position.alt_m, 1000, 1e-6);
  EXPECT_NEAR(eye.yaw_deg, 123, 1e-9);
  EXPECT_NEAR(eye.pitch_deg, 7, 1e-9);
  EXPECT_NEAR(eye.roll_deg, -11, 1e-9);
}

// A yaw offset of +60 deg looks 60 deg right of the nose: level flight
// heading 30 gives heading 90; banked and pitched, the eye's forward axis
// is the nose turned 60 deg about the body's down axis.
TEST(Eyepoint, YawOffsetLooksRightOfTheNose) {
  GeodeticPose eye = eyepointPose({{47, 8, 1000}, 30, 0, 0}, {0, 0, 0, 60, 0, 0});
  EXPECT_NEAR(eye.yaw_deg, 90, 1e-9);
  EXPECT_NEAR(eye.pitch_deg, 0, 1e-9);
  EXPECT_NEAR(eye.roll_deg, 0, 1e-9);
  eye = eyepointPose({{47, 8, 1000}, 350, 0, 0}, {0, 0, 0, -60, 0, 0});
  EXPECT_NEAR(eye.yaw_deg, -70, 1e-9);  // 290 deg

  const GeodeticPose banked{{-33, 151, 3000}, 200, 10, 25};
  const BodyAxes body = bodyAxes(banked);
  const BodyAxes seen = bodyAxes(eyepointPose(banked, {0, 0, 0, 60, 0, 0}));
  EXPECT_NEAR(angle_deg(seen.forward, body.forward), 60, 1e-9);
  EXPECT_NEAR(dot(seen.forward, body.right), std::sin(60 * kDeg), 1e-12);  // to the right
  EXPECT_NEAR(dot(seen.down, body.down), 1, 1e-12);                        // about the body's down axis
}

// Pitch and roll offsets: a pitch of +20 looks 20 deg above the nose; a roll
// of +90 puts the eye's right axis along the body's down axis.
TEST(Eyepoint, PitchAndRollOffsets) {
  const GeodeticPose level{{10, -70, 500}, 0, 0, 0};
  GeodeticPose eye = eyepointPose(level, {0, 0, 0, 0, 20, 0});
  EXPECT_NEAR(eye.pitch_deg, 20, 1e-9);
  EXPECT_NEAR(eye.yaw_deg, 0, 1e-9);
  const BodyAxes body = bodyAxes(level);
  const BodyAxes rolled = bodyAxes(eyepointPose(level, {0, 0, 0, 0, 0, 90}));
  EXPECT_NEAR(dot(rolled.right, body.down), 1, 1e-12);
}

// An x offset of 10 m moves the eye 10 m along the heading, y along the
// right wing, z down the body's down axis.
TEST(Eyepoint, OffsetsMoveAlongTheBodyAxes) {
  const GeodeticPose entity{{47, 8, 1000}, 45, 0, 0};
  const BodyAxes body = bodyAxes(entity);
  const Vec3d start = toEcef(entity.position);
  const GeodeticPose eye = eyepointPose(entity, {10, 0, 0, 0, 0, 0});
  const Vec3d moved = toEcef(eye.position) - start;
  EXPECT_NEAR(length(moved), 10, 1e-6);
  EXPECT_NEAR(dot(moved, body.forward), 10, 1e-6);
  EXPECT_NEAR(geodesicAzimuth_deg(47, 8, eye.position.lat_deg, eye.position.lon_deg), 45, 1e-4);
  const GeodeticPose side = eyepointPose(entity, {0, 4, -3, 0, 0, 0});
  const Vec3d sideMove = toEcef(side.position) - start;
  EXPECT_NEAR(dot(sideMove, body.right), 4, 1e-6);
  // z -3: 3 m up when level; 4 m sideways adds the curvature drop 4^2 / 2R = 1.3e-6 m.
  EXPECT_NEAR(side.position.alt_m, 1003, 1e-5);
  // The heading 10 m on is the heading here, to the meridians' convergence
  // over 10 m (1e-4 deg at 47 deg north).
  EXPECT_NEAR(eye.yaw_deg, 45, 1e-3);
}

TEST(Eyepoint, PoseFromAxesInvertsBodyAxes) {
  for (const GeodeticPose p : {GeodeticPose{{47, 8, 1000}, 123, 7, -11}, GeodeticPose{{-80, 179.9, 10}, -170, -45, 170},
                               GeodeticPose{{0, 0, 0}, 0, 89, 0}}) {
    const BodyAxes a = bodyAxes(p);
    const GeodeticPose back = poseFromAxes(p.position, a.forward, a.right, a.down);
    EXPECT_NEAR(back.yaw_deg, p.yaw_deg, 1e-7);
    EXPECT_NEAR(back.pitch_deg, p.pitch_deg, 1e-7);
    EXPECT_NEAR(back.roll_deg, p.roll_deg, 1e-7);
  }
}

}  // namespace
}  // namespace sky::geo
