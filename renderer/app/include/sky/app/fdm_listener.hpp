// The renderer's FlightGear endpoint on UDP: decodes each --native-fdm
// datagram (FGNetFDM v24) into a pose sample for a PoseSmoother, which the
// render loop asks for the camera at its render time, and into the time of
// day (cur_time + warp, so the sun matches FlightGear's sky) and the
// visibility (the haze). The second way a
// simulator drives a channel, besides CIGI. Malformed datagrams (a wrong
// size or version, a non-finite or absurd field) and poses the smoother
// cannot take are dropped, counted by reason, and logged once per kind; the
// channel keeps drawing from the samples it has.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>

#include "sky/app/drop_counts.hpp"
#include "sky/app/host_atmosphere.hpp"
#include "sky/app/host_clock.hpp"
#include "sky/app/pose_smoother.hpp"
#include "sky/app/shared_state.hpp"
#include "sky/fgfdm/net_fdm.hpp"

namespace sky::app {

// The pose sample a FlightGear packet gives. Altitude is FlightGear's MSL
// altitude, used as the height (the geoid undulation, within ±110 m, is not
// applied: the weather layers are MSL-referenced the same way).
PoseSample poseSampleFrom(const fgfdm::NetFdm& fdm, SteadyTime receivedAt);

class FdmListener {
 public:
  // Binds to address:port (port 0 = ephemeral; see port()).
  FdmListener(boost::asio::io_context& io, const std::string& address, unsigned short port,
              PoseSmootherConfig smoothing = {});

  void start();
  void stop();
  unsigned short port() const { return port_; }

  // The smoothed camera for a frame rendered at `now`, as a HostPose:
  // hostTime_s = render time in seconds since the first accepted datagram
  // arrived, hostFrame = datagrams accepted so far, receivedAt = arrival of
  // the newest one, sequence increments with every call that returns a pose,
  // utc_s = FlightGear's cur_time + warp at the render time (source FlightGear).
  // nullopt until a position is confirmed (see PoseSmoother). Thread-safe.
  std::optional<HostPose> poseAt(std::chrono::steady_clock::time_point now);

  // Takes one datagram received at `now` (what the socket's receive handler
  // calls; public so that tests can drive it without sockets). io thread.
  void handleDatagram(std::span<const std::uint8_t> bytes, std::chrono::steady_clock::time_point now);

  // Thread-safe.
  std::uint64_t datagramsAccepted() const { return accepted_; }
  std::uint64_t datagramsDropped() const { return drops_.total(); }
  const DropCounts& drops() const { return drops_; }
  std::uint64_t outliersDropped() const;
  // The newest datagram's visibility as the channel's atmosphere (source
  // FlightGear); the default one before any. Thread-safe.
  HostAtmosphere atmosphere() const;

 private:
  void receive();
  void dropped(DropReason reason, const std::string& detail);

  boost::asio::ip::udp::socket socket_;
  boost::asio::ip::udp::endpoint from_;
  std::array<std::uint8_t, 65536> rx_{};
  unsigned short port_ = 0;
  std::atomic<std::uint64_t> accepted_{0};
  DropCounts drops_;
  std::set<std::string> loggedReasons_;  // io thread only

  mutable std::mutex mutex_;  // guards the members below
  PoseSmoother smoother_;
  std::optional<std::chrono::steady_clock::time_point> firstAt_, newestAt_;
  std::uint64_t sequence_ = 0;
  // FlightGear's simulated time, cur_time + warp (whole seconds), advanced
  // between datagrams by their arrival times (host_clock.hpp).
  HostClock clock_;
  HostAtmosphere atmosphere_;
};

}  // namespace sky::app
