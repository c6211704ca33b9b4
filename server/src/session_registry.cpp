// Owned sessions (see session_registry.hpp).
#include "sky/server/session_registry.hpp"

#include <utility>
#include <vector>

#include "sky/core/assert.hpp"

namespace sky::server {

void SessionRegistry::add(std::shared_ptr<Session> session) {
  const std::uint64_t id = session->id();
  const bool inserted = sessions_.emplace(id, std::move(session)).second;
  SKY_ASSERT(inserted);
}

void SessionRegistry::remove(const Session& session) { sessions_.erase(session.id()); }

void SessionRegistry::forEach(const std::function<void(Session&)>& f) {
  // A copy: f may close a session, which removes it from the map.
  std::vector<std::shared_ptr<Session>> sessions;
  sessions.reserve(sessions_.size());
  for (const auto& [id, s] : sessions_) sessions.push_back(s);
  for (const auto& s : sessions) f(*s);
}

void SessionRegistry::forEachConst(const std::function<void(const Session&)>& f) const {
  for (const auto& [id, s] : sessions_) f(*s);
}

void SessionRegistry::closeAll() {
  forEach([](Session& s) { s.close(); });
  SKY_ASSERT(sessions_.empty());
}

}  // namespace sky::server
