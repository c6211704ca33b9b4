// The console's WebSocket feed (see console_feed.hpp).
#include "sky/server/console_feed.hpp"

#include <spdlog/spdlog.h>

#include "sky/server/api_json.hpp"
#include "ws_client.hpp"

namespace sky::server {

namespace asio = boost::asio;

namespace {

// JSON text as it goes out. Strings the server did not write itself (an
// author name, a channel) are valid UTF-8 by the time they get here, but a
// replacement character is better than an exception if one is not.
std::string dump(const nlohmann::json& j) { return dumpJson(j); }

WsText shared(std::string text) { return std::make_shared<const std::string>(std::move(text)); }

}  // namespace

nlohmann::json renderersJson(const std::vector<RendererInfo>& renderers) {
  nlohmann::json list = nlohmann::json::array();
  for (const RendererInfo& r : renderers) {
    nlohmann::json j = {{"id", r.id}, {"peer", r.peer}, {"channel", r.report ? r.report->channel : std::string()}};
    if (r.report) {
      const stream::CameraReport& c = *r.report;
      j.update({{"lat_deg", c.lat_deg}, {"lon_deg", c.lon_deg}, {"alt_m", c.alt_m}, {"heading_deg", c.heading_deg},
                {"pitch_deg", c.pitch_deg}, {"roll_deg", c.roll_deg}, {"frame", c.frame},
                {"weather_version", c.weatherVersion}, {"weather_clock_s", c.weatherClock_s},
                {"last_report_age_s", r.lastReportAge_s}});
    } else {
      for (const char* k : {"lat_deg", "lon_deg", "alt_m", "heading_deg", "pitch_deg", "roll_deg", "frame",
                            "weather_version", "weather_clock_s", "last_report_age_s"})
        j[k] = nullptr;
    }
    j["area"] = r.area ? nlohmann::json{{"center_lat_deg", r.area->centerLat_deg},
                                        {"center_lon_deg", r.area->centerLon_deg},
                                        {"radius_m", r.area->radius_m}}
                       : nlohmann::json(nullptr);
    list.push_back(std::move(j));
  }
  return list;
}

std::string consoleHello(const std::string& serverId) {
  return dump({{"type", "hello"}, {"server_id", serverId}, {"api_version", kConsoleApiVersion}});
}

std::string consoleMessage(const char* type, const char* key, const nlohmann::json& payload) {
  return dump({{"type", type}, {key, payload}});
}

class ConsoleFeed::Handler final : public WsClientHandler {
 public:
  explicit Handler(ConsoleFeed& feed) : feed_(feed) {}
  void wsClientClosed(WsClient& client, bool dropped) override { feed_.clientClosed(client, dropped); }

 private:
  ConsoleFeed& feed_;
};

ConsoleFeed::ConsoleFeed(asio::io_context& io, ConsoleFeedOptions options, ConsoleFeedSource source,
                         std::shared_ptr<spdlog::logger> log)
    : options_(options),
      source_(std::move(source)),
      log_(log ? std::move(log) : std::make_shared<spdlog::logger>("sky_console_feed")),
      handler_(std::make_unique<Handler>(*this)),
      pushTimer_(io),
      healthTimer_(io) {}

ConsoleFeed::~ConsoleFeed() { close(); }

void ConsoleFeed::accept(asio::ip::tcp::socket socket,
                         boost::beast::http::request<boost::beast::http::string_body> request) {
  if (closed_) return;
  auto client = std::make_shared<WsClient>(std::move(socket), nextId_++, *handler_, *log_, options_.stallTimeout,
                                           options_.maxQueuedEvents);
  clients_[client->id()] = client;
  client->sendFirst(shared(consoleHello(source_.serverId)));
  client->sendState(stateMessage());
  client->sendRenderers(renderersMessage());
  client->sendHealth(healthMessage());
  client->start(std::move(request));
  // Every client's health counts the new one from now on.
  const WsText health = healthMessage();
  for (auto& [id, c] : clients_)
    if (c != client) c->sendHealth(health);
  startTimers();
}

void ConsoleFeed::changeAccepted(const ChangeEvent& event) {
  if (clients_.empty()) return;
  const WsText e = shared(consoleMessage("event", "event", toJson(event)));
  const WsText s = stateMessage();
  // A copy: a client past its event bound is dropped (and removed) here.
  const auto clients = clients_;
  for (auto& [id, c] : clients) {
    c->sendEvent(e);
    c->sendState(s);
  }
}

void ConsoleFeed::close() {
  if (closed_) return;
  closed_ = true;
  pushTimer_.cancel();
  healthTimer_.cancel();
  const auto clients = clients_;
  for (auto& [id, c] : clients) c->shutdown();
}

void ConsoleFeed::startTimers() {
  if (timersRunning_ || closed_) return;
  timersRunning_ = true;
  pushTimer_.expires_after(options_.pushInterval);
  pushTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) onPushTick();
  });
  healthTimer_.expires_after(options_.healthInterval);
  healthTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) onHealthTick();
  });
}

void ConsoleFeed::onPushTick() {
  if (closed_) return;
  if (clients_.empty()) {
    // Idle without clients: the next accept starts the timers again.
    timersRunning_ = false;
    healthTimer_.cancel();
    return;
  }
  if (renderersDirty_) {
    renderersDirty_ = false;
    const WsText r = renderersMessage();
    for (auto& [id, c] : clients_) c->sendRenderers(r);
  }
  if (source_.moving && source_.moving()) {
    const WsText s = stateMessage();
    for (auto& [id, c] : clients_) c->sendState(s);
  }
  pushTimer_.expires_after(options_.pushInterval);
  pushTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) onPushTick();
  });
}

void ConsoleFeed::onHealthTick() {
  // The push tick decides when the timers stop (no clients).
  if (closed_ || !timersRunning_) return;
  const WsText h = healthMessage();
  for (auto& [id, c] : clients_) c->sendHealth(h);
  healthTimer_.expires_after(options_.healthInterval);
  healthTimer_.async_wait([this](const boost::system::error_code& ec) {
    if (!ec) onHealthTick();
  });
}

WsText ConsoleFeed::stateMessage() const {
  return shared(consoleMessage("state", "state", source_.state ? source_.state() : nlohmann::json::object()));
}

WsText ConsoleFeed::renderersMessage() const {
  return shared(
      consoleMessage("renderers", "renderers", source_.renderers ? source_.renderers() : nlohmann::json::array()));
}

WsText ConsoleFeed::healthMessage() const {
  nlohmann::json h = source_.health ? source_.health() : nlohmann::json::object();
  h["type"] = "health";
  h["ws_clients"] = clients_.size();
  return shared(dump(h));
}

void ConsoleFeed::clientClosed(WsClient& client, bool dropped) {
  if (dropped) ++dropped_;
  log_->info("event=console_{} console={} peer={} clients={}", dropped ? "dropped" : "closed", client.id(),
             client.peer(), clients_.size() - 1);
  // The client stays alive through its pending handlers (they hold it).
  clients_.erase(client.id());
}

}  // namespace sky::server
