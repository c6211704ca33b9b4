// Scenario parsing: the good path, the deploy/ scenarios, and every error path,
// each of which must name the file, the line and the field.
#include <gtest/gtest.h>

#include <string>

#include "sky/server/scenario.hpp"

namespace sky::server {
namespace {

// Line numbers matter: tests below replace whole lines by number.
const char* const kGood =
    "[clock]\n"                                                            // 1
    "start_s = 100.0\n"                                                    // 2
    "rate = 2.0\n"                                                         // 3
    "\n"                                                                   // 4
    "[[layer]]\n"                                                          // 5
    "id = 1\n"                                                             // 6
    "type = \"cumulus\"\n"                                                 // 7
    "base_m = 1500.0\n"                                                    // 8
    "thickness_m = 1500\n"                                                 // 9
    "transition_band_m = 100.0\n"                                          // 10
    "coverage = 0.6\n"                                                     // 11
    "density = 1.0\n"                                                      // 12
    "wind = { speed_mps = 10.0, from_deg = 270.0, vertical_mps = 0.0 }\n"  // 13
    "\n"                                                                   // 14
    "[[layer]]\n"                                                          // 15
    "id = 2\n"                                                             // 16
    "type = \"cirrus\"\n"                                                  // 17
    "base_m = 9000.0\n"                                                    // 18
    "thickness_m = 500.0\n"                                                // 19
    "transition_band_m = 50.0\n"                                           // 20
    "coverage = 0.2\n"                                                     // 21
    "density = 0.5\n"                                                      // 22
    "wind = { speed_mps = 30.0, from_deg = 250.0, vertical_mps = 0.0 }\n"; // 23

// kGood with line `line` (1-based) replaced by `text` (which may be empty).
std::string withLine(int line, const std::string& text) {
  std::string out;
  int n = 1;
  std::size_t start = 0;
  const std::string good = kGood;
  while (start < good.size()) {
    const std::size_t end = good.find('\n', start);
    out += (n == line ? text : good.substr(start, end - start)) + "\n";
    start = end + 1;
    ++n;
  }
  return out;
}

// The error of parsing `text` as "test.toml"; fails the test if it parses.
Error errorOf(const std::string& text) {
  auto r = parseScenario(text, "test.toml");
  EXPECT_FALSE(r.has_value()) << "parsed but should not:\n" << text;
  return r ? Error{} : r.error();
}

#define EXPECT_HAS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

TEST(Scenario, GoodFileParsesEveryField) {
  auto r = parseScenario(kGood, "test.toml");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_DOUBLE_EQ(r->clock.start_s, 100.0);
  EXPECT_DOUBLE_EQ(r->clock.rate, 2.0);
  ASSERT_EQ(r->layers.size(), 2u);
  const weather::CloudLayer& l = r->layers[0];
  EXPECT_EQ(l.id, 1u);
  EXPECT_EQ(l.type, weather::CloudType::Cumulus);
  EXPECT_DOUBLE_EQ(l.base_m, 1500.0);
  EXPECT_DOUBLE_EQ(l.thickness_m, 1500.0);  // written as an integer
  EXPECT_DOUBLE_EQ(l.transitionBand_m, 100.0);
  EXPECT_DOUBLE_EQ(l.coverage, 0.6);
  EXPECT_DOUBLE_EQ(l.density, 1.0);
  EXPECT_DOUBLE_EQ(l.wind.speed_mps, 10.0);
  EXPECT_DOUBLE_EQ(l.wind.fromDirection_deg, 270.0);
  EXPECT_DOUBLE_EQ(l.wind.vertical_mps, 0.0);
  EXPECT_EQ(r->layers[1].type, weather::CloudType::Cirrus);
  EXPECT_DOUBLE_EQ(r->layers[1].density, 0.5);
}

TEST(Scenario, NoLayersIsAClearSky) {
  auto r = parseScenario("[clock]\nstart_s = 0\nrate = 1\n", "clear.toml");
  ASSERT_TRUE(r) << r.error().detail;
  EXPECT_TRUE(r->layers.empty());
}

TEST(Scenario, DeployScenariosLoad) {
  auto cumulus = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/skeleton-cumulus.toml");
  ASSERT_TRUE(cumulus) << cumulus.error().detail;
  ASSERT_EQ(cumulus->layers.size(), 1u);
  EXPECT_EQ(cumulus->layers[0].type, weather::CloudType::Cumulus);
  EXPECT_DOUBLE_EQ(cumulus->layers[0].coverage, 0.6);
  EXPECT_DOUBLE_EQ(cumulus->layers[0].wind.fromDirection_deg, 270.0);

  auto clear = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/clear.toml");
  ASSERT_TRUE(clear) << clear.error().detail;
  ASSERT_EQ(clear->layers.size(), 1u);
  EXPECT_DOUBLE_EQ(clear->layers[0].coverage, 0.0);
}

TEST(Scenario, MissingFileIsIo) {
  auto r = loadScenario("/nonexistent/skyshell.toml");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Io);
  EXPECT_HAS(r.error().detail, "/nonexistent/skyshell.toml");
}

TEST(Scenario, BadCloudTypeNamesLineAndField) {
  const Error e = errorOf(withLine(17, "type = \"cirus\""));
  EXPECT_EQ(e.code, ErrorCode::InvalidArgument);
  EXPECT_HAS(e.detail, "test.toml:17:");
  EXPECT_HAS(e.detail, "layer[1].type");
  EXPECT_HAS(e.detail, "'cirus'");
}

TEST(Scenario, CloudTypeMustBeAString) {
  const Error e = errorOf(withLine(7, "type = 7"));
  EXPECT_HAS(e.detail, "test.toml:7:");
  EXPECT_HAS(e.detail, "layer[0].type");
}

TEST(Scenario, CoverageOutOfRangeNamesLineAndField) {
  const Error e = errorOf(withLine(11, "coverage = 1.5"));
  EXPECT_EQ(e.code, ErrorCode::InvalidArgument);
  EXPECT_HAS(e.detail, "test.toml:11:");
  EXPECT_HAS(e.detail, "layer[0].coverage");
}

TEST(Scenario, NestedWindOutOfRangeNamesLineAndField) {
  const Error e =
      errorOf(withLine(23, "wind = { speed_mps = 30.0, from_deg = 400.0, vertical_mps = 0.0 }"));
  EXPECT_EQ(e.code, ErrorCode::InvalidArgument);
  EXPECT_HAS(e.detail, "test.toml:23:");
  EXPECT_HAS(e.detail, "layer[1].wind.from_deg");
}

TEST(Scenario, NumberOfWrongTypeIsMalformed) {
  const Error e = errorOf(withLine(8, "base_m = \"high\""));
  EXPECT_EQ(e.code, ErrorCode::Malformed);
  EXPECT_HAS(e.detail, "test.toml:8:");
  EXPECT_HAS(e.detail, "layer[0].base_m");
}

TEST(Scenario, UnknownKeysAreRejectedEverywhere) {
  {
    const Error e = errorOf(withLine(12, "densty = 1.0"));
    EXPECT_EQ(e.code, ErrorCode::Malformed);
    EXPECT_HAS(e.detail, "test.toml:12:");
    EXPECT_HAS(e.detail, "layer[0].densty");
    EXPECT_HAS(e.detail, "unknown key");
  }
  {
    const Error e = errorOf(withLine(4, "seed = 3"));
    EXPECT_HAS(e.detail, "test.toml:4:");
    EXPECT_HAS(e.detail, "seed");
  }
  {
    const Error e = errorOf(withLine(3, "rate = 2.0\nspeedup = 2"));
    EXPECT_HAS(e.detail, "test.toml:4:");
    EXPECT_HAS(e.detail, "clock.speedup");
  }
  {
    const Error e = errorOf(
        withLine(13, "wind = { speed_mps = 10.0, from_deg = 270.0, vertical_mps = 0.0, gust = 3 }"));
    EXPECT_HAS(e.detail, "test.toml:13:");
    EXPECT_HAS(e.detail, "layer[0].wind.gust");
  }
}

TEST(Scenario, MissingFieldsAreNamed) {
  {
    // The layer's header line: the key itself has no line.
    const Error e = errorOf(withLine(22, ""));
    EXPECT_EQ(e.code, ErrorCode::Malformed);
    EXPECT_HAS(e.detail, "test.toml:15:");
    EXPECT_HAS(e.detail, "layer[1].density: missing");
  }
  {
    const Error e =
        errorOf(withLine(13, "wind = { speed_mps = 10.0, from_deg = 270.0 }"));
    EXPECT_HAS(e.detail, "layer[0].wind.vertical_mps: missing");
  }
  {
    const Error e = errorOf(withLine(6, ""));
    EXPECT_HAS(e.detail, "layer[0].id: missing");
  }
}

TEST(Scenario, MissingClockTable) {
  const std::string text = std::string(kGood).substr(std::string(kGood).find("[[layer]]"));
  const Error e = errorOf(text);
  EXPECT_HAS(e.detail, "clock: missing");
}

TEST(Scenario, TomlSyntaxErrorGivesItsLine) {
  const Error e = errorOf(withLine(10, "transition_band_m = = 100"));
  EXPECT_EQ(e.code, ErrorCode::Malformed);
  EXPECT_HAS(e.detail, "test.toml:10:");
}

TEST(Scenario, DuplicateLayerIdsAreRejected) {
  const Error e = errorOf(withLine(16, "id = 1"));
  EXPECT_HAS(e.detail, "test.toml:16:");
  EXPECT_HAS(e.detail, "layer[1].id");
}

TEST(Scenario, ClockRateOutOfRange) {
  const Error e = errorOf(withLine(3, "rate = -1.0"));
  EXPECT_EQ(e.code, ErrorCode::InvalidArgument);
  EXPECT_HAS(e.detail, "test.toml:3:");
  EXPECT_HAS(e.detail, "clock.rate");
}

TEST(Scenario, NonFiniteNumbersAreRejected) {
  const Error e = errorOf(withLine(8, "base_m = nan"));
  EXPECT_HAS(e.detail, "test.toml:8:");
  EXPECT_HAS(e.detail, "layer[0].base_m");
}

TEST(Scenario, LayerMustBeAnArrayOfTables) {
  const Error e = errorOf("layer = 3\n[clock]\nstart_s = 0\nrate = 1\n");
  EXPECT_HAS(e.detail, "test.toml:1:");
  EXPECT_HAS(e.detail, "[[layer]]");
}

}  // namespace
}  // namespace sky::server
