// Geodesy against closed forms: WGS84 points whose ECEF coordinates are known
// exactly, body axes at known attitudes, and the vertical ray to a shell.
#include <cmath>

#include <gtest/gtest.h>

#include "sky/geo/geodetic.hpp"
#include "sky/geo/shell.hpp"

namespace sky::geo {
namespace {

TEST(Geodetic, EquatorAndPoleAreClosedForm) {
  const Vec3d eq = toEcef({0, 0, 0});
  EXPECT_NEAR(eq.x, kWgs84A_m, 1e-6);
  EXPECT_NEAR(eq.y, 0, 1e-6);
  const double b = kWgs84A_m * (1 - kWgs84F);  // polar semi-minor axis
  const Vec3d pole = toEcef({90, 0, 100});
  EXPECT_NEAR(pole.z, b + 100, 1e-6);
  EXPECT_NEAR(std::hypot(pole.x, pole.y), 0, 1e-6);
}

TEST(Geodetic, RoundTripAtTheSeams) {
  for (const Geodetic g : {Geodetic{89.9999, 179.9999, 400000}, Geodetic{-45, -179.9999, 10},
                           Geodetic{12.5, 180.0, 1000}, Geodetic{-90, 0, 0}}) {
    const Geodetic back = fromEcef(toEcef(g));
    EXPECT_NEAR(back.lat_deg, g.lat_deg, 1e-9);
    EXPECT_NEAR(back.alt_m, g.alt_m, 1e-6);
    if (std::abs(g.lat_deg) < 90) {
      EXPECT_NEAR(angleDiff_deg(back.lon_deg, g.lon_deg), 0, 1e-9);
    }
  }
}

TEST(Geodetic, BodyAxesFollowHeadingPitchRoll) {
  const Geodetic at{47, 8, 1000};
  const EnuFrame enu = enuFrameAt(at);
  // Heading 90 = east, level.
  BodyAxes a = bodyAxes({at, 90, 0, 0});
  EXPECT_NEAR(dot(a.forward, enu.east), 1, 1e-12);
  EXPECT_NEAR(dot(a.down, enu.up), -1, 1e-12);
  EXPECT_NEAR(dot(a.right, -enu.north), 1, 1e-12);
  // Pitch up 30 while heading north: forward rises by sin 30.
  a = bodyAxes({at, 0, 30, 0});
  EXPECT_NEAR(dot(a.forward, enu.up), 0.5, 1e-12);
  EXPECT_NEAR(dot(a.forward, enu.north), std::sqrt(3) / 2, 1e-12);
  // Roll right 90 heading north: right wing points down.
  a = bodyAxes({at, 0, 0, 90});
  EXPECT_NEAR(dot(a.right, enu.up), -1, 1e-12);
}

TEST(Shell, VerticalRaysMatchAltitudeDifferences) {
  const double R = 6371000.0 + 1500.0;  // shell radius
  const double h = 500.0;               // camera 500 m above the shell
  // Straight down: the shell is 500 m away.
  SphereSpan s = intersectSphere(R + h, h, -1.0);
  ASSERT_TRUE(s.hit);
  EXPECT_NEAR(s.tNear, h, 1e-6);
  EXPECT_NEAR(s.tFar, h + 2 * R, 1e-3);
  // Camera inside, looking up: exit at the shell 700 m above.
  s = intersectSphere(R - 700, -700, 1.0);
  ASSERT_TRUE(s.hit);
  EXPECT_NEAR(s.tFar, 700, 1e-6);
  EXPECT_LT(s.tNear, 0);
}

TEST(Shell, GrazingRayFromAboveTouchesAtTheHorizon) {
  // A camera 10 km above a sphere: the horizon ray (mu = -sqrt(1 - (R/r)^2))
  // is tangent, so both roots meet at the tangent distance sqrt(r^2 - R^2).
  const double R = 6371000.0, h = 10000.0, r = R + h;
  const double mu = -std::sqrt(1 - (R / r) * (R / r));
  const SphereSpan s = intersectSphere(r, h, mu * (1 + 1e-12));
  ASSERT_TRUE(s.hit);
  const double tangent = std::sqrt(h * (2 * R + h));
  EXPECT_NEAR(s.tNear, tangent, 50.0);
  EXPECT_NEAR(s.tFar, tangent, 50.0);
  EXPECT_FALSE(intersectSphere(r, h, mu + 1e-6).hit);
}

}  // namespace
}  // namespace sky::geo
