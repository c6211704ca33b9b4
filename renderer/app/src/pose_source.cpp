// The live channel's pose sources (see pose_source.hpp).
#include "sky/app/pose_source.hpp"

#include <cstdio>

namespace sky::app {

namespace {
std::string format(const char* pattern, auto... values) {
  char buf[512];
  std::snprintf(buf, sizeof buf, pattern, values...);
  return buf;
}
}  // namespace

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
