// ADS-B CSV reader: hand-made files in tests/data/adsb (OpenSky's state-vector
// layout and tracker-export names, written for this test; no real recording
// is on this machine) and in-test variants: columns by name, feet and metres,
// geometric against barometric altitude, "ground", empty positions skipped
// and counted, several aircraft, bad numbers; and the standard-atmosphere
// conversion against its closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "sky/flight/flight.hpp"
#include "warnings.hpp"
#include "sky/weather/standard_atmosphere.hpp"

namespace sky::flight {
namespace {

constexpr double kFt = 0.3048;
// ICAO Doc 7488/3: r0 relating geopotential and geometric height.
constexpr double kR0_m = 6356766.0;
double geometricOfGeopotential(double h_m) { return kR0_m * h_m / (kR0_m - h_m); }

// ADS-B options: the aircraft and the altitude unit (the other fields kept).
ReadOptions adsbOptions(const std::string& icao24, AltitudeUnit unit) {
  ReadOptions options;
  options.icao24 = icao24;
  options.altitudeUnit = unit;
  return options;
}

std::string readData(const std::string& name) {
  std::ifstream in(std::string(SKY_ADSB_DATA_DIR) + "/" + name, std::ios::binary);
  EXPECT_TRUE(in) << name;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(StandardAtmosphere, PressureAltitudeToGeometric) {
  // At sea level geopotential and geometric agree; at FL350 (10668 m) the
  // closed form z = r0 h / (r0 - h) adds 17.9 m.
  EXPECT_NEAR(weather::pressureToGeometricAltitude_m(0), 0, 1e-9);
  EXPECT_NEAR(weather::pressureToGeometricAltitude_m(10668), geometricOfGeopotential(10668), 1e-6);
  EXPECT_NEAR(weather::pressureToGeometricAltitude_m(10668) - 10668, 17.93, 0.01);
  // QNH 1023.25 hPa: an altimeter at 1013.25 reading 0 is ~83 m above sea
  // level (27.3 ft/hPa near the surface, 8.3 m/hPa x 10 hPa).
  EXPECT_NEAR(weather::pressureToGeometricAltitude_m(0, 1023.25), 83.0, 1.0);
}

TEST(FlightAdsb, OpenSkyLayoutGeometricWinsBaroConvertedEmptyAndGroundSkipped) {
  const std::string text = readData("opensky-one-aircraft.csv");
  auto f = parseAdsbCsv(text, "opensky-one-aircraft.csv");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 3u) << allWarnings(*f);
  // Line 4: onground True with no altitude; line 6: lat and lon empty.
  EXPECT_EQ(f->warnings.size(), 2u) << allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "opensky-one-aircraft.csv:4: on the ground without a geometric altitude"))
      << allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "opensky-one-aircraft.csv:6: field 'lat': empty, row skipped")) << allWarnings(*f);
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(1700000010));
  EXPECT_EQ(f->fixes[0].time_s, 0);
  EXPECT_EQ(f->fixes[1].time_s, 20);
  EXPECT_EQ(f->fixes[2].time_s, 30);
  EXPECT_NEAR(f->fixes[0].pose.position.lat_deg, 50.0290, 1e-12);
  EXPECT_NEAR(f->fixes[0].pose.position.lon_deg, 8.5550, 1e-12);
  // Geometric wins over barometric when the row has both.
  EXPECT_NEAR(f->fixes[0].pose.position.alt_m, 320.04, 1e-9);
  EXPECT_NEAR(f->fixes[2].pose.position.alt_m, 1240.0, 1e-9);
  // Barometric only: pressure altitude (geopotential) made geometric.
  EXPECT_NEAR(f->fixes[1].pose.position.alt_m, geometricOfGeopotential(914.4), 1e-6);
  EXPECT_EQ(f->geometricAltitudeFixes, 2u);
  EXPECT_EQ(f->barometricAltitudeFixes, 1u);
  EXPECT_NE(f->altitudeSource.find("geometric ('geoaltitude', m) for 2 fixes"), std::string::npos)
      << f->altitudeSource;
  EXPECT_NE(f->altitudeSource.find("barometric ('baroaltitude', m) to geometric by the ICAO standard atmosphere for 1"),
            std::string::npos)
      << f->altitudeSource;
  // Heading west-south-west from the track (deriveAttitude, as for IGC).
  EXPECT_GT(f->fixes[1].pose.yaw_deg, 230);
  EXPECT_LT(f->fixes[1].pose.yaw_deg, 260);
}

TEST(FlightAdsb, DispatcherReadsAdsbAndOwnCsvByHeader) {
  const std::string text = readData("opensky-one-aircraft.csv");
  auto f = parseFlight(text, "dir/OPENSKY.CSV");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->barometricAltitudeFixes, 1u);
  // Our own format still goes to parseCsv (its attitude kept, no altitude report).
  auto own = parseFlight("# ours\ntime_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n"
                         "0,46,12,1000,90,2,10\n1,46,12.001,1001,90,2,10\n",
                         "own.csv");
  ASSERT_TRUE(own) << own.error().detail;
  EXPECT_EQ(own->fixes[0].pose.roll_deg, 10);
  EXPECT_TRUE(own->altitudeSource.empty());
  EXPECT_FALSE(isAdsbCsvHeader("time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg"));
  EXPECT_TRUE(isAdsbCsvHeader("Timestamp,Latitude,Longitude,Altitude_ft"));
}

TEST(FlightAdsb, TrackerNamesFeetIsoTimeAndGround) {
  auto f = parseFlight(readData("feet-iso-time.csv"), "feet-iso-time.csv");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_TRUE(anyWarningHas(*f, "feet-iso-time.csv:5: on the ground")) << allWarnings(*f);
  // 2023-11-14T22:13:20Z is Unix 1700000000.
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(1700000000));
  EXPECT_EQ(f->fixes[1].time_s, 10.5);
  EXPECT_EQ(f->fixes[2].time_s, 20);
  EXPECT_NEAR(f->fixes[0].pose.position.alt_m, geometricOfGeopotential(1000 * kFt), 1e-6);
  EXPECT_NEAR(f->fixes[2].pose.position.alt_m, geometricOfGeopotential(35000 * kFt), 1e-6);
  EXPECT_EQ(f->barometricAltitudeFixes, 3u);
  EXPECT_NE(f->altitudeSource.find("'altitude_ft', ft"), std::string::npos) << f->altitudeSource;
}

TEST(FlightAdsb, ReadsbNamesInFeetGeometricWins) {
  auto f = parseAdsbCsv("time,lat,lon,alt_baro,alt_geom\n0,1,2,1000,1100\n1,1,2.001,ground,1150\n", "r.csv");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_NEAR(f->fixes[0].pose.position.alt_m, 1100 * kFt, 1e-9);
  // "ground" in the barometric column, but a geometric altitude: kept.
  EXPECT_NEAR(f->fixes[1].pose.position.alt_m, 1150 * kFt, 1e-9);
  EXPECT_EQ(f->geometricAltitudeFixes, 2u);
}

TEST(FlightAdsb, AltitudeUnitFromOptionOrAnError) {
  const std::string text = "Time,Latitude,Longitude,Altitude\n0,1,2,1000\n1,1,2.001,1000\n";
  auto none = parseAdsbCsv(text, "u.csv");
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().detail, "u.csv:1: column 'altitude' does not say its unit: give the altitude unit (ft or m)");
  auto feet = parseAdsbCsv(text, "u.csv", adsbOptions("", AltitudeUnit::Feet));
  ASSERT_TRUE(feet) << feet.error().detail;
  EXPECT_NEAR(feet->fixes[0].pose.position.alt_m, geometricOfGeopotential(1000 * kFt), 1e-6);
  auto metres = parseAdsbCsv(text, "u.csv", adsbOptions("", AltitudeUnit::Metres));
  ASSERT_TRUE(metres) << metres.error().detail;
  EXPECT_NEAR(metres->fixes[0].pose.position.alt_m, geometricOfGeopotential(1000), 1e-6);
  // The option overrides a unit the name gives.
  auto over = parseAdsbCsv("time,lat,lon,geoaltitude\n0,1,2,1000\n1,1,2.001,1000\n", "o.csv", adsbOptions("", AltitudeUnit::Feet));
  ASSERT_TRUE(over) << over.error().detail;
  EXPECT_NEAR(over->fixes[0].pose.position.alt_m, 1000 * kFt, 1e-9);
}

TEST(FlightAdsb, TwoAircraftAreAnErrorListingBoth) {
  auto f = parseFlight(readData("opensky-two-aircraft.csv"), "opensky-two-aircraft.csv");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, ErrorCode::InvalidArgument);
  EXPECT_EQ(f.error().detail,
            "opensky-two-aircraft.csv: 2 aircraft in the file, pick one by its icao24: 3c6444 DLH4AB (3 fixes), "
            "4b1815 SWR12 (2 fixes)");
}

TEST(FlightAdsb, Icao24OptionPicksOne) {
  const std::string text = readData("opensky-two-aircraft.csv");
  auto f = parseFlight(text, "two.csv", adsbOptions("4B1815", AltitudeUnit::FromColumnName));
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_NEAR(f->fixes[0].pose.position.lat_deg, 47.45, 1e-12);
  EXPECT_NEAR(f->fixes[1].pose.position.lon_deg, 8.57, 1e-12);
  EXPECT_NEAR(f->fixes[1].pose.position.alt_m, 3050, 1e-9);
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);

  auto other = parseFlight(text, "two.csv", adsbOptions("3c6444", AltitudeUnit::FromColumnName));
  ASSERT_TRUE(other) << other.error().detail;
  EXPECT_EQ(other->fixes.size(), 3u);

  auto absent = parseFlight(text, "two.csv", adsbOptions("abcdef", AltitudeUnit::FromColumnName));
  ASSERT_FALSE(absent);
  EXPECT_EQ(absent.error().detail,
            "two.csv: no aircraft abcdef in the file; it holds 3c6444 DLH4AB (3 rows), 4b1815 SWR12 (2 rows)");
  auto notHex = parseFlight(text, "two.csv", adsbOptions("xyz", AltitudeUnit::FromColumnName));
  ASSERT_FALSE(notHex);
  EXPECT_EQ(notHex.error().detail, "two.csv: icao24 'xyz' is not 1 to 6 hex digits");
}

TEST(FlightAdsb, MalformedNumberNamesLineAndField) {
  auto f = parseFlight(readData("bad-number.csv"), "bad-number.csv");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, ErrorCode::Malformed);
  EXPECT_EQ(f.error().detail, "bad-number.csv:5: field 'lat': '50.02x9' is not a number");
  auto range = parseAdsbCsv("time,lat,lon,geoaltitude\n0,91,2,1000\n", "r.csv");
  ASSERT_FALSE(range);
  EXPECT_EQ(range.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(range.error().detail.find("r.csv:2: field 'lat': '91' is outside [-90"), std::string::npos)
      << range.error().detail;
  auto time = parseAdsbCsv("time,lat,lon,geoaltitude\n2023-02-30T00:00:00Z,1,2,1000\n", "t.csv");
  ASSERT_FALSE(time);
  EXPECT_NE(time.error().detail.find("t.csv:2: field 'time':"), std::string::npos) << time.error().detail;
  auto ground = parseAdsbCsv("time,lat,lon,geoaltitude,onground\n0,1,2,1000,maybe\n", "g.csv");
  ASSERT_FALSE(ground);
  EXPECT_EQ(ground.error().detail, "g.csv:2: field 'onground': 'maybe' is not true, false, 1 or 0");
}

TEST(FlightAdsb, HeaderAndSizeLimits) {
  auto noAlt = parseAdsbCsv("time,lat,lon\n0,1,2\n", "n.csv");
  ASSERT_FALSE(noAlt);
  EXPECT_NE(noAlt.error().detail.find("n.csv:1: header has no altitude column"), std::string::npos);
  auto twice = parseAdsbCsv("time,lat,latitude,lon,geoaltitude\n", "d.csv");
  ASSERT_FALSE(twice);
  EXPECT_EQ(twice.error().detail, "d.csv:1: columns 'lat' and 'latitude' say the same thing; keep one");
  auto fields = parseAdsbCsv("time,lat,lon,geoaltitude\n0,1,2\n", "f.csv");
  ASSERT_FALSE(fields);
  EXPECT_EQ(fields.error().detail, "f.csv:2: 3 fields, the header has 4");
  const std::string longLine = "time,lat,lon,geoaltitude\n0,1,2,1000" + std::string(kMaxAdsbLineBytes, ' ') + "\n";
  auto tooLong = parseAdsbCsv(longLine, "l.csv");
  ASSERT_FALSE(tooLong);
  EXPECT_EQ(tooLong.error().code, ErrorCode::TooLarge);
  EXPECT_NE(tooLong.error().detail.find("l.csv:2: line of"), std::string::npos);
  auto one = parseAdsbCsv("time,lat,lon,geoaltitude\n0,1,2,1000\n", "o.csv");
  ASSERT_FALSE(one);
  EXPECT_EQ(one.error().detail, "o.csv: 1 usable fixes, a flight needs at least two");
  // Bytes beyond ASCII never reach a message raw.
  auto junk = parseAdsbCsv("time,lat,lon,geoaltitude\n0,\xff\xfe,2,1000\n", "j.csv");
  ASSERT_FALSE(junk);
  EXPECT_EQ(junk.error().detail, "j.csv:2: field 'lat': '?" "?' is not a number");
}

TEST(FlightAdsb, EmptyFieldWarningsAreCapped) {
  std::string text = "time,lat,lon,geoaltitude\n";
  for (int i = 0; i < 20; ++i) text += std::to_string(i) + ",,,\n";
  text += "100,1,2,10\n101,1,2.001,10\n";
  auto f = parseAdsbCsv(text, "e.csv");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_EQ(f->fixes.size(), 2u);
  EXPECT_EQ(f->warnings.size(), kMaxWarningsPerKind + 1) << allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "e.csv: 12 more rows with an empty field skipped (not listed)")) << allWarnings(*f);
}

}  // namespace
}  // namespace sky::flight
