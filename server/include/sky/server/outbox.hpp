// What one session still has to send, bounded by construction: weather is
// state, not events, so a slow subscriber gets the latest state when it
// catches up rather than a growing queue. Pure bookkeeping, no I/O.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <variant>
#include <vector>

#include "sky/stream/messages.hpp"

namespace sky::server {

using Frame = std::vector<std::uint8_t>;  // one length-prefixed frame, ready to write

class Outbox {
 public:
  // The next thing to write: a frame, or a subscription whose snapshot the
  // session builds now (so it carries the clock of the moment it is sent).
  using Item = std::variant<Frame, stream::Subscribe>;

  // Hello and Error: sent in order, before anything else. At most two ever.
  void pushControl(Frame frame);
  // Replaces a subscription of the same area (Subscribe::areaIndex) still
  // waiting for its snapshot.
  void requestSnapshot(const stream::Subscribe& request);
  // Replaces a heartbeat not yet sent.
  void setHeartbeat(Frame frame);
  // Drops pending weather (snapshot, heartbeat): used when closing.
  void dropWeather();

  // Control first, then the snapshots by area index (which also drop a
  // waiting heartbeat: a snapshot carries a newer clock), then the heartbeat.
  std::optional<Item> takeNext();

  bool empty() const;

 private:
  std::deque<Frame> control_;
  std::array<std::optional<stream::Subscribe>, stream::kMaxAreas> snapshots_;  // by area index
  std::optional<Frame> heartbeat_;
};

}  // namespace sky::server
