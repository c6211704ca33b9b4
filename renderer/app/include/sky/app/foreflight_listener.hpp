// The renderer's ForeFlight endpoint on UDP (--foreflight-port; the format's
// port is 49002): XGPS position lines, and XATT attitude lines when the
// sender has them (X-Plane does; FlightGear's foreflight-xgps does not), as
// the pose samples of a PoseSmoother, like the FlightGear FDM input. With
// this an X-Plane 11/12 user points "Send to ForeFlight" (Settings > Network)
// at the renderer and sees its clouds around their aircraft.
//
// Senders are sparse (about 1 Hz for XGPS) and coarse (FlightGear writes
// 0.001 deg, ~110 m), so the smoother extrapolates along the sent track and
// ground speed rather than waiting a second for the next fix; corrections
// fade in. Without XATT the attitude is derived from the track as for an
// IGC file: heading = track (held below kMinTrackSpeed_mps), pitch = climb
// angle, bank = a coordinated turn's at the track's rate of turn.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "sky/app/pose_smoother.hpp"
#include "sky/app/smoothed_input.hpp"
#include "sky/foreflight/foreflight.hpp"

namespace sky::app {

// The smoothing a ~1 Hz feed needs: no render delay (waiting for the next
// fix would cost a second of latency), extrapolation along the sent
// velocity for up to 3 s (two missed fixes), then held.
PoseSmootherConfig foreflightSmoothing();

// Turns ForeFlight messages into pose samples. Pure: arrival times are
// passed in. One per sender stream.
class ForeFlightTrack {
 public:
  // Below this ground speed the track is noise (a parked aircraft sends
  // 0.000): the heading is held. 2 m/s.
  static constexpr double kMinTrackSpeed_mps = 2.0;
  // An XATT older than this no longer gives the attitude (the sender stopped
  // sending it): derived again. 2 s.
  static constexpr double kAttitudeFresh_s = 2.0;
  // Derived angles are clamped: pitch to +-30 deg, bank to +-60 deg (a 2 g
  // coordinated turn), as for flight files (protocol/flight/src/attitude.cpp).
  static constexpr double kMaxDerivedPitch_deg = 30.0, kMaxDerivedBank_deg = 60.0;

  // The sample an XGPS gives, or none for an XATT (kept for the next XGPS)
  // and other kinds.
  std::optional<PoseSample> take(const foreflight::Message& message, SteadyTime receivedAt);

 private:
  std::optional<foreflight::Attitude> attitude_;
  SteadyTime attitudeAt_{};
  std::optional<foreflight::Position> previous_;
  SteadyTime previousAt_{};
  double heading_deg = 0;
  double climb_mps = 0, turnRate_degps = 0;
};

class ForeFlightListener : public SmoothedInput {
 public:
  // Binds to address:port (port 0 = ephemeral; see port()). The format
  // carries no time of day: startUtc_s (--utc) is the time at the first
  // line, advanced in real time; none: the fixed sun.
  ForeFlightListener(boost::asio::io_context& io, const std::string& address, unsigned short port,
                     std::optional<double> startUtc_s = std::nullopt,
                     PoseSmootherConfig smoothing = foreflightSmoothing())
      : SmoothedInput(io, address, port, smoothing, startUtc_s, "ForeFlight") {}

  // poseAt (smoothed_input.hpp): hostFrame counts XGPS lines taken.
  void handleDatagram(std::span<const std::uint8_t> bytes, SteadyTime now) override;

  // Thread-safe.
  std::uint64_t positionsAccepted() const { return samplesTaken(); }
  std::uint64_t attitudesAccepted() const { return attitudes_; }
  std::uint64_t otherLines() const { return others_; }

 private:
  std::atomic<std::uint64_t> attitudes_{0}, others_{0};
  ForeFlightTrack track_;  // io thread only
};

}  // namespace sky::app
