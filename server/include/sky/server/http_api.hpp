// The weather server's HTTP API (JSON) on the server's own io_context:
//   GET  /healthz        "ok"
//   GET  /metrics        Prometheus text: changes applied and rejected, subscribers
//   GET  /api/state      the weather now (layers, pending ramps, clock)
//   GET  /api/events?limit=N   the newest N change events
//   POST /api/changes    a change request (api_json.hpp); needs the token
//   POST /api/scenario   a scenario file; needs the token
//   POST /api/metar      METAR reports previewed, or applied with the token
//                        (metar_api.hpp)
//   GET  /api/metar/stations  the station table with each station's latest
//                        applied report (metar_stations.hpp)
//   GET  /, /console/*   the operator console's files, when options.console is set
//                        (console_files.hpp)
//   GET  /api/renderers  the weather-stream subscribers and their cameras
//   GET  /api/conditions the weather at points (conditions_api.hpp)
//   GET  /api/wind       the wind field over an area at a height (wind_api.hpp)
//   GET  /api/ws         WebSocket upgrade: the console's live feed (console_feed.hpp)
//   POST /api/grib       a GRIB2 forecast (forecast_files.hpp); needs the token. Decoded
//                        off the io thread (worker_slots.hpp), answered once loaded
// Routes, their methods, body limits and token rules are one table
// (http_routes.hpp); each request goes through HttpExchange
// (http_exchange.hpp), which checks Host, Origin, the token and the body
// limit before the body is read. Every endpoint, with its JSON, status codes
// and caps, is in server/API.md. One request per connection; connections in
// flight are capped. Loopback unless configured otherwise.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "sky/core/result.hpp"
#include "sky/server/console_feed.hpp"
#include "sky/server/lightning_service.hpp"
#include "sky/server/grib_isolated.hpp"
#include "sky/server/http_guard.hpp"
#include "sky/server/http_routes.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/metar.hpp"
#include "sky/server/metar_stations.hpp"
#include "sky/server/rejections.hpp"
#include "sky/server/worker_slots.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class ConsoleFiles;
class HttpConnection;
class HttpExchange;
struct DecodedForecast;

// POST /api/grib decodes at most this many forecasts at once, off the io
// thread; another request meanwhile is answered 503. One: the weather holds
// one forecast, so a second decoding beside it would only replace it or be
// replaced, and each decode holds its files' bytes three times over (the
// request or the file, the decoder's reading, the store's copy) and a
// decoder process on a core the io thread needs.
inline constexpr std::size_t kGribDecodeSlots = 1;
// The Retry-After of that 503, s: the bundled NAM file (0.9 MB) decodes in
// about half a second on a 2-core machine, a regional forecast of a few MB
// in a few seconds.
inline constexpr int kGribBusyRetryAfter_s = 5;

struct HttpApiOptions {
  std::string listenAddress = "127.0.0.1";
  std::uint16_t port = 0;   // 0: ephemeral
  std::string token;        // empty: read-only (changes are refused)
  std::vector<Station> stations;  // METAR station table for POST /api/metar
  std::shared_ptr<const ConsoleFiles> console;  // null: no console pages
  std::string serverId = "skyshell-weatherd";  // in the WebSocket hello
  ConsoleFeedOptions feed;
  // Connections being read or answered at once (WebSocket clients are the
  // feed's and count there). 256: a few consoles and tools need a handful;
  // the cap keeps a flood of idle connections from using every descriptor.
  std::size_t maxConnections = 256;
  // Host names besides localhost, 127.0.0.1, [::1] and the listen address
  // that reach this server (no port), and more allowed Origins (as browsers
  // send them: "http://ops-console:8080"). See http_guard.hpp.
  std::vector<std::string> allowedHosts;
  std::vector<std::string> allowedOrigins;
  // POST /api/grib: the decoder, and the directory files may be named in
  // (empty: uploads only).
  GribDecoder gribDecoder;
  std::string gribDir;
  std::shared_ptr<spdlog::logger> log;
};

// What the API reads from the rest of the server (all called on the io
// thread). Accepted changes reach the stream through LiveWeather's listeners.
struct HttpApiHooks {
  std::function<std::size_t()> subscribers;      // for /metrics and the console's health
  std::function<std::string()> extraMetrics;     // more Prometheus text for /metrics (other inputs)
  std::function<nlohmann::json()> renderers;     // GET /api/renderers: the array
  Rejections* rejections = nullptr;              // counted here, shown in /metrics and health
  // POST /api/events (a flash now, sent to the renderers) and the newest
  // flashes for GET /api/events. Without them the API has no lightning.
  std::function<weather::LightningFlash(const FlashRequest&)> triggerLightning;
  std::function<std::vector<weather::LightningFlash>(std::size_t)> flashes;
  // GET /api/cluster: the NATS cluster's members (NatsWeather::cluster).
  // Without it (no --nats) the route answers {"nats": false, "members": []}.
  std::function<nlohmann::json()> cluster;
};

class HttpApi {
 public:
  static Result<std::unique_ptr<HttpApi>> create(boost::asio::io_context& io, HttpApiOptions options,
                                                 LiveWeather& weather, HttpApiHooks hooks);
  ~HttpApi();
  std::uint16_t port() const { return port_; }
  // Stops accepting, stops the GRIB decodes in flight (their decoder
  // processes killed, their threads joined), closes the connections in
  // flight and the console's WebSocket clients.
  void close();
  // The renderer list changed (a subscriber came, went or reported).
  void renderersChanged() { feed_.renderersChanged(); }
  ConsoleFeed& feed() { return feed_; }

  struct Counters {
    std::uint64_t requests = 0, applied = 0, rejected = 0, unauthorized = 0;
  };
  const Counters& counters() const { return counters_; }
  std::size_t connectionsInFlight() const;

 private:
  friend class HttpExchange;
  friend class HttpConnection;
  struct Registry;

  HttpApi(boost::asio::io_context& io, HttpApiOptions options, LiveWeather& weather, HttpApiHooks hooks);
  void accept();
  void admit(boost::asio::ip::tcp::socket socket);
  // Counts a refused input; logs the first of each reason (the rest are in /metrics).
  void refused(RejectReason reason, std::string_view detail);
  nlohmann::json healthJson() const;

  // The endpoints (http_endpoints.cpp), behind HttpExchange's checks. No
  // reply: the endpoint answers later, through request.later.
  std::optional<HttpReply> serve(Endpoint endpoint, const ApiRequest& request);
  HttpReply metrics();
  HttpReply events(std::string_view query);
  HttpReply lightning(const ApiRequest& request);
  HttpReply changes(const ApiRequest& request);
  HttpReply scenario(const ApiRequest& request);
  HttpReply metar(const ApiRequest& request);
  std::optional<HttpReply> grib(const ApiRequest& request);
  // A forecast decoded for POST /api/grib, applied and answered (io thread).
  HttpReply gribDecoded(Result<DecodedForecast> decoded);
  HttpReply gribRefused(int status, const std::string& detail);
  HttpReply unauthorized(const char* what);
  HttpReply consoleFile(std::string_view method, std::string_view path) const;
  // The answer to a WebSocket upgrade while the feed is full (503).
  HttpReply refuseFeed();

  HttpApiOptions options_;
  HostRules hostRules_;
  LiveWeather& weather_;
  HttpApiHooks hooks_;
  ConsoleFeed feed_;
  std::size_t weatherListener_ = 0;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer acceptRetry_;
  // Shared with the connections, which may outlive the API (their handlers
  // are destroyed with the io_context).
  std::shared_ptr<Registry> registry_;
  std::uint16_t port_ = 0;
  Counters counters_;
  MetarStationBoard metarStations_;  // the reports POST /api/metar applied
  // POST /api/grib's decodes. Closed (its threads joined) by close(), before
  // anything their results would touch goes.
  WorkerSlots gribDecodes_;
  std::array<bool, kRejectReasons> logged_{};
  bool acceptErrorLogged_ = false;
  bool closed_ = false;
};

}  // namespace sky::server
