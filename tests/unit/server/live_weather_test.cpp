// The server's live weather: it starts from the scenario, changes apply all or
// nothing, ramps interpolate on the weather clock (hand-computed midpoints),
// scheduled changes wait for their time, layers fade out before removal, the
// clock pauses/runs/jumps, and every accepted change is an event.
#include <gtest/gtest.h>

#include "sky/server/live_weather.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;

const WallClock::time_point kT0{std::chrono::hours(1000)};

weather::CloudLayer cumulus(std::uint32_t id, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1500;
  l.thickness_m = 1000;
  l.coverage = coverage;
  l.density = 1;
  l.wind = {10, 270, 0};
  return l;
}

struct Fixture {
  WallClock::time_point now = kT0;
  LiveWeather weather;
  explicit Fixture(double rate = 1.0)
      : weather(
            [&] {
              Scenario s;
              s.clock = {1000.0, rate};
              s.layers = {cumulus(1, 0.3)};
              return s;
            }(),
            kT0, [this] { return now; }, [] { return std::int64_t{1700000000000}; }) {}
  ChangeRequest one(WeatherChange c) { return ChangeRequest{{std::move(c)}, "test", "api"}; }
};

TEST(LiveWeather, StartsFromTheScenario) {
  Fixture f(10.0);
  f.now = kT0 + 3s;
  const WeatherView v = f.weather.view();
  EXPECT_DOUBLE_EQ(v.clock_s, 1030.0);
  EXPECT_DOUBLE_EQ(v.clockRate, 10.0);
  ASSERT_EQ(v.layers.size(), 1u);
  EXPECT_EQ(v.layers[0].id, 1u);
  EXPECT_EQ(v.lastSequence, 0u);
}

TEST(LiveWeather, RampsCoverageOnTheWeatherClock) {
  Fixture f;
  auto target = cumulus(1, 0.9);
  auto applied = f.weather.submit(f.one(SetLayer{target, Timing{std::nullopt, 600}}));
  ASSERT_TRUE(applied) << applied.error().detail;
  EXPECT_EQ(applied->sequence, 1u);
  EXPECT_EQ(applied->summary, "layer 1 (cumulus) coverage 0.30 -> 0.90 over 600 s");
  // 0.3 -> 0.9 over 600 s: 0.6 at 300 s, 0.9 from 600 s on.
  EXPECT_NEAR(f.weather.layersAt(1000)[0].coverage, 0.3, 1e-12);
  EXPECT_NEAR(f.weather.layersAt(1300)[0].coverage, 0.6, 1e-12);
  EXPECT_NEAR(f.weather.layersAt(1600)[0].coverage, 0.9, 1e-12);
  EXPECT_NEAR(f.weather.layersAt(5000)[0].coverage, 0.9, 1e-12);
  EXPECT_TRUE(f.weather.changing(1300));
  EXPECT_FALSE(f.weather.changing(1600));
  f.now = kT0 + 150s;
  const WeatherView v = f.weather.view();
  EXPECT_NEAR(v.layers[0].coverage, 0.45, 1e-12);
  ASSERT_EQ(v.pending.size(), 1u);
  EXPECT_DOUBLE_EQ(v.pending[0].end_s, 1600.0);
}

TEST(LiveWeather, ScheduledChangesWaitAndNewLayersFadeIn) {
  Fixture f;
  auto stratus = cumulus(2, 0.8);
  stratus.type = weather::CloudType::Stratus;
  stratus.base_m = 400;
  stratus.thickness_m = 300;
  ASSERT_TRUE(f.weather.submit(f.one(SetLayer{stratus, Timing{2000.0, 100}})));
  EXPECT_EQ(f.weather.layersAt(1999).size(), 1u);  // not yet
  const auto mid = f.weather.layersAt(2050);
  ASSERT_EQ(mid.size(), 2u);
  EXPECT_NEAR(mid[1].coverage, 0.4, 1e-12);         // fading in from 0
  EXPECT_EQ(mid[1].type, weather::CloudType::Stratus);
  // A start in the past is refused, naming the field.
  auto past = f.weather.submit(f.one(SetLayer{stratus, Timing{500.0, 0}}));
  ASSERT_FALSE(past);
  EXPECT_EQ(past.error().detail.rfind("changes[0].at_s: 500.0 is in the past", 0), 0u) << past.error().detail;
}

TEST(LiveWeather, RemovedLayersFadeOutThenGo) {
  Fixture f;
  ASSERT_TRUE(f.weather.submit(f.one(RemoveLayer{1, Timing{std::nullopt, 200}})));
  EXPECT_NEAR(f.weather.layersAt(1100)[0].coverage, 0.15, 1e-12);
  EXPECT_TRUE(f.weather.layersAt(1200).empty());
  auto unknown = f.weather.submit(f.one(RemoveLayer{9, Timing{}}));
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().detail, "changes[0].id: no layer 9");
}

TEST(LiveWeather, ABatchIsAllOrNothing) {
  Fixture f;
  auto good = cumulus(1, 0.5);
  auto bad = cumulus(2, 1.4);  // coverage out of range
  ChangeRequest r{{SetLayer{good, Timing{}}, SetLayer{bad, Timing{}}}, "test", "api"};
  auto refused = f.weather.submit(r);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().detail.find("changes[1].layer:"), std::string::npos) << refused.error().detail;
  EXPECT_NE(refused.error().detail.find("coverage"), std::string::npos);
  const WeatherView v = f.weather.view();
  ASSERT_EQ(v.layers.size(), 1u);
  EXPECT_DOUBLE_EQ(v.layers[0].coverage, 0.3);  // the first change did not half-apply
  EXPECT_EQ(v.lastSequence, 0u);
  EXPECT_TRUE(f.weather.events(10).empty());
  EXPECT_EQ(f.weather.rejected(), 1u);
  EXPECT_FALSE(f.weather.submit(ChangeRequest{{}, "test", "api"}));
  // A region with no size and no layers is refused, and names why.
  auto emptyRegion = f.weather.submit(f.one(SetRegion{}));
  ASSERT_FALSE(emptyRegion);
  EXPECT_NE(emptyRegion.error().detail.find("changes[0].region"), std::string::npos) << emptyRegion.error().detail;
  EXPECT_TRUE(f.weather.view().regions.empty());
  EXPECT_EQ(f.weather.rejected(), 3u);
}

TEST(LiveWeather, ClockPausesRunsAndJumps) {
  Fixture f;
  f.now = kT0 + 10s;
  ASSERT_TRUE(f.weather.submit(f.one(SetClock{0.0, std::nullopt})));  // pause at 1010
  f.now = kT0 + 100s;
  EXPECT_DOUBLE_EQ(f.weather.clockNow(), 1010.0);
  ASSERT_TRUE(f.weather.submit(f.one(SetClock{60.0, 43200.0})));
  f.now = kT0 + 101s;
  EXPECT_DOUBLE_EQ(f.weather.clockNow(), 43260.0);
  EXPECT_FALSE(f.weather.submit(f.one(SetClock{5000.0, std::nullopt})));
  EXPECT_FALSE(f.weather.submit(f.one(SetClock{})));
  const auto events = f.weather.events(10);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].sequence, 2u);
  EXPECT_EQ(events[1].summary, "weather clock jumps to 43200 s, rate x60");
  EXPECT_EQ(events[1].author, "test");
}

}  // namespace
}  // namespace sky::server
