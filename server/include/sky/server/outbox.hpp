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

inline constexpr std::size_t kMaxEventFrames = 32;

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
  // An event (a Lightning frame): sent once, in order, after control and
  // before weather (a flash is late after a few frames). At most
  // kMaxEventFrames wait; past that the oldest is dropped, and the count of
  // dropped events is kept (the peer has stopped reading).
  void pushEvent(Frame frame);
  std::uint64_t droppedEvents() const { return droppedEvents_; }
  // Replaces a heartbeat not yet sent.
  void setHeartbeat(Frame frame);
  // Drops pending weather (snapshot, heartbeat) and events: used when closing.
  void dropWeather();

  // Control first, then events, then the snapshots by area index (which also drop a
  // waiting heartbeat: a snapshot carries a newer clock), then the heartbeat.
  std::optional<Item> takeNext();

  bool empty() const;

 private:
  std::deque<Frame> control_;
  std::deque<Frame> events_;
  std::uint64_t droppedEvents_ = 0;
  std::array<std::optional<stream::Subscribe>, stream::kMaxAreas> snapshots_;  // by area index
  std::optional<Frame> heartbeat_;
};

}  // namespace sky::server
