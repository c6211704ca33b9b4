// Weather stream client (see weather_client.hpp).
#include "sky/app/weather_client.hpp"

#include <spdlog/spdlog.h>

#include "sky/core/overloaded.hpp"

namespace sky::app {

namespace asio = boost::asio;
using Clock = std::chrono::steady_clock;

namespace {
// Reconnect backoff grows to this cap: short enough that a restarted server
// is picked up within seconds, long enough not to spin on a dead one.
constexpr std::chrono::milliseconds kMaxBackoff{2000};
}  // namespace

WeatherClient::WeatherClient(asio::io_context& io, SharedState& state, std::string host,
                             unsigned short port)
    : io_(io), state_(state), host_(std::move(host)), port_(port), socket_(io), retryTimer_(io) {}

void WeatherClient::start() {
  asio::post(io_, [this] { connect(); });
}

void WeatherClient::stop() {
  asio::post(io_, [this] {
    stopped_ = true;
    retryTimer_.cancel();
    boost::system::error_code ec;
    socket_.close(ec);
  });
}

void WeatherClient::subscribe(const stream::Subscribe& area) {
  asio::post(io_, [this, area] {
    area_ = area;
    if (socket_.is_open()) send(area);
  });
}

void WeatherClient::connect() {
  if (stopped_) return;
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(host_, ec);
  if (ec) {
    spdlog::error("weather server address '{}' is not an IP address", host_);
    return;
  }
  socket_ = asio::ip::tcp::socket(io_);
  socket_.async_connect({address, port_}, [this](boost::system::error_code e) {
    if (e) {
      scheduleReconnect();
      return;
    }
    spdlog::info("connected to weather server {}:{}", host_, port_);
    backoff_ = std::chrono::milliseconds(250);
    decoder_ = stream::FrameDecoder();
    inFlight_.clear();
    pending_.reset();
    state_.setConnected(true);
    if (area_) send(*area_);
    read();
  });
}

void WeatherClient::scheduleReconnect() {
  if (stopped_) return;
  state_.setConnected(false);
  boost::system::error_code ec;
  socket_.close(ec);
  retryTimer_.expires_after(backoff_);
  backoff_ = std::min(backoff_ * 2, kMaxBackoff);
  retryTimer_.async_wait([this](boost::system::error_code e) {
    if (!e) connect();
  });
}

void WeatherClient::read() {
  socket_.async_read_some(asio::buffer(rx_), [this](boost::system::error_code ec, std::size_t n) {
    if (ec) {
      if (!stopped_) spdlog::warn("weather server connection lost: {}", ec.message());
      scheduleReconnect();
      return;
    }
    decoder_.append(std::span(rx_.data(), n));
    while (true) {
      auto frame = decoder_.next();
      if (!frame) {
        ++malformed_;
        spdlog::error("weather stream: {}; reconnecting", describe(frame.error()));
        scheduleReconnect();
        return;
      }
      if (!*frame) break;
      onFrame(**frame);
    }
    read();
  });
}

void WeatherClient::onFrame(std::span<const std::uint8_t> payload) {
  auto message = stream::decodeMessage(payload);
  if (!message) {
    ++malformed_;
    spdlog::warn("weather stream: dropped a frame: {}", describe(message.error()));
    return;
  }
  const auto now = Clock::now();
  std::visit(Overloaded{
                 [&](const stream::Hello& h) {
                   clockRate_ = h.clockRate;
                   state_.setClock(h.weatherClock_s, h.clockRate, now);
                   spdlog::info("weather server '{}' protocol {} clock {:.1f} s x{}", h.serverId,
                                h.protocolVersion, h.weatherClock_s, h.clockRate);
                 },
                 [&](const weather::WeatherSnapshot& s) {
                   spdlog::info("weather snapshot: {} layers, {} tiles at S2 level {}", s.layers.size(),
                                s.tiles.size(), s.tileLevel);
                   state_.setSnapshot(s, now);
                 },
                 [&](const weather::WeatherDelta& d) {
                   if (auto r = state_.applyDelta(d, now); !r) {
                     ++malformed_;
                     spdlog::warn("weather stream: dropped a Delta: {}; asking for a new Snapshot", r.error().detail);
                     if (area_) send(*area_);
                   }
                 },
                 [&](const stream::Heartbeat& h) { state_.setClock(h.weatherClock_s, clockRate_, now); },
                 [&](const stream::StreamError& e) {
                   spdlog::warn("weather server error {}: {}", e.code, e.detail);
                 },
                 [&](const stream::Subscribe&) {
                   ++malformed_;
                   spdlog::warn("weather stream: a server must not send Subscribe; dropped");
                 }},
             *message);
}

void WeatherClient::send(const stream::Message& message) {
  auto bytes = stream::encodeFrame(stream::encodeMessage(message));
  if (!inFlight_.empty()) {
    pending_ = std::move(bytes);  // coalesce: only the newest request matters
    return;
  }
  inFlight_ = std::move(bytes);
  flushWrite();
}

void WeatherClient::flushWrite() {
  asio::async_write(socket_, asio::buffer(inFlight_), [this](boost::system::error_code ec, std::size_t) {
    inFlight_.clear();
    if (ec) return;  // the read side notices and reconnects
    if (pending_) {
      inFlight_ = std::move(*pending_);
      pending_.reset();
      flushWrite();
    }
  });
}

}  // namespace sky::app
