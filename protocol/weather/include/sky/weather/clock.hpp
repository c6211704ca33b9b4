// The weather clock every process advects clouds with: `rate` weather seconds
// per wall second from an anchor. Defined once here; the server runs it and a
// renderer re-anchors its copy on every Hello, Snapshot and Heartbeat. Wall
// time is always passed in (protocol/ reads no clocks), so it is testable.
#pragma once

#include <chrono>

namespace sky::weather {

using WallClock = std::chrono::steady_clock;

// The farthest weather clock, s, either way from 0, that a question about the
// weather at a given clock may name (GET /api/conformance?clock_s=, and the
// frames skyshell-conformance reads to ask it): a century, past any replay's
// or timeline's, yet a bound on the values a request can carry. The server's
// query parser and the tool's reader both use it, so a frame the tool reads
// is one the server answers.
inline constexpr double kMaxAskedClock_s = 100 * 365.25 * 86400;

class WeatherClock {
 public:
  WeatherClock() = default;
  // start_s: weather clock at wallStart, s (finite). rate: weather seconds per
  // wall second, [0, 3600] (the range Hello carries).
  WeatherClock(double start_s, double rate, WallClock::time_point wallStart);

  // clock_s = start_s + rate × (wallNow − wallStart). wallNow may precede
  // wallStart (the result is then before start_s).
  double at(WallClock::time_point wallNow) const;

  double start_s() const { return start_s_; }
  double rate() const { return rate_; }

 private:
  double start_s_ = 0;
  double rate_ = 1;
  WallClock::time_point wallStart_{};
};

}  // namespace sky::weather
