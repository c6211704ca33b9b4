// The renderer's CIGI 3.3 endpoint on UDP: takes the ownship pose from each
// host datagram (IG Control + Entity Control for entity 0) into SharedState
// and answers with Start of Frame. Malformed datagrams are dropped, counted,
// and logged once per reason.
#pragma once

#include <array>
#include <cstdint>
#include <set>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio.hpp>

#include "sky/app/shared_state.hpp"
#include "sky/cigi/codec.hpp"

namespace sky::app {

class CigiListener {
 public:
  // Binds to address:port (port 0 = ephemeral; see port()).
  CigiListener(boost::asio::io_context& io, SharedState& state, const std::string& address,
               unsigned short port);

  void start();
  void stop();
  unsigned short port() const { return port_; }

  std::uint64_t datagramsAccepted() const { return accepted_; }
  std::uint64_t datagramsDropped() const { return dropped_; }

 private:
  void receive();
  void onDatagram(std::span<const std::uint8_t> bytes);
  void dropped(const std::string& reason);

  boost::asio::ip::udp::socket socket_;
  boost::asio::ip::udp::endpoint from_;
  std::array<std::uint8_t, 65536> rx_{};
  SharedState& state_;
  unsigned short port_ = 0;
  std::uint32_t igFrame_ = 0;
  std::uint64_t accepted_ = 0;
  std::uint64_t dropped_ = 0;
  std::set<std::string> loggedReasons_;
};

}  // namespace sky::app
