// Bounded per-session outbound state (see outbox.hpp).
#include "sky/server/outbox.hpp"

#include <algorithm>
#include <utility>

#include "sky/core/assert.hpp"

namespace sky::server {

namespace {
// Hello, then at most one Error before the session closes.
constexpr std::size_t kMaxControlFrames = 2;
}  // namespace

void Outbox::pushControl(Frame frame) {
  SKY_ASSERT(control_.size() < kMaxControlFrames);
  control_.push_back(std::move(frame));
}

void Outbox::requestSnapshot(const stream::Subscribe& request) {
  SKY_ASSERT(request.areaIndex < stream::kMaxAreas);  // decodeMessage checks it
  snapshots_[request.areaIndex] = request;
}

void Outbox::pushEvent(Frame frame) {
  events_.push_back(std::move(frame));
  while (events_.size() > kMaxEventFrames) {
    events_.pop_front();
    ++droppedEvents_;
  }
}

void Outbox::setHeartbeat(Frame frame) { heartbeat_ = std::move(frame); }

void Outbox::dropWeather() {
  for (auto& s : snapshots_) s.reset();
  heartbeat_.reset();
  events_.clear();
}

std::optional<Outbox::Item> Outbox::takeNext() {
  if (!control_.empty()) {
    Frame f = std::move(control_.front());
    control_.pop_front();
    return Item(std::move(f));
  }
  if (!events_.empty()) {
    Frame f = std::move(events_.front());
    events_.pop_front();
    return Item(std::move(f));
  }
  for (auto& pending : snapshots_)
    if (pending) {
      const stream::Subscribe request = *pending;
      pending.reset();
      heartbeat_.reset();
      return Item(request);
    }
  if (heartbeat_) {
    Frame f = std::move(*heartbeat_);
    heartbeat_.reset();
    return Item(std::move(f));
  }
  return std::nullopt;
}

bool Outbox::empty() const {
  return control_.empty() && events_.empty() && !heartbeat_ &&
         std::none_of(snapshots_.begin(), snapshots_.end(), [](const auto& s) { return s.has_value(); });
}

}  // namespace sky::server
