// Ill-formed UTF-8 in flight files and in their names (issue 18): refused
// (CSV, GPX) or replaced, never echoed raw in a message; the helper of
// protocol/flight (utf8_text.hpp) against the Unicode 15 §3.9 examples.
#include <string>

#include <gtest/gtest.h>

#include "sky/flight/flight.hpp"
#include "sky/flight/utf8_text.hpp"

namespace sky::flight {
namespace {

const std::string kFfd = "\xEF\xBF\xBD";  // U+FFFD

TEST(Utf8Text, FindsTheFirstIllFormedSequence) {
  EXPECT_EQ(firstInvalidUtf8(""), std::nullopt);
  EXPECT_EQ(firstInvalidUtf8("plain ascii"), std::nullopt);
  EXPECT_EQ(firstInvalidUtf8("J\xC3\xB6rg \xE2\x82\xAC \xF0\x9F\x9B\xA9"), std::nullopt);  // ö € 🛩
  EXPECT_EQ(firstInvalidUtf8("ab\x80"), std::optional<std::size_t>(2));          // lone continuation
  EXPECT_EQ(firstInvalidUtf8("a\xC0\xAF"), std::optional<std::size_t>(1));       // overlong '/'
  EXPECT_EQ(firstInvalidUtf8("a\xE0\x80\xAF"), std::optional<std::size_t>(1));   // overlong, 3 bytes
  EXPECT_EQ(firstInvalidUtf8("a\xED\xA0\x80"), std::optional<std::size_t>(1));   // surrogate D800
  EXPECT_EQ(firstInvalidUtf8("a\xF4\x90\x80\x80"), std::optional<std::size_t>(1));  // above U+10FFFF
  EXPECT_EQ(firstInvalidUtf8("a\xF5"), std::optional<std::size_t>(1));
  EXPECT_EQ(firstInvalidUtf8("abc\xE2\x82"), std::optional<std::size_t>(3));     // truncated at the end
  EXPECT_EQ(firstInvalidUtf8("Latin-1 J\xF6rg"), std::optional<std::size_t>(9));
}

// Unicode 15 §3.9, Table 3-8: "61 F1 80 80 E1 80 C2 62 80 63 80 BF 64" gives
// a FFFD FFFD FFFD b FFFD c FFFD FFFD d (maximal subparts).
TEST(Utf8Text, ReplacesMaximalSubparts) {
  EXPECT_EQ(replaceInvalidUtf8("\x61\xF1\x80\x80\xE1\x80\xC2\x62\x80\x63\x80\xBF\x64"),
            "a" + kFfd + kFfd + kFfd + "b" + kFfd + "c" + kFfd + kFfd + "d");
  EXPECT_EQ(replaceInvalidUtf8("J\xC3\xB6rg"), "J\xC3\xB6rg");
}

TEST(Utf8Text, CutsOnCharacterBoundaries) {
  const std::string s = "ab\xE2\x82\xAC";  // a b €
  EXPECT_EQ(cutUtf8(s, 10), s);
  EXPECT_EQ(cutUtf8(s, 5), s);
  EXPECT_EQ(cutUtf8(s, 4), "ab");
  EXPECT_EQ(cutUtf8(s, 3), "ab");
  EXPECT_EQ(cutUtf8(s, 2), "ab");
  EXPECT_EQ(cutUtf8(s, 0), "");
  EXPECT_EQ(messageText("x\x1b[31m\xFFy"), "x?[31m" + kFfd + "y");
  const std::string cut = messageText(std::string(10, 'a') + "\xE2\x82\xAC", 12);
  EXPECT_EQ(cut, std::string(10, 'a') + "...");
  EXPECT_FALSE(firstInvalidUtf8(cut));
}

// Every message a reader gives is well-formed UTF-8 without control bytes.
void expectCleanMessage(const std::string& m) {
  EXPECT_FALSE(firstInvalidUtf8(m)) << m;
  for (char c : m) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20) << m;
}

constexpr const char* kCsvHeader = "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n";

TEST(FlightUtf8, CsvWithIllFormedUtf8IsRefusedNamingLineAndByte) {
  const std::string text = std::string(kCsvHeader) + "0,46,12,900,0,0,0\n# pilot J\xF6rg\n1,46,12,900,0,0,0\n";
  const auto r = parseCsv(text, "a.csv");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Malformed);
  EXPECT_EQ(r.error().detail, "a.csv:3: byte 10 of the line is not UTF-8");
  // In a field: refused before the field is read, not echoed.
  const auto f = parseCsv(std::string(kCsvHeader) + "0,4\xC0\xAF,12,900,0,0,0\n1,46,12,900,0,0,0\n", "a.csv");
  ASSERT_FALSE(f);
  expectCleanMessage(f.error().detail);
  // Well-formed text beyond ASCII in a comment is fine.
  EXPECT_TRUE(parseCsv(std::string(kCsvHeader) + "# J\xC3\xB6rg\n0,46,12,900,0,0,0\n1,46,12,900,0,0,0\n", "a.csv"));
  // A field that is not a number is quoted as printable ASCII only.
  const auto n = parseCsv(std::string(kCsvHeader) + "0,\xC3\xB6\x1b[2J,12,900,0,0,0\n", "a.csv");
  ASSERT_FALSE(n);
  expectCleanMessage(n.error().detail);
}

TEST(FlightUtf8, IllFormedSourceNamesAreReplaced) {
  const std::string name = "fl\xFF\x1bight.csv";
  const auto r = parseCsv("nonsense\n", name);
  ASSERT_FALSE(r);
  expectCleanMessage(r.error().detail);
  EXPECT_EQ(r.error().detail.rfind("fl" + kFfd + "?ight.csv:1:", 0), 0u) << r.error().detail;
  const auto u = parseFlight("", "flight.\xFF\xFE");
  ASSERT_FALSE(u);
  expectCleanMessage(u.error().detail);
  const auto g = parseGpx("<gpx/>", name.substr(0, name.size() - 4) + ".gpx");
  ASSERT_FALSE(g);
  expectCleanMessage(g.error().detail);
}

// IGC: bytes beyond ASCII in records we do not read are allowed (Latin-1
// pilot names are common); a junk line quoted in a warning is ASCII only.
TEST(FlightUtf8, IgcKeepsItsFixesAndWarnsInCleanText) {
  const std::string igc =
      "AXXX\nHFDTE010120\nHFPLTPILOTINCHARGE:J\xF6rg \xFF\xFE\n"
      "B1200004600000N01200000EA0090000900\n"
      "\xC3\x28 junk line \x1b[31m\n"
      "B1200104600100N01200100EA0090000900\n"
      "B12002\xF6\xF6\xF6\n";
  const auto r = parseIgc(igc, "x\xFF.igc");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_EQ(r->fixes.size(), 2u);
  ASSERT_FALSE(r->warnings.empty());
  for (const auto& w : r->warnings) expectCleanMessage(w);
}

// GPX: text that is not UTF-8 in a UTF-8 document is an XML error (expat);
// the message does not carry the bytes.
TEST(FlightUtf8, GpxWithIllFormedUtf8IsRefused) {
  const std::string head = "<?xml version=\"1.0\"?><gpx><trk><name>";
  const std::string tail =
      "</name><trkseg>"
      "<trkpt lat=\"46\" lon=\"12\"><ele>900</ele><time>2020-01-01T12:00:00Z</time></trkpt>"
      "<trkpt lat=\"46.01\" lon=\"12\"><ele>900</ele><time>2020-01-01T12:00:10Z</time></trkpt>"
      "</trkseg></trk></gpx>";
  ASSERT_TRUE(parseGpx(head + "J\xC3\xB6rg" + tail, "a.gpx"));
  for (const std::string bad : {"J\xF6rg", "\xC0\xAF", "\xED\xA0\x80", "\xF4\x90\x80\x80", "\xE2\x82"}) {
    const auto r = parseGpx(head + bad + tail, "a.gpx");
    ASSERT_FALSE(r) << bad;
    expectCleanMessage(r.error().detail);
  }
  // An ill-formed value in an attribute: refused the same way.
  std::string attr = head + "n" + tail;
  attr.replace(attr.find("lat=\"46\""), 8, "lat=\"4\xFF\"");
  const auto a = parseGpx(attr, "a.gpx");
  ASSERT_FALSE(a);
  expectCleanMessage(a.error().detail);
}

}  // namespace
}  // namespace sky::flight
