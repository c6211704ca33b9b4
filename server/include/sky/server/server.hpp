// The weather stream server: owns the io_context (one, run on one thread), the
// acceptor, the heartbeat timer, optional SIGINT/SIGTERM handling and the
// session registry. Shuts down by cancelling its work, so run() returns.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <atomic>
#include <functional>
#include <vector>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "sky/core/result.hpp"
#include "sky/server/area_frames.hpp"
#include "sky/server/session.hpp"
#include "sky/server/session_registry.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/host_clocks.hpp"
#include "sky/server/lightning_service.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/rejections.hpp"
#include "sky/server/weather_state.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

// Subscribers one server serves at once. One cockpit has one to six display
// channels, each one connection; 64 serves ten such cockpits from one server
// and bounds what a flood of connections costs (each holds a socket, a read
// buffer of 64 KiB and its areas' snapshots).
inline constexpr std::size_t kDefaultMaxSubscribers = 64;
// The most --max-subscribers may ask for: the tile cache holds areas for
// each, and 4096 renderers is past what one process serves (512 takes 70 %
// of a core in a regional storm: docs/weather-server-scaling.md).
inline constexpr std::size_t kMaxSubscribersOption = 4096;

struct ServerOptions {
  std::string listenAddress = "127.0.0.1";  // loopback unless a deployment opens it
  std::uint16_t port = 0;                   // 0: an ephemeral port (see Server::port)
  std::chrono::milliseconds heartbeatInterval{1000};  // > 0
  std::string serverId = "skyshell-weatherd";         // sent in Hello
  std::size_t maxCellsPerSnapshot = kDefaultMaxCells;
  bool handleSignals = true;  // SIGINT/SIGTERM stop the server (off in tests); caught from create() on
  // A subscriber whose frame has not gone out in this long has stopped
  // reading and is dropped (its weather was coalesced until then).
  std::chrono::milliseconds stallTimeout{10000};
  // A connection past this many subscribers is sent an Error (TooLarge,
  // "server full") and closed.
  std::size_t maxSubscribers = kDefaultMaxSubscribers;
  LightningOptions lightning;  // the flash process (lightning_service.hpp)
  std::function<WallClock::time_point()> wallNow = [] { return WallClock::now(); };
  std::shared_ptr<spdlog::logger> log;  // null: log nothing
};

class Server final : private SessionHandler {
 public:
  // Binds and listens. Errors: InvalidArgument (listen address), Io (bind).
  static Result<std::unique_ptr<Server>> create(ServerOptions options, WeatherState state);

  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;
  ~Server();

  std::uint16_t port() const { return port_; }
  boost::asio::io_context& io() { return io_; }
  LiveWeather& weather() { return weather_; }
  // Every subscriber gets fresh weather for its area (call on the io
  // thread). Every change the LiveWeather accepts does this already.
  void weatherChanged();
  // The weather was replaced from outside its inputs (a follower folding its
  // leader's log, a server taking the lead): every subscriber gets fresh
  // weather and the timeline timer is set anew. Call on the io thread.
  void weatherReplaced();
  // Call on the io thread (the registry is its own).
  std::size_t subscribers() const { return registry_.size(); }
  // Every subscriber as the console sees it (area, last camera report), by
  // session id. Call on the io thread.
  std::vector<RendererInfo> renderers() const;
  // Every area every subscriber asked for (a relay takes the weather of
  // these: state_cells.hpp). Call on the io thread.
  std::vector<weather::SphericalCap> subscribedAreas() const;
  // Runs on the io thread whenever a subscriber connects, subscribes, reports
  // its camera or goes away (the console coalesces these).
  void onRenderersChanged(std::function<void()> f) { onRenderersChanged_.push_back(std::move(f)); }
  // Refused inputs by reason, shared by every input of this server.
  Rejections& rejections() { return rejections_; }
  const Rejections& rejections() const { return rejections_; }
  // Stream counters (readable from any thread, for /metrics and tests).
  struct StreamCounters {
    std::atomic<std::uint64_t> frames{0}, bytes{0}, stalledDropped{0};
    std::atomic<std::uint64_t> acceptFailures{0};  // accept() calls that failed (e.g. EMFILE)
    std::atomic<std::uint64_t> handlerExceptions{0};  // exceptions that reached run() (the last boundary)
    // Lightning flashes drawn by the process, asked for, left out by the
    // per-tick cap, and event frames dropped for subscribers not reading.
    std::atomic<std::uint64_t> flashesDrawn{0}, flashesTriggered{0}, flashesCapped{0}, eventsDropped{0};
    // Host clock proposals taken, and how many set a host's offset anew.
    std::atomic<std::uint64_t> hostClockProposals{0}, hostClockChanges{0};
    // LightningRequests answered, those that computed storm cells, and the
    // times a session's input waited for its budget (session.hpp).
    std::atomic<std::uint64_t> lightningRequests{0}, lightningCellsComputed{0}, lightningInputPauses{0};
  };
  const StreamCounters& streamCounters() const { return streamCounters_; }
  // Prometheus text of the stream counters.
  std::string streamMetrics() const;
  // A flash now at the request's place, sent to every subscriber it
  // reaches, and the newest flashes (oldest first). Call on the io thread.
  weather::LightningFlash triggerLightning(const FlashRequest& request);
  std::vector<weather::LightningFlash> recentFlashes(std::size_t limit) const { return lightning_.recent(limit); }
  // Runs on the io thread when the server shuts down: whatever else lives on
  // its io_context (the HTTP API, the CIGI input) closes there too, so run()
  // can return. Every function added runs, in the order added.
  void onShutdown(std::function<void()> f) { onShutdown_.push_back(std::move(f)); }

  // Serves until stop() or a signal. Call from one thread only. An exception
  // a handler throws past every inner boundary is caught here, counted
  // (handler_failed), logged, and the loop runs on: one bad input must not
  // end the process.
  void run();
  // Asks the server to shut down; safe from any thread and from signal-free
  // tests. run() returns once every session is closed.
  void stop();

 private:
  Server(ServerOptions options, WeatherState state);
  Result<void> listen();
  void accept();
  void onAccept(const boost::system::error_code& ec, boost::asio::ip::tcp::socket socket);
  void scheduleHeartbeat();
  // The flash process's flashes since the last call, sent to the
  // subscribers they reach.
  void drawLightning();
  void sendFlashes(const std::vector<weather::LightningFlash>& flashes);
  // Queues an event frame for a session, counting what its full queue drops.
  void sendEventCounted(Session& session, const Frame& frame);
  // Sets the timeline timer for the next scenario timeline entry, by the
  // weather clock's rate (a frozen clock waits for the next clock change).
  void armTimeline();
  void fireTimeline();
  void shutdown();
  double clockNow() const;

  std::shared_ptr<const AreaSnapshot> snapshotFor(const stream::Subscribe& request) override;
  std::shared_ptr<const Frame> frameFor(const std::shared_ptr<const AreaSnapshot>& held,
                                        const std::shared_ptr<const AreaSnapshot>& now) override;
  void sessionClosed(Session& session) override;
  void frameSent(std::size_t bytes) override;
  void sessionStalled(Session& session) override;
  void rendererChanged(Session& session) override;
  void hostClockProposed(Session& session, const stream::HostClock& proposal) override;
  bool lightningRequested(Session& session, const stream::LightningRequest& request) override;
  void inputPaused(Session& session) override;
  void protocolRejected(Session& session, const Error& error) override;
  void sessionFailed(Session& session, const std::string& what) override;
  void renderersChanged();
  // Logs `message` at warn the first time its kind is seen; later ones of
  // the kind are only counted (a hostile peer must not flood the log).
  void warnOnce(const std::string& kind, const std::string& message);
  void handlerFailed(const std::string& what);

  // Member order is destruction order in reverse: the io_context goes last,
  // destroying handlers (and the sessions they keep alive) after the rest.
  boost::asio::io_context io_;
  ServerOptions options_;
  std::shared_ptr<spdlog::logger> log_;
  LiveWeather weather_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer acceptRetry_;
  boost::asio::steady_timer heartbeat_;
  boost::asio::steady_timer timelineTimer_;
  std::optional<boost::asio::signal_set> signals_;
  SessionRegistry registry_;
  // Connections past maxSubscribers, being sent their Error: not subscribers.
  SessionRegistry refused_;
  std::set<std::string> warned_;  // kinds warnOnce has logged
  std::chrono::milliseconds acceptDelay_{0};  // current back-off after failed accepts
  StreamCounters streamCounters_;
  Rejections rejections_;
  std::vector<std::function<void()>> onRenderersChanged_;
  TileCache tileCache_;
  AreaFrames areaFrames_;  // cleared at every change (weatherChanged)
  LightningService lightning_;
  HostClocks hostClocks_;
  // When a host clock change was last logged at info: a peer that sends
  // offsets far apart changes it at every proposal, and must not flood the
  // log (the counter counts them all).
  std::chrono::steady_clock::time_point hostClockLoggedAt_{};
  std::uint16_t port_ = 0;
  std::uint64_t nextSessionId_ = 1;
  bool stopped_ = false;
  std::vector<std::function<void()>> onShutdown_;  // in the order added
};

}  // namespace sky::server
