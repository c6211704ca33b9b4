// The nats.c handles NatsLog owns (nats_log.hpp), shared by its files:
// every handle is held by a unique_ptr with its destroy function. Private to
// the server library's sources.
#pragma once

#include <chrono>
#include <map>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>

#include <nats/nats.h>

#include "sky/server/nats_log.hpp"

namespace sky::server {

template <class T, void (*Destroy)(T*)>
struct NatsDeleter {
  void operator()(T* p) const {
    if (p) Destroy(p);
  }
};
template <class T, void (*Destroy)(T*)>
using Owned = std::unique_ptr<T, NatsDeleter<T, Destroy>>;

using OptionsPtr = Owned<natsOptions, natsOptions_Destroy>;
using ConnectionPtr = Owned<natsConnection, natsConnection_Destroy>;
using JsPtr = Owned<jsCtx, jsCtx_Destroy>;
using StreamInfoPtr = Owned<jsStreamInfo, jsStreamInfo_Destroy>;
using MsgPtr = Owned<natsMsg, natsMsg_Destroy>;
using PubAckPtr = Owned<jsPubAck, jsPubAck_Destroy>;
using MetaPtr = Owned<jsMsgMetaData, jsMsgMetaData_Destroy>;
using KvPtr = Owned<kvStore, kvStore_Destroy>;
using SubscriptionPtr = Owned<natsSubscription, natsSubscription_Destroy>;

// What failed, with nats.c's status, JetStream's error code and the
// client's last error text; a timeout is Timeout, the rest Io.
Error natsError(const std::string& what, natsStatus s, jsErrCode jerr = static_cast<jsErrCode>(0));

// Makes a stream unless it exists; on a server that is not clustered asks
// again with one replica. Returns the replicas it has.
Result<int> ensureStream(jsCtx* js, jsStreamConfig& config);

// The forecast files' stream (nats_files.cpp), made beside the log.
Result<void> ensureFilesStream(jsCtx* js, const NatsLogOptions& options, int replicas);

// InvalidArgument unless `key` may be a key of the areas bucket.
Result<void> checkAreaKey(const std::string& key);

// The message handler's state: outlives the subscription until nats.c says
// no callback of it runs any more (natsSubscription_SetOnCompleteCB).
struct FollowState {
  std::mutex mutex;
  std::condition_variable done;
  bool complete = false;
  NatsLog::EntryHandler onEntry;
};

// How long stopFollowing waits for a message callback under way to finish.
inline constexpr std::chrono::seconds kFollowStopWait{5};

// The areas' watch handler, shared by every key's subscription; it outlives
// the connection (declared before it in Handles), and `handler` is emptied
// first, so a message delivered while the relay closes calls nothing.
struct AreaWatch {
  std::mutex mutex;
  NatsLog::AreaHandler handler;
  std::string subjectPrefix;  // "$KV.<bucket>."
};

struct NatsLog::Handles {
  NatsLogOptions options;
  int replicas = 1;
  AreaWatch areaWatch;
  // Destruction order is the reverse: the subscription, then the JetStream
  // context, then the connection.
  ConnectionPtr connection;
  JsPtr js;
  KvPtr registry;  // the cluster's registry bucket
  KvPtr areas;     // the weather by cell, for the relays
  std::map<std::string, SubscriptionPtr> areaSubscriptions;  // by key
  std::shared_ptr<FollowState> follow;
  SubscriptionPtr subscription;

  ~Handles() {
    stop();
    {
      std::lock_guard lock(areaWatch.mutex);
      areaWatch.handler = nullptr;
    }
    for (auto& [key, sub] : areaSubscriptions) natsSubscription_Unsubscribe(sub.get());
  }

  void stop() {
    if (!subscription) return;
    natsSubscription_Unsubscribe(subscription.get());
    std::unique_lock lock(follow->mutex);
    const bool complete = follow->done.wait_for(lock, kFollowStopWait, [this] { return follow->complete; });
    follow->onEntry = nullptr;
    lock.unlock();
    subscription.reset();
    // Not told that its callbacks are over (a client cut off from every
    // server): the state stays allocated for them, a few bytes per such stop.
    if (!complete) new std::shared_ptr<FollowState>(follow);
    follow.reset();
  }
};

}  // namespace sky::server
