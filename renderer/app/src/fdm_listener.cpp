// FlightGear native-FDM UDP endpoint of a renderer channel (see fdm_listener.hpp).
#include "sky/app/fdm_listener.hpp"

#include <numbers>

#include <spdlog/spdlog.h>

namespace sky::app {

namespace asio = boost::asio;

namespace {
constexpr double kMetresPerFoot = 0.3048;  // international foot, exact
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
// A steady instant as the FlightGear clock's host time line, s.
double secondsOf(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}
}  // namespace

PoseSample poseSampleFrom(const fgfdm::NetFdm& fdm, SteadyTime receivedAt) {
  PoseSample s;
  s.receivedAt = receivedAt;
  s.pose.position = {fdm.lat_rad * kDegPerRad, geo::normalizeLon_deg(fdm.lon_rad * kDegPerRad), fdm.alt_m};
  s.pose.yaw_deg = geo::normalizeLon_deg(fdm.psi_rad * kDegPerRad);
  s.pose.pitch_deg = fdm.theta_rad * kDegPerRad;
  s.pose.roll_deg = geo::normalizeLon_deg(fdm.phi_rad * kDegPerRad);
  s.velocityNed_mps = geo::Vec3d{fdm.vNorth_fps * kMetresPerFoot, fdm.vEast_fps * kMetresPerFoot,
                                 fdm.vDown_fps * kMetresPerFoot};
  return s;
}

FdmListener::FdmListener(asio::io_context& io, const std::string& address, unsigned short port,
                         PoseSmootherConfig smoothing)
    : socket_(io), smoother_(smoothing) {
  const asio::ip::udp::endpoint ep(asio::ip::make_address(address), port);
  socket_.open(ep.protocol());
  socket_.bind(ep);
  port_ = socket_.local_endpoint().port();
}

void FdmListener::start() { receive(); }

void FdmListener::stop() {
  boost::system::error_code ec;
  socket_.close(ec);
}

HostAtmosphere FdmListener::atmosphere() const {
  std::lock_guard lock(mutex_);
  return atmosphere_;
}

std::uint64_t FdmListener::outliersDropped() const {
  std::lock_guard lock(mutex_);
  return smoother_.outliersDropped();
}

void FdmListener::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) handleDatagram(std::span(rx_.data(), n), std::chrono::steady_clock::now());
    receive();
  });
}

void FdmListener::dropped(DropReason reason, const std::string& detail) {
  drops_.add(reason);
  if (loggedReasons_.insert(dropKind(reason, detail)).second)
    spdlog::warn("FlightGear FDM: dropped a datagram ({}): {} (further drops of this kind are only counted)",
                 toString(reason), detail);
}

void FdmListener::handleDatagram(std::span<const std::uint8_t> bytes, std::chrono::steady_clock::time_point now) {
  auto fdm = fgfdm::decodeNetFdm(bytes);
  if (!fdm) {
    dropped(dropReasonOf(fdm.error().code), fdm.error().detail);
    return;
  }
  std::unique_lock lock(mutex_);
  if (!smoother_.add(poseSampleFrom(*fdm, now))) {
    lock.unlock();
    dropped(DropReason::Unusable, "the pose smoother cannot take its pose (a value outside the ranges it takes)");
    return;
  }
  if (!firstAt_) firstAt_ = now;
  newestAt_ = now;
  clock_.advanceTo(secondsOf(now));
  clock_.set(double(fdm->curTime_unix) + fdm->warp_s, 1.0, TimeSource::FlightGear);
  atmosphere_ = withFlightGearVisibility(atmosphere_, fdm->visibility_m);
  ++accepted_;
}

std::optional<HostPose> FdmListener::poseAt(std::chrono::steady_clock::time_point now) {
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
