// The renderer's connection to skyshell-weatherd: connects, subscribes for the
// camera's area, keeps the latest snapshot and the weather clock in
// SharedState, and reconnects with backoff when the server goes away (the
// last weather stays in SharedState meanwhile).
#pragma once

#include <array>
#include <chrono>
#include <optional>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>

#include "sky/app/shared_state.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace sky::app {

class WeatherClient {
 public:
  WeatherClient(boost::asio::io_context& io, SharedState& state, std::string host, unsigned short port);

  void start();
  void stop();
  // Thread-safe: asks for weather around a new area (posted to the io thread).
  void subscribe(const stream::Subscribe& area);

  std::uint64_t malformedFrames() const { return malformed_; }

 private:
  void connect();
  void scheduleReconnect();
  void read();
  void onFrame(std::span<const std::uint8_t> payload);
  void send(const stream::Message& message);
  void flushWrite();

  boost::asio::io_context& io_;
  SharedState& state_;
  std::string host_;
  unsigned short port_;
  boost::asio::ip::tcp::socket socket_;
  boost::asio::steady_timer retryTimer_;
  std::chrono::milliseconds backoff_{250};
  stream::FrameDecoder decoder_;
  std::array<std::uint8_t, 16384> rx_{};
  std::optional<stream::Subscribe> area_;
  // Bounded outbound: one frame in flight, and only the newest Subscribe waits.
  std::vector<std::uint8_t> inFlight_;
  std::optional<std::vector<std::uint8_t>> pending_;
  double clockRate_ = 1;
  std::uint64_t malformed_ = 0;
  bool stopped_ = false;
};

}  // namespace sky::app
