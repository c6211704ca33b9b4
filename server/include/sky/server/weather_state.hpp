// What a server starts from: a scenario and the wall time its weather clock
// starts at. The running weather (changes, ramps) is LiveWeather.
#pragma once

#include "sky/server/scenario.hpp"
#include "sky/server/weather_clock.hpp"

namespace sky::server {

struct WeatherState {
  WeatherState(const Scenario& s, WallClock::time_point start) : scenario(s), wallStart(start) {}
  Scenario scenario;
  WallClock::time_point wallStart;
};

}  // namespace sky::server
