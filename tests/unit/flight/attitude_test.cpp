// Attitude derivation against closed forms: a circle flown at constant speed
// and turn rate banks at atan(v*omega/g) with the heading turning at omega; a
// straight climb pitches at atan(climb/speed); limits clamp; a stationary
// logger holds its heading. Also the civil-date arithmetic.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sky/flight/flight.hpp"

namespace sky::flight {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG_mps2 = 9.80665;
const geo::Geodetic kOrigin{46.0, 12.0, 1000.0};

// A fix at east/north metres from kOrigin in its tangent plane, altitude alt.
Fix fixAt(double t_s, double east_m, double north_m, double alt_m) {
  const geo::EnuFrame enu = geo::enuFrameAt(kOrigin);
  geo::Geodetic g = geo::fromEcef(enu.originEcef_m + enu.east * east_m + enu.north * north_m);
  g.alt_m = alt_m;
  return Fix{t_s, {g, 0, 0, 0}};
}

// Clockwise (dir = +1, a right turn) or counter-clockwise circle of radius R
// at speed v, one fix per second for duration.
Flight circle(double radius_m, double speed_mps, double dir, double duration_s) {
  Flight f;
  const double omega = speed_mps / radius_m;
  for (double t = 0; t <= duration_s; t += 1) {
    const double theta = dir * omega * t;  // bearing of the aircraft from the centre
    f.fixes.push_back(fixAt(t, radius_m * std::sin(theta), radius_m * std::cos(theta), 1000));
  }
  return f;
}

class CircleTest : public ::testing::TestWithParam<double> {};

TEST_P(CircleTest, BankAndHeadingMatchTheClosedForm) {
  const double dir = GetParam();
  const double radius_m = 200, speed_mps = 20, omega = speed_mps / radius_m;
  Flight f = circle(radius_m, speed_mps, dir, 200);  // three turns, through north each time
  deriveAttitude(f);
  const double bank_deg = dir * std::atan(speed_mps * omega / kG_mps2) * 180 / kPi;  // 11.53 deg
  // Near the ends the differences are one-sided and the windows narrow: the
  // turn-rate fit's half-width (15 s) + the bank average's (2.5 s) + 1 s.
  constexpr std::size_t kEdge = 18;
  for (std::size_t i = kEdge; i + kEdge < f.fixes.size(); ++i) {
    const double t = f.fixes[i].time_s;
    // Tangent to the circle: bearing from the centre + 90 deg (turning right).
    const double heading_deg = dir * (omega * t * 180 / kPi + 90);
    EXPECT_NEAR(geo::angleDiff_deg(heading_deg, f.fixes[i].pose.yaw_deg), 0, 0.01) << "t=" << t;
    // The chord speed is 2R sin(omega)/2 = 0.9983 v: bank within 0.05 deg.
    EXPECT_NEAR(f.fixes[i].pose.roll_deg, bank_deg, 0.05) << "t=" << t;
    EXPECT_NEAR(f.fixes[i].pose.pitch_deg, 0, 1e-6) << "t=" << t;
  }
}
INSTANTIATE_TEST_SUITE_P(RightAndLeft, CircleTest, ::testing::Values(1.0, -1.0));

TEST(Attitude, StraightClimbPitchesAtTheClimbAngle) {
  Flight f;
  const double speed_mps = 25, climb_mps = 2.5;
  for (int t = 0; t <= 60; ++t) f.fixes.push_back(fixAt(t, 0, speed_mps * t, 1000 + climb_mps * t));
  deriveAttitude(f);
  const double pitch_deg = std::atan2(climb_mps, speed_mps) * 180 / kPi;  // 5.71 deg
  for (const Fix& x : f.fixes) {
    EXPECT_NEAR(x.pose.pitch_deg, pitch_deg, 0.01) << "t=" << x.time_s;
    EXPECT_NEAR(geo::angleDiff_deg(0, x.pose.yaw_deg), 0, 0.01) << "t=" << x.time_s;
    EXPECT_NEAR(x.pose.roll_deg, 0, 0.01) << "t=" << x.time_s;
  }
}

TEST(Attitude, ClampsToTheStatedLimits) {
  Flight tight = circle(50, 50, 1, 30);  // tan(bank) = v^2/(R g) = 5.1: 79 deg
  deriveAttitude(tight);
  EXPECT_EQ(tight.fixes[15].pose.roll_deg, 60);
  Flight steep;
  for (int t = 0; t <= 10; ++t) steep.fixes.push_back(fixAt(t, 10.0 * t, 0, 1000 - 20.0 * t));  // 63 deg dive
  deriveAttitude(steep);
  EXPECT_EQ(steep.fixes[5].pose.pitch_deg, -30);
  EXPECT_NEAR(steep.fixes[5].pose.yaw_deg, 90, 0.01);  // east
}

TEST(Attitude, StationaryLoggerHoldsItsHeadingAndIsLevel) {
  Flight f;
  // Sits still (0.5 m jitter) for 10 s, then flies east at 10 m/s.
  for (int t = 0; t < 10; ++t) f.fixes.push_back(fixAt(t, (t % 2) * 0.5, 0, 500 + (t % 2)));
  for (int t = 10; t <= 30; ++t) f.fixes.push_back(fixAt(t, 10.0 * (t - 10), 0, 500));
  deriveAttitude(f);
  for (int t = 0; t < 8; ++t) {
    EXPECT_NEAR(f.fixes[t].pose.yaw_deg, 90, 1e-3) << "t=" << t;  // back-filled from the first movement
    EXPECT_EQ(f.fixes[t].pose.pitch_deg, 0) << "t=" << t;
    EXPECT_EQ(f.fixes[t].pose.roll_deg, 0) << "t=" << t;
  }
}

TEST(Attitude, DoesNotTurnAcrossAGap) {
  // East for 20 s, a 5-minute gap, then north: no bank is invented over the gap.
  Flight f;
  for (int t = 0; t <= 20; ++t) f.fixes.push_back(fixAt(t, 20.0 * t, 0, 800));
  for (int t = 320; t <= 340; ++t) f.fixes.push_back(fixAt(t, 400, 20.0 * (t - 320) + 1000, 800));
  deriveAttitude(f);
  for (const Fix& x : f.fixes) EXPECT_NEAR(x.pose.roll_deg, 0, 0.01) << "t=" << x.time_s;
  EXPECT_NEAR(f.fixes[20].pose.yaw_deg, 90, 0.01);
  EXPECT_NEAR(geo::angleDiff_deg(0, f.fixes[21].pose.yaw_deg), 0, 0.01);
}

TEST(Attitude, DaysFromCivil) {
  EXPECT_EQ(daysFromCivil(1970, 1, 1), 0);
  EXPECT_EQ(daysFromCivil(1969, 12, 31), -1);
  EXPECT_EQ(daysFromCivil(2000, 3, 1), 11017);
  EXPECT_EQ(daysFromCivil(2016, 4, 3), 16894);
  EXPECT_EQ(daysFromCivil(2020, 9, 4), 18509);
  EXPECT_EQ(daysFromCivil(1600, 1, 1), -135140);
}

}  // namespace
}  // namespace sky::flight
