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
#pragma once

#include <array>
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

#include "sky/core/result.hpp"
#include "sky/server/cigi_weather.hpp"
#include "sky/server/change.hpp"
#include "sky/server/rejections.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class CigiWeatherInput {
 public:
  struct Counters {
    std::uint64_t datagrams = 0;   // received
    std::uint64_t malformed = 0;   // dropped: did not decode
    std::uint64_t rejected = 0;    // decoded, but the weather was refused
    std::uint64_t applied = 0;     // produced an accepted change request
    std::uint64_t unchanged = 0;   // decoded, nothing differed from before
  };

  // Binds UDP address:port (0: ephemeral). Refused datagrams are counted in
  // `rejections` too (cigi_malformed, cigi_refused) when it is given. Accepted
  // changes reach the subscribers through the WeatherService's listeners.
  static Result<std::unique_ptr<CigiWeatherInput>> create(boost::asio::io_context& io, const std::string& address,
                                                          std::uint16_t port, WeatherService& weather,
                                                          Rejections* rejections,
                                                          std::shared_ptr<spdlog::logger> log);
  std::uint16_t port() const { return port_; }
  void close();
  const Counters& counters() const { return counters_; }

  // One datagram from `sender` (exposed for tests and the fuzz target).
  void onDatagram(std::span<const std::uint8_t> bytes, const std::string& sender);

 private:
  CigiWeatherInput(boost::asio::io_context& io, WeatherService& weather, Rejections* rejections,
                   std::shared_ptr<spdlog::logger> log);
  void receive();
  void logOnce(const std::string& kind, const std::string& message);

  boost::asio::ip::udp::socket socket_;
  boost::asio::ip::udp::endpoint from_;
  std::array<std::uint8_t, 65536> buffer_{};
  WeatherService& weather_;
  Rejections* rejections_;
  std::shared_ptr<spdlog::logger> log_;
  std::map<std::string, CigiWeatherMapper> mappers_;  // by sender "address:port"
  std::set<std::string> logged_;
  std::uint16_t port_ = 0;
  Counters counters_;
};

}  // namespace sky::server
