// A subscriber's connection (see session.hpp).
#include "sky/server/session.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <span>
#include <type_traits>
#include <utility>
#include <variant>

#include <boost/asio/write.hpp>
#include <spdlog/spdlog.h>

namespace sky::server {

namespace asio = boost::asio;

namespace {

// How long a session that was sent an Error waits for the peer to close before
// closing itself. Closing at once could reset the connection while the Error
// is still unread (unread input makes the kernel send RST, not FIN).
constexpr std::chrono::seconds kDrainTimeout{2};

Frame encodeErrorFrame(const Error& error) {
  // StreamError codes are sky::ErrorCode values, so both ends read one enum.
  const stream::StreamError message{static_cast<std::uint16_t>(error.code), error.detail};
  return stream::encodeFrame(stream::encodeMessage(message));
}

}  // namespace

Session::Session(asio::ip::tcp::socket socket, std::uint64_t id, SessionHandler& handler,
                 spdlog::logger& log, std::chrono::milliseconds stallTimeout)
    : socket_(std::move(socket)),
      drainTimer_(socket_.get_executor()),
      stallTimer_(socket_.get_executor()),
      pauseTimer_(socket_.get_executor()),
      stallTimeout_(stallTimeout),
      id_(id),
      handler_(handler),
      log_(log) {
  boost::system::error_code ec;
  const auto remote = socket_.remote_endpoint(ec);
  peer_ = ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
}

template <class F>
void Session::guarded(const char* where, F&& f) {
  // The boundary of one peer: whatever a handler throws (a bad_alloc from a
  // hostile size, a bug) ends this session, never the server's io thread.
  try {
    f();
  } catch (const std::exception& e) {
    handler_.sessionFailed(*this, std::string(where) + ": " + e.what());
    close();
  } catch (...) {
    handler_.sessionFailed(*this, std::string(where) + ": unknown exception");
    close();
  }
}

void Session::start(Frame hello) {
  guarded("start", [&] {
    outbox_.pushControl(std::move(hello));
    writeNext();
    readMore();
  });
}

void Session::refuse(const Error& error) {
  guarded("refuse", [&] {
    state_ = State::ErrorQueued;
    outbox_.pushControl(encodeErrorFrame(error));
    writeNext();
    readMore();
  });
}

void Session::sendHeartbeat(const Frame& heartbeat) {
  if (state_ != State::Open) return;
  outbox_.setHeartbeat(heartbeat);
  writeNext();
}

void Session::sendEvent(const Frame& frame) {
  if (state_ != State::Open) return;
  outbox_.pushEvent(frame);
  writeNext();
}

std::vector<weather::SphericalCap> Session::areas() const {
  std::vector<weather::SphericalCap> out;
  for (const Area& a : areas_)
    if (a.subscription) out.push_back(a.subscription->area);
  return out;
}

void Session::weatherChanged() {
  if (state_ != State::Open) return;
  bool any = false;
  for (const Area& a : areas_)
    if (a.subscription) {
      outbox_.requestSnapshot(*a.subscription);
      any = true;
    }
  if (any) writeNext();
}

void Session::close() {
  if (state_ == State::Closed) return;
  state_ = State::Closed;
  boost::system::error_code ignored;
  socket_.close(ignored);
  drainTimer_.cancel();
  stallTimer_.cancel();
  pauseTimer_.cancel();
  handler_.sessionClosed(*this);
}

void Session::readMore() {
  socket_.async_read_some(asio::buffer(readBuffer_),
                          [self = shared_from_this()](const boost::system::error_code& ec,
                                                      std::size_t bytes) { self->onRead(ec, bytes); });
}

void Session::onRead(const boost::system::error_code& ec, std::size_t bytes) {
  guarded("read", [&] { handleRead(ec, bytes); });
}

void Session::handleRead(const boost::system::error_code& ec, std::size_t bytes) {
  if (state_ == State::Closed) return;
  if (ec) {
    if (ec == asio::error::eof)
      log_.info("event=session_eof session={} peer={}", id_, peer_);
    else
      log_.info("event=session_read_failed session={} peer={} error={:?}", id_, peer_, ec.message());
    close();
    return;
  }
  if (state_ == State::Open) decoder_.append(std::span<const std::uint8_t>(readBuffer_.data(), bytes));
  handleDecoded();
}

void Session::handleDecoded() {
  while (state_ == State::Open && !inputPaused_) {
    auto frame = decoder_.next();
    if (!frame) {
      protocolError(frame.error());
      break;
    }
    if (!*frame) break;
    auto message = stream::decodeMessage(**frame);
    if (!message) {
      protocolError(message.error());
      break;
    }
    handleMessage(*message);
  }
  // After an Error the rest of the input is read and discarded until EOF.
  if (state_ != State::Closed && !inputPaused_) readMore();
}

void Session::spendLightningBudget() {
  const auto now = std::chrono::steady_clock::now();
  const double elapsed_s = std::chrono::duration<double>(now - lightningBudgetAt_).count();
  lightningBudgetAt_ = now;
  lightningBudget_ = std::min(kLightningComputeBurst, lightningBudget_ + elapsed_s * kLightningComputeRate_perS) - 1;
  if (lightningBudget_ >= 0 || inputPaused_) return;
  inputPaused_ = true;
  handler_.inputPaused(*this);
  log_.debug("event=input_paused session={} peer={} reason=lightning_budget", id_, peer_);
  pauseTimer_.expires_after(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(-lightningBudget_ / kLightningComputeRate_perS)));
  pauseTimer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (ec || self->state_ == State::Closed) return;
    self->guarded("resume", [&] {
      self->inputPaused_ = false;
      self->handleDecoded();
    });
  });
}

void Session::handleMessage(const stream::Message& message) {
  if (const auto* subscribe = std::get_if<stream::Subscribe>(&message)) {
    log_.debug("event=subscribe session={} peer={} area={} lat_deg={} lon_deg={} radius_m={} level={}", id_, peer_,
               subscribe->areaIndex, subscribe->area.centerLat_deg, subscribe->area.centerLon_deg,
               subscribe->area.radius_m, subscribe->tileLevel);
    areas_[subscribe->areaIndex].subscription = *subscribe;  // decodeMessage checked the index
    outbox_.requestSnapshot(*subscribe);
    writeNext();
    handler_.rendererChanged(*this);
  } else if (const auto* report = std::get_if<stream::CameraReport>(&message)) {
    report_ = *report;
    reportAt_ = std::chrono::steady_clock::now();
    handler_.rendererChanged(*this);
  } else if (const auto* proposal = std::get_if<stream::HostClock>(&message)) {
    hostClockHost_ = proposal->host;
    handler_.hostClockProposed(*this, *proposal);
  } else if (const auto* asked = std::get_if<stream::LightningRequest>(&message)) {
    if (handler_.lightningRequested(*this, *asked)) spendLightningBudget();
  } else if (const auto* unknown = std::get_if<stream::UnknownKind>(&message)) {
    // A newer client of our major version: what we do not know, we ignore.
    if (!unknownKindLogged_)
      log_.info("event=unknown_kind_ignored session={} peer={} body_type={}", id_, peer_,
                unknown->bodyType);
    unknownKindLogged_ = true;
  } else if (std::holds_alternative<stream::Heartbeat>(message)) {
    // A client's keep-alive: nothing to answer.
  } else if (const auto* error = std::get_if<stream::StreamError>(&message)) {
    log_.info("event=client_error session={} peer={} code={} detail={:?}; closing", id_, peer_, error->code,
              error->detail);
    close();
  } else {
    protocolError(Error{ErrorCode::Unsupported, std::string(stream::kindName(message)) +
                                                    " is sent by servers, not clients"});
  }
}

RendererInfo Session::info(std::chrono::steady_clock::time_point now) const {
  RendererInfo out{id_, peer_, std::nullopt, report_, 0};
  // The console shows the detailed area, the one around the camera.
  if (areas_[0].subscription) out.area = areas_[0].subscription->area;
  if (report_) out.lastReportAge_s = std::max(0.0, std::chrono::duration<double>(now - reportAt_).count());
  return out;
}

void Session::protocolError(const Error& error) {
  // The handler logs the first of each kind; every one is here at debug.
  log_.debug("event=stream_malformed session={} peer={} detail={:?}; sending Error and closing", id_, peer_,
             describe(error));
  handler_.protocolRejected(*this, error);
  state_ = State::ErrorQueued;
  outbox_.dropWeather();
  outbox_.pushControl(encodeErrorFrame(error));
  writeNext();
}

void Session::writeNext() {
  if (writeInFlight_ || state_ == State::Closed || state_ == State::Draining) return;
  auto item = outbox_.takeNext();
  if (!item) {
    if (state_ == State::ErrorQueued) beginDrain();
    return;
  }
  std::visit(
      [this](auto&& next) {
        if constexpr (std::is_same_v<std::decay_t<decltype(next)>, stream::Subscribe>)
          writing_ = weatherFrame(next);
        else
          writing_ = std::move(next);
      },
      std::move(*item));
  writeInFlight_ = true;
  const std::uint64_t generation = ++writeGeneration_;
  asio::async_write(socket_, asio::buffer(writing_),
                    [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                      self->guarded("write", [&] { self->onWritten(ec); });
                    });
  stallTimer_.expires_after(stallTimeout_);
  stallTimer_.async_wait([self = shared_from_this(), generation](const boost::system::error_code& ec) {
    self->guarded("stall timer", [&] { self->onStallTimer(ec, generation); });
  });
}

void Session::onStallTimer(const boost::system::error_code& ec, std::uint64_t generation) {
  // Cancelled, superseded by a later write, or that write has completed.
  if (ec || generation != writeGeneration_ || !writeInFlight_ || state_ == State::Closed) return;
  log_.warn("event=subscriber_stalled session={} peer={} frame_bytes={} stall_ms={}; dropped", id_, peer_,
            writing_.size(), stallTimeout_.count());
  handler_.sessionStalled(*this);
  close();
}

Frame Session::weatherFrame(const stream::Subscribe& request) {
  std::shared_ptr<const AreaSnapshot> now = handler_.snapshotFor(request);
  Area& area = areas_[request.areaIndex];
  const std::shared_ptr<const Frame> frame = handler_.frameFor(area.peerHolds, now);
  area.peerHolds = std::move(now);
  return *frame;
}

void Session::onWritten(const boost::system::error_code& ec) {
  writeInFlight_ = false;
  stallTimer_.cancel();
  if (state_ == State::Closed) return;
  if (ec) {
    log_.info("event=session_write_failed session={} peer={} error={:?}", id_, peer_, ec.message());
    close();
    return;
  }
  handler_.frameSent(writing_.size());
  writeNext();
}

void Session::beginDrain() {
  state_ = State::Draining;
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_send, ignored);
  drainTimer_.expires_after(kDrainTimeout);
  drainTimer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (!ec) self->guarded("drain timer", [&] { self->close(); });
  });
}

}  // namespace sky::server
