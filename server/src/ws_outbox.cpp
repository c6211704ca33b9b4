// A console client's bounded outbound messages (see ws_outbox.hpp).
#include "sky/server/ws_outbox.hpp"

namespace sky::server {

bool WsOutbox::pushEvent(WsText event) {
  if (events_.size() >= maxEvents_) return false;
  events_.push_back(std::move(event));
  return true;
}

std::optional<WsText> WsOutbox::takeNext() {
  auto take = [](std::optional<WsText>& slot) {
    WsText t = std::move(*slot);
    slot.reset();
    return t;
  };
  if (first_) return take(first_);
  if (!events_.empty()) {
    WsText t = std::move(events_.front());
    events_.pop_front();
    return t;
  }
  if (state_) return take(state_);
  if (renderers_) return take(renderers_);
  if (health_) return take(health_);
  return std::nullopt;
}

}  // namespace sky::server
