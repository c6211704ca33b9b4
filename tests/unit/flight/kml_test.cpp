// KML / KMZ reader: hand-made files in FlightAware's and Flightradar24's
// export layouts (tests/data/kml; no real export is on this machine) with
// the values expected worked out by hand, the same track zipped as a KMZ,
// and in-test documents for choosing among several tracks, a path without
// times, and the errors (line and field named).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "sky/flight/flight.hpp"
#include "warnings.hpp"

namespace sky::flight {
namespace {

std::string readData(const std::string& name) {
  std::ifstream in(std::string(SKY_KML_DATA_DIR) + "/" + name, std::ios::binary);
  EXPECT_TRUE(in) << name;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// 2024-03-10T14:00:00Z: 2024-01-01 is Unix day 19723 (1704067200 s); then
// 31 (January) + 29 (February, leap) + 9 days and 14 h.
constexpr std::int64_t kMarch10At1400_s = 1704067200 + (31 + 29 + 9) * 86400 + 14 * 3600;

void expectFlightAwareTrack(const ParsedFlight& f, const std::string& source) {
  // The gx:Track's five points, the fourth a repeat of the third's time.
  ASSERT_EQ(f.fixes.size(), 4u) << allWarnings(f);
  EXPECT_EQ(kMarch10At1400_s, 1710079200);
  EXPECT_EQ(f.startUtc_s, kMarch10At1400_s);
  const double times[] = {0, 10, 20, 40.5};
  const double lons[] = {8.50, 8.51, 8.52, 8.54};
  const double alts[] = {100, 150, 200, 300};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(f.fixes[i].time_s, times[i]) << i;
    EXPECT_DOUBLE_EQ(f.fixes[i].pose.position.lat_deg, 50.0) << i;
    EXPECT_DOUBLE_EQ(f.fixes[i].pose.position.lon_deg, lons[i]) << i;
    EXPECT_DOUBLE_EQ(f.fixes[i].pose.position.alt_m, alts[i]) << i;
  }
  // Line 21 holds the repeated <when>.
  EXPECT_TRUE(anyWarningHas(f, source + ":21: field 'time': same as the previous fix")) << allWarnings(f);
  // Due east along the parallel: a geodesic between points 0.01 deg apart
  // at 50 N starts within a few thousandths of a degree of 90.
  EXPECT_NEAR(f.fixes[1].pose.yaw_deg, 90.0, 0.01);
  // The <when> lines of the kept points (line 21 was the repeat).
  EXPECT_EQ(f.fixLines, (std::vector<std::size_t>{18, 19, 20, 22}));
  EXPECT_TRUE(f.attitudeFromTrack);
  EXPECT_EQ(f.aircraft, "track 'DLH400'");
}

TEST(Kml, FlightAwareTrackGivesItsPointsAndIgnoresMarkersAndThePath) {
  const auto f = parseFlight(readData("flightaware-track.kml"), "flightaware-track.kml");
  ASSERT_TRUE(f) << f.error().detail;
  expectFlightAwareTrack(*f, "flightaware-track.kml");
}

TEST(Kml, KmzHoldsTheSameTrackAsDocKml) {
  const auto f = parseFlight(readData("flightaware-track.kmz"), "flightaware-track.kmz");
  ASSERT_TRUE(f) << f.error().detail;
  expectFlightAwareTrack(*f, "flightaware-track.kmz (doc.kml)");
}

TEST(Kml, Flightradar24PointsWithTimeStampsAreOneTrack) {
  const auto f = parseFlight(readData("flightradar24-points.kml"), "fr24.kml");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->startUtc_s, kMarch10At1400_s);
  const double times[] = {0, 30, 60};
  const double lats[] = {51.47, 51.48, 51.49};
  const double alts[] = {25, 500, 1000};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(f->fixes[i].time_s, times[i]) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.lat_deg, lats[i]) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.lon_deg, -0.4543) << i;
    EXPECT_DOUBLE_EQ(f->fixes[i].pose.position.alt_m, alts[i]) << i;
  }
  // Due north: the yaw is 0 (or just under 360 after smoothing's unwrap).
  const double yaw = f->fixes[1].pose.yaw_deg;
  EXPECT_LT(std::min(yaw, 360.0 - yaw), 0.01) << yaw;
  // 475 m in 30 s, 1113 m along the ground: pitch atan(475/1113) = 23.1 deg.
  EXPECT_NEAR(f->fixes[1].pose.pitch_deg, 23.1, 1.0);
}

std::string twoTracks() {
  return R"(<kml xmlns="http://www.opengis.net/kml/2.2" xmlns:gx="http://www.google.com/kml/ext/2.2"><Document>
<Placemark><name>A</name><gx:Track><altitudeMode>absolute</altitudeMode>
<when>2024-03-10T14:00:00Z</when><when>2024-03-10T14:00:01Z</when>
<gx:coord>1 2 3</gx:coord><gx:coord>1.001 2 4</gx:coord></gx:Track></Placemark>
<Placemark><name>B</name><gx:Track><altitudeMode>absolute</altitudeMode>
<when>2024-03-10T15:00:00+01:00</when><when>2024-03-10T15:00:05+01:00</when>
<gx:coord>-5 -6 700</gx:coord><gx:coord>-5.01 -6 710</gx:coord></gx:Track></Placemark>
</Document></kml>)";
}

TEST(Kml, SeveralTracksNeedOneChosenByName) {
  const auto all = parseKml(twoTracks(), "two.kml");
  ASSERT_FALSE(all);
  EXPECT_EQ(all.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(all.error().detail.find("2 tracks in the file, pick one by its name: 'A' (2 points), 'B' (2 points)"),
            std::string::npos)
      << all.error().detail;
  ReadOptions options;
  options.track = "B";
  const auto b = parseFlight(twoTracks(), "two.kml", options);
  ASSERT_TRUE(b) << b.error().detail;
  ASSERT_EQ(b->fixes.size(), 2u);
  // 15:00:00+01:00 is 14:00:00Z.
  EXPECT_EQ(b->startUtc_s, kMarch10At1400_s);
  EXPECT_DOUBLE_EQ(b->fixes[1].time_s, 5.0);
  EXPECT_DOUBLE_EQ(b->fixes[1].pose.position.lon_deg, -5.01);
  EXPECT_DOUBLE_EQ(b->fixes[1].pose.position.lat_deg, -6.0);
  EXPECT_DOUBLE_EQ(b->fixes[1].pose.position.alt_m, 710.0);
  options.track = "C";
  const auto c = parseKml(twoTracks(), "two.kml", options);
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().detail.find("no track named 'C'"), std::string::npos) << c.error().detail;
}

TEST(Kml, APathWithoutTimesIsAnErrorThatSaysSo) {
  const auto f = parseKml(R"(<kml><Placemark><name>p</name><LineString><coordinates>
1,2,3 1.1,2,3</coordinates></LineString></Placemark></kml>)",
                          "path.kml");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, ErrorCode::Unsupported);
  EXPECT_NE(f.error().detail.find("has a path (1 LineString placemark(s)) but no times"), std::string::npos)
      << f.error().detail;
}

TEST(Kml, ErrorsNameLineAndField) {
  const auto expectError = [](const std::string& body, const std::string& needle, ErrorCode code) {
    const std::string text = "<kml>\n<Placemark><gx:Track xmlns:gx=\"x\">\n" + body + "\n</gx:Track></Placemark></kml>";
    const auto f = parseKml(text, "e.kml");
    ASSERT_FALSE(f) << body;
    EXPECT_EQ(f.error().code, code) << f.error().detail;
    EXPECT_NE(f.error().detail.find(needle), std::string::npos) << f.error().detail;
  };
  const std::string whens = "<when>2024-03-10T14:00:00Z</when><when>2024-03-10T14:00:01Z</when>\n";
  expectError(whens + "<gx:coord>1 95 3</gx:coord><gx:coord>1 2 3</gx:coord>", "e.kml:4: field 'gx:coord': '1 95 3'",
              ErrorCode::InvalidArgument);
  expectError(whens + "<gx:coord>1 x 3</gx:coord><gx:coord>1 2 3</gx:coord>", "e.kml:4: field 'gx:coord'",
              ErrorCode::Malformed);
  expectError(whens + "<gx:coord>1 2</gx:coord><gx:coord>1 2 3</gx:coord>", "is not three numbers",
              ErrorCode::Malformed);
  expectError(whens + "<gx:coord>1 2 3</gx:coord>", "e.kml:2: gx:Track with 2 <when> and 1 <gx:coord>",
              ErrorCode::Malformed);
  expectError("<when>2024-03-10 14:00</when>", "e.kml:3: field 'when'", ErrorCode::Malformed);
  expectError("<altitudeMode>relativeToGround</altitudeMode>", "field 'altitudeMode': 'relativeToGround'",
              ErrorCode::Unsupported);
  const auto xml = parseKml("<kml><Placemark>\n</kml>", "x.kml");
  ASSERT_FALSE(xml);
  EXPECT_NE(xml.error().detail.find("x.kml:2: XML:"), std::string::npos) << xml.error().detail;
}

TEST(Kml, NoAltitudeModeIsReadAsAbsoluteWithAWarning) {
  const auto f = parseKml(R"(<kml><Placemark><Track>
<when>2024-03-10T14:00:00Z</when><when>2024-03-10T14:00:01Z</when>
<coord>1 2 3</coord><coord>1.001 2 4</coord></Track></Placemark></kml>)",
                          "m.kml");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_DOUBLE_EQ(f->fixes[1].pose.position.alt_m, 4.0);
  EXPECT_TRUE(anyWarningHas(*f, "no altitudeMode")) << allWarnings(*f);
}

TEST(Kmz, DamagedOrOversizeEntryIsRefused) {
  const std::string kmz = readData("flightaware-track.kmz");
  // A byte of the deflate data flipped: zlib or the CRC-32 says so.
  std::string damaged = kmz;
  damaged[40] = static_cast<char>(damaged[40] ^ 0x55);
  const auto d = parseKmz(damaged, "d.kmz");
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, ErrorCode::Malformed) << d.error().detail;
  // The central directory claims 2 GiB uncompressed: refused before inflating.
  std::string big = kmz;
  const auto central = big.find(std::string("PK\x01\x02", 4));
  ASSERT_NE(central, std::string::npos);
  for (std::size_t i = 0; i < 4; ++i) big[central + 24 + i] = i == 3 ? '\x7f' : '\xff';
  const auto b = parseKmz(big, "b.kmz");
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code, ErrorCode::TooLarge) << b.error().detail;
  const auto n = parseKmz("not a zip at all, just text", "n.kmz");
  ASSERT_FALSE(n);
  EXPECT_NE(n.error().detail.find("not a zip archive"), std::string::npos) << n.error().detail;
}

}  // namespace
}  // namespace sky::flight
