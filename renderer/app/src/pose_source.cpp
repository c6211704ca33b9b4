// The channel's pose sources (see pose_source.hpp).
#include "sky/app/pose_source.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace sky::app {

namespace {
std::string format(const char* pattern, auto... values) {
  char buf[512];
  std::snprintf(buf, sizeof buf, pattern, values...);
  return buf;
}
}  // namespace

HostPose FlightPoseSource::poseAtFlightTime(double t_s, std::uint32_t hostFrame) const {
  HostPose p;
  const double first_s = flight_.fixes.front().time_s;
  p.pose = flight::sample(flight_, first_s + t_s);
  p.hostFrame = hostFrame;
  p.hostTime_s = t_s;
  if (!fixedSun_ && flight_.startUtc_s) {
    p.utc_s = double(*flight_.startUtc_s) + t_s;
    p.timeSource = TimeSource::FlightFile;
  }
  return p;
}

std::optional<HostPose> FlightPoseSource::poseAt(SteadyTime now) {
  if (flight_.fixes.empty()) return std::nullopt;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double t_s = std::min(startFlight_s_ + std::max(elapsed_s, 0.0) * pace_, flight_.duration_s());
  HostPose p = poseAtFlightTime(t_s, frames_++);
  p.receivedAt = now;
  return p;
}

std::string FdmPoseSource::progress() const {
  return ", FlightGear FDM dropped " + std::to_string(fdm_.datagramsDropped());
}

std::string FdmPoseSource::summary() const {
  return format("render: FlightGear FDM datagrams accepted %llu, dropped %llu (%s), outliers discarded %llu",
                static_cast<unsigned long long>(fdm_.datagramsAccepted()),
                static_cast<unsigned long long>(fdm_.datagramsDropped()), fdm_.drops().summary().c_str(),
                static_cast<unsigned long long>(fdm_.outliersDropped()));
}

std::string ForeFlightPoseSource::progress() const {
  return ", ForeFlight dropped " + std::to_string(lines_.datagramsDropped());
}

std::string ForeFlightPoseSource::summary() const {
  return format("render: ForeFlight positions %llu, attitudes %llu, other lines %llu, datagrams dropped %llu (%s), "
                "outliers discarded %llu",
                static_cast<unsigned long long>(lines_.positionsAccepted()),
                static_cast<unsigned long long>(lines_.attitudesAccepted()),
                static_cast<unsigned long long>(lines_.otherLines()),
                static_cast<unsigned long long>(lines_.datagramsDropped()), lines_.drops().summary().c_str(),
                static_cast<unsigned long long>(lines_.outliersDropped()));
}

}  // namespace sky::app
