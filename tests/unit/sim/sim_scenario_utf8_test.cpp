// skyshell-scenario files with ill-formed UTF-8 (issue 18): refused before
// the TOML parser sees them, naming line and column, without echoing the
// bytes; well-formed text beyond ASCII still parses and survives into the
// JSON the API gets (nlohmann::json::dump throws on ill-formed UTF-8).
#include <string>

#include <gtest/gtest.h>

#include "sky/flight/utf8_text.hpp"
#include "sky/sim/sim_scenario.hpp"

namespace sky::sim {
namespace {

std::string scenarioWithWhat(const std::string& what) {
  return "[flight]\nfile = \"a.csv\"\n\n[[action]]\nat_s = 1\nwhat = \"" + what +
         "\"\nrequest = { author = \"" + what + "\" }\n";
}

TEST(SimScenarioUtf8, IllFormedUtf8IsRefusedNamingLineAndColumn) {
  for (const std::string bad : {"J\xF6rg", "\xC0\xAF", "\xED\xA0\x80", "\xF4\x90\x80\x80", "\xE2\x82"}) {
    const auto s = parseSimScenario(scenarioWithWhat(bad), "s.toml", ".");
    ASSERT_FALSE(s) << bad;
    EXPECT_EQ(s.error().code, ErrorCode::Malformed);
    EXPECT_EQ(s.error().detail.rfind("s.toml:6:", 0), 0u) << s.error().detail;
    EXPECT_FALSE(flight::firstInvalidUtf8(s.error().detail)) << s.error().detail;
  }
  // In a comment and in a key: the same.
  EXPECT_FALSE(parseSimScenario("# \xFF\n" + scenarioWithWhat("x"), "s.toml", "."));
  EXPECT_FALSE(parseSimScenario("[flight]\n\"f\xFF\" = 1\n", "s.toml", "."));
  // A surrogate written as an escape is no character either (TOML 1.0:
  // escapes are Unicode scalar values); the parser refuses it.
  EXPECT_FALSE(parseSimScenario(scenarioWithWhat("\\uD800"), "s.toml", "."));
}

TEST(SimScenarioUtf8, WellFormedTextBeyondAsciiParsesAndDumps) {
  const auto s = parseSimScenario(scenarioWithWhat("J\xC3\xB6rg \xE2\x9B\x85"), "s.toml", ".");
  ASSERT_TRUE(s) << s.error().detail;
  ASSERT_EQ(s->actions.size(), 1u);
  EXPECT_EQ(s->actions[0].what, "J\xC3\xB6rg \xE2\x9B\x85");
  EXPECT_NO_THROW(s->actions[0].request.dump());
}

TEST(SimScenarioUtf8, AnIllFormedSourceNameIsReplaced) {
  const auto s = parseSimScenario("[flight]\n", "s\xFF.toml", ".");
  ASSERT_FALSE(s);
  EXPECT_FALSE(flight::firstInvalidUtf8(s.error().detail)) << s.error().detail;
  const auto missing = loadSimScenario("/nonexistent/s\xFF\x1b.toml");
  ASSERT_FALSE(missing);
  EXPECT_FALSE(flight::firstInvalidUtf8(missing.error().detail));
  EXPECT_EQ(missing.error().detail.find('\x1b'), std::string::npos);
}

}  // namespace
}  // namespace sky::sim
