// An eyepoint fixed to an entity, as CIGI 3.3 View Control places a view: an
// offset along the entity's body axes and a rotation relative to them,
// composed onto the entity's pose to give the camera's own geodetic pose.
// Shared by the renderer and anything that checks where a channel looks.
#pragma once

#include "sky/geo/geodetic.hpp"

namespace sky::geo {

// View Control's eyepoint: x forward, y right, z down (m, the entity's body
// axes); yaw (right +), then pitch (up +), then roll (right side down +)
// relative to the entity's body axes, deg, the same z-y-x sequence as a
// pose's yaw/pitch/roll in its local north-east-down frame.
struct EyepointOffset {
  double x_m = 0, y_m = 0, z_m = 0;
  double yaw_deg = 0, pitch_deg = 0, roll_deg = 0;
};

// The camera pose of an eyepoint on `entity` (finite values; any angles):
// its position (offset along the entity's body axes, in ECEF, back to
// geodetic) and its yaw/pitch/roll in the local frame at that position.
// Yaw comes back in (-180, 180], pitch in [-90, 90], roll in (-180, 180];
// looking straight up or down (pitch +-90) the yaw and roll split is the
// one atan2 gives.
GeodeticPose eyepointPose(const GeodeticPose& entity, const EyepointOffset& offset);

// The yaw/pitch/roll (deg) of orthonormal body axes (ECEF) at `position`:
// the inverse of bodyAxes there.
GeodeticPose poseFromAxes(const Geodetic& position, const Vec3d& forward, const Vec3d& right, const Vec3d& down);

}  // namespace sky::geo
