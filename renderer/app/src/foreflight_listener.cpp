// ForeFlight UDP endpoint of a renderer channel (see foreflight_listener.hpp).
#include "sky/app/foreflight_listener.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <spdlog/spdlog.h>

namespace sky::app {

namespace asio = boost::asio;

namespace {
constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kGravity_mps2 = 9.80665;
// Successive fixes closer in time than this give no rates (a burst of two):
// the last rates are kept. 0.2 s.
constexpr double kMinRateBaseline_s = 0.2;

double secondsOf(SteadyTime t) { return std::chrono::duration<double>(t.time_since_epoch()).count(); }
}  // namespace

PoseSmootherConfig foreflightSmoothing() {
  PoseSmootherConfig c;
  c.renderDelay_s = 0.0;
  c.maxExtrapolation_s = 3.0;
  // 0.001 deg of latitude is 111 m: two fixes a second apart may differ by
  // that much more than the aircraft moved.
  c.plausibleSlack_m = 250.0;
  return c;
}

std::optional<PoseSample> ForeFlightTrack::take(const foreflight::Message& message, SteadyTime receivedAt) {
  if (const auto* a = std::get_if<foreflight::Attitude>(&message)) {
    attitude_ = *a;
    attitudeAt_ = receivedAt;
    return std::nullopt;
  }
  const auto* p = std::get_if<foreflight::Position>(&message);
  if (!p) return std::nullopt;

  if (p->groundSpeed_mps >= kMinTrackSpeed_mps) {
    const double dt = previous_ ? std::chrono::duration<double>(receivedAt - previousAt_).count() : 0.0;
    if (previous_ && dt >= kMinRateBaseline_s && previous_->groundSpeed_mps >= kMinTrackSpeed_mps)
      turnRate_degps = geo::angleDiff_deg(previous_->track_deg, p->track_deg) / dt;
    heading_deg = p->track_deg;
  } else {
    turnRate_degps = 0;
  }
  if (previous_) {
    const double dt = std::chrono::duration<double>(receivedAt - previousAt_).count();
    if (dt >= kMinRateBaseline_s) climb_mps = (p->alt_m - previous_->alt_m) / dt;
  }
  previous_ = *p;
  previousAt_ = receivedAt;

  PoseSample s;
  s.receivedAt = receivedAt;
  s.pose.position = {p->lat_deg, geo::normalizeLon_deg(p->lon_deg), p->alt_m};
  const double track = p->track_deg * kDegToRad;
  s.velocityNed_mps = geo::Vec3d{p->groundSpeed_mps * std::cos(track), p->groundSpeed_mps * std::sin(track), -climb_mps};
  const bool fresh = attitude_ && std::chrono::duration<double>(receivedAt - attitudeAt_).count() <= kAttitudeFresh_s;
  if (fresh) {
    s.pose.yaw_deg = geo::normalizeLon_deg(attitude_->heading_deg);
    s.pose.pitch_deg = attitude_->pitch_deg;
    s.pose.roll_deg = attitude_->roll_deg;
  } else {
    const double v = p->groundSpeed_mps;
    s.pose.yaw_deg = geo::normalizeLon_deg(heading_deg);
    s.pose.pitch_deg = v >= kMinTrackSpeed_mps
                           ? std::clamp(std::atan2(climb_mps, v) * kRadToDeg, -kMaxDerivedPitch_deg, kMaxDerivedPitch_deg)
                           : 0.0;
    // Coordinated turn: tan(bank) = v * omega / g.
    s.pose.roll_deg = std::clamp(std::atan(v * turnRate_degps * kDegToRad / kGravity_mps2) * kRadToDeg,
                                 -kMaxDerivedBank_deg, kMaxDerivedBank_deg);
  }
  return s;
}

ForeFlightListener::ForeFlightListener(asio::io_context& io, const std::string& address, unsigned short port,
                                       std::optional<double> startUtc_s, PoseSmootherConfig smoothing)
    : socket_(io), smoother_(smoothing), clock_(startUtc_s) {
  const asio::ip::udp::endpoint ep(asio::ip::make_address(address), port);
  socket_.open(ep.protocol());
  socket_.bind(ep);
  port_ = socket_.local_endpoint().port();
}

void ForeFlightListener::start() { receive(); }

void ForeFlightListener::stop() {
  boost::system::error_code ec;
  socket_.close(ec);
}

std::uint64_t ForeFlightListener::outliersDropped() const {
  std::lock_guard lock(mutex_);
  return smoother_.outliersDropped();
}

void ForeFlightListener::receive() {
  socket_.async_receive_from(asio::buffer(rx_), from_, [this](boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) handleDatagram(std::span(rx_.data(), n), std::chrono::steady_clock::now());
    receive();
  });
}

void ForeFlightListener::dropped(DropReason reason, const std::string& detail) {
  drops_.add(reason);
  if (loggedReasons_.insert(dropKind(reason, detail)).second)
    spdlog::warn("ForeFlight: dropped a datagram ({}): {} (further drops of this kind are only counted)",
                 toString(reason), detail);
}

void ForeFlightListener::handleDatagram(std::span<const std::uint8_t> bytes, SteadyTime now) {
  auto messages = foreflight::parseDatagram(bytes);
  if (!messages) {
    dropped(dropReasonOf(messages.error().code), messages.error().detail);
    return;
  }
  for (const auto& m : *messages) {
    if (std::holds_alternative<foreflight::Other>(m)) {
      ++others_;
      continue;
    }
    if (std::holds_alternative<foreflight::Attitude>(m)) ++attitudes_;
    const auto sample = track_.take(m, now);
    if (!sample) continue;
    std::unique_lock lock(mutex_);
    if (!smoother_.add(*sample)) {
      lock.unlock();
      dropped(DropReason::Unusable, "the pose smoother cannot take its pose (a value outside the ranges it takes)");
      continue;
    }
    if (!firstAt_) firstAt_ = now;
    newestAt_ = now;
    clock_.advanceTo(secondsOf(now));
    ++accepted_;
  }
}

std::optional<HostPose> ForeFlightListener::poseAt(SteadyTime now) {
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
