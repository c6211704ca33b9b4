// The registry of a weather cluster on NATS: every skyshell-weatherd with
// --nats and every skyshell-relay puts its record (cluster_member.hpp) in a
// KV bucket whose keys expire unless put again (NatsLog::putMember), and
// reads everyone's back, for GET /api/cluster and the console's cluster
// panel. Its NATS requests run on a thread of its own, so a slow cluster
// delays neither the weather stream (the io thread) nor the lease's
// renewals (the election thread); the io thread only describes this member.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "sky/server/cluster_member.hpp"
#include "sky/server/nats_log.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

// How often a member puts its record and reads the others': the registry's
// time to live (NatsLogOptions::registryTtl, 5 s) is five of these, so a
// member is listed on through four lost puts and gone 5 s after it died.
inline constexpr std::chrono::milliseconds kRegistryEvery{1000};
// Records read back at most: a cluster is a few servers and a relay per
// site; the bound keeps a flooded bucket from costing memory and time.
inline constexpr std::size_t kMaxRegistryMembers = 256;

class ClusterRegistry {
 public:
  // describe: this member's record now, called on the io thread.
  ClusterRegistry(NatsLog& log, boost::asio::io_context& io, std::function<ClusterMember()> describe,
                  std::shared_ptr<spdlog::logger> logger);
  ~ClusterRegistry();
  ClusterRegistry(const ClusterRegistry&) = delete;
  ClusterRegistry& operator=(const ClusterRegistry&) = delete;

  // Starts describing (on the io thread) and putting and reading (on the
  // registry's thread), every kRegistryEvery. Call once, before the io
  // context runs or on its thread.
  void start();
  // Stops both; call on the io thread (or after it stopped).
  void stop();

  // GET /api/cluster's body: {"members": [records, the leader first, then
  // followers and relays, each by id], "read_age_ms": since the bucket was
  // last read (null: not yet), "malformed_records": records of the last read
  // that were left out as malformed}.
  // Any thread.
  nlohmann::json view() const;

 private:
  void describeLater();
  void loop();
  // One round on the registry's thread: put this member's record, read all.
  void round();

  NatsLog& log_;
  std::function<ClusterMember()> describe_;
  std::shared_ptr<spdlog::logger> logger_;
  boost::asio::steady_timer describeTimer_;  // the io thread's

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::optional<ClusterMember> self_;     // the io thread's last description
  std::vector<ClusterMember> members_;    // as last read, sorted
  std::optional<std::chrono::steady_clock::time_point> readAt_;
  std::uint64_t dropped_ = 0;  // malformed records in the last read
  bool warnedDropped_ = false, warnedFailed_ = false;  // the first of each is logged, the rest counted
  std::thread thread_;  // last: started after every member it uses
};

}  // namespace sky::server
