// The CIGI host side of a replay: turns a flight and a host frame counter
// into the datagrams a simulator host would send (IG Control + ownship Entity
// Control, and the views of a multi-channel display), and keeps count of the
// IGs' Start of Frame replies.
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
  // A display of `channels` side-by-side channels, each channelWidth_deg
  // wide (> 0; 0: one channel, the View Definition above): every frame
  // carries, for channel i (view id i), a View Definition of half-angles
  // +-W/2 horizontally and +-atan(tan(W/2) / aspect) vertically, and a View
  // Control turning it (i - (N - 1) / 2) W to the right of the nose.
  std::uint32_t channels = 1;
  double channelWidth_deg = 0;
};

// Channel i's View Definition and View Control (view id i) for a display of
// `channels` channels of width channelWidth_deg (0 < W < 178) and aspect
// width / height (HostOptions).
cigi::ViewDefinition channelViewDefinition(std::uint32_t i, double channelWidth_deg, double aspect);
cigi::ViewControl channelViewControl(std::uint32_t i, std::uint32_t channels, double channelWidth_deg);

class CigiHost {
 public:
  explicit CigiHost(HostOptions options = {}) : options_(options) {}

  // The datagram for the next host frame, showing the ownship at `pose`.
  // flightTime_s becomes the CIGI timestamp (10 us ticks). The first frame
  // also carries View Definition (with channels, every frame carries each
  // channel's, so a channel started late gets its view with its first pose);
  // with a start date, every frame whose UTC minute changed (and the first)
  // carries Celestial Sphere Control. `request`, when given, is appended
  // last (an Environmental Conditions Request, kSize bytes at the end).
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
  // The Last Host Frame Number of the newest valid Start of Frame.
  std::optional<std::uint32_t> lastStartOfFrameHostFrame() const { return lastSofHostFrame_; }

 private:
  HostOptions options_;
  std::uint32_t hostFrame_ = 0;
  std::optional<std::int64_t> lastCelestialMinute_;
  std::optional<std::uint32_t> lastAckedHostFrame_;
  std::optional<std::uint32_t> lastIgFrame_;
  std::optional<std::uint32_t> lastSofHostFrame_;
  std::uint64_t sofReceived_ = 0;
  std::uint64_t malformed_ = 0;
  std::vector<cigi::Packet> lastReplies_;
};

}  // namespace sky::sim
