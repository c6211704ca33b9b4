// The weather clock (see weather_clock.hpp).
#include "sky/server/weather_clock.hpp"

#include <cmath>

#include "sky/core/assert.hpp"

namespace sky::server {

WeatherClock::WeatherClock(double start_s, double rate, WallClock::time_point wallStart)
    : start_s_(start_s), rate_(rate), wallStart_(wallStart) {
  // Scenario loading checks both; a bad value here is a bug of the caller.
  SKY_ASSERT(std::isfinite(start_s));
  SKY_ASSERT(std::isfinite(rate) && rate >= 0 && rate <= 3600);
}

double WeatherClock::at(WallClock::time_point wallNow) const {
  const std::chrono::duration<double> elapsed = wallNow - wallStart_;
  return start_s_ + rate_ * elapsed.count();
}

}  // namespace sky::server
