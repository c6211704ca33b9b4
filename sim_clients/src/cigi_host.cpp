// CIGI host frames for a replayed ownship.
#include "sky/sim/cigi_host.hpp"

#include <cmath>

namespace sky::sim {

std::vector<std::uint8_t> CigiHost::nextFrame(const geo::GeodeticPose& pose, double flightTime_s) {
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

  cigi::DatagramWriter w(order_);
  w.add(ig).add(own);
  return w.bytes();
}

bool CigiHost::onIgDatagram(std::span<const std::uint8_t> bytes) {
  auto d = cigi::decodeDatagram(bytes);
  if (!d || d->packets.empty() || !std::holds_alternative<cigi::StartOfFrame>(d->packets[0])) {
    ++malformed_;
    return false;
  }
  lastIgFrame_ = std::get<cigi::StartOfFrame>(d->packets[0]).igFrame;
  ++sofReceived_;
  return true;
}

}  // namespace sky::sim
