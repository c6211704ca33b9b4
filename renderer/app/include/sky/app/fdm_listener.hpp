// The renderer's FlightGear endpoint on UDP: decodes each --native-fdm
// datagram (FGNetFDM v24) into a pose sample for a PoseSmoother, which the
// render loop asks for the camera at its render time, and into the time of
// day (cur_time: FlightGear's simulated time, its warp already in it, so
// the sun matches FlightGear's sky) and the
// visibility (the haze). The second way a
// simulator drives a channel, besides CIGI. Malformed datagrams (a wrong
// size or version, a non-finite or absurd field) and poses the smoother
// cannot take are dropped, counted by reason, and logged once per kind; the
// channel keeps drawing from the samples it has.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "sky/app/host_atmosphere.hpp"
#include "sky/app/pose_smoother.hpp"
#include "sky/app/smoothed_input.hpp"
#include "sky/fgfdm/net_fdm.hpp"

namespace sky::app {

// The pose sample a FlightGear packet gives. Altitude is FlightGear's MSL
// altitude, used as the height (the geoid undulation, within ±110 m, is not
// applied: the weather layers are MSL-referenced the same way).
PoseSample poseSampleFrom(const fgfdm::NetFdm& fdm, SteadyTime receivedAt);

class FdmListener : public SmoothedInput {
 public:
  // Binds to address:port (port 0 = ephemeral; see port()).
  FdmListener(boost::asio::io_context& io, const std::string& address, unsigned short port,
              PoseSmootherConfig smoothing = {})
      : SmoothedInput(io, address, port, smoothing, std::nullopt, "FlightGear FDM") {}

  // poseAt (smoothed_input.hpp): utc_s is FlightGear's cur_time at
  // the render time (source FlightGear).
  void handleDatagram(std::span<const std::uint8_t> bytes, SteadyTime now) override;

  // Thread-safe.
  std::uint64_t datagramsAccepted() const { return samplesTaken(); }
  // The newest datagram's visibility as the channel's atmosphere (source
  // FlightGear); the default one before any. Thread-safe.
  HostAtmosphere atmosphere() const;

 private:
  HostAtmosphere atmosphere_;  // guarded by mutex_
};

}  // namespace sky::app
