// readsb / tar1090 trace reader: a hand-made trace in readsb's documented
// row layout (tests/data/readsb, one row per case) read plain and gzip'd,
// with the values expected worked out by hand from the file; and in-test
// traces for the errors (JSON path and field named) and the bounds.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "sky/flight/flight.hpp"
#include "warnings.hpp"

namespace sky::flight {
namespace {

constexpr double kFt = 0.3048;
// ICAO Doc 7488/3: r0 relating geopotential and geometric height.
constexpr double kR0_m = 6356766.0;

std::string readData(const std::string& name) {
  std::ifstream in(std::string(SKY_READSB_DATA_DIR) + "/" + name, std::ios::binary);
  EXPECT_TRUE(in) << name;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void expectHandMadeTrace(const ParsedFlight& f) {
  // Kept: rows 1, 2, 3 and 6 (base 1700000000.5 + 10, 20, 30, 50 s).
  // Skipped: 0 (ground, no alt_geom), 4 (null position), 5 (stale),
  // 7 (same time as 6), 8 (null altitude).
  ASSERT_EQ(f.fixes.size(), 4u) << allWarnings(f);
  EXPECT_EQ(f.startUtc_s, 1700000010);  // floor(1700000010.5)
  EXPECT_DOUBLE_EQ(f.fixes[0].time_s, 0.5);
  EXPECT_DOUBLE_EQ(f.fixes[1].time_s, 10.5);
  EXPECT_DOUBLE_EQ(f.fixes[2].time_s, 20.5);
  EXPECT_DOUBLE_EQ(f.fixes[3].time_s, 40.5);
  EXPECT_DOUBLE_EQ(f.fixes[0].pose.position.lat_deg, 50.001);
  EXPECT_DOUBLE_EQ(f.fixes[0].pose.position.lon_deg, 8.49);
  EXPECT_DOUBLE_EQ(f.fixes[3].pose.position.lat_deg, 50.005);
  EXPECT_DOUBLE_EQ(f.fixes[3].pose.position.lon_deg, 8.45);
  // Row 1: alt_geom 1100 ft wins over the barometric 1000 ft.
  EXPECT_NEAR(f.fixes[0].pose.position.alt_m, 1100 * kFt, 1e-9);
  // Row 2: barometric 1500 ft = 457.2 m of pressure altitude; at QNH
  // 1013.25 that is geopotential 457.2 m, geometric r0 h / (r0 - h)
  // = 457.2 * 6356766 / 6356308.8 = 457.2329 m.
  EXPECT_NEAR(f.fixes[1].pose.position.alt_m, 1500 * kFt * kR0_m / (kR0_m - 1500 * kFt), 1e-6);
  EXPECT_NEAR(f.fixes[1].pose.position.alt_m, 457.2329, 1e-4);
  // Row 3: flags 8, so column 3's 2000 ft is geometric.
  EXPECT_NEAR(f.fixes[2].pose.position.alt_m, 2000 * kFt, 1e-9);
  // Row 6: alt_geom 2600 ft.
  EXPECT_NEAR(f.fixes[3].pose.position.alt_m, 2600 * kFt, 1e-9);
  EXPECT_EQ(f.geometricAltitudeFixes, 3u);
  EXPECT_EQ(f.barometricAltitudeFixes, 1u);
  EXPECT_EQ(f.altitudeSource,
            "geometric ('alt_geom', ft) for 3 fixes; barometric ('alt_baro', ft) to geometric by the ICAO "
            "standard atmosphere for 1 fix");
  EXPECT_TRUE(anyWarningHas(f, "trace[0]: on the ground without a geometric altitude")) << allWarnings(f);
  EXPECT_TRUE(anyWarningHas(f, "trace[4]: no position")) << allWarnings(f);
  EXPECT_TRUE(anyWarningHas(f, "trace[5]: stale position")) << allWarnings(f);
  EXPECT_TRUE(anyWarningHas(f, "trace[6]: a new leg starts")) << allWarnings(f);
  EXPECT_TRUE(anyWarningHas(f, "same as the previous fix")) << allWarnings(f);
  EXPECT_TRUE(anyWarningHas(f, "trace[8]: no altitude")) << allWarnings(f);
  // Heading from the track: each step is +0.001 deg of latitude and -0.01
  // of longitude, north-west. On the ellipsoid at 50 deg the meridian radius
  // M is 6372 km and the prime vertical N 6391 km (WGS84), so east/north
  // = 0.01 cos 50 N / (0.001 M) = 6.447 and the azimuth is
  // 360 - atan(6.447) = 278.82 deg.
  EXPECT_NEAR(f.fixes[1].pose.yaw_deg, 278.82, 0.05);
  EXPECT_TRUE(f.attitudeFromTrack);
  EXPECT_EQ(f.aircraft, "icao24 3c6444, registration D-TEST");
}

TEST(ReadsbTrace, HandMadeTraceGivesTheRowsWorkedOutByHand) {
  const auto f = parseFlight(readData("trace_full_3c6444.json"), "trace_full_3c6444.json");
  ASSERT_TRUE(f) << f.error().detail;
  expectHandMadeTrace(*f);
}

TEST(ReadsbTrace, GzipCompressedTraceReadsTheSame) {
  const std::string bytes = readData("trace_full_3c6444-gzip.json");
  ASSERT_GE(bytes.size(), 2u);
  ASSERT_EQ(static_cast<unsigned char>(bytes[0]), 0x1f);  // really gzip
  const auto f = parseFlight(bytes, "trace_full_3c6444-gzip.json");
  ASSERT_TRUE(f) << f.error().detail;
  expectHandMadeTrace(*f);
}

TEST(ReadsbTrace, Icao24MustMatchTheFile) {
  const std::string text = readData("trace_full_3c6444.json");
  ReadOptions options;
  options.icao24 = "3C6444";
  EXPECT_TRUE(parseReadsbTrace(text, "t.json", options));
  options.icao24 = "4b1814";
  const auto f = parseReadsbTrace(text, "t.json", options);
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(f.error().detail.find("'3c6444', not 4b1814"), std::string::npos) << f.error().detail;
}

TEST(ReadsbTrace, ErrorsNameTheJsonPathAndField) {
  const auto expectError = [](const std::string& text, const std::string& needle, ErrorCode code) {
    const auto f = parseReadsbTrace(text, "t.json");
    ASSERT_FALSE(f) << text;
    EXPECT_EQ(f.error().code, code) << f.error().detail;
    EXPECT_NE(f.error().detail.find(needle), std::string::npos) << f.error().detail;
  };
  expectError(R"({"timestamp":1,"trace":[[0,91.5,8,1000],[1,50,8,1000]]})", "t.json: JSON '/trace/0/1' (lat)",
              ErrorCode::InvalidArgument);
  expectError(R"({"timestamp":1,"trace":[[0,50,8,1000],[1,50,"x",1000]]})", "'/trace/1/2' (lon): not a number",
              ErrorCode::Malformed);
  expectError(R"({"timestamp":1,"trace":[[0,50,8,"air"]]})", "'/trace/0/3' (alt_baro)", ErrorCode::Malformed);
  // 70000 ft barometric is beyond the standard atmosphere's 20 km.
  expectError(R"({"timestamp":1,"trace":[[0,50,8,70000]]})", "'/trace/0/3' (alt_baro)",
              ErrorCode::InvalidArgument);
  expectError(R"({"timestamp":1,"trace":[[0,50,8]]})", "'/trace/0': not an array of at least 4",
              ErrorCode::Malformed);
  expectError(R"({"trace":[]})", "'/timestamp'", ErrorCode::Malformed);
  expectError(R"({"timestamp":1})", "'/trace'", ErrorCode::Malformed);
  expectError(R"({"timestamp":1,"trace":[[0,50,8,1000]]})", "1 usable fixes", ErrorCode::InvalidArgument);
  expectError(R"({"timestamp":1,"trace":[)", "not JSON", ErrorCode::Malformed);
  expectError(std::string(40, '[') + std::string(40, ']'), "nested deeper than 16", ErrorCode::Malformed);
}

TEST(ReadsbTrace, OversizeTraceIsRefusedBeforeParsing) {
  const std::string big(kMaxReadsbTraceBytes + 1, ' ');
  const auto f = parseReadsbTrace(big, "big.json");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, ErrorCode::TooLarge);
}

}  // namespace
}  // namespace sky::flight
