// FlightGear native-FDM UDP endpoint of a renderer channel (see fdm_listener.hpp).
#include "sky/app/fdm_listener.hpp"

#include <numbers>

namespace sky::app {

namespace {
constexpr double kMetresPerFoot = 0.3048;  // international foot, exact
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
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

HostAtmosphere FdmListener::atmosphere() const {
  std::lock_guard lock(mutex_);
  return atmosphere_;
}

void FdmListener::handleDatagram(std::span<const std::uint8_t> bytes, SteadyTime now) {
  auto fdm = fgfdm::decodeNetFdm(bytes);
  if (!fdm) {
    dropped(dropReasonOf(fdm.error().code), fdm.error().detail);
    return;
  }
  if (!addSample(poseSampleFrom(*fdm, now))) return;
  setTimeOfDay(double(fdm->curTime_unix), 1.0, TimeSource::FlightGear, now);
  std::lock_guard lock(mutex_);
  atmosphere_ = withFlightGearVisibility(atmosphere_, fdm->visibility_m);
}

}  // namespace sky::app
