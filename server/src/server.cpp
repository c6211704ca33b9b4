// The weather stream server (see server.hpp).
#include "sky/server/server.hpp"

#include <algorithm>
#include <csignal>
#include <utility>

#include <boost/asio/post.hpp>
#include <spdlog/spdlog.h>

#include "sky/core/assert.hpp"
#include "sky/server/metrics_text.hpp"
#include "sky/stream/framing.hpp"

namespace sky::server {

namespace asio = boost::asio;
using asio::ip::tcp;

namespace {

// Pause before accepting again after a failed accept (e.g. out of file
// descriptors: the pending connection stays in the backlog, so accept fails
// again at once). The pause doubles from the first to the longest while the
// failures go on, and resets after a success: a persistent EMFILE costs a
// few accept calls a second, not a core, and a freed descriptor is used
// within a second.
constexpr std::chrono::milliseconds kAcceptRetryFirst{10};
constexpr std::chrono::milliseconds kAcceptRetryLongest{1000};
// Refused connections (past maxSubscribers) waiting for their Error to go
// out; past this many, further ones are closed without a word, so a flood of
// connections cannot hold descriptors for the drain time.
constexpr std::size_t kMaxRefusing = 64;
// Kinds of warning logged once each; past this many distinct kinds (the
// texts are bounded, this is a second guard), only counters grow.
constexpr std::size_t kMaxWarnedKinds = 256;

// The kind of an error detail, for logging each kind once: its text up to the
// first digit (indices and values differ between occurrences).
std::string kindOf(const std::string& detail) {
  const auto digit = detail.find_first_of("0123456789");
  return detail.substr(0, std::min<std::size_t>(digit, 80));
}
// Longest sleep of the timeline timer: the weather clock is re-read at least
// this often, so an entry is never late by more than the timer's own slack.
constexpr std::chrono::seconds kMaxTimelineSleep{60};

}  // namespace

Result<std::unique_ptr<Server>> Server::create(ServerOptions options, WeatherState state) {
  SKY_ASSERT(options.heartbeatInterval.count() > 0);
  std::unique_ptr<Server> server(new Server(std::move(options), std::move(state)));
  if (auto r = server->listen(); !r) return tl::unexpected(r.error());
  if (server->options_.handleSignals) {
    // From here, not from run(): a SIGTERM that comes while the main still
    // sets up (its port files already written) waits for run() and shuts
    // down cleanly, instead of killing the process by the default action.
    server->signals_.emplace(server->io_, SIGINT, SIGTERM);
    server->signals_->async_wait([s = server.get()](const boost::system::error_code& ec, int signal) {
      if (ec) return;
      s->log_->info("event=shutdown signal={}", signal);
      s->shutdown();
    });
  }
  return server;
}

Server::Server(ServerOptions options, WeatherState state)
    : options_(std::move(options)),
      // A logger without sinks: the library stays silent unless a main asks.
      log_(options_.log ? options_.log : std::make_shared<spdlog::logger>("sky_server")),
      weather_(state.scenario, state.wallStart, options_.wallNow,
               [] {
                 return std::chrono::duration_cast<std::chrono::milliseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                     .count();
               }),
      acceptor_(io_),
      acceptRetry_(io_),
      heartbeat_(io_),
      timelineTimer_(io_),
      // A covering for every area the subscribers may hold at once, and the
      // lightning's own.
      tileCache_(std::max(TileCache::kDefaultMaxCoverings,
                          options_.maxSubscribers * stream::kMaxAreas + kMaxLightningAreas)),
      lightning_(options_.lightning, &tileCache_) {
  // Every accepted change, from whichever input, reaches every subscriber;
  // it may have moved the clock or brought a new timeline.
  weather_.addListener([this](const ChangeEvent&) {
    weatherChanged();
    armTimeline();
  });
}

Server::~Server() = default;

Result<void> Server::listen() {
  boost::system::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options_.listenAddress, ec);
  if (ec)
    return fail(ErrorCode::InvalidArgument,
                "listen address '" + options_.listenAddress + "': " + ec.message());
  const tcp::endpoint endpoint(address, options_.port);
  const std::string where = "listen " + options_.listenAddress + ":" + std::to_string(options_.port);
  if (acceptor_.open(endpoint.protocol(), ec); ec)
    return fail(ErrorCode::Io, where + ": open: " + ec.message());
  if (acceptor_.set_option(tcp::acceptor::reuse_address(true), ec); ec)
    return fail(ErrorCode::Io, where + ": SO_REUSEADDR: " + ec.message());
  if (acceptor_.bind(endpoint, ec); ec) return fail(ErrorCode::Io, where + ": bind: " + ec.message());
  if (acceptor_.listen(asio::socket_base::max_listen_connections, ec); ec)
    return fail(ErrorCode::Io, where + ": listen: " + ec.message());
  port_ = acceptor_.local_endpoint().port();
  return {};
}

void Server::run() {
  accept();
  scheduleHeartbeat();
  armTimeline();
  log_->info("event=serving layers={} clock_s={:.3f} rate={}", weather_.layersAt(clockNow()).size(),
             clockNow(), weather_.clock().rate());
  // The last boundary: every input has its own (session.cpp, the CIGI input,
  // the HTTP API); an exception that still escapes a handler is caught here
  // and run() is called again, which asio allows after a handler threw.
  for (;;) {
    try {
      io_.run();
      break;
    } catch (const std::exception& e) {
      handlerFailed(e.what());
    } catch (...) {
      handlerFailed("unknown exception");
    }
  }
  log_->info("event=stopped");
}

void Server::handlerFailed(const std::string& what) {
  streamCounters_.handlerExceptions.fetch_add(1, std::memory_order_relaxed);
  rejections_.count(RejectReason::HandlerFailed);
  warnOnce("handler " + kindOf(what), "event=handler_exception detail=\"" + what + "\"; serving on");
}

void Server::warnOnce(const std::string& kind, const std::string& message) {
  if (warned_.size() >= kMaxWarnedKinds || !warned_.insert(kind).second) return;
  log_->warn("{} (further ones of this kind are only counted)", message);
}

void Server::stop() {
  asio::post(io_, [this] { shutdown(); });
}

void Server::shutdown() {
  if (stopped_) return;
  stopped_ = true;
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  acceptRetry_.cancel();
  heartbeat_.cancel();
  timelineTimer_.cancel();
  if (signals_) signals_->cancel(ignored);
  registry_.closeAll();
  refused_.closeAll();
  for (const auto& f : onShutdown_) f();
}

void Server::accept() {
  acceptor_.async_accept([this](const boost::system::error_code& ec, tcp::socket socket) {
    onAccept(ec, std::move(socket));
  });
}

void Server::onAccept(const boost::system::error_code& ec, tcp::socket socket) {
  if (stopped_) return;
  if (ec) {
    streamCounters_.acceptFailures.fetch_add(1, std::memory_order_relaxed);
    acceptDelay_ = std::clamp(acceptDelay_ * 2, kAcceptRetryFirst, kAcceptRetryLongest);
    warnOnce("accept " + ec.message(), "event=accept_failed error=\"" + ec.message() + "\"; retrying with back-off up to " +
                                           std::to_string(kAcceptRetryLongest.count()) + " ms");
    acceptRetry_.expires_after(acceptDelay_);
    acceptRetry_.async_wait([this](const boost::system::error_code& e) {
      if (!e && !stopped_) accept();
    });
    return;
  }
  acceptDelay_ = std::chrono::milliseconds{0};
  boost::system::error_code ignored;
  // Frames are whole messages: send each as soon as it is written.
  socket.set_option(tcp::no_delay(true), ignored);
  if (registry_.size() >= options_.maxSubscribers) {
    rejections_.count(RejectReason::SubscriberCap);
    if (refused_.size() >= kMaxRefusing) {
      socket.close(ignored);  // already telling enough others; this one gets no Error
    } else {
      auto session = std::make_shared<Session>(std::move(socket), nextSessionId_++,
                                               static_cast<SessionHandler&>(*this), *log_, options_.stallTimeout);
      warnOnce("subscriber cap", "event=subscriber_refused peer=" + session->peer() + " subscribers=" +
                                     std::to_string(registry_.size()) + " cap=" +
                                     std::to_string(options_.maxSubscribers));
      refused_.add(session);
      session->refuse(Error{ErrorCode::TooLarge, "server full: " + std::to_string(registry_.size()) +
                                                     " subscribers, at most " +
                                                     std::to_string(options_.maxSubscribers)});
    }
    accept();
    return;
  }
  auto session = std::make_shared<Session>(std::move(socket), nextSessionId_++,
                                           static_cast<SessionHandler&>(*this), *log_, options_.stallTimeout);
  log_->info("event=session_connected session={} peer={} subscribers={}", session->id(), session->peer(),
             registry_.size() + 1);
  registry_.add(session);
  const stream::Hello hello{stream::kProtocolVersion, options_.serverId, clockNow(), weather_.clock().rate(),
                            stream::kFeatureCameraReports | stream::kFeatureAreas | stream::kFeatureHostClock |
                                stream::kFeatureTileDrift | stream::kFeatureLightningRequests};
  session->start(stream::encodeFrame(stream::encodeMessage(hello)));
  renderersChanged();
  accept();
}

void Server::scheduleHeartbeat() {
  heartbeat_.expires_after(options_.heartbeatInterval);
  heartbeat_.async_wait([this](const boost::system::error_code& ec) {
    if (ec || stopped_) return;
    const Frame frame = stream::encodeFrame(stream::encodeMessage(stream::Heartbeat{clockNow()}));
    registry_.forEach([&frame](Session& s) { s.sendHeartbeat(frame); });
    // While a change ramps, subscribers follow it at the heartbeat's pace.
    if (weather_.changing(clockNow())) weatherChanged();
    drawLightning();
    scheduleHeartbeat();
  });
}

void Server::drawLightning() {
  std::vector<weather::SphericalCap> areas;
  registry_.forEachConst([&areas](const Session& s) {
    for (const weather::SphericalCap& a : s.areas()) areas.push_back(a);
  });
  const auto before = lightning_.counters();
  const std::vector<weather::LightningFlash> flashes = lightning_.tick(weather_, clockNow(), areas);
  streamCounters_.flashesDrawn.fetch_add(lightning_.counters().drawn - before.drawn, std::memory_order_relaxed);
  streamCounters_.flashesCapped.fetch_add(lightning_.counters().dropped - before.dropped, std::memory_order_relaxed);
  sendFlashes(flashes);
}

weather::LightningFlash Server::triggerLightning(const FlashRequest& request) {
  const weather::LightningFlash flash = lightning_.trigger(weather_, clockNow(), request);
  streamCounters_.flashesTriggered.fetch_add(1, std::memory_order_relaxed);
  log_->info("event=lightning_triggered kind={} lat_deg={:.5f} lon_deg={:.5f} clock_s={:.3f}",
             weather::toString(flash.kind), flash.lat_deg, flash.lon_deg, flash.time_s);
  sendFlashes({flash});
  return flash;
}

void Server::sendFlashes(const std::vector<weather::LightningFlash>& flashes) {
  if (flashes.empty()) return;
  registry_.forEach([&](Session& s) {
    stream::Lightning message{clockNow(), {}, std::nullopt};
    const std::vector<weather::SphericalCap> areas = s.areas();
    for (const weather::LightningFlash& f : flashes)
      if (std::any_of(areas.begin(), areas.end(), [&](const auto& a) { return flashReaches(a, f); }))
        message.flashes.push_back(f);
    if (message.flashes.empty()) return;
    sendEventCounted(s, stream::encodeFrame(stream::encodeMessage(message)));
  });
}

void Server::armTimeline() {
  if (stopped_) return;
  const auto next = weather_.nextTimelineAt();
  if (!next) {
    timelineTimer_.cancel();
    return;
  }
  const double now = clockNow(), rate = weather_.clock().rate();
  std::chrono::steady_clock::duration wait = std::chrono::steady_clock::duration::zero();
  if (*next > now) {
    if (rate <= 0) {
      timelineTimer_.cancel();  // frozen: a clock change arms it again
      return;
    }
    wait = std::min<std::chrono::steady_clock::duration>(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>((*next - now) / rate)),
        kMaxTimelineSleep);
  }
  timelineTimer_.expires_after(wait);
  timelineTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec && !stopped_) fireTimeline();
  });
}

void Server::fireTimeline() {
  for (const auto& o : weather_.runTimeline()) {
    if (o.result) {
      log_->info("event=change_applied source=timeline sequence={} at_s={:.1f} summary={:?}", o.result->sequence,
                 o.at_s, o.result->summary);
    } else {
      rejections_.count(RejectReason::TimelineRefused);
      log_->warn("event=timeline_refused at_s={:.1f} detail={:?} (dropped)", o.at_s,
                 o.result.error().detail);
    }
  }
  armTimeline();
}

double Server::clockNow() const { return weather_.clock().at(options_.wallNow()); }

void Server::weatherChanged() {
  areaFrames_.clear(std::chrono::steady_clock::now());
  registry_.forEach([](Session& s) { s.weatherChanged(); });
}

void Server::weatherReplaced() {
  weatherChanged();
  armTimeline();
}

std::shared_ptr<const AreaSnapshot> Server::snapshotFor(const stream::Subscribe& request) {
  return areaFrames_.snapshot(request, std::chrono::steady_clock::now(), [&] {
    const double clock_s = clockNow();
    const auto field = weather_.fieldAt(clock_s);
    BuiltSnapshot built =
        buildSnapshotWithGenerations(request, weather_.layersAt(clock_s), clock_s, options_.maxCellsPerSnapshot,
                                     weather_.regionsAt(clock_s), &tileCache_, field.get());
    log_->debug("event=snapshot level={} asked={} tiles={}", built.snapshot.tileLevel, request.tileLevel,
                tileCount(built));
    return built;
  });
}

std::shared_ptr<const Frame> Server::frameFor(const std::shared_ptr<const AreaSnapshot>& held,
                                              const std::shared_ptr<const AreaSnapshot>& now) {
  return areaFrames_.frame(held, now);
}

void Server::frameSent(std::size_t bytes) {
  streamCounters_.frames.fetch_add(1, std::memory_order_relaxed);
  streamCounters_.bytes.fetch_add(bytes, std::memory_order_relaxed);
}

void Server::sessionStalled(Session&) { streamCounters_.stalledDropped.fetch_add(1, std::memory_order_relaxed); }

std::string Server::streamMetrics() const {
  std::string m;
  auto line = [&m](const char* name, const char* help, std::uint64_t v) { appendMetric(m, name, "counter", help, v); };
  line("skyshell_stream_frames_total", "weather stream frames sent", streamCounters_.frames.load());
  line("skyshell_stream_bytes_total", "weather stream bytes sent", streamCounters_.bytes.load());
  line("skyshell_subscribers_dropped_total", "subscribers dropped for not reading",
       streamCounters_.stalledDropped.load());
  line("skyshell_accept_failures_total", "stream accept() calls that failed (retried with back-off)",
       streamCounters_.acceptFailures.load());
  line("skyshell_handler_exceptions_total", "exceptions caught by the io loop's last boundary",
       streamCounters_.handlerExceptions.load());
  line("skyshell_lightning_flashes_total", "lightning flashes drawn by the storm process",
       streamCounters_.flashesDrawn.load());
  line("skyshell_lightning_triggered_total", "lightning flashes asked for (POST /api/events)",
       streamCounters_.flashesTriggered.load());
  line("skyshell_lightning_capped_total", "flashes past the per-tick cap, not sent",
       streamCounters_.flashesCapped.load());
  line("skyshell_lightning_requests_total", "renderers' requests for the flashes of an interval (headless replays)",
       streamCounters_.lightningRequests.load());
  line("skyshell_lightning_request_cells_total", "lightning requests that computed their storm cells (the costly ones)",
       streamCounters_.lightningCellsComputed.load());
  line("skyshell_lightning_input_pauses_total", "times a session's input waited for its lightning budget",
       streamCounters_.lightningInputPauses.load());
  line("skyshell_host_clock_proposals_total", "CIGI host clock estimates proposed by renderers",
       streamCounters_.hostClockProposals.load());
  line("skyshell_host_clock_changes_total", "times a host's clock offset was set anew (first channel, or a jump)",
       streamCounters_.hostClockChanges.load());
  line("skyshell_stream_events_dropped_total", "event frames dropped for subscribers not reading",
       streamCounters_.eventsDropped.load());
  return m;
}

void Server::sessionClosed(Session& session) {
  if (refused_.contains(session)) {
    refused_.remove(session);
    return;
  }
  log_->info("event=session_closed session={} peer={} subscribers={}", session.id(), session.peer(),
             registry_.size() - 1);
  registry_.remove(session);
  renderersChanged();
}

void Server::rendererChanged(Session&) { renderersChanged(); }

void Server::sendEventCounted(Session& session, const Frame& frame) {
  const std::uint64_t droppedBefore = session.droppedEvents();
  session.sendEvent(frame);
  streamCounters_.eventsDropped.fetch_add(session.droppedEvents() - droppedBefore, std::memory_order_relaxed);
}

void Server::hostClockProposed(Session& session, const stream::HostClock& proposal) {
  streamCounters_.hostClockProposals.fetch_add(1, std::memory_order_relaxed);
  const HostClockAnswer answer = hostClocks_.propose(proposal);
  const Frame frame = stream::encodeFrame(stream::encodeMessage(answer.held));
  if (!answer.changed) {
    sendEventCounted(session, frame);
    return;
  }
  streamCounters_.hostClockChanges.fetch_add(1, std::memory_order_relaxed);
  const auto now = std::chrono::steady_clock::now();
  const bool loud = now - hostClockLoggedAt_ >= std::chrono::seconds(1);
  if (loud) hostClockLoggedAt_ = now;
  log_->log(loud ? spdlog::level::info : spdlog::level::debug,
            "event=host_clock host={:?} offset_s={:.6f} rate={} from_session={}", answer.held.host,
            answer.held.offset_s, answer.held.rate, session.id());
  registry_.forEach([&](Session& s) {
    if (s.hostClockHost() == answer.held.host) sendEventCounted(s, frame);
  });
}

bool Server::lightningRequested(Session& session, const stream::LightningRequest& request) {
  const std::vector<weather::SphericalCap> areas = session.areas();
  bool computed = false;
  stream::Lightning answer{clockNow(), lightning_.drawIn(weather_, request.from_s, request.to_s, areas, &computed),
                           request.to_s};
  streamCounters_.lightningRequests.fetch_add(1, std::memory_order_relaxed);
  if (computed) streamCounters_.lightningCellsComputed.fetch_add(1, std::memory_order_relaxed);
  sendEventCounted(session, stream::encodeFrame(stream::encodeMessage(answer)));
  return computed;
}

void Server::inputPaused(Session& session) {
  streamCounters_.lightningInputPauses.fetch_add(1, std::memory_order_relaxed);
  warnOnce("lightning budget", "event=input_paused session=" + std::to_string(session.id()) + " peer=" +
                                   session.peer() + " reason=\"LightningRequests over storm cells past " +
                                   std::to_string(static_cast<int>(kLightningComputeRate_perS)) +
                                   " computations a second\"; its input waits");
}

void Server::protocolRejected(Session& session, const Error& error) {
  rejections_.count(RejectReason::StreamMalformed);
  warnOnce("stream " + kindOf(error.detail), "event=stream_malformed session=" + std::to_string(session.id()) +
                                                 " peer=" + session.peer() + " detail=\"" + describe(error) +
                                                 "\"; sent Error, closing");
}

void Server::sessionFailed(Session& session, const std::string& what) {
  rejections_.count(RejectReason::HandlerFailed);
  warnOnce("session " + kindOf(what), "event=session_exception session=" + std::to_string(session.id()) +
                                          " peer=" + session.peer() + " detail=\"" + what + "\"; closed");
}

void Server::renderersChanged() {
  // Not while shutting down: the listeners' owners may be closing too.
  if (stopped_) return;
  for (const auto& f : onRenderersChanged_) f();
}

std::vector<RendererInfo> Server::renderers() const {
  std::vector<RendererInfo> out;
  const auto now = std::chrono::steady_clock::now();
  registry_.forEachConst([&](const Session& s) { out.push_back(s.info(now)); });
  return out;
}

std::vector<weather::SphericalCap> Server::subscribedAreas() const {
  std::vector<weather::SphericalCap> out;
  registry_.forEachConst([&](const Session& s) {
    for (const auto& a : s.areas()) out.push_back(a);
  });
  return out;
}

}  // namespace sky::server
