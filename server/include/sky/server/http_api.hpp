// The weather server's HTTP API (JSON) on the server's own io_context:
//   GET  /healthz        "ok"
//   GET  /metrics        Prometheus text: changes applied and rejected, subscribers
//   GET  /api/state      the weather now (layers, pending ramps, clock)
//   GET  /api/events?limit=N   the newest N change events
//   POST /api/changes    a change request (api_json.hpp); needs
//                        "Authorization: Bearer <token>"; 200 once applied,
//                        400 {"error": ...} naming the field, 401 without the token
//   POST /api/metar      METAR reports previewed, or applied with the token
//                        (metar_api.hpp)
//   GET  /, /console/*   the operator console's files, when options.console is set
//                        (console_files.hpp)
//   GET  /api/renderers  the weather-stream subscribers and their cameras
//   GET  /api/ws         WebSocket upgrade: the console's live feed (console_feed.hpp)
// Every endpoint, with its JSON, is in server/API.md.
// One request per connection (Connection: close); bodies over 64 KiB and
// clients slower than 10 s are dropped. Loopback unless configured otherwise.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "sky/core/result.hpp"
#include "sky/server/console_feed.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/metar.hpp"
#include "sky/server/rejections.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class ConsoleFiles;

struct HttpApiOptions {
  std::string listenAddress = "127.0.0.1";
  std::uint16_t port = 0;   // 0: ephemeral
  std::string token;        // empty: read-only (changes are refused)
  std::vector<Station> stations;  // METAR station table for POST /api/metar
  std::shared_ptr<const ConsoleFiles> console;  // null: no console pages
  std::string serverId = "skyshell-weatherd";  // in the WebSocket hello
  ConsoleFeedOptions feed;
  std::shared_ptr<spdlog::logger> log;
};

// What the API reads from the rest of the server (all called on the io
// thread). Accepted changes reach the stream through LiveWeather's listeners.
struct HttpApiHooks {
  std::function<std::size_t()> subscribers;      // for /metrics and the console's health
  std::function<std::string()> extraMetrics;     // more Prometheus text for /metrics (other inputs)
  std::function<nlohmann::json()> renderers;     // GET /api/renderers: the array
  Rejections* rejections = nullptr;              // counted here, shown in /metrics and health
};

class HttpApi {
 public:
  static Result<std::unique_ptr<HttpApi>> create(boost::asio::io_context& io, HttpApiOptions options,
                                                 LiveWeather& weather, HttpApiHooks hooks);
  ~HttpApi();
  std::uint16_t port() const { return port_; }
  // Stops accepting and closes the console's WebSocket clients.
  void close();
  // The renderer list changed (a subscriber came, went or reported).
  void renderersChanged() { feed_.renderersChanged(); }
  ConsoleFeed& feed() { return feed_; }

  struct Counters {
    std::uint64_t requests = 0, applied = 0, rejected = 0, unauthorized = 0;
  };
  const Counters& counters() const { return counters_; }

  // The response to one request (exposed for the connection class).
  struct Reply {
    int status = 200;
    std::string contentType = "application/json";
    std::string body;
  };
  Reply handle(const std::string& method, const std::string& target, const std::string& authorization,
               const std::string& body);
  // The answer to a WebSocket upgrade while the feed is full (503).
  Reply refuseFeed();

 private:
  HttpApi(boost::asio::io_context& io, HttpApiOptions options, LiveWeather& weather, HttpApiHooks hooks);
  void accept();
  void reject(RejectReason reason) {
    if (hooks_.rejections) hooks_.rejections->count(reason);
  }
  nlohmann::json healthJson() const;

  boost::asio::io_context& io_;
  HttpApiOptions options_;
  LiveWeather& weather_;
  HttpApiHooks hooks_;
  ConsoleFeed feed_;
  std::size_t weatherListener_ = 0;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::uint16_t port_ = 0;
  Counters counters_;
  bool closed_ = false;
};

}  // namespace sky::server
