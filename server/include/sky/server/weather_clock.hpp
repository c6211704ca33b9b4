// The weather clock: the time every process advects clouds with. It runs at
// `rate` weather seconds per wall second from `start_s`. Wall time is always
// passed in, never read here, so the model is deterministic under test.
#pragma once

#include <chrono>

namespace sky::server {

using WallClock = std::chrono::steady_clock;

class WeatherClock {
 public:
  // start_s: weather clock at wallStart, s (finite). rate: weather seconds per
  // wall second, [0, 3600] (the range Hello carries).
  WeatherClock(double start_s, double rate, WallClock::time_point wallStart);

  // clock_s = start_s + rate × (wallNow − wallStart). wallNow may precede
  // wallStart (the result is then before start_s).
  double at(WallClock::time_point wallNow) const;

  double start_s() const { return start_s_; }
  double rate() const { return rate_; }

 private:
  double start_s_;
  double rate_;
  WallClock::time_point wallStart_;
};

}  // namespace sky::server
