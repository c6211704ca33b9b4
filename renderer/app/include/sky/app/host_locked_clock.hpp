// The weather clock of a frame drawn for a CIGI host frame: offset + rate x
// host time (IG Control timestamp), with the offset every channel of the
// host agrees on (sky/weather/host_clock_lock.hpp says why and how). This
// channel estimates the offset from each frame's arrival; it draws with the
// offset the server holds for the host when the server has sent one that
// stands against the estimate, and otherwise with its own snapped estimate,
// which it proposes to the server.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "sky/stream/messages.hpp"
#include "sky/weather/clock.hpp"

namespace sky::app {

// Where a frame's weather clock came from (the frame metadata's
// "weather_clock_lock").
enum class HostClockSource {
  None,    // no host time (or a stopped clock): the server's clock at arrival
  Local,   // this channel's own snapped estimate
  Server,  // the offset the server holds for the host: the same on every channel
};
const char* toString(HostClockSource source);

struct HostClockReading {
  double weatherClock_s = 0;
  HostClockSource source = HostClockSource::None;
  // This channel's estimate, to send to the server (when it takes them): set
  // while the channel draws with its own, at most every kProposalInterval.
  std::optional<stream::HostClock> proposal;
};

class HostLockedClock {
 public:
  // A proposal is repeated this often until the server's offset comes (a
  // lost or refused one is not waited for forever).
  static constexpr std::chrono::milliseconds kProposalInterval{500};

  // The weather clock of a frame stamped hostTime_s by host `host` (nullopt
  // when the host marks the time invalid) that arrived at `receivedAt`, with
  // the server's clock as this channel holds it and the offset the server
  // last sent (none before one comes, or from a server without
  // kFeatureHostClock).
  HostClockReading at(std::optional<double> hostTime_s, const std::string& host, const weather::WeatherClock& server,
                      std::chrono::steady_clock::time_point receivedAt,
                      const std::optional<stream::HostClock>& fromServer);

  // The offset this channel's own estimate holds (weather s), once one is.
  std::optional<double> localOffset_s() const { return offset_s_; }

 private:
  std::optional<double> offset_s_;
  double rate_ = 1;
  std::optional<std::chrono::steady_clock::time_point> lastProposalAt_;
  std::optional<double> lastProposal_s_;
};

}  // namespace sky::app
