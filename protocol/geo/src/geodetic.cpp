// WGS84 conversions through GeographicLib (Geocentric, Math, Geodesic).
#include "sky/geo/geodetic.hpp"

#include <cmath>
#include <numbers>

#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/Math.hpp>

namespace sky::geo {

namespace {
constexpr double kDegToRad = std::numbers::pi / 180.0;
}

Vec3d toEcef(const Geodetic& g) {
  Vec3d out;
  GeographicLib::Geocentric::WGS84().Forward(g.lat_deg, g.lon_deg, g.alt_m, out.x, out.y, out.z);
  return out;
}

Geodetic fromEcef(const Vec3d& ecef_m) {
  Geodetic g;
  GeographicLib::Geocentric::WGS84().Reverse(ecef_m.x, ecef_m.y, ecef_m.z, g.lat_deg, g.lon_deg,
                                             g.alt_m);
  return g;
}

EnuFrame enuFrameAt(const Geodetic& g) {
  // GeographicLib returns the rotation M (row-major) whose columns are the
  // east, north and up unit vectors in ECEF.
  std::vector<double> m(9);
  EnuFrame f;
  GeographicLib::Geocentric::WGS84().Forward(g.lat_deg, g.lon_deg, g.alt_m, f.originEcef_m.x,
                                             f.originEcef_m.y, f.originEcef_m.z, m);
  f.east = {m[0], m[3], m[6]};
  f.north = {m[1], m[4], m[7]};
  f.up = {m[2], m[5], m[8]};
  return f;
}

Axes rotatedAxes(const Axes& base, double yaw_deg, double pitch_deg, double roll_deg) {
  const double cy = std::cos(yaw_deg * kDegToRad), sy = std::sin(yaw_deg * kDegToRad);
  const double cp = std::cos(pitch_deg * kDegToRad), sp = std::sin(pitch_deg * kDegToRad);
  const double cr = std::cos(roll_deg * kDegToRad), sr = std::sin(roll_deg * kDegToRad);
  // Yaw about down, then pitch about the new right axis, then roll about the
  // new forward axis.
  const Vec3d f1 = base.forward * cy + base.right * sy;
  const Vec3d r1 = base.right * cy - base.forward * sy;
  const Vec3d forward = f1 * cp - base.down * sp;
  const Vec3d d2 = base.down * cp + f1 * sp;
  return {forward, r1 * cr + d2 * sr, d2 * cr - r1 * sr};
}

BodyAxes bodyAxes(const GeodeticPose& pose) {
  const EnuFrame enu = enuFrameAt(pose.position);
  const Axes a = rotatedAxes({enu.north, enu.east, -enu.up}, pose.yaw_deg, pose.pitch_deg, pose.roll_deg);
  return {enu.originEcef_m, a.forward, a.right, a.down};
}

double normalizeLon_deg(double lon_deg) {
  const double n = GeographicLib::Math::AngNormalize(lon_deg);
  return n == 180.0 ? -180.0 : n;
}

double angleDiff_deg(double a_deg, double b_deg) { return GeographicLib::Math::AngDiff(a_deg, b_deg); }

double geodesicDistance_m(double lat1_deg, double lon1_deg, double lat2_deg, double lon2_deg) {
  double s12 = 0;
  GeographicLib::Geodesic::WGS84().Inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg, s12);
  return s12;
}

double geodesicAzimuth_deg(double lat1_deg, double lon1_deg, double lat2_deg, double lon2_deg) {
  if (lat1_deg == lat2_deg && lon1_deg == lon2_deg) return 0.0;
  double azi1 = 0, azi2 = 0;
  GeographicLib::Geodesic::WGS84().Inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg, azi1, azi2);
  return azi1;
}

}  // namespace sky::geo
