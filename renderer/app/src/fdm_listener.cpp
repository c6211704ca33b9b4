// FlightGear native-FDM UDP endpoint of a renderer channel (see fdm_listener.hpp).
#include "sky/app/fdm_listener.hpp"

#include <numbers>

#include <spdlog/spdlog.h>

namespace sky::app {

namespace asio = boost::asio;

namespace {
constexpr double kMetresPerFoot = 0.3048;  // international foot, exact
constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// The decoder's detail without its digits ("field lat_rad: 7.2 outside ...")
// is the kind we log once: the field, not the values.
std::string reasonKind(const std::string& detail) {
  std::string kind;
  for (char c : detail)
    if (c < '0' || c > '9') kind += c;
  return kind.substr(0, 80);
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

std::uint64_t FdmListener::outliersDropped() const {
  std::lock_guard lock(mutex_);
  return smoother_.outliersDropped();
}

void FdmListener::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) onDatagram(std::span(rx_.data(), n));
    receive();
  });
}

void FdmListener::dropped(const std::string& reason) {
  ++dropped_;
  if (loggedReasons_.insert(reasonKind(reason)).second)
    spdlog::warn("FlightGear FDM: dropped a datagram: {} (further drops of this kind are only counted)", reason);
}

void FdmListener::onDatagram(std::span<const std::uint8_t> bytes) {
  const auto now = std::chrono::steady_clock::now();
  auto fdm = fgfdm::decodeNetFdm(bytes);
  if (!fdm) {
    dropped(fdm.error().detail);
    return;
  }
  ++accepted_;
  std::lock_guard lock(mutex_);
  if (!firstAt_) firstAt_ = now;
  newestAt_ = now;
  smoother_.add(poseSampleFrom(*fdm, now));
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
  return p;
}

}  // namespace sky::app
