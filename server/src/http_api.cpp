// The weather server's HTTP API (see http_api.hpp).
#include "sky/server/http_api.hpp"

#include <charconv>
#include <chrono>

#include <boost/asio/ip/address.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <spdlog/spdlog.h>

#include "sky/server/api_json.hpp"
#include "sky/server/conditions_api.hpp"
#include "sky/server/console_files.hpp"
#include "sky/server/metar_api.hpp"
#include "sky/server/scenario_api.hpp"

namespace sky::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

namespace {

constexpr std::size_t kMaxBody = 64 * 1024;
// A scenario may carry up to 1024 timeline entries of a few hundred bytes.
constexpr std::size_t kMaxScenarioBody = 1024 * 1024;
constexpr auto kClientDeadline = std::chrono::seconds(10);
constexpr std::size_t kDefaultEvents = 100, kMaxEvents = 10000;

class Connection : public std::enable_shared_from_this<Connection> {
 public:
  Connection(tcp::socket socket, HttpApi& api) : stream_(std::move(socket)), api_(api) {}
  void start() {
    stream_.expires_after(kClientDeadline);
    // The header first: the body limit depends on the path.
    http::async_read_header(stream_, buffer_, parser_,
                            [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onHeader(ec); });
  }

 private:
  void onHeader(beast::error_code ec) {
    if (ec) return;  // the client went away, was too slow or sent no HTTP
    const std::string_view target(parser_.get().target().data(), parser_.get().target().size());
    bodyLimit_ = target.substr(0, target.find('?')) == "/api/scenario" ? kMaxScenarioBody : kMaxBody;
    parser_.body_limit(bodyLimit_);
    http::async_read(stream_, buffer_, parser_,
                     [self = shared_from_this()](beast::error_code e, std::size_t) { self->onRead(e); });
  }

  void onRead(beast::error_code ec) {
    HttpApi::Reply reply;
    if (ec == http::error::body_limit) {
      reply = {413, "application/json",
               nlohmann::json{{"error", "body: over " + std::to_string(bodyLimit_ / 1024) + " KiB"}, {"field", "body"}}
                   .dump()};
    } else if (ec) {
      return;  // the client went away or was too slow: nothing to answer
    } else if (isFeedUpgrade(parser_.get())) {
      if (!api_.feed().full()) {
        // The console's WebSocket takes the connection over.
        stream_.expires_never();
        api_.feed().accept(stream_.release_socket(), parser_.release());
        return;
      }
      reply = api_.refuseFeed();
    } else {
      const auto& req = parser_.get();
      reply = api_.handle(std::string(req.method_string()), std::string(req.target()),
                          std::string(req[http::field::authorization]), req.body());
    }
    response_.result(static_cast<unsigned>(reply.status));
    response_.version(11);
    response_.set(http::field::content_type, reply.contentType);
    response_.set(http::field::server, "skyshell-weatherd");
    response_.keep_alive(false);
    response_.body() = std::move(reply.body);
    response_.prepare_payload();
    http::async_write(stream_, response_, [self = shared_from_this()](beast::error_code, std::size_t) {
      beast::error_code ignored;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    });
  }

  static bool isFeedUpgrade(const http::request<http::string_body>& req) {
    const std::string_view target(req.target().data(), req.target().size());
    return beast::websocket::is_upgrade(req) && target.substr(0, target.find('?')) == "/api/ws";
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request_parser<http::string_body> parser_;
  std::size_t bodyLimit_ = kMaxBody;
  http::response<http::string_body> response_;
  HttpApi& api_;
};

std::string errorJson(const std::string& detail) {
  // "path: what" -> field = path, for the console to show next to the field.
  const auto colon = detail.find(": ");
  nlohmann::json j = {{"error", detail}};
  if (colon != std::string::npos) j["field"] = detail.substr(0, colon);
  return j.dump();
}

}  // namespace

HttpApi::HttpApi(asio::io_context& io, HttpApiOptions options, LiveWeather& weather, HttpApiHooks hooks)
    : io_(io),
      options_(std::move(options)),
      weather_(weather),
      hooks_(std::move(hooks)),
      feed_(io, options_.feed,
            ConsoleFeedSource{options_.serverId, [this] { return toJson(weather_.view()); },
                              [this] { return hooks_.renderers ? hooks_.renderers() : nlohmann::json::array(); },
                              [this] { return healthJson(); },
                              [this] {
                                const double now = weather_.clockNow();
                                return weather_.rampRunning(now) || weather_.drifting(now);
                              }},
            options_.log),
      acceptor_(io) {
  // Every accepted change, from whichever input, goes to the console.
  weatherListener_ = weather_.addListener([this](const ChangeEvent& e) { feed_.changeAccepted(e); });
}

HttpApi::~HttpApi() {
  close();
  weather_.removeListener(weatherListener_);
}

HttpApi::Reply HttpApi::refuseFeed() {
  ++counters_.requests;
  reject(RejectReason::WsRefused);
  return {503, "application/json",
          errorJson("ws: " + std::to_string(feed_.clients()) + " console clients connected, at most " +
                    std::to_string(options_.feed.maxClients))};
}

nlohmann::json HttpApi::healthJson() const {
  return {{"subscribers", hooks_.subscribers ? hooks_.subscribers() : 0},
          {"changes_applied", weather_.accepted()},
          {"rejected", hooks_.rejections ? hooks_.rejections->json() : nlohmann::json::object()}};
}

Result<std::unique_ptr<HttpApi>> HttpApi::create(asio::io_context& io, HttpApiOptions options, LiveWeather& weather,
                                                 HttpApiHooks hooks) {
  std::unique_ptr<HttpApi> api(new HttpApi(io, std::move(options), weather, std::move(hooks)));
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(api->options_.listenAddress, ec);
  if (ec) return fail(ErrorCode::InvalidArgument, "HTTP listen address '" + api->options_.listenAddress + "': " + ec.message());
  const tcp::endpoint endpoint(address, api->options_.port);
  api->acceptor_.open(endpoint.protocol(), ec);
  if (!ec) api->acceptor_.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) api->acceptor_.bind(endpoint, ec);
  if (!ec) api->acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    return fail(ErrorCode::Io, "HTTP API on " + api->options_.listenAddress + ":" + std::to_string(api->options_.port) +
                                   ": " + ec.message());
  api->port_ = api->acceptor_.local_endpoint().port();
  api->accept();
  return api;
}

void HttpApi::close() {
  if (closed_) return;
  closed_ = true;
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  feed_.close();
}

void HttpApi::accept() {
  acceptor_.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (closed_) return;
    if (!ec) std::make_shared<Connection>(std::move(socket), *this)->start();
    accept();
  });
}

HttpApi::Reply HttpApi::handle(const std::string& method, const std::string& target,
                               const std::string& authorization, const std::string& body) {
  ++counters_.requests;
  const std::string path = target.substr(0, target.find('?'));
  const std::string query = target.find('?') == std::string::npos ? "" : target.substr(target.find('?') + 1);
  if (method == "GET" && path == "/healthz") return {200, "text/plain", "ok\n"};
  if (method == "GET" && path == "/metrics") {
    std::string m;
    auto line = [&m](const char* name, const char* help, const char* type, std::uint64_t v) {
      m += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n" + name + " " +
           std::to_string(v) + "\n";
    };
    line("skyshell_http_requests_total", "HTTP requests handled", "counter", counters_.requests);
    line("skyshell_changes_applied_total", "weather changes applied (every input)", "counter", weather_.accepted());
    line("skyshell_changes_rejected_total", "weather changes refused as invalid", "counter", counters_.rejected);
    line("skyshell_changes_unauthorized_total", "change requests without the token", "counter", counters_.unauthorized);
    line("skyshell_subscribers", "weather stream subscribers connected", "gauge",
         hooks_.subscribers ? hooks_.subscribers() : 0);
    line("skyshell_ws_clients", "console WebSocket clients connected", "gauge", feed_.clients());
    line("skyshell_ws_clients_dropped_total", "console WebSocket clients dropped for not reading", "counter",
         feed_.dropped());
    if (hooks_.rejections) m += hooks_.rejections->metrics();
    if (hooks_.extraMetrics) m += hooks_.extraMetrics();
    return {200, "text/plain; version=0.0.4", m};
  }
  if (method == "GET" && path == "/api/state") return {200, "application/json", toJson(weather_.view()).dump()};
  if (method == "GET" && path == "/api/renderers") {
    const nlohmann::json list = hooks_.renderers ? hooks_.renderers() : nlohmann::json::array();
    return {200, "application/json",
            nlohmann::json{{"renderers", list}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)};
  }
  if (method == "GET" && path == "/api/conditions") {
    auto q = parseConditionsQuery(query);
    if (!q) return {400, "application/json", errorJson(q.error().detail)};
    return {200, "application/json", conditionsJson(weather_, *q).dump()};
  }
  if (path == "/api/ws")
    return {426, "application/json", errorJson("upgrade: GET /api/ws is a WebSocket (send Upgrade: websocket)")};
  if (method == "GET" && path == "/api/events") {
    std::size_t limit = kDefaultEvents;
    if (query.rfind("limit=", 0) == 0) {
      const std::string v = query.substr(6);
      std::size_t n = 0;
      const auto [end, err] = std::from_chars(v.data(), v.data() + v.size(), n);
      if (err != std::errc() || end != v.data() + v.size() || n == 0 || n > kMaxEvents)
        return {400, "application/json", errorJson("limit: '" + v + "' is not in 1..10000")};
      limit = n;
    }
    nlohmann::json list = nlohmann::json::array();
    for (const auto& e : weather_.events(limit)) list.push_back(toJson(e));
    return {200, "application/json", nlohmann::json{{"events", list}}.dump()};
  }
  if (path == "/api/changes") {
    if (method != "POST") return {405, "application/json", errorJson("method: use POST")};
    if (options_.token.empty() || authorization != "Bearer " + options_.token) {
      ++counters_.unauthorized;
      reject(RejectReason::Unauthorized);
      return {401, "application/json",
              errorJson(std::string("authorization: ") +
                        (options_.token.empty() ? "this server has no token: read-only" : "missing or wrong token"))};
    }
    auto request = parseChangeRequest(body);
    if (!request) {
      ++counters_.rejected;
      reject(RejectReason::HttpInvalid);
      return {400, "application/json", errorJson(request.error().detail)};
    }
    request->source = "api";
    if (request->author.empty()) request->author = "api";
    auto applied = weather_.submit(*request);
    if (!applied) {
      ++counters_.rejected;
      reject(RejectReason::HttpInvalid);
      if (options_.log)
        options_.log->info("event=change_refused source=api author={:?} detail={:?}", request->author,
                           applied.error().detail);
      return {applied.error().code == ErrorCode::Unsupported ? 501 : 400, "application/json",
              errorJson(applied.error().detail)};
    }
    ++counters_.applied;
    if (options_.log)
      options_.log->info("event=change_applied source=api sequence={} author={:?} summary={:?}", applied->sequence,
                         request->author, applied->summary);
    return {200, "application/json",
            nlohmann::json{{"sequence", applied->sequence}, {"clock_s", applied->clock_s}, {"summary", applied->summary}}
                .dump()};
  }
  if (path == "/api/scenario") {
    if (method != "POST") return {405, "application/json", errorJson("method: use POST")};
    if (options_.token.empty() || authorization != "Bearer " + options_.token) {
      ++counters_.unauthorized;
      reject(RejectReason::Unauthorized);
      return {401, "application/json", errorJson("authorization: loading a scenario needs the token")};
    }
    auto upload = parseScenarioUpload(body);
    if (!upload) {
      reject(RejectReason::ScenarioInvalid);
      return {400, "application/json", errorJson(upload.error().detail)};
    }
    auto scenario = parseScenario(upload->toml, upload->name);
    Result<AppliedChange> applied =
        scenario ? weather_.loadScenario(*scenario, upload->name, upload->author.empty() ? "api" : upload->author)
                 : Result<AppliedChange>(tl::unexpected(scenario.error()));
    if (!applied) {
      reject(RejectReason::ScenarioInvalid);
      if (options_.log)
        options_.log->info("event=scenario_refused name={:?} detail={:?}", upload->name, applied.error().detail);
      return {400, "application/json", scenarioErrorJson(applied.error().detail, upload->name).dump()};
    }
    if (options_.log)
      options_.log->info("event=change_applied source=scenario sequence={} author={:?} summary={:?}", applied->sequence,
                         upload->author, applied->summary);
    return {200, "application/json",
            nlohmann::json{{"sequence", applied->sequence},
                           {"clock_s", applied->clock_s},
                           {"summary", applied->summary},
                           {"layers", scenario->layers.size()},
                           {"timeline", scenario->timeline.size()}}
                .dump()};
  }
  if (path == "/api/metar") {
    if (method != "POST") return {405, "application/json", errorJson("method: use POST")};
    auto request = parseMetarRequest(body);
    if (!request) {
      ++counters_.rejected;
      reject(RejectReason::HttpInvalid);
      return {400, "application/json", errorJson(request.error().detail)};
    }
    // A preview reads; applying changes the weather and needs the token.
    if (request->apply && (options_.token.empty() || authorization != "Bearer " + options_.token)) {
      ++counters_.unauthorized;
      reject(RejectReason::Unauthorized);
      return {401, "application/json", errorJson("authorization: applying METAR needs the token")};
    }
    const MetarReply reply = handleMetar(*request, options_.stations, weather_);
    if (reply.body.contains("reports"))
      for (const auto& r : reply.body["reports"])
        if (r.value("ok", true) == false) reject(RejectReason::MetarUnparsed);
    if (request->apply) {
      if (reply.status == 200) {
        ++counters_.applied;
        if (options_.log)
          options_.log->info("event=change_applied source=metar sequence={} summary={:?}",
                             reply.body["applied"]["sequence"].get<std::uint64_t>(),
                             reply.body["applied"]["summary"].get<std::string>());
      } else {
        ++counters_.rejected;
        reject(RejectReason::HttpInvalid);
      }
    }
    return {reply.status, "application/json", reply.body.dump()};
  }
  if (method == "GET" && options_.console)
    if (const ConsoleFile* f = options_.console->find(path)) return {200, f->contentType, f->body};
  return {404, "application/json", errorJson("path: no " + method + " " + path)};
}

}  // namespace sky::server
