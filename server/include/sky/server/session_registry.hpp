// The sessions a server owns. Sessions stay alive while registered or while
// one of their I/O operations is pending; closing one removes it from here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>

#include "sky/server/session.hpp"

namespace sky::server {

class SessionRegistry {
 public:
  void add(std::shared_ptr<Session> session);
  void remove(const Session& session);
  // Calls f on every registered session; f may close (and so remove) sessions.
  void forEach(const std::function<void(Session&)>& f);
  // Calls f on every registered session, in id order; f must not close any.
  void forEachConst(const std::function<void(const Session&)>& f) const;
  // Closes every session (cancelling their I/O): part of server shutdown.
  void closeAll();
  std::size_t size() const { return sessions_.size(); }
  bool contains(const Session& session) const { return sessions_.count(session.id()) > 0; }

 private:
  std::map<std::uint64_t, std::shared_ptr<Session>> sessions_;  // by session id
};

}  // namespace sky::server
