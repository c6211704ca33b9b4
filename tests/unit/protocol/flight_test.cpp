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
  EXPECT_NEAR(mid.yaw_deg, 0.0, 1e-9);  // 350 -> 10 passes through north
  EXPECT_NEAR(mid.roll_deg, -5, 1e-9);
  EXPECT_EQ(sample(*f, -1).position.alt_m, 1000);
  EXPECT_EQ(sample(*f, 99).position.alt_m, 1100);
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
  const auto kml = parseFlight(csv, "a.kml");
  ASSERT_FALSE(kml);
  EXPECT_NE(kml.error().detail.find("'.kml'"), std::string::npos);
}

}  // namespace
}  // namespace sky::flight
