// What one console WebSocket client still has to receive, bounded by
// construction like the stream's Outbox: state, renderers and health are
// latest-value slots (a slow console gets the newest, never a backlog);
// events are a queue, since each is one accepted change, bounded so a client
// that falls too far behind is dropped rather than buffered. Pure
// bookkeeping, no I/O.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>

namespace sky::server {

using WsText = std::shared_ptr<const std::string>;  // one JSON text message, shared by every client

class WsOutbox {
 public:
  explicit WsOutbox(std::size_t maxEvents) : maxEvents_(maxEvents) {}

  // The hello: sent before anything else.
  void pushFirst(WsText hello) { first_ = std::move(hello); }
  // Queues an event; false when maxEvents are already waiting (the client
  // is too far behind and should be dropped).
  bool pushEvent(WsText event);
  // Replace what is waiting in their slot.
  void setState(WsText state) { state_ = std::move(state); }
  void setRenderers(WsText renderers) { renderers_ = std::move(renderers); }
  void setHealth(WsText health) { health_ = std::move(health); }

  // Hello, then events in order, then the state (which is at least as new as
  // every event before it), then renderers, then health.
  std::optional<WsText> takeNext();
  bool empty() const { return !first_ && events_.empty() && !state_ && !renderers_ && !health_; }
  std::size_t queuedEvents() const { return events_.size(); }

 private:
  std::size_t maxEvents_;
  std::optional<WsText> first_;
  std::deque<WsText> events_;
  std::optional<WsText> state_, renderers_, health_;
};

}  // namespace sky::server
