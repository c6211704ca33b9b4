// The renderer's connection to skyshell-weatherd: connects, subscribes for the
// camera's areas (the detailed one, and the wide coarse one when the server
// takes a second area: Hello's kFeatureAreas), keeps the latest snapshots and the weather clock in
// SharedState, and reconnects with backoff when the server goes away (the
// last weather stays in SharedState meanwhile). It also tells a server that
// takes them (Hello's kFeatureCameraReports) where this channel's camera is,
// for the operator console: a CameraReport at most 2 Hz.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>

#include "sky/app/shared_state.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace sky::app {

class WeatherClient {
 public:
  // channel: this channel's name in the console (at most
  // stream::kMaxChannelBytes of UTF-8; longer is cut); empty: "render@<host>".
  WeatherClient(boost::asio::io_context& io, SharedState& state, std::string host, unsigned short port,
                std::string channel = {});

  void start();
  void stop();
  // Thread-safe: asks for weather around a new area (posted to the io
  // thread); it replaces the area of the same Subscribe::areaIndex. An area
  // other than 0 goes only to a server that takes it (and again on every
  // reconnect to one).
  void subscribe(const stream::Subscribe& area);
  // Whether the server connected last said it takes more than one area.
  bool serverTakesAreas() const { return serverTakesAreas_.load(); }
  // Thread-safe, cheap enough to call every frame: the pose this channel
  // rendered frame `frame` from, with the weather version it held and the
  // weather clock it drew. Sent as a CameraReport when the server takes them,
  // at most every kMinReportInterval, and then only when the pose moved
  // materially, the weather version changed, or kReportKeepAlive passed.
  void reportCamera(const geo::GeodeticPose& pose, std::uint64_t frame, std::uint64_t weatherVersion,
                    double weatherClock_s);

  // 2 Hz: the console's renderer list refreshes at that rate.
  static constexpr std::chrono::milliseconds kMinReportInterval{500};
  // A still camera is still reported this often, so the console sees it alive.
  static constexpr std::chrono::milliseconds kReportKeepAlive{5000};
  // "Moved materially": a tenth of the smallest tile (~1 km, S2 level 13) in
  // position, and a degree in attitude (what a map marker can show).
  static constexpr double kReportMove_m = 100;
  static constexpr double kReportTurn_deg = 1;

  // Thread-safe: proposes this channel's estimate of a host's clock
  // (host_locked_clock.hpp) to a server that takes them (Hello's
  // kFeatureHostClock); the server's answer lands in SharedState::hostClock.
  void proposeHostClock(const stream::HostClock& proposal);
  bool serverTakesHostClock() const { return serverTakesHostClock_.load(); }

  // Thread-safe: asks a server that takes them (Hello's
  // kFeatureLightningRequests) for its lightning process's flashes in the
  // weather-clock interval (from_s, to_s] over this client's areas; the
  // answer's flashes join SharedState's, and SharedState::lightningAnsweredTo
  // becomes to_s. For a headless replay, whose frames run at their own clock.
  void requestLightning(double from_s, double to_s);
  // Call before start() on a client that asks for its flashes: while the
  // server takes requests, the flashes it sends as its own clock runs are
  // left out (their clock is not the asker's, and would prune its flashes).
  void takeOnlyAskedFlashes() { onlyAskedFlashes_ = true; }
  bool serverTakesLightningRequests() const { return serverTakesLightningRequests_.load(); }

  std::uint64_t reportsSent() const { return reportsSent_.load(); }

  std::uint64_t malformedFrames() const { return malformed_.load(); }

 private:
  void connect();
  void scheduleReconnect();
  void read();
  void onFrame(std::span<const std::uint8_t> payload);
  void send(const stream::Message& message);
  void flushWrite();
  bool reportWorthSending(const stream::CameraReport& r, std::chrono::steady_clock::time_point now);

  boost::asio::io_context& io_;
  SharedState& state_;
  std::string host_;
  unsigned short port_;
  boost::asio::ip::tcp::socket socket_;
  boost::asio::steady_timer retryTimer_;
  std::chrono::milliseconds backoff_{250};
  stream::FrameDecoder decoder_;
  std::array<std::uint8_t, 16384> rx_{};
  std::array<std::optional<stream::Subscribe>, stream::kMaxAreas> areas_;  // by area index
  // Bounded outbound: one frame in flight; waiting, only the newest Subscribe
  // of each area, the newest HostClock proposal, the newest LightningRequest
  // and the newest CameraReport (in that order).
  std::vector<std::uint8_t> inFlight_;
  std::array<std::optional<std::vector<std::uint8_t>>, stream::kMaxAreas> pendingSubscribe_;
  std::optional<std::vector<std::uint8_t>> pendingReport_;
  std::optional<std::vector<std::uint8_t>> pendingHostClock_;
  std::optional<std::vector<std::uint8_t>> pendingLightning_;
  std::string channel_;
  // Set from the io thread on the server's Hello; read by reportCamera.
  std::atomic<bool> serverTakesReports_{false};
  std::atomic<bool> serverTakesAreas_{false};
  std::atomic<bool> serverTakesHostClock_{false};
  std::atomic<bool> serverTakesLightningRequests_{false};
  bool onlyAskedFlashes_ = false;  // set before start(); read on the io thread
  // The server marks which layers' tiles drift (kFeatureTileDrift); an
  // older server meant all of them to. Read on the stream's thread only.
  bool serverMarksTileDrift_ = false;
  std::atomic<bool> reportNow_{false};  // after a (re)connect: the next call reports
  std::atomic<std::uint64_t> reportsSent_{0};
  // reportCamera's throttle, on the caller's thread.
  std::mutex reportMutex_;
  std::optional<stream::CameraReport> lastReport_;
  std::chrono::steady_clock::time_point lastReportAt_{};
  double clockRate_ = 1;               // io thread only
  std::atomic<std::uint64_t> malformed_{0};  // written by the io thread, read by the render loop
  bool stopped_ = false;               // io thread only (stop() posts)
};

}  // namespace sky::app
