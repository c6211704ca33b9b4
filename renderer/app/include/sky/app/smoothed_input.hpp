// What the renderer's smoothed UDP inputs share (FlightGear's native FDM,
// ForeFlight lines): a socket bound to one port, a PoseSmoother fed with the
// samples the datagrams give, the time of day they carry (or --utc's),
// drops counted by reason and logged once per kind. A subclass decodes its
// format in handleDatagram and hands samples to addSample; the render loop
// asks poseAt for the camera at its render time.
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
#include "sky/app/host_clock.hpp"
#include "sky/app/pose_smoother.hpp"
#include "sky/app/shared_state.hpp"

namespace sky::app {

class SmoothedInput {
 public:
  // Binds to address:port (port 0 = ephemeral; see port()). logName names
  // the input in log lines ("FlightGear FDM"); startUtc_s: the time of day
  // at the first sample when the format carries none (--utc).
  SmoothedInput(boost::asio::io_context& io, const std::string& address, unsigned short port,
                PoseSmootherConfig smoothing, std::optional<double> startUtc_s, const char* logName);
  virtual ~SmoothedInput() = default;
  SmoothedInput(const SmoothedInput&) = delete;
  SmoothedInput& operator=(const SmoothedInput&) = delete;

  void start();
  void stop();
  unsigned short port() const { return port_; }

  // The smoothed camera for a frame rendered at `now`, as a HostPose:
  // hostTime_s = render time in seconds since the first sample arrived,
  // hostFrame = samples taken so far, receivedAt = arrival of the newest,
  // sequence increments with every call that returns a pose, utc_s = the
  // time of day at the render time. nullopt until a position is confirmed
  // (see PoseSmoother). Thread-safe.
  std::optional<HostPose> poseAt(SteadyTime now);

  // Takes one datagram received at `now` (what the socket's receive handler
  // calls; public so that tests can drive it without sockets). io thread.
  virtual void handleDatagram(std::span<const std::uint8_t> bytes, SteadyTime now) = 0;

  // Thread-safe.
  std::uint64_t samplesTaken() const { return accepted_; }
  std::uint64_t datagramsDropped() const { return drops_.total(); }
  const DropCounts& drops() const { return drops_; }
  std::uint64_t outliersDropped() const;

 protected:
  // A datagram dropped: counted, logged once per kind. io thread.
  void dropped(DropReason reason, const std::string& detail);
  // Feeds a sample (arrived at sample.receivedAt) to the smoother; false
  // (counted as unusable) when it cannot take it. io thread.
  bool addSample(const PoseSample& sample);
  // The format's own time of day (UTC s, to resolution_s), at `now`. io thread.
  void setTimeOfDay(double utc_s, double resolution_s, TimeSource source, SteadyTime now);

  mutable std::mutex mutex_;  // guards the smoother, the clock and what subclasses keep with them

 private:
  void receive();

  boost::asio::ip::udp::socket socket_;
  boost::asio::ip::udp::endpoint from_;
  std::array<std::uint8_t, 65536> rx_{};
  unsigned short port_ = 0;
  const char* logName_;
  std::atomic<std::uint64_t> accepted_{0};
  DropCounts drops_;
  std::set<std::string> loggedReasons_;  // io thread only

  PoseSmoother smoother_;
  HostClock clock_;
  std::optional<SteadyTime> firstAt_, newestAt_;
  std::uint64_t sequence_ = 0;
};

}  // namespace sky::app
