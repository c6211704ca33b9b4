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

struct HostOptions {
  cigi::ByteOrder order = cigi::ByteOrder::Big;
  double verticalFov_deg = 60;  // View Definition sent with the first frame
  double aspect = 16.0 / 9.0;   // width / height of the channel
  // UTC (s since 1970) at flight time 0, when the record has a date: then
  // Celestial Sphere Control carries the recorded date and time.
  std::optional<std::int64_t> startUtc_s;
};

class CigiHost {
 public:
  explicit CigiHost(HostOptions options = {}) : options_(options) {}

  // The datagram for the next host frame, showing the ownship at `pose`.
  // flightTime_s becomes the CIGI timestamp (10 us ticks). The first frame
  // also carries View Definition; with a start date, every frame whose UTC
  // minute changed (and the first) carries Celestial Sphere Control.
  // `request`, when given, is appended (an Environmental Conditions Request).
  std::vector<std::uint8_t> nextFrame(const geo::GeodeticPose& pose, double flightTime_s,
                                      const std::optional<cigi::EnvironmentalConditionsRequest>& request = {});

  // Feeds one datagram received from the IG; returns whether it was a valid
  // Start of Frame. Malformed datagrams are counted, never thrown.
  bool onIgDatagram(std::span<const std::uint8_t> bytes);
  // The packets after Start of Frame in the last valid IG datagram (answers
  // to conditions requests, for a ConditionsProbe).
  const std::vector<cigi::Packet>& lastReplies() const { return lastReplies_; }

  std::uint32_t framesSent() const { return hostFrame_; }
  // Host frames the newest Start of Frame says the IG has not seen yet.
  std::uint32_t igLagFrames() const { return lastAckedHostFrame_ ? hostFrame_ - 1 - *lastAckedHostFrame_ : hostFrame_; }
  std::uint64_t startOfFramesReceived() const { return sofReceived_; }
  std::uint64_t malformedReceived() const { return malformed_; }
  std::optional<std::uint32_t> lastIgFrame() const { return lastIgFrame_; }

 private:
  HostOptions options_;
  std::uint32_t hostFrame_ = 0;
  std::optional<std::int64_t> lastCelestialMinute_;
  std::optional<std::uint32_t> lastAckedHostFrame_;
  std::optional<std::uint32_t> lastIgFrame_;
  std::uint64_t sofReceived_ = 0;
  std::uint64_t malformed_ = 0;
  std::vector<cigi::Packet> lastReplies_;
};

}  // namespace sky::sim
