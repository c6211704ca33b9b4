// ForeFlight UDP endpoint of a renderer channel (see foreflight_listener.hpp).
#include "sky/app/foreflight_listener.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sky::app {

namespace {
constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kGravity_mps2 = 9.80665;
// Successive fixes closer in time than this give no rates (a burst of two):
// the last rates are kept. 0.2 s.
constexpr double kMinRateBaseline_s = 0.2;
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
    if (const auto sample = track_.take(m, now)) addSample(*sample);
  }
}

}  // namespace sky::app
