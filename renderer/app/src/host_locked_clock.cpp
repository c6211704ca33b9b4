// The weather clock locked to the CIGI host's time (see host_locked_clock.hpp).
#include "sky/app/host_locked_clock.hpp"

#include <cmath>

namespace sky::app {

double HostLockedClock::at(std::optional<double> hostTime_s, const weather::WeatherClock& server,
                           std::chrono::steady_clock::time_point receivedAt) {
  const double serverNow_s = server.at(receivedAt);
  const double rate = server.rate();
  // A stopped clock reads the same on every channel already; without a host
  // time there is nothing shared to lock to.
  if (!hostTime_s || rate <= 0) {
    offset_s_.reset();
    return serverNow_s;
  }
  const double grid_s = kHostClockGrid_s * rate;
  const double estimate_s = serverNow_s - rate * *hostTime_s;
  if (!offset_s_ || rate != rate_ || std::abs(estimate_s - *offset_s_) > kHostClockRelatchSteps * grid_s) {
    offset_s_ = std::round(estimate_s / grid_s) * grid_s;
    rate_ = rate;
  }
  return *offset_s_ + rate * *hostTime_s;
}

}  // namespace sky::app
