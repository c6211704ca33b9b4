// GPX reader: a valid track (with namespaces, waypoints and extensions that
// must be ignored), an error naming line and field for every bad value,
// expat's line for malformed XML, and the shared time-order rules.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "sky/flight/flight.hpp"
#include "warnings.hpp"

namespace sky::flight {
namespace {

// Line 1 is the XML declaration, line 2 <gpx>, 3 <wpt> (ignored), 4 <trk>,
// 5 <trkseg>; points start on line 6, one per line.
std::string gpx(const std::string& points) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<gpx version=\"1.1\" creator=\"test\" xmlns=\"http://www.topografix.com/GPX/1/1\">\n"
         "<wpt lat=\"1\" lon=\"2\"><ele>5</ele><time>2001-01-01T00:00:00Z</time></wpt>\n"
         "<trk><name>t</name>\n"
         "<trkseg>\n" +
         points + "</trkseg></trk></gpx>\n";
}

std::string pt(const std::string& lat, const std::string& lon, const std::string& ele, const std::string& time) {
  std::string s = "<trkpt lat=\"" + lat + "\" lon=\"" + lon + "\">";
  if (!ele.empty()) s += "<ele>" + ele + "</ele>";
  if (!time.empty()) s += "<time>" + time + "</time>";
  return s + "</trkpt>\n";
}

void expectError(const std::string& text, const std::string& needle) {
  auto f = parseGpx(text, "bad.gpx");
  ASSERT_FALSE(f) << "parsed: " << text;
  EXPECT_NE(f.error().detail.find(needle), std::string::npos) << f.error().detail;
}

TEST(FlightGpx, ReadsATrack) {
  const std::string text = gpx(pt("46.5", "12.25", "1000.5", "2020-09-04T16:27:53.250Z") +
                               pt("46.501", "12.25", "1001", "2020-09-04T16:27:54.250Z") +
                               "<trkpt lat=\"46.502\" lon=\"12.25\">\n <ele> 1002 </ele>\n"
                               " <time>2020-09-04T18:27:55.250+02:00</time>\n"
                               " <extensions><time>junk that is not ours</time></extensions></trkpt>\n");
  auto f = parseGpx(text, "good.gpx");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_TRUE(f->warnings.empty());
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->startUtc_s, std::optional<std::int64_t>(1599236873));  // 2020-09-04T16:27:53Z
  EXPECT_DOUBLE_EQ(f->fixes[0].time_s, 0.25);
  EXPECT_DOUBLE_EQ(f->fixes[1].time_s, 1.25);
  EXPECT_DOUBLE_EQ(f->fixes[2].time_s, 2.25);  // +02:00 offset taken off
  EXPECT_EQ(f->fixes[0].pose.position.lat_deg, 46.5);
  EXPECT_EQ(f->fixes[0].pose.position.lon_deg, 12.25);
  EXPECT_EQ(f->fixes[0].pose.position.alt_m, 1000.5);
  EXPECT_EQ(f->fixes[2].pose.position.alt_m, 1002);
  // Flying north: the derived heading says so.
  EXPECT_NEAR(geo::angleDiff_deg(0, f->fixes[1].pose.yaw_deg), 0, 1e-6);
}

TEST(FlightGpx, NamespacePrefixesAreIgnored) {
  const std::string text =
      "<g:gpx xmlns:g=\"http://www.topografix.com/GPX/1/0\"><g:trk><g:trkseg>"
      "<g:trkpt lat=\"1\" lon=\"2\"><g:ele>3</g:ele><g:time>2020-01-01T00:00:00Z</g:time></g:trkpt>"
      "<g:trkpt lat=\"1\" lon=\"2.001\"><g:ele>3</g:ele><g:time>2020-01-01T00:00:01Z</g:time></g:trkpt>"
      "</g:trkseg></g:trk></g:gpx>";
  auto f = parseGpx(text, "ns.gpx");
  ASSERT_TRUE(f) << f.error().detail;
  EXPECT_EQ(f->fixes.size(), 2u);
}

TEST(FlightGpx, ErrorsNameLineAndField) {
  const std::string ok = pt("46", "12", "1000", "2020-09-04T16:27:53Z");
  const std::string t2 = "2020-09-04T16:27:54Z";
  expectError(gpx(ok + pt("46", "12", "", t2)), "bad.gpx:7: field 'ele': missing");
  expectError(gpx(ok + pt("46", "12", "1000", "")), "bad.gpx:7: field 'time': missing");
  expectError(gpx(ok + pt("4x6", "12", "1000", t2)), "bad.gpx:7: field 'lat': '4x6' is not a number");
  expectError(gpx(ok + pt("91", "12", "1000", t2)), "bad.gpx:7: field 'lat': 91 outside [-90, 90]");
  expectError(gpx(ok + pt("46", "-180.5", "1000", t2)), "bad.gpx:7: field 'lon'");
  expectError(gpx(ok + "<trkpt lon=\"12\"><ele>1</ele><time>" + t2 + "</time></trkpt>\n"),
              "bad.gpx:7: field 'lat': missing");
  expectError(gpx(ok + pt("46", "12", "high", t2)), "bad.gpx:7: field 'ele': 'high' is not a number");
  expectError(gpx(ok + pt("46", "12", "1e9", t2)), "bad.gpx:7: field 'ele'");
  expectError(gpx(ok + pt("46", "12", "1000", "2020-09-04T16:27:54")), "bad.gpx:7: field 'time'");  // no zone
  expectError(gpx(ok + pt("46", "12", "1000", "2020-13-04T16:27:54Z")), "bad.gpx:7: field 'time'");
  expectError(gpx(ok), "bad.gpx: 1 usable <trkpt>, a flight needs at least two");
}

TEST(FlightGpx, MalformedXmlNamesTheLine) {
  expectError(gpx(pt("46", "12", "1000", "2020-09-04T16:27:53Z") + "<trkpt lat=\"46\" lon=\"12\"><ele>1</time>\n"),
              "bad.gpx:7: XML: mismatched tag");
  expectError("", "bad.gpx:1: XML: no element found");
  expectError("<gpx><trk><trkseg>\n<trkpt lat=\"1\" lon=\"2\">", "bad.gpx:2: XML:");
}

// Bug (found by fuzzing): a time cut short after its offset sign,
// "...T00:00:00+0", threw std::out_of_range from string_view::substr.
TEST(FlightGpx, TruncatedTimeOffsetIsAnError) {
  const std::string ok = pt("46", "12", "1000", "2020-09-04T16:27:53Z");
  expectError(gpx(ok + pt("46", "12", "1000", "2020-09-04T16:27:54+0")), "bad.gpx:7: field 'time'");
  expectError(gpx(ok + pt("46", "12", "1000", "2020-09-04T16:27:54.")), "bad.gpx:7: field 'time'");
}

// Bug (found by fuzzing, LeakSanitizer): a <trkpt> nested inside an open
// one's <time> replaced the open point while the text buffer still pointed
// into it. The inner one is not a track point of ours.
TEST(FlightGpx, NestedTrackPointIsIgnored) {
  const std::string text = gpx("<trkpt lat=\"46\" lon=\"12\"><ele>1</ele><time>2020-09-04T16:27:53Z"
                               "<trk><trkseg><trkpt lat=\"1\" lon=\"1\"><ele>1</ele><time>2020-01-01T00:00:00Z"
                               "</time></trkpt></trkseg></trk></time></trkpt>\n" +
                               pt("46.001", "12", "1", "2020-09-04T16:27:54Z"));
  auto f = parseGpx(text, "n.gpx");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 2u);
  EXPECT_EQ(f->fixes[0].pose.position.lat_deg, 46);
}

TEST(FlightGpx, OutOfOrderAndDuplicateTimesAreSkippedWithAWarning) {
  const std::string text = gpx(pt("46", "12", "1000", "2020-09-04T16:27:53Z") +
                               pt("46.001", "12", "1000", "2020-09-04T16:27:55Z") +
                               pt("46.002", "12", "1000", "2020-09-04T16:27:54Z") +  // line 8: back
                               pt("46.003", "12", "1000", "2020-09-04T16:27:55Z") +  // line 9: same
                               pt("46.004", "12", "1000", "2020-09-04T16:30:56Z"));  // line 10: gap
  auto f = parseGpx(text, "o.gpx");
  ASSERT_TRUE(f) << f.error().detail;
  ASSERT_EQ(f->fixes.size(), 3u);
  EXPECT_EQ(f->fixes[1].pose.position.lat_deg, 46.001);
  EXPECT_TRUE(anyWarningHas(*f, "o.gpx:8: field 'time': 1 s before the previous fix, fix skipped"));
  EXPECT_TRUE(anyWarningHas(*f, "o.gpx:9: field 'time': same as the previous fix, fix skipped"));
  EXPECT_TRUE(anyWarningHas(*f, "o.gpx:10: field 'time': 181 s gap before this fix (kept)"));
}

}  // namespace
}  // namespace sky::flight
