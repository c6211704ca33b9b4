// X-Plane FDR reader: hand-made files in X-Plane's FDR text layout
// (tests/data/fdr; version 4 rows with attitude across midnight UTC, and
// version 2 DATA rows) with the values expected worked out by hand, and
// in-test files for the errors (line and field named).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sky/flight/flight.hpp"
#include "warnings.hpp"

namespace sky::flight {
namespace {

constexpr double kFt = 0.3048;

std::string readData(const std::string& name) {
  std::ifstream in(std::string(SKY_FDR_DATA_DIR) + "/" + name, std::ios::binary);
  EXPECT_TRUE(in) << name;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Fdr, Version4RowsGiveTheFilesPitchAndRollAcrossMidnight) {
  const auto f = parseFlight(readData("xplane-v4.fdr"), "xplane-v4.fdr");
  ASSERT_TRUE(f) << f.error().detail;
  // Rows at 23:59:58.5, 23:59:59.5, (23:59:59.5 again: skipped), then
  // 00:00:00.5 and 00:00:01.5 of the next day.
  ASSERT_EQ(f->fixes.size(), 4u) << allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "xplane-v4.fdr:16: field 'time': same as the previous fix")) << allWarnings(*f);
  // DATE 03/10/2024 (US order): 2024-03-10 is Unix day 19792 (2024-01-01 is
  // day 19723, plus 31 + 29 + 9); the first row, 23:59:58.5, is
  // 23 * 3600 + 59 * 60 + 58.5 = 86398.5 s into it.
  EXPECT_EQ(f->startUtc_s, (19723 + 31 + 29 + 9) * std::int64_t{86400} + 86398);
  const double times[] = {0.5, 1.5, 2.5, 3.5};
  const double lons[] = {-122.0, -121.999, -121.998, -121.997};
  const double altsFt[] = {1000, 1010, 1020, 1030};
  const double pitches[] = {2.0, 2.5, 3.0, 3.5};
  const double rolls[] = {-1.5, -2.0, 5.0, 10.0};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(f->fixes[i].time_s, times[i]) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.lat_deg, 37.5) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.lon_deg, lons[i]) << i;
    EXPECT_NEAR(f->fixes[i].pose.position.alt_m, altsFt[i] * kFt, 1e-9) << i;
    // The file's attitude, not the track's (which would be level flight).
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.pitch_deg, pitches[i]) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.roll_deg, rolls[i]) << i;
    // Yaw from the track (the file's 95 is magnetic): due east along the
    // parallel, 90 within a few thousandths of a degree.
    EXPECT_NEAR(f->fixes[i].pose.yaw_deg, 90.0, 0.01) << i;
  }
  EXPECT_NE(f->altitudeSource.find("pitch and roll from the file"), std::string::npos) << f->altitudeSource;
  // Lines of the kept rows (16 was the repeat); the file's attitude is kept
  // by the cleaning (not derived again).
  EXPECT_EQ(f->fixLines, (std::vector<std::size_t>{14, 15, 17, 18}));
  EXPECT_FALSE(f->attitudeFromTrack);
  EXPECT_EQ(f->aircraft, "tail N12345");
}

TEST(Fdr, Version2DataRowsGivePositionAndTheTrackTheAttitude) {
  const auto f = parseFlight(readData("xplane-v2-data.fdr"), "v2.fdr");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 3u) << allWarnings(*f);
  // DATE 07/04/05 is 2005-07-04: 2005-01-01 is Unix day 35 * 365 + 9 leap
  // days = 12784, plus 181 days (January to June) and 3; TIME 12:00:00.
  EXPECT_EQ(f->startUtc_s, (12784 + 181 + 3) * std::int64_t{86400} + 12 * 3600);
  const double lats[] = {40.000, 40.001, 40.002};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(f->fixes[i].time_s, 2.0 * static_cast<double>(i)) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.lat_deg, lats[i]) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.lon_deg, -105.0) << i;
    EXPECT_NEAR(f->fixes[i].pose.position.alt_m, (6000 + 10 * static_cast<double>(i)) * kFt, 1e-9) << i;
  }
  // Due north, climbing 10 ft (3.048 m) per 0.001 deg of latitude (111.0 m
  // at 40 N): pitch atan(3.048 / 111.0) = 1.57 deg; wings level.
  const double yaw = f->fixes[1].pose.yaw_deg;
  EXPECT_LT(std::min(yaw, 360.0 - yaw), 0.01) << yaw;
  EXPECT_NEAR(f->fixes[1].pose.pitch_deg, 1.57, 0.02);
  EXPECT_NEAR(f->fixes[1].pose.roll_deg, 0.0, 0.01);
  EXPECT_TRUE(anyWarningHas(*f, "v2.fdr:10: not a header or DATA row")) << allWarnings(*f);
  EXPECT_TRUE(f->attitudeFromTrack);
}

TEST(Fdr, ErrorsNameLineAndField) {
  const auto expectError = [](const std::string& text, const std::string& needle, ErrorCode code) {
    const auto f = parseFdr(text, "e.fdr");
    ASSERT_FALSE(f) << text;
    EXPECT_EQ(f.error().code, code) << f.error().detail;
    EXPECT_NE(f.error().detail.find(needle), std::string::npos) << f.error().detail;
  };
  const std::string head = "A\n4\nDATE, 03/10/2024\n";
  expectError("X\n4\n", "e.fdr:1: field 'line ending'", ErrorCode::Malformed);
  expectError("A\n5\n", "e.fdr:2: field 'version': '5'", ErrorCode::Unsupported);
  expectError(head + "10:00:00, 1, 2, 3, 4, 5\n", "e.fdr:4: 6 columns", ErrorCode::Malformed);
  expectError(head + "10:00:00, 1, 95, 3, 4, 5, 6\n", "e.fdr:4: field 'latitude': 95",
              ErrorCode::InvalidArgument);
  expectError(head + "10:00:00, 1, 2, 3, 4, 120, 6\n", "e.fdr:4: field 'pitch'", ErrorCode::InvalidArgument);
  expectError(head + "10:00:00, x, 2, 3, 4, 5, 6\n", "e.fdr:4: field 'longitude': 'x' is not a number",
              ErrorCode::Malformed);
  expectError(head + "10:0:00, 1, 2, 3, 4, 5, 6\n", "e.fdr:4: field 'time': '10:0:00' is neither",
              ErrorCode::Malformed);
  expectError(head + "10:00:00, 1, 2, 3, 4, 5, 6\n5, 1, 2, 3, 4, 5, 6\n", "mix zulu times", ErrorCode::Malformed);
  expectError(head + "10:00:00, 1, 2, 3, 4, 5, 6\n", "1 usable data rows", ErrorCode::InvalidArgument);
}

TEST(Fdr, AnUnreadableDateIsAWarningAndNoStartDate) {
  const auto f = parseFdr("A\n4\nDATE, 18/01/2023\n10:00:00, 1, 2, 3, 4, 5, 6\n10:00:01, 1.0001, 2, 3, 4, 5, 6\n",
                          "d.fdr");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_FALSE(f->startUtc_s);
  EXPECT_TRUE(anyWarningHas(*f, "d.fdr:3: field 'DATE': '18/01/2023' is not MM/DD/YY")) << allWarnings(*f);
}

}  // namespace
}  // namespace sky::flight
