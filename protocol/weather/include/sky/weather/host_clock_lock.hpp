// One rule for the weather clock of the frames a CIGI host stamps, shared by
// the renderers (each estimates it) and the server (which holds one per host
// for all of them). A frame's weather clock is offset + rate x host time
// (IG Control timestamp). Channels of one display draw a host frame at
// different wall times, so the server's clock read at render time would
// differ between them and the clouds would not line up across a seam; the
// host's time is what they share, and the offset is what they must agree on.
//
// A channel estimates the offset as the server's clock at the frame's arrival
// minus rate x host time, which differs between channels by their arrival
// spread (milliseconds on loopback, tens under a loaded CI run). Snapping the
// estimate to a grid makes most channels agree bit for bit, but an estimate
// within the spread of a grid line snaps either way (seen in CI: two channels
// 1 s apart for a whole run). So a channel proposes its snapped estimate to
// the server, the server keeps the first one per host and sends it to every
// channel that proposed for that host, and channels draw with the server's.
#pragma once

#include <cmath>

namespace sky::weather {

// The grid an estimate snaps to, in wall seconds of the server's clock (times
// its rate in weather seconds). The price is a frame's clock up to half of it
// from the server's: 5 m of cloud drift at 10 m/s wind.
inline constexpr double kHostClockGrid_s = 1.0;
// An offset held stands until an estimate moves more than this many grid
// steps from it: the server's clock was set, or the host's time jumped (a
// replay looped); every channel sees the same jump.
inline constexpr double kHostClockRelatchSteps = 2.0;
// A channel takes the server's offset when its own estimate is within the
// relatch bound plus this: the server kept an offset against the channel's
// snapped proposal, which is up to half a step from the estimate itself.
inline constexpr double kHostClockAdoptSlackSteps = 0.5;

// The estimate snapped to the grid, weather s.
inline double snapHostClockOffset(double estimate_s, double rate) {
  const double grid_s = kHostClockGrid_s * rate;
  return std::round(estimate_s / grid_s) * grid_s;
}

// Whether an offset held still stands against an estimate (both weather s),
// with slackSteps grid steps more than the relatch bound.
inline bool hostClockOffsetHolds(double held_s, double estimate_s, double rate, double slackSteps = 0) {
  return std::abs(estimate_s - held_s) <= (kHostClockRelatchSteps + slackSteps) * kHostClockGrid_s * rate;
}

}  // namespace sky::weather
