// Clients of skyshell-weatherd for the integration tests: a console on the
// WebSocket feed (every read with a deadline), a bare weather-stream peer,
// and the status line of a raw upgrade request.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/write.hpp>
// GCC 12 at -O2 reports a boost::optional inside Beast's HTTP response parser
// (the client's handshake) as maybe uninitialized: a false positive.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <nlohmann/json.hpp>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

namespace sky::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;

// A console: one WebSocket, every read with a deadline.
class Console {
 public:
  explicit Console(unsigned port) : ws_(io_) {
    beast::get_lowest_layer(ws_).connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"),
                                                       static_cast<unsigned short>(port)));
    ws_.handshake("127.0.0.1:" + std::to_string(port), "/api/ws", ec_);
  }
  bool open() const { return !ec_; }

  // The next message; nullopt when none came within `timeout` or the feed closed.
  std::optional<nlohmann::json> read(std::chrono::milliseconds timeout = 20s) {
    beast::flat_buffer buffer;
    bool done = false;
    beast::error_code error;
    ws_.async_read(buffer, [&](beast::error_code ec, std::size_t) {
      error = ec;
      done = true;
    });
    io_.restart();
    io_.run_for(timeout);
    if (!done) {
      beast::get_lowest_layer(ws_).cancel();
      io_.restart();
      io_.run();
      return std::nullopt;
    }
    if (error) return std::nullopt;
    return nlohmann::json::parse(beast::buffers_to_string(buffer.data()));
  }
  // The next message of `type` whose payload satisfies pred, skipping others.
  template <class Pred>
  std::optional<nlohmann::json> readUntil(const std::string& type, Pred pred, std::chrono::seconds within = 30s) {
    const auto deadline = std::chrono::steady_clock::now() + within;
    while (std::chrono::steady_clock::now() < deadline) {
      auto m = read();
      if (!m) return std::nullopt;
      if ((*m)["type"] == type && pred(*m)) return m;
    }
    return std::nullopt;
  }
  std::optional<nlohmann::json> readType(const std::string& type) {
    return readUntil(type, [](const nlohmann::json&) { return true; });
  }

 private:
  asio::io_context io_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::error_code ec_;
};

// A renderer as far as the stream goes: subscribes and reports its camera.
class StreamPeer {
 public:
  explicit StreamPeer(unsigned port) : socket_(io_) {
    socket_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  }
  void send(const stream::Message& m) {
    asio::write(socket_, asio::buffer(stream::encodeFrame(stream::encodeMessage(m))));
  }
  void close() {
    boost::system::error_code ignored;
    socket_.close(ignored);
  }

 private:
  asio::io_context io_;
  tcp::socket socket_;
};

// The status line the server answers a WebSocket upgrade with, read off a
// plain socket (Beast's client does not keep a declined response).
inline std::string upgradeStatus(unsigned port) {
  asio::io_context io;
  tcp::socket socket(io);
  socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)));
  const std::string request =
      "GET /api/ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  asio::write(socket, asio::buffer(request));
  std::string reply;
  boost::system::error_code ec;
  asio::read_until(socket, asio::dynamic_buffer(reply), "\r\n", ec);
  return reply.substr(0, reply.find("\r\n"));
}

}  // namespace sky::test
