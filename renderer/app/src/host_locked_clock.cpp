// The weather clock locked to the CIGI host's time (see host_locked_clock.hpp).
#include "sky/app/host_locked_clock.hpp"

#include "sky/weather/host_clock_lock.hpp"

namespace sky::app {

const char* toString(HostClockSource source) {
  switch (source) {
    case HostClockSource::None: return "none";
    case HostClockSource::Local: return "local";
    case HostClockSource::Server: return "server";
  }
  return "none";
}

HostClockReading HostLockedClock::at(std::optional<double> hostTime_s, const std::string& host,
                                     const weather::WeatherClock& server,
                                     std::chrono::steady_clock::time_point receivedAt,
                                     const std::optional<stream::HostClock>& fromServer) {
  const double serverNow_s = server.at(receivedAt);
  const double rate = server.rate();
  // A stopped clock reads the same on every channel already; without a host
  // time there is nothing shared to lock to.
  if (!hostTime_s || rate <= 0) {
    offset_s_.reset();
    return {serverNow_s, HostClockSource::None, std::nullopt};
  }
  const double estimate_s = serverNow_s - rate * *hostTime_s;
  if (fromServer && fromServer->host == host && fromServer->rate == rate &&
      weather::hostClockOffsetHolds(fromServer->offset_s, estimate_s, rate, weather::kHostClockAdoptSlackSteps)) {
    offset_s_ = fromServer->offset_s;
    rate_ = rate;
    return {fromServer->offset_s + rate * *hostTime_s, HostClockSource::Server, std::nullopt};
  }
  if (!offset_s_ || rate != rate_ || !weather::hostClockOffsetHolds(*offset_s_, estimate_s, rate)) {
    offset_s_ = weather::snapHostClockOffset(estimate_s, rate);
    rate_ = rate;
  }
  HostClockReading out{*offset_s_ + rate * *hostTime_s, HostClockSource::Local, std::nullopt};
  if (!host.empty() && (!lastProposalAt_ || lastProposal_s_ != *offset_s_ ||
                        receivedAt - *lastProposalAt_ >= kProposalInterval)) {
    out.proposal = stream::HostClock{host, *offset_s_, rate};
    lastProposalAt_ = receivedAt;
    lastProposal_s_ = *offset_s_;
  }
  return out;
}

}  // namespace sky::app
