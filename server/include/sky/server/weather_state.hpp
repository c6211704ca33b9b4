// The one true weather state of a server: the cloud layers and the weather
// clock. Later sources (console, CIGI, METAR) change it; for now a scenario
// sets it at start-up.
#pragma once

#include <span>
#include <vector>

#include "sky/server/scenario.hpp"
#include "sky/server/weather_clock.hpp"
#include "sky/weather/model.hpp"

namespace sky::server {

class WeatherState {
 public:
  // The scenario's weather, its clock starting at wallStart.
  WeatherState(const Scenario& scenario, WallClock::time_point wallStart)
      : layers_(scenario.layers),
        clock_(scenario.clock.start_s, scenario.clock.rate, wallStart) {}

  std::span<const weather::CloudLayer> layers() const { return layers_; }
  const WeatherClock& clock() const { return clock_; }

 private:
  std::vector<weather::CloudLayer> layers_;
  WeatherClock clock_;
};

}  // namespace sky::server
