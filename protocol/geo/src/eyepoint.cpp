// Eyepoint composition (see eyepoint.hpp).
#include "sky/geo/eyepoint.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sky::geo {

namespace {
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
}  // namespace

GeodeticPose poseFromAxes(const Geodetic& position, const Vec3d& forward, const Vec3d& right, const Vec3d& down) {
  const EnuFrame enu = enuFrameAt(position);
  const Vec3d localDown = -enu.up;
  // The rows of the body-to-NED rotation's z-y-x decomposition: forward's
  // north/east/down components give yaw and pitch, the right and down axes'
  // down components the roll.
  const double fNorth = dot(forward, enu.north), fEast = dot(forward, enu.east), fDown = dot(forward, localDown);
  GeodeticPose pose;
  pose.position = position;
  pose.yaw_deg = std::atan2(fEast, fNorth) * kRadToDeg;
  pose.pitch_deg = std::asin(std::clamp(-fDown, -1.0, 1.0)) * kRadToDeg;
  pose.roll_deg = std::atan2(dot(right, localDown), dot(down, localDown)) * kRadToDeg;
  return pose;
}

GeodeticPose eyepointPose(const GeodeticPose& entity, const EyepointOffset& o) {
  const BodyAxes body = bodyAxes(entity);
  const Vec3d eyeEcef_m = body.posEcef_m + body.forward * o.x_m + body.right * o.y_m + body.down * o.z_m;
  // The view's rotation applied in the body frame: the same sequence as
  // bodyAxes applies in north-east-down, with the body axes in their place.
  const Axes view = rotatedAxes({body.forward, body.right, body.down}, o.yaw_deg, o.pitch_deg, o.roll_deg);
  return poseFromAxes(fromEcef(eyeEcef_m), view.forward, view.right, view.down);
}

}  // namespace sky::geo
