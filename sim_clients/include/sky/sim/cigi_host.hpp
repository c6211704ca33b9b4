// The CIGI host side of a replay: turns a flight and a host frame counter
// into the datagrams a simulator host would send (IG Control + ownship Entity
// Control), and keeps count of the IG's Start of Frame replies.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "sky/cigi/codec.hpp"
#include "sky/flight/flight.hpp"

namespace sky::sim {

class CigiHost {
 public:
  explicit CigiHost(cigi::ByteOrder order = cigi::ByteOrder::Big) : order_(order) {}

  // The datagram for the next host frame, showing the ownship at `pose`.
  // flightTime_s becomes the CIGI timestamp (10 us ticks).
  std::vector<std::uint8_t> nextFrame(const geo::GeodeticPose& pose, double flightTime_s);

  // Feeds one datagram received from the IG; returns whether it was a valid
  // Start of Frame. Malformed datagrams are counted, never thrown.
  bool onIgDatagram(std::span<const std::uint8_t> bytes);

  std::uint32_t framesSent() const { return hostFrame_; }
  std::uint64_t startOfFramesReceived() const { return sofReceived_; }
  std::uint64_t malformedReceived() const { return malformed_; }
  std::optional<std::uint32_t> lastIgFrame() const { return lastIgFrame_; }

 private:
  cigi::ByteOrder order_;
  std::uint32_t hostFrame_ = 0;
  std::optional<std::uint32_t> lastIgFrame_;
  std::uint64_t sofReceived_ = 0;
  std::uint64_t malformed_ = 0;
};

}  // namespace sky::sim
