// The weather clock (see clock.hpp).
#include "sky/weather/clock.hpp"

#include <cmath>

#include "sky/core/assert.hpp"

namespace sky::weather {

WeatherClock::WeatherClock(double start_s, double rate, WallClock::time_point wallStart)
    : start_s_(start_s), rate_(rate), wallStart_(wallStart) {
  // Callers check both at their input edge; a bad value here is a bug.
  SKY_ASSERT(std::isfinite(start_s));
  SKY_ASSERT(std::isfinite(rate) && rate >= 0 && rate <= 3600);
}

double WeatherClock::at(WallClock::time_point wallNow) const {
  const std::chrono::duration<double> elapsed = wallNow - wallStart_;
  return start_s_ + rate_ * elapsed.count();
}

}  // namespace sky::weather
