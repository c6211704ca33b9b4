// skyshell-scenario files: the documented format parses into the flight and
// actions (TOML request tables become the JSON the API gets); every mistake is
// an error naming file, line and field; the bundled examples parse.
#include <gtest/gtest.h>

#include "sky/sim/sim_scenario.hpp"

namespace sky::sim {
namespace {

constexpr const char* kGood = R"(# comment
[flight]
file = "flights/a.csv"
speed = 4
start_s = 10
end_s = 600.5

[[action]]
at_s = 300
what = "later one, written first"
request = { changes = [ { op = "set_clock", rate = 60 } ] }

[[action]]
at_s = 30.0
what = "thicken the deck"
api = "changes"
request.author = "instructor"
request.changes = [ { op = "set_layer", ramp_s = 120, layer = { id = 1, coverage = 0.9, on = true } } ]
)";

TEST(SimScenario, ParsesTheDocumentedFormat) {
  auto s = parseSimScenario(kGood, "s.toml", "/base");
  ASSERT_TRUE(s) << s.error().detail;
  EXPECT_EQ(s->flightFile, std::filesystem::path("/base/flights/a.csv"));
  EXPECT_EQ(s->speed, 4.0);
  EXPECT_EQ(s->start_s, 10.0);
  EXPECT_EQ(s->end_s, 600.5);
  ASSERT_EQ(s->actions.size(), 2u);
  // Sorted by time.
  EXPECT_EQ(s->actions[0].at_s, 30.0);
  EXPECT_EQ(s->actions[0].what, "thicken the deck");
  EXPECT_EQ(s->actions[0].line, 13u);  // its [[action]] header
  const nlohmann::json want = nlohmann::json::parse(
      R"({"author":"instructor","changes":[{"op":"set_layer","ramp_s":120,"layer":{"id":1,"coverage":0.9,"on":true}}]})");
  EXPECT_EQ(s->actions[0].request, want);
  EXPECT_EQ(s->actions[1].request["changes"][0]["rate"], 60);
  EXPECT_EQ(s->actions[0].target, "/api/changes");
  EXPECT_EQ(s->actions[1].target, "/api/changes");  // the default
}

TEST(SimScenario, AnActionMayPostMetarReports) {
  auto s = parseSimScenario(R"([flight]
file = "a.csv"
[[action]]
at_s = 5
what = "LIPA lowers"
api = "metar"
request = { apply = true, reports = ["METAR LIPA 221150Z 24008KT 9999 OVC008 12/06 Q1018"] }
)",
                            "s.toml", "/base");
  ASSERT_TRUE(s) << s.error().detail;
  EXPECT_EQ(s->actions[0].target, "/api/metar");
  EXPECT_EQ(s->actions[0].request["reports"].size(), 1u);
  auto bad = parseSimScenario("[flight]\nfile = \"a.csv\"\n[[action]]\nat_s = 1\nwhat = \"x\"\napi = \"state\"\nrequest = {}\n",
                              "s.toml", ".");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().detail.find("s.toml:6:7: action[0].api: must be \"changes\" or \"metar\""), std::string::npos)
      << bad.error().detail;
}

TEST(SimScenario, ErrorsNameLineAndField) {
  struct Case {
    const char* text;
    const char* want;
  };
  const Case cases[] = {
      {"[flight]\nfile = \"a.csv\"\nsped = 2\n", "s.toml:3:8: flight.sped: unknown key"},
      {"[flight]\nspeed = 2\n", "flight.file: missing"},
      {"[flight]\nfile = \"a.csv\"\nspeed = 500\n", "s.toml:3:9: flight.speed: 500.000000 outside [0.050000, 100.000000]"},
      {"[flight]\nfile = \"a.csv\"\nstart_s = 50\nend_s = 40\n", "flight.end_s: must be after start_s"},
      {"[flight]\nfile = \"a.csv\"\n[[action]]\nat_s = 1\nrequest = {}\n", "action[0].what: missing"},
      {"[flight]\nfile = \"a.csv\"\nend_s = 10\n[[action]]\nat_s = 11\nwhat = \"x\"\nrequest = {}\n",
       "action[0].at_s: 11.000000 outside the flown part"},
      {"[flight]\nfile = \"a.csv\"\n[[action]]\nat_s = \"soon\"\nwhat = \"x\"\nrequest = {}\n",
       "s.toml:4:8: action[0].at_s: must be a number"},
      {"[flight]\nfile = \"a.csv\"\n[[action]]\nat_s = 1\nwhat = \"x\"\nrequest = 5\n", "action[0].request: must be a table"},
      {"[flight\nfile = 1", "s.toml:1:"},
      {"", "flight: missing"},
  };
  for (const auto& c : cases) {
    auto s = parseSimScenario(c.text, "s.toml", ".");
    ASSERT_FALSE(s) << c.text;
    EXPECT_NE(s.error().detail.find(c.want), std::string::npos) << "got: " << s.error().detail;
  }
}

TEST(SimScenario, BundledExamplesParse) {
  for (const char* name : {"climb-into-sun.toml", "demo-live-weather.toml", "demo-forecast-weather.toml"}) {
    auto s = loadSimScenario(std::filesystem::path(SKY_SOURCE_DIR) / "deploy/sim-scenarios" / name);
    ASSERT_TRUE(s) << s.error().detail;
    EXPECT_TRUE(std::filesystem::exists(s->flightFile)) << s->flightFile;
    EXPECT_FALSE(s->actions.empty());
  }
}

}  // namespace
}  // namespace sky::sim
