// Scenario timelines: parsing (the bundled storm-timeline.toml, strict
// errors naming file, line and field), loading a scenario into the live
// weather (its start replaces the weather; every entry checked against the
// weather it will meet, or the scenario is refused with the state
// unchanged), entries made as the weather clock reaches them, shown as
// pending meanwhile, and kept across a restart in a real SQLite file.
#include <filesystem>

#include <gtest/gtest.h>

#include "sky/server/api_json.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/scenario.hpp"
#include "sky/server/weather_store.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::server {
namespace {

using Op = weather::TimelineEntry::Op;

const WallClock::time_point kT0{std::chrono::hours(1000)};

constexpr const char* kStart = R"(
[clock]
start_s = 100
rate = 1

[[layer]]
id = 1
type = "cumulus"
base_m = 1500
thickness_m = 1000
transition_band_m = 100
coverage = 0.3
density = 1
wind = { speed_mps = 10, from_deg = 270, vertical_mps = 0 }
)";

const char* kLayer2 =
    "{ id = 2, type = \"stratus\", base_m = 400, thickness_m = 300, transition_band_m = 50, coverage = 0.8, "
    "density = 0.7, wind = { speed_mps = 5, from_deg = 200, vertical_mps = 0 } }";

// kStart plus these [[timeline]] entries.
std::string withTimeline(const std::string& entries) { return std::string(kStart) + entries; }

Result<Scenario> parse(const std::string& text) { return parseScenario(text, "t.toml"); }

TEST(TimelineParse, TheBundledStormScenario) {
  auto s = loadScenario(SKY_SOURCE_DIR "/deploy/scenarios/storm-timeline.toml");
  ASSERT_TRUE(s) << s.error().detail;
  ASSERT_EQ(s->layers.size(), 1u);
  ASSERT_EQ(s->timeline.size(), 4u);
  EXPECT_EQ(s->timeline[0].op, Op::SetLayer);
  EXPECT_EQ(s->timeline[0].at_s, 120);
  EXPECT_EQ(s->timeline[0].ramp_s, 600);
  EXPECT_NEAR(s->timeline[0].layer.coverage, 0.8, 1e-12);
  EXPECT_EQ(s->timeline[1].op, Op::SetRegion);
  EXPECT_EQ(s->timeline[1].region.id, 7u);
  EXPECT_TRUE(s->timeline[1].region.driftsWithWind);
  ASSERT_EQ(s->timeline[1].region.layers.size(), 1u);
  EXPECT_EQ(s->timeline[1].region.layers[0].type, weather::CloudType::Cumulonimbus);
  // Same at_s: file order.
  EXPECT_EQ(s->timeline[2].op, Op::RemoveRegion);
  EXPECT_EQ(s->timeline[3].op, Op::SetLayer);
  EXPECT_EQ(s->timeline[2].at_s, s->timeline[3].at_s);
  EXPECT_NE(s->timeline[1].where.find("storm-timeline.toml:"), std::string::npos);
  EXPECT_NE(s->timeline[1].where.find(": timeline[1]"), std::string::npos) << s->timeline[1].where;
}

TEST(TimelineParse, EntriesAreOrderedByTime) {
  auto s = parse(withTimeline(R"(
[[timeline]]
at_s = 500
op = "remove_layer"
id = 1

[[timeline]]
at_s = 200
op = "set_clock"
rate = 60
)"));
  ASSERT_TRUE(s) << s.error().detail;
  ASSERT_EQ(s->timeline.size(), 2u);
  EXPECT_EQ(s->timeline[0].op, Op::SetClock);
  EXPECT_EQ(s->timeline[0].rate, 60);
  EXPECT_FALSE(s->timeline[0].jumpTo_s);
  EXPECT_EQ(s->timeline[1].op, Op::RemoveLayer);
  // "where" is the entry's own line: [[timeline]] of the file's second entry.
  EXPECT_EQ(s->timeline[0].where.rfind("t.toml:", 0), 0u);
  EXPECT_NE(s->timeline[0].where.find(": timeline[1]"), std::string::npos) << s->timeline[0].where;
}

TEST(TimelineParse, ErrorsNameFileLineAndField) {
  struct Case {
    std::string entries;
    std::string expected;  // in the error
  };
  const int line = 15;  // kStart has 14 lines: the entry starts on line 15
  const Case cases[] = {
      {"[[timeline]]\nat_s = 50\nop = \"remove_layer\"\nid = 1\n", "timeline[0].at_s: 50.000000 is before clock.start_s"},
      {"[[timeline]]\nat_s = 200\nop = \"explode\"\n", "timeline[0].op: 'explode' is not one of"},
      {"[[timeline]]\nat_s = 200\nop = \"set_clock\"\n", "timeline[0].rate: set_clock needs rate or jump_to_s"},
      {"[[timeline]]\nat_s = 200\nop = \"set_clock\"\nrate = 7200\n", "timeline[0].rate: 7200"},
      {"[[timeline]]\nat_s = 200\nop = \"remove_layer\"\nid = 1\nramp_s = -1\n", "timeline[0].ramp_s: -1"},
      {"[[timeline]]\nat_s = 200\nop = \"remove_layer\"\nid = 1\ncolour = 3\n", "timeline[0].colour: unknown key"},
      {"[[timeline]]\nat_s = 200\nop = \"remove_region\"\nid = 0\n", "timeline[0].id: must be an integer in [1, 65535]"},
      {"[[timeline]]\nat_s = 200\nop = \"set_layer\"\n", "timeline[0].layer: missing (required)"},
      {std::string("[[timeline]]\nat_s = 200\nop = \"set_layer\"\nlayer = ") + kLayer2 + "\n", ""},
      {"[[timeline]]\nat_s = 200\nop = \"set_region\"\n[timeline.region]\nid = 3\ncenter_lat_deg = 46\n"
       "center_lon_deg = 13\nsize_x_m = 0\nsize_y_m = 1000\nlayers = []\n",
       "timeline[0].region.size_x_m: region 3: size_x_m 0"},
  };
  for (const Case& c : cases) {
    auto s = parse(withTimeline(c.entries));
    if (c.expected.empty()) {
      EXPECT_TRUE(s) << c.entries << "\n" << s.error().detail;
      continue;
    }
    ASSERT_FALSE(s) << c.entries;
    EXPECT_EQ(s.error().detail.rfind("t.toml:", 0), 0u) << s.error().detail;
    EXPECT_NE(s.error().detail.find(c.expected), std::string::npos) << s.error().detail;
    const int at = std::stoi(s.error().detail.substr(7));
    EXPECT_GE(at, line) << s.error().detail;
  }
  // A layer out of range points at its field.
  std::string bad = std::string("[[timeline]]\nat_s = 200\nop = \"set_layer\"\nlayer = ") + kLayer2 + "\n";
  bad.replace(bad.find("coverage = 0.8"), 14, "coverage = 1.4");
  auto s = parse(withTimeline(bad));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().detail.find("timeline[0].layer.coverage: layer 2: coverage 1.4"), std::string::npos)
      << s.error().detail;
}

struct Live {
  WallClock::time_point now = kT0;
  LiveWeather weather;
  Live()
      : weather(
            [] {
              auto s = parseScenario(kStart, "start.toml");
              return *s;
            }(),
            kT0, [this] { return now; }, [] { return std::int64_t{1700000000000}; }) {}
};

weather::CloudLayer layer(std::uint32_t id, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = weather::CloudType::Altostratus;
  l.base_m = 4000;
  l.thickness_m = 500;
  l.coverage = coverage;
  l.density = 1;
  return l;
}

const char* kAddThenRemove = R"(
[[timeline]]
at_s = 200
op = "set_layer"
ramp_s = 100
layer = { id = 2, type = "stratus", base_m = 400, thickness_m = 300, transition_band_m = 50, coverage = 0.8, density = 0.7, wind = { speed_mps = 5, from_deg = 200, vertical_mps = 0 } }

[[timeline]]
at_s = 400
op = "remove_layer"
id = 2

[[timeline]]
at_s = 400
op = "set_clock"
rate = 10
)";

TEST(Timeline, LoadingAScenarioReplacesTheWeatherAndSchedulesItsTimeline) {
  Live f;
  // Something the scenario will replace: a second layer and the clock moved.
  ASSERT_TRUE(f.weather.submit({{SetLayer{layer(5, 0.5), {}}, SetClock{2.0, 9000.0}}, "op", "api"}));
  auto s = parse(withTimeline(kAddThenRemove));
  ASSERT_TRUE(s) << s.error().detail;
  auto loaded = f.weather.loadScenario(*s, "t.toml", "instructor");
  ASSERT_TRUE(loaded) << loaded.error().detail;
  EXPECT_EQ(loaded->summary, "scenario t.toml loaded: 1 layer(s), 3 timeline entries, clock 100 s at x1");
  const WeatherView v = f.weather.view();
  EXPECT_DOUBLE_EQ(v.clock_s, 100);
  EXPECT_DOUBLE_EQ(v.clockRate, 1);
  ASSERT_EQ(v.layers.size(), 1u) << "layer 5 is gone: the scenario's start is the whole weather";
  EXPECT_EQ(v.layers[0].id, 1u);
  // What is scheduled next, soonest first.
  ASSERT_EQ(v.pending.size(), 3u);
  EXPECT_EQ(v.pending[0].kind, "timeline");
  EXPECT_EQ(v.pending[0].sequence, 0u);
  EXPECT_EQ(v.pending[0].start_s, 200);
  EXPECT_EQ(v.pending[0].end_s, 300);
  EXPECT_EQ(v.pending[0].summary, "t.toml: layer 2 (stratus) coverage -> 0.80 over 100 s");
  EXPECT_EQ(v.pending[1].start_s, 400);
  EXPECT_EQ(f.weather.nextTimelineAt(), std::optional<double>(200));
  const auto events = f.weather.events(10);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].source, "scenario");
  EXPECT_EQ(events[1].author, "instructor");
  // And its JSON, as GET /api/state shows it.
  const auto j = toJson(v);
  EXPECT_EQ(j["pending"][0]["kind"], "timeline");
}

TEST(Timeline, EntriesAreMadeWhenTheClockReachesThem) {
  Live f;
  auto s = parse(withTimeline(kAddThenRemove));
  ASSERT_TRUE(s);
  ASSERT_TRUE(f.weather.loadScenario(*s, "t.toml", "instructor"));
  EXPECT_TRUE(f.weather.runTimeline().empty()) << "clock 100: nothing is due";
  f.now = kT0 + 150s;  // clock 250
  auto done = f.weather.runTimeline();
  ASSERT_EQ(done.size(), 1u);
  ASSERT_TRUE(done[0].result) << done[0].result.error().detail;
  EXPECT_EQ(done[0].at_s, 200);
  // The ramp starts when the entry is made (clock 250) and runs 100 s.
  auto layers = f.weather.layersAt(f.weather.clockNow());
  ASSERT_EQ(layers.size(), 2u);
  EXPECT_NEAR(layers[1].coverage, 0.0, 1e-12);
  EXPECT_NEAR(f.weather.layersAt(300)[1].coverage, 0.4, 1e-12);
  EXPECT_EQ(f.weather.events(1)[0].author, "scenario:t.toml");
  EXPECT_EQ(f.weather.events(1)[0].source, "scenario");
  EXPECT_EQ(f.weather.view().pending.size(), 3u) << "the ramp running, then two timeline entries";
  // Both entries of clock 400 come as one change.
  f.now = kT0 + 301s;  // clock 401
  const auto sequence = f.weather.view().lastSequence;
  done = f.weather.runTimeline();
  ASSERT_EQ(done.size(), 1u);
  ASSERT_TRUE(done[0].result) << done[0].result.error().detail;
  EXPECT_EQ(done[0].result->sequence, sequence + 1);
  EXPECT_EQ(f.weather.layersAt(f.weather.clockNow()).size(), 1u);
  EXPECT_DOUBLE_EQ(f.weather.clock().rate(), 10);
  EXPECT_FALSE(f.weather.nextTimelineAt());
  EXPECT_TRUE(f.weather.view().pending.empty());
}

TEST(Timeline, AnEntryTheWeatherCannotTakeRefusesTheScenarioAndChangesNothing) {
  Live f;
  const auto hash = f.weather.stateHash();
  // Removes layer 2 before it exists (the set_layer comes later).
  auto s = parse(withTimeline(R"(
[[timeline]]
at_s = 300
op = "remove_layer"
id = 2

[[timeline]]
at_s = 500
op = "set_layer"
layer = { id = 2, type = "stratus", base_m = 400, thickness_m = 300, transition_band_m = 50, coverage = 0.8, density = 0.7, wind = { speed_mps = 5, from_deg = 200, vertical_mps = 0 } }
)"));
  ASSERT_TRUE(s) << s.error().detail;
  auto loaded = f.weather.loadScenario(*s, "t.toml", "instructor");
  ASSERT_FALSE(loaded);
  EXPECT_EQ(loaded.error().code, ErrorCode::InvalidArgument);
  EXPECT_EQ(loaded.error().detail.rfind("t.toml:16:1: timeline[0].id: no layer 2", 0), 0u) << loaded.error().detail;
  EXPECT_EQ(f.weather.stateHash(), hash);
  EXPECT_TRUE(f.weather.events(10).empty());
  // The same at start (scheduleTimeline): refused too.
  EXPECT_FALSE(f.weather.scheduleTimeline(*s, "t.toml"));
  EXPECT_FALSE(f.weather.nextTimelineAt());
}

TEST(Timeline, AnEntryRefusedWhenDueIsDroppedAndTheRestGoOn) {
  Live f;
  auto s = parse(withTimeline(kAddThenRemove));
  ASSERT_TRUE(s);
  ASSERT_TRUE(f.weather.loadScenario(*s, "t.toml", "instructor"));
  f.now = kT0 + 150s;
  ASSERT_EQ(f.weather.runTimeline().size(), 1u);
  // The operator removes layer 2 before the timeline does.
  ASSERT_TRUE(f.weather.submit({{RemoveLayer{2, {}}}, "op", "api"}));
  f.now = kT0 + 301s;
  const auto rejected = f.weather.rejected();
  auto done = f.weather.runTimeline();
  ASSERT_EQ(done.size(), 1u);
  ASSERT_FALSE(done[0].result);
  EXPECT_NE(done[0].result.error().detail.find("timeline[1].id: no layer 2"), std::string::npos)
      << done[0].result.error().detail;
  EXPECT_EQ(f.weather.rejected(), rejected + 1);
  EXPECT_FALSE(f.weather.nextTimelineAt()) << "dropped, with the set_clock of its batch";
  EXPECT_DOUBLE_EQ(f.weather.clock().rate(), 1);
}

TEST(Timeline, AWaitingTimelineSurvivesARestart) {
  const fs::path dir = fs::temp_directory_path() / "skyshell-timeline-test";
  fs::create_directories(dir);
  const fs::path file = dir / "timeline.db";
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(file.string() + suffix);
  std::uint64_t hash = 0;
  auto s = parse(withTimeline(kAddThenRemove));
  ASSERT_TRUE(s);
  {
    auto store = WeatherStore::open(file);
    ASSERT_TRUE(store) << store.error().detail;
    Live f;
    ASSERT_TRUE(store->save(f.weather.toJson(), nullptr));
    f.weather.attachStore(&*store);
    ASSERT_TRUE(f.weather.loadScenario(*s, "t.toml", "instructor"));
    f.now = kT0 + 150s;
    ASSERT_EQ(f.weather.runTimeline().size(), 1u);
    hash = f.weather.stateHash();
  }
  auto store = WeatherStore::open(file);
  ASSERT_TRUE(store);
  auto saved = store->load();
  ASSERT_TRUE(saved && *saved);
  Live f;
  ASSERT_TRUE(f.weather.restore((*saved)->state, (*saved)->events));
  EXPECT_EQ(f.weather.stateHash(), hash);
  ASSERT_EQ(f.weather.timeline().size(), 2u) << "the entries of clock 400 still wait";
  EXPECT_EQ(f.weather.timeline()[0].where, s->timeline[1].where);
  EXPECT_EQ(f.weather.view().pending.back().summary, "t.toml: weather clock rate x10");
}

}  // namespace
}  // namespace sky::server
