// The smoothed UDP inputs' shared part (see smoothed_input.hpp).
#include "sky/app/smoothed_input.hpp"

#include <spdlog/spdlog.h>

namespace sky::app {

namespace asio = boost::asio;

namespace {
// A steady instant as the host time line of the time of day, s.
double secondsOf(SteadyTime t) { return std::chrono::duration<double>(t.time_since_epoch()).count(); }
}  // namespace

SmoothedInput::SmoothedInput(asio::io_context& io, const std::string& address, unsigned short port,
                             PoseSmootherConfig smoothing, std::optional<double> startUtc_s, const char* logName)
    : socket_(io), logName_(logName), smoother_(smoothing), clock_(startUtc_s) {
  const asio::ip::udp::endpoint ep(asio::ip::make_address(address), port);
  socket_.open(ep.protocol());
  socket_.bind(ep);
  port_ = socket_.local_endpoint().port();
}

void SmoothedInput::start() { receive(); }

void SmoothedInput::stop() {
  boost::system::error_code ec;
  socket_.close(ec);
}

std::uint64_t SmoothedInput::outliersDropped() const {
  std::lock_guard lock(mutex_);
  return smoother_.outliersDropped();
}

void SmoothedInput::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) handleDatagram(std::span(rx_.data(), n), std::chrono::steady_clock::now());
    receive();
  });
}

void SmoothedInput::dropped(DropReason reason, const std::string& detail) {
  drops_.add(reason);
  if (loggedReasons_.insert(dropKind(reason, detail)).second)
    spdlog::warn("{}: dropped a datagram ({}): {} (further drops of this kind are only counted)", logName_,
                 toString(reason), detail);
}

bool SmoothedInput::addSample(const PoseSample& sample) {
  const SteadyTime now = sample.receivedAt;
  std::unique_lock lock(mutex_);
  if (!smoother_.add(sample)) {
    lock.unlock();
    dropped(DropReason::Unusable, "the pose smoother cannot take its pose (a value outside the ranges it takes)");
    return false;
  }
  if (!firstAt_) firstAt_ = now;
  newestAt_ = now;
  clock_.advanceTo(secondsOf(now));
  ++accepted_;
  return true;
}

void SmoothedInput::setTimeOfDay(double utc_s, double resolution_s, TimeSource source, SteadyTime now) {
  std::lock_guard lock(mutex_);
  clock_.advanceTo(secondsOf(now));
  clock_.set(utc_s, resolution_s, source);
}

std::optional<HostPose> SmoothedInput::poseAt(SteadyTime now) {
  std::lock_guard lock(mutex_);
  const auto smoothed = smoother_.poseAt(now);
  if (!smoothed) return std::nullopt;
  HostPose p;
  p.pose = smoothed->pose;
  p.hostFrame = static_cast<std::uint32_t>(accepted_.load());
  p.hostTime_s = std::chrono::duration<double>(smoothed->renderTime - *firstAt_).count();
  p.sequence = ++sequence_;
  p.receivedAt = *newestAt_;
  p.utc_s = clock_.utcAt(secondsOf(smoothed->renderTime));
  p.timeSource = clock_.source();
  return p;
}

}  // namespace sky::app
