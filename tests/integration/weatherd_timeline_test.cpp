// Scenario timelines through a real skyshell-weatherd with a real SQLite
// file: a --scenario timeline is listed as pending and made as the weather
// clock reaches it (an event of source scenario, pushed to a console);
// POST /api/scenario needs the token, refuses a bad scenario naming file,
// line and field with the weather unchanged, and loads a good one whose
// waiting timeline survives a restart on the same --db.
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "weatherd_console_client.hpp"
#include "weatherd_process.hpp"

namespace sky::test {
namespace {

// The clock runs at x100: the entry at 300 s comes ~2 s after the start, the
// one at 100000 s not within the test.
const char* kFastTimeline = R"([clock]
start_s = 100
rate = 100

[[layer]]
id = 1
type = "cumulus"
base_m = 1500
thickness_m = 1000
transition_band_m = 100
coverage = 0.3
density = 1
wind = { speed_mps = 10, from_deg = 270, vertical_mps = 0 }

[[timeline]]
at_s = 300
op = "set_layer"
ramp_s = 60
layer = { id = 2, type = "stratus", base_m = 400, thickness_m = 300, transition_band_m = 50, coverage = 0.8, density = 0.7, wind = { speed_mps = 5, from_deg = 200, vertical_mps = 0 } }

[[timeline]]
at_s = 100000
op = "remove_layer"
id = 1
ramp_s = 600
)";

std::string write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path.string();
}

TEST(WeatherdTimeline, AScenarioTimelineIsPendingThenMadeOnTheWeatherClock) {
  const auto dir = std::filesystem::path(SKY_TEST_OUTPUT_DIR) / "weatherd-timeline-files";
  std::filesystem::create_directories(dir);
  Weatherd w("weatherd-timeline", write(dir / "fast.toml", kFastTimeline));
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  Console console(w.httpPort);
  ASSERT_TRUE(console.open());
  auto state = console.readType("state");
  ASSERT_TRUE(state);
  const auto& pending = (*state)["state"]["pending"];
  ASSERT_EQ(pending.size(), 2u) << state->dump();
  EXPECT_EQ(pending[0]["kind"], "timeline");
  EXPECT_EQ(pending[0]["start_s"], 300);
  EXPECT_EQ(pending[0]["end_s"], 360);
  EXPECT_EQ(pending[0]["summary"], "fast.toml: layer 2 (stratus) coverage -> 0.80 over 60 s");
  EXPECT_EQ(pending[1]["start_s"], 100000);

  // At clock 300 the server makes the first entry: its event reaches the console.
  auto event = console.readUntil("event", [](const nlohmann::json&) { return true; }, 60s);
  ASSERT_TRUE(event) << w.process->log();
  EXPECT_EQ((*event)["event"]["source"], "scenario");
  EXPECT_EQ((*event)["event"]["author"], "scenario:fast.toml");
  EXPECT_GE((*event)["event"]["clock_s"].get<double>(), 300);
  auto after = console.readType("state");
  ASSERT_TRUE(after);
  EXPECT_EQ((*after)["state"]["layers"].size(), 2u);
  const auto& left = (*after)["state"]["pending"];
  ASSERT_FALSE(left.empty());
  EXPECT_EQ(left.back()["kind"], "timeline");
  EXPECT_EQ(left.back()["start_s"], 100000);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

TEST(WeatherdTimeline, PostScenarioChecksLoadsAndSurvivesARestart) {
  const auto dir = std::filesystem::path(SKY_TEST_OUTPUT_DIR) / "weatherd-post-scenario-db";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string db = (dir / "weather.db").string();
  std::optional<Weatherd> w;
  w.emplace("weatherd-post-scenario", SKY_SCENARIO_CLOUDY, false, std::vector<std::string>{"--db", db});
  ASSERT_GT(w->httpPort, 0u) << w->process->log();
  // A slow clock this time: nothing comes due.
  std::string scenario = kFastTimeline;
  scenario.replace(scenario.find("rate = 100"), 10, "rate = 0.001");

  EXPECT_EQ(w->request("POST", "/api/scenario", scenario, "").status, 401);
  // Refused: the timeline removes a layer the scenario never has.
  std::string bad = scenario;
  bad.replace(bad.find("id = 1\nramp_s = 600"), 6, "id = 9");
  const auto refused = w->request("POST", "/api/scenario",
                                  nlohmann::json{{"toml", bad}, {"name", "exercise.toml"}}.dump());
  ASSERT_EQ(refused.status, 400) << refused.body;
  const auto err = nlohmann::json::parse(refused.body);
  EXPECT_EQ(err["file"], "exercise.toml");
  EXPECT_EQ(err["line"], 21) << err.dump();  // the entry's [[timeline]]
  EXPECT_EQ(err["field"], "timeline[1].id");
  EXPECT_NE(err["error"].get<std::string>().find("no layer 9"), std::string::npos) << err.dump();
  // A TOML syntax error: the line too.
  const auto broken = w->request("POST", "/api/scenario", "[clock]\nstart_s = \n");
  ASSERT_EQ(broken.status, 400);
  EXPECT_EQ(nlohmann::json::parse(broken.body)["line"], 2) << broken.body;
  auto state = nlohmann::json::parse(w->request("GET", "/api/state").body);
  EXPECT_EQ(state["sequence"], 0) << "a refused scenario changes nothing";
  EXPECT_TRUE(state["pending"].empty());

  const auto loaded = w->request("POST", "/api/scenario", scenario);
  ASSERT_EQ(loaded.status, 200) << loaded.body;
  const auto ok = nlohmann::json::parse(loaded.body);
  EXPECT_EQ(ok["sequence"], 1);
  EXPECT_EQ(ok["timeline"], 2);
  state = nlohmann::json::parse(w->request("GET", "/api/state").body);
  ASSERT_EQ(state["pending"].size(), 2u);
  EXPECT_NEAR(state["clock_s"].get<double>(), 100, 1);
  EXPECT_EQ(state["clock_rate"], 0.001);
  const std::string metrics = w->request("GET", "/metrics").body;
  EXPECT_NE(metrics.find("skyshell_rejected_inputs_total{reason=\"scenario_invalid\"} 2\n"), std::string::npos)
      << metrics;

  // Restart on the same file: the timeline still waits.
  EXPECT_EQ(w->process->stop(), 0) << w->process->log();
  w.emplace("weatherd-post-scenario-2", SKY_SCENARIO_CLOUDY, false, std::vector<std::string>{"--db", db});
  ASSERT_GT(w->httpPort, 0u) << w->process->log();
  const auto restored = nlohmann::json::parse(w->request("GET", "/api/state").body);
  EXPECT_EQ(restored["sequence"], 1);
  EXPECT_EQ(restored["pending"], state["pending"]);
  EXPECT_EQ(w->process->stop(), 0) << w->process->log();
}

}  // namespace
}  // namespace sky::test
