// The cluster's registry: describe on the io thread, put and read on a
// thread of its own (see cluster_registry.hpp).
#include "sky/server/cluster_registry.hpp"

#include <algorithm>
#include <tuple>
#include <utility>

#include <spdlog/spdlog.h>

namespace sky::server {

ClusterRegistry::ClusterRegistry(NatsLog& log, boost::asio::io_context& io, std::function<ClusterMember()> describe,
                                 std::shared_ptr<spdlog::logger> logger)
    : log_(log),
      describe_(std::move(describe)),
      logger_(logger ? std::move(logger) : std::make_shared<spdlog::logger>("sky_registry")),
      describeTimer_(io) {}

ClusterRegistry::~ClusterRegistry() { stop(); }

void ClusterRegistry::start() {
  {
    std::lock_guard lock(mutex_);
    self_ = describe_();
  }
  describeLater();
  thread_ = std::thread([this] { loop(); });
}

void ClusterRegistry::stop() {
  describeTimer_.cancel();
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ClusterRegistry::describeLater() {
  describeTimer_.expires_after(kRegistryEvery);
  describeTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (ec) return;
    ClusterMember self = describe_();
    {
      std::lock_guard lock(mutex_);
      if (stopping_) return;
      self_ = std::move(self);
    }
    describeLater();
  });
}

void ClusterRegistry::loop() {
  for (;;) {
    round();
    std::unique_lock lock(mutex_);
    if (wake_.wait_for(lock, kRegistryEvery, [this] { return stopping_; })) return;
  }
}

void ClusterRegistry::round() {
  std::optional<ClusterMember> self;
  {
    std::lock_guard lock(mutex_);
    self = self_;
  }
  if (self) {
    if (auto put = log_.putMember(self->id, clusterMemberJson(*self).dump()); !put) {
      std::lock_guard lock(mutex_);
      if (!std::exchange(warnedFailed_, true))
        logger_->warn("event=registry_put_failed detail={:?} (later failures are not logged)", describe(put.error()));
    }
  }
  auto values = log_.members(kMaxRegistryMembers);
  if (!values) return;  // a NATS election or a lost server: the last list stands, its age grows
  std::vector<ClusterMember> members;
  std::uint64_t bad = 0;
  std::string firstBad;
  for (const std::string& v : *values) {
    auto m = decodeClusterMember(v);
    if (m) {
      members.push_back(std::move(*m));
    } else {
      if (bad++ == 0) firstBad = describe(m.error());
    }
  }
  std::sort(members.begin(), members.end(), [](const ClusterMember& a, const ClusterMember& b) {
    return std::tie(a.role, a.id) < std::tie(b.role, b.id);
  });
  std::lock_guard lock(mutex_);
  members_ = std::move(members);
  readAt_ = std::chrono::steady_clock::now();
  dropped_ = bad;
  if (bad > 0 && !std::exchange(warnedDropped_, true))
    logger_->warn("event=registry_record_dropped detail={:?} (later ones are only counted)", firstBad);
}

nlohmann::json ClusterRegistry::view() const {
  std::lock_guard lock(mutex_);
  nlohmann::json members = nlohmann::json::array();
  for (const ClusterMember& m : members_) members.push_back(clusterMemberJson(m));
  nlohmann::json age = nullptr;
  if (readAt_)
    age = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - *readAt_).count();
  return {{"members", std::move(members)}, {"read_age_ms", std::move(age)}, {"malformed_records", dropped_}};
}

}  // namespace sky::server
