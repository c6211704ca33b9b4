// skyshell-replay --info's lines (info.hpp) and --max-speed's parsing
// (clean.hpp): the format by extension and header, the time span and UTC
// start, the bounding box and the cleaning's counts, from small records
// whose values are known by construction.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "sky/flight/clean.hpp"
#include "sky/flight/info.hpp"

namespace sky::flight {
namespace {

std::string lineStarting(const std::vector<std::string>& lines, const std::string& key) {
  for (const auto& l : lines)
    if (l.rfind(key, 0) == 0) return l;
  return "(no line '" + key + "')";
}

TEST(FlightInfo, FormatByExtensionAndHeader) {
  EXPECT_EQ(formatName("time,icao24,lat,lon,baroaltitude\n", "a.CSV"), "ADS-B CSV");
  EXPECT_EQ(formatName("# ours\ntime_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n", "a.csv"), "Skyshell CSV");
  EXPECT_EQ(formatName("", "x/a.igc"), "IGC");
  EXPECT_EQ(formatName("", "a.gpx"), "GPX");
  EXPECT_EQ(formatName("", "trace_full_3c6444.json"), "readsb trace JSON");
  EXPECT_EQ(formatName("", "a.kmz"), "KMZ");
  EXPECT_EQ(formatName("", "a.FDR"), "X-Plane FDR");
  EXPECT_EQ(formatName("", "a.fgtape"), ".fgtape (unknown)");
}

TEST(FlightInfo, LinesSayWhatTheFileHolds) {
  // Three fixes of an ADS-B track from 2024-03-01T12:00:00Z (1709294400 s),
  // the middle one spoofed 2 deg north; 60 s at ~140 m/s eastward along 46 N.
  ParsedFlight f;
  f.startUtc_s = 1709294400;
  f.aircraft = "icao24 3c6444, callsign DLH9U";
  f.altitudeSource = "geometric ('geoaltitude', m) for 4 fixes";
  f.fixes = {Fix{0, {{46.0, 7.0, 9000}, 0, 0, 0}}, Fix{30, {{48.0, 7.05, 9100}, 0, 0, 0}},
             Fix{60, {{46.0, 7.1, 9200}, 0, 0, 0}}, Fix{90, {{46.0, 7.15, 9300}, 0, 0, 0}}};
  f.fixLines = {2, 3, 4, 5};
  const auto report = clean(f, {}, "a.csv");
  ASSERT_TRUE(report);
  const auto lines = describeFlight(f, "ADS-B CSV", &*report, {});
  EXPECT_EQ(lineStarting(lines, "format:"), "format: ADS-B CSV");
  EXPECT_EQ(lineStarting(lines, "aircraft:"), "aircraft: icao24 3c6444, callsign DLH9U");
  EXPECT_EQ(lineStarting(lines, "time:"), "time: 0.0 s to 90.0 s of the record (0h01m30s)");
  EXPECT_EQ(lineStarting(lines, "utc start:"), "utc start: 2024-03-01T12:00:00Z");
  EXPECT_EQ(lineStarting(lines, "fixes:"), "fixes: 3");
  // Without the spoofed fix the box is one latitude.
  EXPECT_EQ(lineStarting(lines, "bounding box:"),
            "bounding box: lat 46.00000 to 46.00000 deg, lon 7.00000 to 7.15000 deg, altitude 9000 to 9300 m");
  EXPECT_EQ(lineStarting(lines, "altitude:"), "altitude: geometric ('geoaltitude', m) for 4 fixes");
  EXPECT_NE(lineStarting(lines, "cleaning:").find("kept 3 of 4 fixes; 1 dropped (speed)"), std::string::npos)
      << lineStarting(lines, "cleaning:");
  bool lineNamed = false;
  for (const auto& l : lines) lineNamed |= l.find("1 fix at line 3") != std::string::npos;
  EXPECT_TRUE(lineNamed);
}

TEST(FlightInfo, WithoutCleaningOrDate) {
  ParsedFlight f;
  f.fixes = {Fix{0, {{-10, 179.9, 100}, 0, 0, 0}}, Fix{10, {{-10, -179.9, 100}, 0, 0, 0}}};
  const auto lines = describeFlight(f, "GPX", nullptr, {});
  EXPECT_EQ(lineStarting(lines, "aircraft:"), "aircraft: not recorded in the file");
  EXPECT_EQ(lineStarting(lines, "utc start:"), "utc start: not recorded (no date in the file)");
  EXPECT_EQ(lineStarting(lines, "cleaning:"), "cleaning: off (--no-clean): the track as read");
  EXPECT_NE(lineStarting(lines, "bounding box:").find("crosses the antimeridian"), std::string::npos);
}

TEST(FlightInfo, MaxSpeedTakesMetresPerSecondOrKnots) {
  EXPECT_EQ(parseSpeed_mps("350"), 350.0);
  EXPECT_EQ(parseSpeed_mps("350m/s"), 350.0);
  EXPECT_EQ(parseSpeed_mps(" 250 m/s "), 250.0);
  EXPECT_NEAR(*parseSpeed_mps("680kt"), 680 * 1852.0 / 3600, 1e-9);  // 349.8 m/s
  EXPECT_NEAR(*parseSpeed_mps("100 kt"), 51.4444, 1e-4);
  EXPECT_FALSE(parseSpeed_mps(""));
  EXPECT_FALSE(parseSpeed_mps("kt"));
  EXPECT_FALSE(parseSpeed_mps("0"));
  EXPECT_FALSE(parseSpeed_mps("-5"));
  EXPECT_FALSE(parseSpeed_mps("fast"));
  EXPECT_FALSE(parseSpeed_mps("350 km/h"));
  EXPECT_FALSE(parseSpeed_mps("inf"));
}

}  // namespace
}  // namespace sky::flight
