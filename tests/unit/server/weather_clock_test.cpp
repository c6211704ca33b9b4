// The weather clock with injected wall time: clock = start + rate × elapsed.
#include <gtest/gtest.h>

#include <chrono>

#include "sky/server/weather_clock.hpp"
#include "sky/server/weather_state.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;

const WallClock::time_point kT0{std::chrono::seconds(1000)};

TEST(WeatherClock, StartsAtStart) {
  const WeatherClock clock(100.0, 2.0, kT0);
  EXPECT_DOUBLE_EQ(clock.at(kT0), 100.0);
}

TEST(WeatherClock, RunsAtRate) {
  const WeatherClock clock(100.0, 2.0, kT0);
  EXPECT_DOUBLE_EQ(clock.at(kT0 + 1500ms), 103.0);
  EXPECT_DOUBLE_EQ(clock.at(kT0 + 1h), 100.0 + 7200.0);
  const WeatherClock fast(0.0, 3600.0, kT0);
  EXPECT_DOUBLE_EQ(fast.at(kT0 + 10s), 36000.0);
}

TEST(WeatherClock, RateZeroFreezes) {
  const WeatherClock clock(42.0, 0.0, kT0);
  EXPECT_DOUBLE_EQ(clock.at(kT0 + 10min), 42.0);
}

TEST(WeatherClock, WallTimeBeforeStartGivesEarlierClock) {
  const WeatherClock clock(100.0, 1.0, kT0);
  EXPECT_DOUBLE_EQ(clock.at(kT0 - 2s), 98.0);
}

TEST(WeatherClock, SubMillisecondWallTime) {
  const WeatherClock clock(0.0, 1.0, kT0);
  EXPECT_NEAR(clock.at(kT0 + 250us), 250e-6, 1e-12);
}

}  // namespace
}  // namespace sky::server
