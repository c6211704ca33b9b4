// The console's live feed: WebSocket clients on the HTTP API's port
// (GET /api/ws upgrades; no token, it only reads) get JSON text messages
//   {"type":"hello","server_id":..,"api_version":1}   first
//   {"type":"state","state":STATE}          on connect, after every accepted
//        change, and at most 2 Hz while a ramp runs or a region drifts
//   {"type":"event","event":EVENT}          each accepted change
//   {"type":"renderers","renderers":[..]}   on connect, then at most 2 Hz when
//        a subscriber connects, subscribes, reports its camera or leaves
//   {"type":"health",...}                   on connect and every 2 s
// (shapes in server/API.md). Clients are bounded in number; each one's
// outbound messages are bounded (ws_outbox.hpp) and a client that stops
// reading is dropped. Runs on the server's io_context, one thread.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <utility>  // before asio: Boost 1.74 asio uses std::exchange without including it
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>

#include "sky/server/change.hpp"
#include "sky/server/renderer_info.hpp"
#include "sky/server/ws_outbox.hpp"

namespace spdlog {
class logger;
}

namespace sky::server {

class WsClient;

// Version of the console's JSON (HTTP and WebSocket): bumped on an
// incompatible change; fields may be added within a version.
inline constexpr int kConsoleApiVersion = 1;

struct ConsoleFeedOptions {
  std::size_t maxClients = 32;       // browsers open at once (an instructor station has a few)
  std::size_t maxQueuedEvents = 256; // events waiting for one client before it is dropped
  std::chrono::milliseconds stallTimeout{10000};  // as the weather stream's subscribers
  std::chrono::milliseconds pushInterval{500};    // 2 Hz: state while moving, renderers when changed
  std::chrono::milliseconds healthInterval{2000};
};

// Where the feed's messages come from (called on the io thread).
struct ConsoleFeedSource {
  std::string serverId;
  std::function<nlohmann::json()> state;      // GET /api/state
  std::function<nlohmann::json()> renderers;  // the array of GET /api/renderers
  std::function<nlohmann::json()> health;     // {"subscribers", "changes_applied", "rejected"}
  std::function<bool()> moving;               // the state changes by itself (ramp, drift)
};

class ConsoleFeed {
 public:
  ConsoleFeed(boost::asio::io_context& io, ConsoleFeedOptions options, ConsoleFeedSource source,
              std::shared_ptr<spdlog::logger> log);
  ~ConsoleFeed();
  ConsoleFeed(const ConsoleFeed&) = delete;
  ConsoleFeed& operator=(const ConsoleFeed&) = delete;

  // Whether another client would be over maxClients (then answer 503).
  bool full() const { return clients_.size() >= options_.maxClients; }
  // Takes a connection whose HTTP request asked to upgrade; sends hello,
  // state, renderers and health once the WebSocket is open.
  void accept(boost::asio::ip::tcp::socket socket,
              boost::beast::http::request<boost::beast::http::string_body> request);
  // An accepted change: its event, then the state, to every client now.
  void changeAccepted(const ChangeEvent& event);
  // The renderer list changed: sent at the next push tick.
  void renderersChanged() { renderersDirty_ = true; }
  // Closes every client (a close frame where possible) and stops the
  // timers: part of server shutdown. Later accepts are refused.
  void close();

  std::size_t clients() const { return clients_.size(); }
  std::uint64_t dropped() const { return dropped_; }

 private:
  class Handler;
  void startTimers();
  void onPushTick();
  void onHealthTick();
  WsText stateMessage() const;
  WsText renderersMessage() const;
  WsText healthMessage() const;
  void clientClosed(WsClient& client, bool dropped);

  ConsoleFeedOptions options_;
  ConsoleFeedSource source_;
  std::shared_ptr<spdlog::logger> log_;
  std::unique_ptr<Handler> handler_;
  boost::asio::steady_timer pushTimer_, healthTimer_;
  std::map<std::uint64_t, std::shared_ptr<WsClient>> clients_;  // by id
  std::uint64_t nextId_ = 1;
  std::uint64_t dropped_ = 0;
  bool renderersDirty_ = false;
  bool timersRunning_ = false;
  bool closed_ = false;
};

// The renderer list as JSON (GET /api/renderers, the "renderers" message):
// [{"id", "channel", "peer", "lat_deg", "lon_deg", "alt_m", "heading_deg",
//   "pitch_deg", "roll_deg", "frame", "weather_version", "weather_clock_s",
//   "area": {"center_lat_deg", "center_lon_deg", "radius_m"},
//   "last_report_age_s"}]; before a CameraReport the pose fields, frame,
// weather_version, weather_clock_s and the age are null and channel is "";
// before a Subscribe the area is null.
nlohmann::json renderersJson(const std::vector<RendererInfo>& renderers);

// The messages, for the feed and for tests: exactly one JSON object each.
std::string consoleHello(const std::string& serverId);
std::string consoleMessage(const char* type, const char* key, const nlohmann::json& payload);

}  // namespace sky::server
