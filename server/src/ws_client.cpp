// A console WebSocket connection (see ws_client.hpp).
#include "ws_client.hpp"

#include <spdlog/spdlog.h>

namespace sky::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;

namespace {

// What the console may send us: nothing is read from it yet, so anything
// past a small message is a misbehaving client.
constexpr std::size_t kMaxIncomingBytes = 4096;
// The upgrade and a close must finish in this long; a console that goes
// silent (no pong to our pings) for kIdleTimeout is gone.
constexpr auto kHandshakeTimeout = std::chrono::seconds(10);
constexpr auto kIdleTimeout = std::chrono::seconds(60);
// At shutdown a close frame gets this long before the socket is closed.
constexpr auto kShutdownGrace = std::chrono::seconds(1);

}  // namespace

WsClient::WsClient(asio::ip::tcp::socket socket, std::uint64_t id, WsClientHandler& handler, spdlog::logger& log,
                   std::chrono::milliseconds stallTimeout, std::size_t maxEvents)
    : ws_(std::move(socket)),
      stallTimer_(ws_.get_executor()),
      closeTimer_(ws_.get_executor()),
      stallTimeout_(stallTimeout),
      id_(id),
      handler_(handler),
      log_(log),
      outbox_(maxEvents) {
  boost::system::error_code ec;
  const auto remote = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
  peer_ = ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
}

void WsClient::start(beast::http::request<beast::http::string_body> request) {
  // The websocket stream keeps its own timeouts; the TCP stream's must be off.
  beast::get_lowest_layer(ws_).expires_never();
  websocket::stream_base::timeout timeouts{};
  timeouts.handshake_timeout = kHandshakeTimeout;
  timeouts.idle_timeout = kIdleTimeout;
  timeouts.keep_alive_pings = true;
  ws_.set_option(timeouts);
  ws_.set_option(websocket::stream_base::decorator(
      [](websocket::response_type& res) { res.set(beast::http::field::server, "skyshell-weatherd"); }));
  ws_.read_message_max(kMaxIncomingBytes);
  ws_.text(true);
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
    if (self->closed_) return;
    if (ec) {
      self->log_.info("event=console_upgrade_failed console={} peer={} error={:?}", self->id_, self->peer_,
                      ec.message());
      self->close();
      return;
    }
    self->open_ = true;
    self->log_.info("event=console_connected console={} peer={}", self->id_, self->peer_);
    self->readMore();
    self->writeNext();
  });
}

void WsClient::sendFirst(WsText hello) {
  if (closing_ || closed_) return;
  outbox_.pushFirst(std::move(hello));
  writeNext();
}

void WsClient::sendEvent(WsText event) {
  if (closing_ || closed_) return;
  if (!outbox_.pushEvent(std::move(event))) {
    log_.warn("event=console_stalled console={} peer={} events_waiting={}; dropped", id_, peer_,
              outbox_.queuedEvents());
    close(true);
    return;
  }
  writeNext();
}

void WsClient::sendState(WsText state) {
  if (closing_ || closed_) return;
  outbox_.setState(std::move(state));
  writeNext();
}

void WsClient::sendRenderers(WsText renderers) {
  if (closing_ || closed_) return;
  outbox_.setRenderers(std::move(renderers));
  writeNext();
}

void WsClient::sendHealth(WsText health) {
  if (closing_ || closed_) return;
  outbox_.setHealth(std::move(health));
  writeNext();
}

void WsClient::readMore() {
  ws_.async_read(readBuffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (self->closed_) return;
    if (ec) {
      if (ec != websocket::error::closed)
        self->log_.info("event=console_read_failed console={} peer={} error={:?}", self->id_, self->peer_, ec.message());
      else
        self->log_.info("event=console_eof console={} peer={}", self->id_, self->peer_);
      self->close();
      return;
    }
    // The console sends nothing we act on (changes go through HTTP).
    self->readBuffer_.consume(self->readBuffer_.size());
    self->readMore();
  });
}

void WsClient::writeNext() {
  if (!open_ || writeInFlight_ || closing_ || closed_) return;
  auto next = outbox_.takeNext();
  if (!next) return;
  writing_ = std::move(*next);
  writeInFlight_ = true;
  const std::uint64_t generation = ++writeGeneration_;
  ws_.async_write(asio::buffer(*writing_), [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->writeInFlight_ = false;
    self->stallTimer_.cancel();
    if (self->closed_) return;
    if (ec) {
      self->log_.info("event=console_write_failed console={} peer={} error={:?}", self->id_, self->peer_, ec.message());
      self->close();
      return;
    }
    if (self->closing_) {
      self->sendCloseFrame();  // shutdown waited for this message
      return;
    }
    self->writeNext();
  });
  stallTimer_.expires_after(stallTimeout_);
  stallTimer_.async_wait([self = shared_from_this(), generation](const boost::system::error_code& ec) {
    if (ec || generation != self->writeGeneration_ || !self->writeInFlight_ || self->closed_) return;
    self->log_.warn("event=console_stalled console={} peer={} message_bytes={} stall_ms={}; dropped", self->id_,
                    self->peer_, self->writing_->size(), self->stallTimeout_.count());
    self->close(true);
  });
}

void WsClient::shutdown() {
  if (closing_ || closed_) return;
  closing_ = true;
  if (!open_) {
    close();
    return;
  }
  closeTimer_.expires_after(kShutdownGrace);
  closeTimer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (!ec) self->close();
  });
  // With a message on the wire the close frame follows it (the write's
  // handler sends it): cutting the socket mid-message would leave the console
  // without the reason.
  if (!writeInFlight_) sendCloseFrame();
}

void WsClient::sendCloseFrame() {
  ws_.async_close(websocket::close_code::going_away, [self = shared_from_this()](beast::error_code) {
    self->close();
  });
}

void WsClient::close(bool dropped) {
  if (closed_) return;
  closed_ = true;
  // Cancels the read, a write and the websocket's own timers.
  beast::get_lowest_layer(ws_).close();
  stallTimer_.cancel();
  closeTimer_.cancel();
  handler_.wsClientClosed(*this, dropped);
}

}  // namespace sky::server
