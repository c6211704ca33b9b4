// CSV flights: the documented format parses; every error names line and
// field; sampling interpolates positions and wraps angles the short way.
#include <gtest/gtest.h>

#include "sky/flight/flight.hpp"

namespace sky::flight {
namespace {

const char* kGood =
    "# a short test flight\n"
    "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n"
    "0,46.0,12.0,1000,350,0,0\n"
    "\n"
    "10,46.0,12.01,1100,10,2,-10\r\n";

TEST(FlightCsv, ParsesTheDocumentedFormat) {
  auto f = parseCsv(kGood, "good.csv");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_EQ(f->fixes[1].pose.position.lon_deg, 12.01);
  EXPECT_EQ(f->duration_s(), 10);
}

TEST(FlightCsv, ErrorsNameLineAndField) {
  auto expectError = [](const std::string& text, const std::string& needle) {
    auto f = parseCsv(text, "bad.csv");
    ASSERT_FALSE(f);
    EXPECT_NE(f.error().detail.find(needle), std::string::npos) << f.error().detail;
  };
  const std::string header = "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n";
  expectError("time,lat\n", "bad.csv:1: header");
  expectError(header + "0,46,12,1000,0,0,0\n1,4x6,12,1000,0,0,0\n", "bad.csv:3: field 'lat_deg': '4x6'");
  expectError(header + "0,46,12,1000,0,0,0\n1,46,12,1000,0,95,0\n", "bad.csv:3: field 'pitch_deg'");
  expectError(header + "0,46,12,1000,0,0,0\n0,46,12,1000,0,0,0\n", "bad.csv:3: field 'time_s'");
  expectError(header + "0,46,12,1000,0,0\n", "bad.csv:2: 6 fields");
  expectError(header + "0,46,12,1000,0,0,0\n", "at least two fixes");
}

TEST(FlightCsv, SampleInterpolatesAndWrapsHeading) {
  auto f = parseCsv(kGood, "good.csv");
  ASSERT_TRUE(f);
  const geo::GeodeticPose mid = sample(*f, 5);
  EXPECT_NEAR(mid.position.lon_deg, 12.005, 1e-6);
  EXPECT_NEAR(mid.position.alt_m, 1050, 1e-6);
  // 350 -> 10 passes through north. Heading and bank change together here, so
  // the slerped attitude is not exactly the two half angles: for changes this
  // small they agree to second order (0.04 and 0.09 degrees here).
  EXPECT_NEAR(mid.yaw_deg, 0.0, 0.1);
  EXPECT_NEAR(mid.roll_deg, -5, 0.1);
  EXPECT_EQ(sample(*f, -1).position.alt_m, 1000);
  EXPECT_EQ(sample(*f, 99).position.alt_m, 1100);
}

// Hand-worked attitudes: between two attitudes that differ by a rotation
// about one body axis, the midpoint is the half rotation about it (exact for
// slerp); across north and across a roll of 180 it takes the short way.
TEST(FlightSample, AttitudeBySlerp) {
  auto fix = [](double t, double yaw, double pitch, double roll) {
    Fix f;
    f.time_s = t;
    f.pose.position = {10, 20, 1000};
    f.pose.yaw_deg = yaw;
    f.pose.pitch_deg = pitch;
    f.pose.roll_deg = roll;
    return f;
  };
  Flight f;
  f.fixes = {fix(0, 350, 0, 30), fix(1, 10, 0, 30),  fix(2, 10, 0, -30), fix(3, 10, 80, -30),
             fix(4, 10, 80, -170), fix(5, 10, 80, 170)};
  // Heading alone, wings banked 30 throughout: yaw is the first of the three
  // rotations, so this is one rotation about the local vertical.
  const auto turn = sample(f, 0.5);
  EXPECT_NEAR(std::fmod(turn.yaw_deg + 180.0, 360.0) - 180.0, 0.0, 1e-9);
  EXPECT_NEAR(turn.pitch_deg, 0.0, 1e-9);
  EXPECT_NEAR(turn.roll_deg, 30.0, 1e-9);
  // Bank alone: 30 -> -30 passes through wings level.
  const auto level = sample(f, 1.5);
  EXPECT_NEAR(level.yaw_deg, 10.0, 1e-9);
  EXPECT_NEAR(level.pitch_deg, 0.0, 1e-9);
  EXPECT_NEAR(level.roll_deg, 0.0, 1e-9);
  // Pitch alone with the wings banked: qa^-1 qb = Rx(30) Ry(80) Rx(-30), one
  // rotation by 80 degrees, whose half lands on pitch 40 with the same bank.
  const auto climb = sample(f, 2.5);
  EXPECT_NEAR(climb.pitch_deg, 40.0, 1e-9);
  EXPECT_NEAR(climb.yaw_deg, 10.0, 1e-9);
  EXPECT_NEAR(climb.roll_deg, -30.0, 1e-9);
  // Roll across 180: -170 -> 170 passes through 180, not through 0.
  const auto inverted = sample(f, 4.5);
  EXPECT_NEAR(std::abs(inverted.roll_deg), 180.0, 1e-6);
  EXPECT_NEAR(inverted.pitch_deg, 80.0, 1e-6);
  for (double t = 0; t <= 5; t += 0.01) {
    const auto p = sample(f, t);
    EXPECT_TRUE(std::isfinite(p.yaw_deg) && std::isfinite(p.pitch_deg) && std::isfinite(p.roll_deg)) << t;
    EXPECT_GE(p.yaw_deg, 0.0);
    EXPECT_LT(p.yaw_deg, 360.0);
  }
}

// Over the pole the track's heading jumps from 0 (north, on 170W) to 180
// (south, on 10E), yet the aircraft flies straight: between the two fixes the
// camera must keep looking along the meridian plane (level, nose along the
// track), not swing through east or west as a heading interpolation would.
TEST(FlightSample, AttitudeIsContinuousOverThePole) {
  Flight f;
  Fix a, b;
  a.time_s = 0;
  a.pose.position = {89.99, -170.0, 10000};
  a.pose.yaw_deg = 0;
  b.time_s = 9;
  b.pose.position = {89.99, 10.0, 10000};
  b.pose.yaw_deg = 180;
  f.fixes = {a, b};
  // Nose direction in ECEF at each sample: consecutive samples turn little.
  auto nose = [](const geo::GeodeticPose& p) {
    const geo::EnuFrame e = geo::enuFrameAt(p.position);
    const double y = p.yaw_deg * 3.14159265358979323846 / 180, c = std::cos(p.pitch_deg * 3.14159265358979323846 / 180);
    return e.north * (std::cos(y) * c) + e.east * (std::sin(y) * c) +
           e.up * std::sin(p.pitch_deg * 3.14159265358979323846 / 180);
  };
  const geo::Vec3d start = nose(sample(f, 0));
  for (double t = 0; t <= 9; t += 0.25) {
    const auto p = sample(f, t);
    // Both fixes look along the same great circle (the 170W/10E meridian
    // plane): every sample must too, within 0.01 degrees.
    EXPECT_NEAR(geo::dot(nose(p), start), 1.0, 1e-6) << "t=" << t << " yaw " << p.yaw_deg;
    EXPECT_NEAR(p.pitch_deg, 0.0, 0.01) << t;
    EXPECT_NEAR(p.roll_deg, 0.0, 0.01) << t;
  }
}

TEST(FlightFile, FormatFollowsTheExtensionInAnyCase) {
  const std::string csv = "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n0,1,2,3,0,0,0\n1,1,2,3,0,0,0\n";
  EXPECT_TRUE(parseFlight(csv, "dir.v2/a.CSV"));
  // The same text as IGC has no B records: the IGC reader's error, not CSV's success.
  EXPECT_FALSE(parseFlight(csv, "a.igc"));
  const auto unknown = parseFlight(csv, "dir.csv/flight");
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::Unsupported);
  EXPECT_NE(unknown.error().detail.find("dir.csv/flight"), std::string::npos);
  // The same text as KML is not XML: the KML reader's error.
  const auto kml = parseFlight(csv, "a.KML");
  ASSERT_FALSE(kml);
  EXPECT_NE(kml.error().code, ErrorCode::Unsupported);
  // FlightGear's tapes are not read (flight.hpp says why).
  const auto tape = parseFlight(csv, "a.fgtape");
  ASSERT_FALSE(tape);
  EXPECT_EQ(tape.error().code, ErrorCode::Unsupported);
  EXPECT_NE(tape.error().detail.find("'.fgtape'"), std::string::npos);
}

}  // namespace
}  // namespace sky::flight
