// The weather by cell on NATS (see nats_log.hpp): a KV bucket the leader
// writes, and core subscriptions on the keys' subjects that a relay watches.
#include "nats_handles.hpp"

namespace sky::server {

namespace {

bool validAreaKey(const std::string& key) {
  if (key.empty() || key.size() > 128 || key.front() == '.' || key.back() == '.') return false;
  for (char c : key)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
          c == '=' || c == '.'))
      return false;
  return true;
}

}  // namespace

Result<void> checkAreaKey(const std::string& key) {
  if (!validAreaKey(key)) return fail(ErrorCode::InvalidArgument, "areas bucket: key " + key + ": not a KV key");
  return {};
}

namespace {

void onAreaMessage(natsConnection*, natsSubscription*, natsMsg* raw, void* closure) {
  MsgPtr msg(raw);
  auto* watch = static_cast<AreaWatch*>(closure);
  const char* subject = natsMsg_GetSubject(msg.get());
  if (!subject) return;
  std::string key(subject);
  if (key.rfind(watch->subjectPrefix, 0) != 0) return;
  key.erase(0, watch->subjectPrefix.size());
  std::string bytes(natsMsg_GetData(msg.get()), static_cast<std::size_t>(natsMsg_GetDataLength(msg.get())));
  std::lock_guard lock(watch->mutex);
  if (watch->handler) watch->handler(key, std::move(bytes));
}

}  // namespace

Result<std::optional<std::string>> NatsLog::readArea(const std::string& key) {
  if (auto ok = checkAreaKey(key); !ok) return tl::unexpected(ok.error());
  kvEntry* raw = nullptr;
  const natsStatus s = kvStore_Get(&raw, h_->areas.get(), key.c_str());
  const Owned<kvEntry, kvEntry_Destroy> entry(raw);
  if (s == NATS_NOT_FOUND) return std::optional<std::string>{};  // never put, or deleted
  if (s != NATS_OK) return tl::unexpected(natsError("areas get " + key, s));
  const auto* data = static_cast<const char*>(kvEntry_Value(entry.get()));
  const int size = kvEntry_ValueLen(entry.get());
  if (!data || size <= 0) return std::optional<std::string>{};
  return std::optional<std::string>(std::string(data, static_cast<std::size_t>(size)));
}

void NatsLog::onArea(AreaHandler handler) {
  std::lock_guard lock(h_->areaWatch.mutex);
  h_->areaWatch.handler = std::move(handler);
}

Result<void> NatsLog::watchArea(const std::string& key) {
  if (auto ok = checkAreaKey(key); !ok) return ok;
  if (h_->areaSubscriptions.count(key)) return {};
  natsSubscription* raw = nullptr;
  const std::string subject = h_->areaWatch.subjectPrefix + key;
  if (natsStatus s = natsConnection_Subscribe(&raw, h_->connection.get(), subject.c_str(), onAreaMessage, &h_->areaWatch);
      s != NATS_OK)
    return tl::unexpected(natsError("subscribe " + subject, s));
  h_->areaSubscriptions.emplace(key, SubscriptionPtr(raw));
  return {};
}

void NatsLog::unwatchArea(const std::string& key) {
  auto it = h_->areaSubscriptions.find(key);
  if (it == h_->areaSubscriptions.end()) return;
  natsSubscription_Unsubscribe(it->second.get());
  h_->areaSubscriptions.erase(it);
}

}  // namespace sky::server
