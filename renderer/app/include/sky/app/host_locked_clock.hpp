// The weather clock of a frame drawn for a CIGI host frame. Channels of one
// display draw the same host frame at different wall times (each when its
// GPU is free), so the server's clock read at render time (WeatherClock::at)
// differs between them and the clouds would not line up across a seam. The
// host's IG Control timestamp is the time all channels share: a frame's
// weather clock is rate x host time + an offset, the offset between the
// server's clock and the host's estimated at the frame's arrival and snapped
// to a grid, so channels whose estimates differ by their arrival spread
// (milliseconds) hold the same offset, bit for bit.
#pragma once

#include <chrono>
#include <optional>

#include "sky/weather/clock.hpp"

namespace sky::app {

// The grid the offset snaps to, in wall seconds of the server's clock (times
// its rate in weather seconds). 1 s: channels' estimates differ by their
// arrival spread, measured 1.5-1.7 ms on loopback with three channels
// (tests/integration/three_channel_test.cpp prints it), so they snap to
// different points only when one lies within that spread of a grid line
// (about 0.2 % of starts); the price is a frame's clock up to 0.5 s from the
// server's, 5 m of cloud drift at 10 m/s wind, far below a cloud's size.
inline constexpr double kHostClockGrid_s = 1.0;
// The offset is estimated anew each frame and kept until the estimate moves
// more than this many grid steps from it: the server's clock was set, or the
// host's timestamp jumped (a replay looped); all channels see the same jump.
inline constexpr double kHostClockRelatchSteps = 2.0;

class HostLockedClock {
 public:
  // The weather clock, s, of a frame stamped hostTime_s by the host (IG
  // Control timestamp; nullopt when the host marks it invalid) that arrived
  // at `receivedAt`, with the server's clock as this channel holds it.
  // Without a host time, the server's clock at the arrival.
  double at(std::optional<double> hostTime_s, const weather::WeatherClock& server,
            std::chrono::steady_clock::time_point receivedAt);

  // The offset held (weather s), once one is.
  std::optional<double> offset_s() const { return offset_s_; }

 private:
  std::optional<double> offset_s_;
  double rate_ = 1;
};

}  // namespace sky::app
