// CIGI host frames for a replayed ownship.
#include "sky/sim/cigi_host.hpp"

#include <cmath>

#include "sky/cigi/celestial_time.hpp"

namespace sky::sim {

namespace {
constexpr double kDegPerRad = 57.29577951308232;
}  // namespace

cigi::ViewDefinition channelViewDefinition(std::uint32_t i, double channelWidth_deg, double aspect) {
  const double halfH_deg = channelWidth_deg / 2;
  const double halfV_deg = std::atan(std::tan(halfH_deg / kDegPerRad) / aspect) * kDegPerRad;
  cigi::ViewDefinition vd;
  vd.viewId = static_cast<std::uint16_t>(i);
  vd.leftEnable = vd.rightEnable = vd.topEnable = vd.bottomEnable = true;
  vd.left_deg = static_cast<float>(-halfH_deg);
  vd.right_deg = static_cast<float>(halfH_deg);
  vd.top_deg = static_cast<float>(halfV_deg);
  vd.bottom_deg = static_cast<float>(-halfV_deg);
  return vd;
}

cigi::ViewControl channelViewControl(std::uint32_t i, std::uint32_t channels, double channelWidth_deg) {
  cigi::ViewControl vc;
  vc.viewId = static_cast<std::uint16_t>(i);
  vc.entityId = 0;
  vc.xEnable = vc.yEnable = vc.zEnable = vc.rollEnable = vc.pitchEnable = vc.yawEnable = true;
  vc.yaw_deg = static_cast<float>((double(i) - (double(channels) - 1) / 2) * channelWidth_deg);
  return vc;
}

std::vector<std::uint8_t> CigiHost::nextFrame(const geo::GeodeticPose& pose, double flightTime_s,
                                              const std::optional<cigi::EnvironmentalConditionsRequest>& request) {
  cigi::IgControl ig;
  ig.mode = cigi::IgMode::Operate;
  ig.hostFrame = hostFrame_++;
  ig.timestampValid = true;
  // 10 us ticks, wrapping as CIGI's 32-bit counter does.
  ig.timestamp_10us = static_cast<std::uint32_t>(
      static_cast<std::uint64_t>(std::llround(flightTime_s * 1.0e5)) & 0xffffffffu);
  ig.lastIgFrame = lastIgFrame_.value_or(0);

  cigi::EntityControl own;
  own.entityId = 0;
  own.state = cigi::EntityState::Active;
  own.lat_deg = pose.position.lat_deg;
  own.lon_deg = geo::normalizeLon_deg(pose.position.lon_deg);
  own.alt_m = pose.position.alt_m;
  own.yaw_deg = static_cast<float>(std::fmod(std::fmod(pose.yaw_deg, 360.0) + 360.0, 360.0));
  own.pitch_deg = static_cast<float>(pose.pitch_deg);
  own.roll_deg = static_cast<float>(geo::angleDiff_deg(0.0, pose.roll_deg));

  cigi::DatagramWriter w(options_.order);
  w.add(ig).add(own);
  if (options_.channelWidth_deg > 0) {
    for (std::uint32_t i = 0; i < options_.channels; ++i)
      w.add(channelViewDefinition(i, options_.channelWidth_deg, options_.aspect))
          .add(channelViewControl(i, options_.channels, options_.channelWidth_deg));
  } else if (ig.hostFrame == 0) {
    // Symmetric frustum from the vertical field of view and the aspect ratio.
    const double halfV_deg = options_.verticalFov_deg / 2;
    const double halfH_deg = std::atan(std::tan(halfV_deg / kDegPerRad) * options_.aspect) * kDegPerRad;
    cigi::ViewDefinition vd;
    vd.leftEnable = vd.rightEnable = vd.topEnable = vd.bottomEnable = true;
    vd.left_deg = static_cast<float>(-halfH_deg);
    vd.right_deg = static_cast<float>(halfH_deg);
    vd.top_deg = static_cast<float>(halfV_deg);
    vd.bottom_deg = static_cast<float>(-halfV_deg);
    w.add(vd);
  }
  if (options_.startUtc_s) {
    const auto utc = *options_.startUtc_s + static_cast<std::int64_t>(std::floor(flightTime_s));
    if (!lastCelestialMinute_ || *lastCelestialMinute_ != utc / 60) {
      lastCelestialMinute_ = utc / 60;
      w.add(cigi::celestialAt(utc));
    }
  }
  if (request) w.add(*request);
  return w.bytes();
}

bool CigiHost::onIgDatagram(std::span<const std::uint8_t> bytes) {
  auto d = cigi::decodeDatagram(bytes);
  if (!d || d->packets.empty() || !std::holds_alternative<cigi::StartOfFrame>(d->packets[0])) {
    ++malformed_;
    return false;
  }
  const auto& sof = std::get<cigi::StartOfFrame>(d->packets[0]);
  lastIgFrame_ = sof.igFrame;
  lastSofHostFrame_ = sof.lastHostFrame;
  if (!lastAckedHostFrame_ || sof.lastHostFrame > *lastAckedHostFrame_) lastAckedHostFrame_ = sof.lastHostFrame;
  ++sofReceived_;
  lastReplies_.assign(d->packets.begin() + 1, d->packets.end());
  return true;
}

}  // namespace sky::sim
