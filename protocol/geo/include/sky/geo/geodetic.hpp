// WGS84 geodesy shared by every process: geodetic <-> ECEF, local east-north-up
// frames, and a camera pose (CIGI's yaw/pitch/roll, NED body axes) as ECEF
// vectors. Everything is double precision; conversions go through
// GeographicLib, never hand-rolled formulas.
#pragma once

#include "sky/geo/vec3.hpp"

namespace sky::geo {

// WGS84 semi-major axis and flattening (NIMA TR8350.2), for documentation and
// sanity tests; the conversions use GeographicLib's own WGS84 constants.
inline constexpr double kWgs84A_m = 6378137.0;
inline constexpr double kWgs84F = 1.0 / 298.257223563;

struct Geodetic {
  double lat_deg = 0;  // geodetic latitude, [-90, 90]
  double lon_deg = 0;  // longitude, any value (normalised to [-180, 180) on output)
  double alt_m = 0;    // height above the WGS84 ellipsoid
};

// A camera or aircraft pose as CIGI's Entity Control gives it: yaw is the true
// heading (clockwise from north), then pitch (nose up +), then roll (right wing
// down +), applied in that order to the local north-east-down frame.
struct GeodeticPose {
  Geodetic position;
  double yaw_deg = 0;
  double pitch_deg = 0;
  double roll_deg = 0;
};

// Local tangent frame at a point: unit vectors in ECEF.
struct EnuFrame {
  Vec3d originEcef_m;
  Vec3d east, north, up;  // up = ellipsoid normal (geodetic vertical)
};

// Body axes of a pose as ECEF unit vectors (CIGI body convention: x forward,
// y right, z down).
struct BodyAxes {
  Vec3d posEcef_m;
  Vec3d forward, right, down;
};

// Three orthonormal axes (ECEF unit vectors): x forward, y right, z down.
struct Axes {
  Vec3d forward, right, down;
};

// `base` turned by yaw about its down axis, then pitch about the new right
// axis, then roll about the new forward axis (deg; the aerospace z-y-x
// sequence). bodyAxes is this applied to north, east, down.
Axes rotatedAxes(const Axes& base, double yaw_deg, double pitch_deg, double roll_deg);

Vec3d toEcef(const Geodetic& g);
Geodetic fromEcef(const Vec3d& ecef_m);
EnuFrame enuFrameAt(const Geodetic& g);
BodyAxes bodyAxes(const GeodeticPose& pose);

// Longitude normalised to [-180, 180) (GeographicLib's AngNormalize).
double normalizeLon_deg(double lon_deg);
// Signed smallest difference b - a of two angles, in (-180, 180].
double angleDiff_deg(double a_deg, double b_deg);

// Great-circle (on the ellipsoid: geodesic) distance between two points, m.
double geodesicDistance_m(double lat1_deg, double lon1_deg, double lat2_deg, double lon2_deg);
// Azimuth at point 1 of the geodesic to point 2 (clockwise from true north),
// deg in [-180, 180]; 0 when the points coincide (no direction exists).
double geodesicAzimuth_deg(double lat1_deg, double lon1_deg, double lat2_deg, double lon2_deg);

}  // namespace sky::geo
