// IGC reader: both date forms, I-record extensions, midnight, every anomaly
// in a small in-test file (each skipped or kept with a warning naming its
// line), and two real logger files checked against values read by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "sky/flight/flight.hpp"
#include "warnings.hpp"

namespace sky::flight {
namespace {

// A B record: time "HHMMSS", position "DDMMmmmNDDDMMmmmE", validity,
// pressure and GNSS altitude in metres, then extension bytes.
std::string b(const std::string& hhmmss, char validity = 'A', int pressure_m = 950, int gnss_m = 1000,
              const std::string& position = "4612584N01249706E", const std::string& extra = "") {
  char alt[16];
  std::snprintf(alt, sizeof alt, "%05d%05d", pressure_m, gnss_m);
  return "B" + hhmmss + position + validity + alt + extra + "\r\n";
}

const std::string kHeader = "AXXX001\r\nHFDTE030416\r\n";

TEST(FlightIgc, ReadsFixesAndShortDate) {
  auto f = parseIgc(kHeader + b("120000") + b("120001", 'A', 960, 1010, "4612500S01249000W"), "a.igc");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);
  EXPECT_EQ(f->fixes[0].time_s, 0);
  EXPECT_EQ(f->fixes[1].time_s, 1);
  EXPECT_NEAR(f->fixes[0].pose.position.lat_deg, 46 + 12.584 / 60, 1e-12);
  EXPECT_NEAR(f->fixes[0].pose.position.lon_deg, 12 + 49.706 / 60, 1e-12);
  EXPECT_EQ(f->fixes[0].pose.position.alt_m, 1000);  // GNSS, not pressure
  EXPECT_NEAR(f->fixes[1].pose.position.lat_deg, -(46 + 12.5 / 60), 1e-12);
  EXPECT_NEAR(f->fixes[1].pose.position.lon_deg, -(12 + 49.0 / 60), 1e-12);
  // 2016-04-03 is day 16894 since 1970-01-01; first fix at 12:00:00 UTC.
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(16894LL * 86400 + 12 * 3600));
}

TEST(FlightIgc, ReadsLongDateFormAndIgnoresNonAsciiHeaders) {
  const std::string text = "AXCT2ed\r\nHOSITSite:Teufelsm\xc3\xbchle\r\nHFPLTPILOT:J\xfcrgen\r\n"
                           "HFDTEDATE:040920,01\r\n" +
                           b("162753") + b("162754");
  auto f = parseIgc(text, "b.igc");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_EQ(f->fixes.size(), 2u);
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(1599236873));  // 2020-09-04T16:27:53Z
}

TEST(FlightIgc, MissingOrBadDateLeavesStartEmptyWithAWarning) {
  auto none = parseIgc("AXXX\n" + b("120000") + b("120001"), "n.igc");
  ASSERT_TRUE(none);
  EXPECT_FALSE(none->startUtc_s);
  EXPECT_TRUE(anyWarningHas(*none, "n.igc: no HFDTE")) << allWarnings(*none);
  auto bad = parseIgc("HFDTE310216\n" + b("120000") + b("120001"), "d.igc");  // 31 February
  ASSERT_TRUE(bad);
  EXPECT_FALSE(bad->startUtc_s);
  EXPECT_TRUE(anyWarningHas(*bad, "d.igc:1: field 'date'")) << allWarnings(*bad);
}

TEST(FlightIgc, IRecordExtensionsAreSkippedAndLadLodRefine) {
  // FXA (3 bytes, 36-38) before LAD (39) and LOD (40): the fixed fields stay
  // where they are and the extra digits add 1e-4 minutes.
  const std::string text = kHeader + "I033638FXA3939LAD4040LOD\r\n" +
                           b("120000", 'A', 950, 1000, "4612584N01249706E", "02375") +
                           b("120001", 'A', 950, 1000, "4612584N01249706E", "023");  // LAD/LOD cut off
  auto f = parseIgc(text, "i.igc");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_NEAR(f->fixes[0].pose.position.lat_deg, 46 + 12.5847 / 60, 1e-12);
  EXPECT_NEAR(f->fixes[0].pose.position.lon_deg, 12 + 49.7065 / 60, 1e-12);
  EXPECT_NEAR(f->fixes[1].pose.position.lat_deg, 46 + 12.584 / 60, 1e-12);
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);
}

TEST(FlightIgc, WideLadExtensionUsesItsFirstNineDigitsAndDoesNotOverflow) {
  // LAD declared over bytes 36-63 (28 digits): the value would overflow a
  // 64-bit integer (the fuzzer found this); the first nine digits refine the
  // minutes, the rest must only be digits. A non-digit in the run leaves the
  // minutes unrefined.
  const std::string digits28 = "7" + std::string(27, '3');
  const std::string text = kHeader + "I013663LAD\r\n" +
                           b("120000", 'A', 950, 1000, "4612584N01249706E", digits28) +
                           b("120001", 'A', 950, 1000, "4612584N01249706E", "7" + std::string(20, '3') + "x333333");
  auto f = parseIgc(text, "w.igc");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_NEAR(f->fixes[0].pose.position.lat_deg, 46 + (12.584 + 0.000733333333) / 60, 1e-14);
  EXPECT_NEAR(f->fixes[1].pose.position.lat_deg, 46 + 12.584 / 60, 1e-14);
}

TEST(FlightIgc, BadIRecordIgnoresExtensionsWithAWarning) {
  auto f = parseIgc(kHeader + "I02363XLAD\r\n" + b("120000") + b("120001"), "i.igc");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fixes.size(), 2u);
  EXPECT_TRUE(anyWarningHas(*f, "i.igc:3: field 'extensions'")) << allWarnings(*f);
}

TEST(FlightIgc, MidnightUtcAddsADay) {
  auto f = parseIgc(kHeader + b("235958") + b("235959") + b("000000") + b("000001"), "m.igc");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(f->fixes[i].time_s, static_cast<double>(i));
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(16894LL * 86400 + 86398));
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);
}

// Line numbers: kHeader is lines 1-2, so the n-th B record is line n + 2.
TEST(FlightIgc, OutOfOrderFixIsSkippedWithAWarning) {
  auto f = parseIgc(kHeader + b("120000") + b("120005") + b("120003") + b("120006"), "o.igc");
  ASSERT_TRUE(f);
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->fixes[2].time_s, 6);
  EXPECT_TRUE(anyWarningHas(*f, "o.igc:5: field 'time': 2 s before the previous fix, fix skipped"))
      << allWarnings(*f);
}

TEST(FlightIgc, DuplicateTimeIsSkippedWithAWarning) {
  auto f = parseIgc(kHeader + b("120000") + b("120001", 'A', 950, 1001) + b("120001", 'A', 950, 1002) +
                        b("120002"),
                    "d.igc");
  ASSERT_TRUE(f);
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->fixes[1].pose.position.alt_m, 1001);  // the first of the two is kept
  EXPECT_TRUE(anyWarningHas(*f, "d.igc:5: field 'time': same as the previous fix")) << allWarnings(*f);
}

TEST(FlightIgc, GapIsKeptWithAWarning) {
  auto f = parseIgc(kHeader + b("120000") + b("120001") + b("120301") + b("120302"), "g.igc");
  ASSERT_TRUE(f);
  ASSERT_EQ(f->fixes.size(), 4u);
  EXPECT_EQ(f->fixes[2].time_s, 181);
  EXPECT_TRUE(anyWarningHas(*f, "g.igc:5: field 'time': 180 s gap before this fix (kept)")) << allWarnings(*f);
}

TEST(FlightIgc, FixWithoutAltitudeIsSkippedWithAWarning) {
  auto f = parseIgc(kHeader + b("120000") + b("120001", 'A', 0, 0) + b("120002"), "z.igc");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fixes.size(), 2u);
  EXPECT_TRUE(anyWarningHas(*f, "z.igc:4: fields 'pressure altitude', 'gnss altitude': both 0")) << allWarnings(*f);
}

TEST(FlightIgc, ZeroGnssAltitudeFallsBackToPressureWithOneWarning) {
  auto f = parseIgc(kHeader + b("120000", 'A', 950, 0) + b("120001", 'A', 951, 0) + b("120002", 'A', -12, 0),
                    "p.igc");
  ASSERT_TRUE(f);
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->fixes[0].pose.position.alt_m, 950);
  EXPECT_EQ(f->fixes[2].pose.position.alt_m, -12);  // below sea level: "-0012"
  ASSERT_EQ(f->warnings.size(), 1u) << allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "p.igc:3: field 'gnss altitude': 0, using pressure altitude"));
}

TEST(FlightIgc, ValidityVIsSkippedWithAWarning) {
  auto f = parseIgc(kHeader + b("120000") + b("120001", 'V') + b("120002"), "v.igc");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fixes.size(), 2u);
  EXPECT_TRUE(anyWarningHas(*f, "v.igc:4: field 'validity': 'V'")) << allWarnings(*f);
}

TEST(FlightIgc, JunkLinesAreSkippedWithAWarningNamingLineAndField) {
  const std::string text = kHeader + b("120000") +
                           "\xff\xfe garbage\r\n"              // line 4: not a record
                           "B1200014612584N01249706EA00950\r\n"  // 5: truncated
                           "B1260024612584N01249706EA0095001000\r\n"  // 6: minute 60
                           "B1200034699584N01249706EA0095001000\r\n"  // 7: 99 minutes
                           "B1200044612584X01249706EA0095001000\r\n"  // 8: hemisphere X
                           "B1200054612584N01249706EQ0095001000\r\n"  // 9: validity Q
                           "B1200064612584N01249706EA00x5001000\r\n"  // 10: pressure
                           "B1200074612584N01249706EA0095001y00\r\n"  // 11: gnss
                           "B1200084612584N18149706EA0095001000\r\n"  // 12: longitude 181
                           "\r\n" +                                  // 13: blank, ignored
                           b("120009");
  auto f = parseIgc(text, "j.igc");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fixes.size(), 2u);
  const std::string w = allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:4: '?? garbage' is not an IGC record")) << w;
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:5: B record of 30 bytes")) << w;
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:6: field 'time': '126002'")) << w;
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:7: field 'latitude'")) << w;
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:8: field 'latitude'")) << w;
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:9: field 'validity': 'Q'")) << w;
  EXPECT_TRUE(anyWarningHas(*f, "j.igc:10: field 'pressure altitude'")) << w;
  // Only kMaxWarningsPerKind junk lines are listed; the rest are counted.
  EXPECT_TRUE(anyWarningHas(*f, "j.igc: 1 more unreadable lines skipped")) << w;
}

TEST(FlightIgc, WarningsOfOneKindAreCapped) {
  std::string text = kHeader + b("120000");
  for (int s = 1; s <= 20; ++s) text += b("1200" + std::string(s < 10 ? "0" : "") + std::to_string(s), 'V');
  text += b("120030");
  auto f = parseIgc(text, "c.igc");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->warnings.size(), kMaxWarningsPerKind + 1) << allWarnings(*f);
  EXPECT_TRUE(anyWarningHas(*f, "c.igc: 12 more fixes with validity 'V' skipped")) << allWarnings(*f);
}

TEST(FlightIgc, FewerThanTwoUsableFixesIsAnError) {
  auto f = parseIgc(kHeader + b("120000") + b("120001", 'V'), "e.igc");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().detail, "e.igc: 1 usable B fixes, a flight needs at least two");
  EXPECT_FALSE(parseIgc("", "empty.igc"));
}

// Bug (found by fuzzing): a one-byte "H" line threw std::out_of_range from
// string_view::substr while looking for "DTE".
TEST(FlightIgc, ShortRecordsDoNotThrow) {
  auto f = parseIgc("H\nHF\nHFDTE\nI\nI9\n" + b("120000") + b("120001"), "s.igc");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->fixes.size(), 2u);
  EXPECT_FALSE(f->startUtc_s);
}

// ---- Real files -------------------------------------------------------------

std::string readData(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(SKY_FLIGHT_DATA_DIR) / name;
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void expectAltitudeRange(const Flight& f, double lo_m, double hi_m) {
  const auto [mn, mx] = std::minmax_element(f.fixes.begin(), f.fixes.end(), [](const Fix& a, const Fix& c) {
    return a.pose.position.alt_m < c.pose.position.alt_m;
  });
  EXPECT_EQ(mn->pose.position.alt_m, lo_m);
  EXPECT_EQ(mx->pose.position.alt_m, hi_m);
}

void expectSaneAttitude(const Flight& f) {
  for (const Fix& x : f.fixes) {
    ASSERT_GE(x.pose.yaw_deg, 0);
    ASSERT_LT(x.pose.yaw_deg, 360);
    ASSERT_LE(std::abs(x.pose.pitch_deg), 30);
    ASSERT_LE(std::abs(x.pose.roll_deg), 60);
  }
}

TEST(FlightIgcRealFiles, GliderThermallingNeItaly) {
  const std::string text = readData("glider-thermalling-ne-italy.igc");
  if (text.empty()) GTEST_SKIP() << "no " << SKY_FLIGHT_DATA_DIR << "/glider-thermalling-ne-italy.igc";
  auto f = parseIgc(text, "glider.igc");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);
  ASSERT_EQ(f->fixes.size(), 5380u);
  // B1200004612584N01249706EA0098801046
  const Fix& first = f->fixes.front();
  EXPECT_EQ(first.time_s, 0);
  EXPECT_NEAR(first.pose.position.lat_deg, 46 + 12.584 / 60, 1e-12);
  EXPECT_NEAR(first.pose.position.lon_deg, 12 + 49.706 / 60, 1e-12);
  EXPECT_EQ(first.pose.position.alt_m, 1046);
  // B1329394612325N01249141EA0021800262
  const Fix& last = f->fixes.back();
  EXPECT_EQ(last.time_s, 5379);  // 13:29:39 - 12:00:00
  EXPECT_NEAR(last.pose.position.lat_deg, 46 + 12.325 / 60, 1e-12);
  EXPECT_NEAR(last.pose.position.lon_deg, 12 + 49.141 / 60, 1e-12);
  EXPECT_EQ(last.pose.position.alt_m, 262);
  expectAltitudeRange(*f, 259, 1143);
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(1459684800));  // 2016-04-03T12:00:00Z
  expectSaneAttitude(*f);
  // It thermals: some stretch is flown banked well over 20 deg.
  EXPECT_TRUE(std::any_of(f->fixes.begin(), f->fixes.end(),
                          [](const Fix& x) { return std::abs(x.pose.roll_deg) > 20; }));
}

TEST(FlightIgcRealFiles, ParagliderXcTrackPhoneLogger) {
  const std::string text = readData("paraglider-xctrack-phone-logger.igc");
  if (text.empty()) GTEST_SKIP() << "no " << SKY_FLIGHT_DATA_DIR << "/paraglider-xctrack-phone-logger.igc";
  ASSERT_NE(text.find("\xc3\xbc"), std::string::npos) << "the file should hold a non-ASCII header byte";
  auto f = parseIgc(text, "paraglider.igc");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_TRUE(f->warnings.empty()) << allWarnings(*f);
  ASSERT_EQ(f->fixes.size(), 583u);
  // B1627534845381N00824437EA008060089373 with I023636LAD3737LOD: LAD 7, LOD 3.
  const Fix& first = f->fixes.front();
  EXPECT_NEAR(first.pose.position.lat_deg, 48 + 45.3817 / 60, 1e-12);
  EXPECT_NEAR(first.pose.position.lon_deg, 8 + 24.4373 / 60, 1e-12);
  EXPECT_EQ(first.pose.position.alt_m, 893);
  // B1637354846311N00823869EA003410042662
  const Fix& last = f->fixes.back();
  EXPECT_EQ(last.time_s, 582);  // 16:37:35 - 16:27:53
  EXPECT_NEAR(last.pose.position.lat_deg, 48 + 46.3116 / 60, 1e-12);
  EXPECT_NEAR(last.pose.position.lon_deg, 8 + 23.8692 / 60, 1e-12);
  EXPECT_EQ(last.pose.position.alt_m, 426);
  expectAltitudeRange(*f, 426, 893);
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(1599236873));  // 2020-09-04T16:27:53Z
  expectSaneAttitude(*f);
}

}  // namespace
}  // namespace sky::flight
