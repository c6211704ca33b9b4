// One console WebSocket connection (private to the ConsoleFeed): accepts the
// upgrade, then writes one JSON text message at a time from its bounded
// WsOutbox while it reads (and ignores) whatever the browser sends, so
// control frames (ping, close) are answered. A write that does not complete
// within the stall bound, or an event queue past its bound, drops the client.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "sky/server/ws_outbox.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class WsClient;

class WsClientHandler {
 public:
  // The client closed and does no more work; `dropped`: it was too slow.
  virtual void wsClientClosed(WsClient& client, bool dropped) = 0;

 protected:
  ~WsClientHandler() = default;
};

class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  WsClient(boost::asio::ip::tcp::socket socket, std::uint64_t id, WsClientHandler& handler, spdlog::logger& log,
           std::chrono::milliseconds stallTimeout, std::size_t maxEvents);

  // Completes the upgrade `request` asked for, then sends what is queued.
  void start(boost::beast::http::request<boost::beast::http::string_body> request);
  // Messages to send (ignored once closing).
  void sendFirst(WsText hello);
  void sendEvent(WsText event);  // past the event bound: dropped
  void sendState(WsText state);
  void sendRenderers(WsText renderers);
  void sendHealth(WsText health);
  // Sends a close frame, after the message being written if there is one (a
  // websocket writes one frame at a time); the socket is closed within a
  // second either way. For server shutdown.
  void shutdown();
  // Closes the socket now. Idempotent.
  void close(bool dropped = false);

  std::uint64_t id() const { return id_; }
  const std::string& peer() const { return peer_; }

 private:
  void readMore();
  void writeNext();
  void sendCloseFrame();

  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  boost::asio::steady_timer stallTimer_;
  boost::asio::steady_timer closeTimer_;
  std::chrono::milliseconds stallTimeout_;
  std::uint64_t id_;
  std::string peer_;
  WsClientHandler& handler_;
  spdlog::logger& log_;
  WsOutbox outbox_;
  boost::beast::flat_buffer readBuffer_;
  WsText writing_;  // the message async_write is sending; kept alive until it completes
  std::uint64_t writeGeneration_ = 0;
  bool open_ = false;  // the upgrade completed
  bool writeInFlight_ = false;
  bool closing_ = false;
  bool closed_ = false;
};

}  // namespace sky::server
