// CIGI 3.3 weather input on UDP: a host that already speaks CIGI sends its
// Weather Control and Environmental Region Control packets here (the same
// host->IG datagrams it sends its image generators), and they become changes
// to the live weather through the WeatherService, with the same checks and
// durability as the HTTP API. One CigiWeatherMapper per sending host, so a
// host resending its weather every frame produces no changes until something
// differs.
//
// Nothing is lost silently: a datagram that does not decode (wrong first
// packet, bad size byte, field out of range) is dropped and counted; a
// datagram whose weather is refused by the model is counted, logged with the
// reason, and leaves the weather as it was. No reply is sent: the server is
// not an IG.
//
// Bounds: state is kept for at most kMaxCigiSenders senders (a sender idle
// for kCigiSenderIdle is forgotten; a new sender past the cap is refused),
// and for at most kMaxCigiRegionsPerSender regions each (cigi_weather.hpp).
//
// Durability: a datagram has no acknowledgement, so its changes are applied
// at once and committed to disk in one transaction per burst, at most
// kCigiCommitBatch after the first of them (WeatherService::submitBatched).
// A crash loses at most the CIGI changes of that last interval; a host
// resends its weather every frame, so it restores them by itself. A clean
// shutdown (close()) commits them first. Changes from the HTTP API are still
// on disk before they are acknowledged.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "sky/core/result.hpp"
#include "sky/server/cigi_weather.hpp"
#include "sky/server/change.hpp"
#include "sky/server/rejections.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

// Senders whose state (CigiWeatherMapper) the input keeps. A cockpit has one
// host, a training centre a few; 16 leaves room for several simulators and
// their instructor stations, and bounds what a flood of senders costs.
inline constexpr std::size_t kMaxCigiSenders = 16;
// A sender silent this long is forgotten (hosts send every frame; a minute of
// silence is a host that stopped), freeing its slot for another.
inline constexpr std::chrono::seconds kCigiSenderIdle{60};
// Longest a CIGI change waits for its commit: a burst of datagrams in this
// window becomes one transaction (one fsync) instead of one per datagram.
// 50 ms is three frames at 60 Hz: what a crash can lose, and a host
// resending every frame makes up for it at once.
inline constexpr std::chrono::milliseconds kCigiCommitBatch{50};

class CigiWeatherInput {
 public:
  struct Counters {
    std::uint64_t datagrams = 0;   // received
    std::uint64_t malformed = 0;   // dropped: did not decode
    std::uint64_t rejected = 0;    // decoded, but the weather was refused
    std::uint64_t applied = 0;     // produced an accepted change request
    std::uint64_t unchanged = 0;   // decoded, nothing differed from before
    std::uint64_t senderRefused = 0;  // dropped: a new sender past kMaxCigiSenders
    std::uint64_t commits = 0;     // batch commits made
    std::uint64_t commitFailures = 0;  // batch commits that failed (retried)
  };

  // Binds UDP address:port (0: ephemeral). Refused datagrams are counted in
  // `rejections` too (cigi_malformed, cigi_refused) when it is given. Accepted
  // changes reach the subscribers through the WeatherService's listeners.
  static Result<std::unique_ptr<CigiWeatherInput>> create(boost::asio::io_context& io, const std::string& address,
                                                          std::uint16_t port, WeatherService& weather,
                                                          Rejections* rejections,
                                                          std::shared_ptr<spdlog::logger> log);
  std::uint16_t port() const { return port_; }
  // Stops receiving and commits the changes still waiting for their batch.
  void close();
  std::size_t senders() const { return mappers_.size(); }
  const Counters& counters() const { return counters_; }

  // One datagram from `sender` (exposed for tests and the fuzz target),
  // handled inside a boundary: an exception drops the datagram (counted
  // handler_failed), never the io thread.
  void onDatagram(std::span<const std::uint8_t> bytes, const std::string& sender);

 private:
  CigiWeatherInput(boost::asio::io_context& io, WeatherService& weather, Rejections* rejections,
                   std::shared_ptr<spdlog::logger> log);
  void receive();
  void handle(std::span<const std::uint8_t> bytes, const std::string& sender);
  void logOnce(const std::string& kind, const std::string& message);
  // The mapper of `sender`, making one if there is room (after forgetting
  // idle senders); null when the input is full.
  CigiWeatherMapper* mapperFor(const std::string& sender);
  void scheduleCommit();
  void commitBatch();

  boost::asio::ip::udp::socket socket_;
  boost::asio::ip::udp::endpoint from_;
  std::array<std::uint8_t, 65536> buffer_{};
  WeatherService& weather_;
  Rejections* rejections_;
  std::shared_ptr<spdlog::logger> log_;
  struct Sender {
    CigiWeatherMapper mapper;
    std::chrono::steady_clock::time_point lastSeen;
  };
  std::map<std::string, Sender> mappers_;  // by sender "address:port"; at most kMaxCigiSenders
  std::set<std::string> logged_;           // kinds logged once; bounded
  boost::asio::steady_timer commitTimer_;
  bool commitPending_ = false;
  std::uint16_t port_ = 0;
  Counters counters_;
};

}  // namespace sky::server
