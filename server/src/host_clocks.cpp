// The host clock offsets the server holds (see host_clocks.hpp).
#include "sky/server/host_clocks.hpp"

#include <algorithm>

#include "sky/weather/host_clock_lock.hpp"

namespace sky::server {

HostClockAnswer HostClocks::propose(const stream::HostClock& proposal) {
  ++uses_;
  if (auto it = hosts_.find(proposal.host); it != hosts_.end()) {
    Entry& e = it->second;
    e.usedAt = uses_;
    if (e.held.rate == proposal.rate && weather::hostClockOffsetHolds(e.held.offset_s, proposal.offset_s, proposal.rate))
      return {e.held, false};
    e.held = proposal;
    return {e.held, true};
  }
  if (hosts_.size() >= kMaxHosts)
    hosts_.erase(std::min_element(hosts_.begin(), hosts_.end(), [](const auto& a, const auto& b) {
      return a.second.usedAt < b.second.usedAt;
    }));
  hosts_.emplace(proposal.host, Entry{proposal, uses_});
  return {proposal, true};
}

}  // namespace sky::server
