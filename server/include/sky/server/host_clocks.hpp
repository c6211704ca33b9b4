// The weather clock offsets the server holds for CIGI hosts, one per host
// (sky/weather/host_clock_lock.hpp): the first channel of a host to propose
// its estimate sets the offset, and every later proposal that stands against
// it gets it back, so all the channels of one display draw a host frame at
// one weather clock, bit for bit, whatever their arrival times. A proposal
// the held offset no longer stands against (the host's time jumped, the
// server's clock was set, its rate changed) replaces it, and every channel of
// that host hears the new one. Runs on the io thread; no I/O.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "sky/stream/messages.hpp"

namespace sky::server {

struct HostClockAnswer {
  stream::HostClock held;  // the offset to draw with
  bool changed = false;    // new or replaced: tell every channel of the host
};

class HostClocks {
 public:
  // Hosts held at most: a display has one host, a site a few; past this the
  // least recently proposed-for host is forgotten (its channels propose
  // again within kProposalInterval and get one back).
  static constexpr std::size_t kMaxHosts = 64;

  HostClockAnswer propose(const stream::HostClock& proposal);
  std::size_t size() const { return hosts_.size(); }

 private:
  struct Entry {
    stream::HostClock held;
    std::uint64_t usedAt = 0;
  };
  std::map<std::string, Entry, std::less<>> hosts_;
  std::uint64_t uses_ = 0;
};

}  // namespace sky::server
