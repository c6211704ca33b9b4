// The weather server's HTTP API: the listening socket, the connections in
// flight and their cap (see http_api.hpp). What a request means is decided by
// HttpExchange (http_exchange.cpp) and the endpoints (http_endpoints.cpp).
#include "sky/server/http_api.hpp"

#include <chrono>

#include <boost/asio/ip/address.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <spdlog/spdlog.h>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/http_exchange.hpp"

namespace sky::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;

namespace {

// A whole request (header and body) must arrive within this long: a client
// that trickles bytes (slowloris) holds a slot no longer.
constexpr auto kClientDeadline = std::chrono::seconds(10);
// After an answer the client's unread bytes (a refused body) are read and
// dropped for up to this long and this many bytes before the socket is
// closed: closing with unread data makes the kernel send a reset, which can
// destroy the answer before the client reads it.
constexpr auto kLingerTime = std::chrono::seconds(2);
constexpr std::size_t kLinger_bytes = 256 * 1024;
// accept() failing (EMFILE, ENFILE, ENOBUFS) is retried after this long
// instead of at once: at the descriptor limit an immediate retry fails
// again and spins a core.
constexpr auto kAcceptRetry = std::chrono::milliseconds(100);

// The answer to a connection past the cap, written without waiting: the
// socket is new, its send buffer empty.
const std::string kBusyReply = [] {
  const std::string body = errorJson("server: too many HTTP connections in flight; try again");
  return "HTTP/1.1 503 Service Unavailable\r\nServer: skyshell-weatherd\r\nContent-Type: application/json\r\n"
         "Connection: close\r\nRetry-After: 1\r\nX-Content-Type-Options: nosniff\r\nContent-Length: " +
         std::to_string(body.size()) + "\r\n\r\n" + body;
}();

void refuseBusy(tcp::socket& socket) {
  boost::system::error_code ignored;
  socket.non_blocking(true, ignored);
  socket.write_some(asio::buffer(kBusyReply), ignored);
  socket.shutdown(tcp::socket::shutdown_both, ignored);
  socket.close(ignored);
}

}  // namespace

struct HttpApi::Registry {
  HttpApi* api = nullptr;  // null once the API is closed: handlers that run later do nothing
  // Open connections by id (accept order): the eviction scan finds the oldest first.
  std::map<std::uint64_t, std::weak_ptr<HttpConnection>> open;
  std::uint64_t nextId = 1;
};

// One accepted connection: one request read through an HttpExchange, its
// answer written (at once, or when the endpoint gives it later), then a
// short lingering read, then closed.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(tcp::socket socket, std::shared_ptr<HttpApi::Registry> registry, std::uint64_t id)
      : stream_(std::move(socket)), registry_(std::move(registry)), id_(id), exchange_(*registry_->api) {}
  ~HttpConnection() { registry_->open.erase(id_); }

  void start() {
    // Called by the endpoint while this connection handles its request. The
    // answer holds the connection (the registry only watches it), so a
    // connection waiting for one lives as long as the endpoint's work keeps
    // it; no member holds it, so nothing holds itself.
    exchange_.waitWith([this] {
      return LaterAnswer([self = shared_from_this()](std::function<HttpReply()> reply) {
        if (!self->registry_->api || self->stopped_) return;
        self->stream_.expires_after(kClientDeadline);  // for writing the answer
        self->proceed([&] { return self->exchange_.afterLater(reply); });
      });
    });
    stream_.expires_after(kClientDeadline);
    http::async_read_header(stream_, buffer_, exchange_.parser(),
                            [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec, false); });
  }
  // Still waiting for its header: the first to go when the cap is reached.
  bool waitingForHeader() const { return !headerDone_; }
  // Past the cap: answered 503 now, its slot freed.
  void evict() {
    stopped_ = true;
    refuseBusy(stream_.socket());
  }
  void stop() {
    stopped_ = true;
    beast::error_code ignored;
    stream_.socket().close(ignored);
  }

 private:
  // The header (body false) or the body has been read, or reading failed:
  // one step of the exchange, then what it says. A handler that runs after
  // the API closed, or after an eviction, does nothing.
  void onRead(beast::error_code ec, bool body) {
    if (!registry_->api || stopped_) return;
    headerDone_ = true;
    proceed([&] { return ec ? exchange_.afterError(ec) : body ? exchange_.afterBody() : exchange_.afterHeader(); });
  }

  // One step of the exchange, then what it says.
  template <class Step>
  void proceed(Step&& step) {
    HttpExchange::Next next = HttpExchange::Next::Close;
    try {
      next = step();
    } catch (const std::exception& e) {
      // HttpExchange answers its own failures; this is the last resort (a
      // failure while building that answer): close, and count it.
      registry_->api->refused(RejectReason::HttpInternal, e.what());
    }
    switch (next) {
      case HttpExchange::Next::ReadBody:
        http::async_read(stream_, buffer_, exchange_.parser(),
                         [self = shared_from_this()](beast::error_code e, std::size_t) { self->onRead(e, true); });
        return;
      case HttpExchange::Next::Answer:
        http::async_write(stream_, exchange_.response(), [self = shared_from_this()](beast::error_code e, std::size_t) {
          if (!e) self->linger();
        });
        return;
      case HttpExchange::Next::Upgrade:
        // The console's WebSocket takes the connection over (and its slot
        // is the feed's from now on).
        stream_.expires_never();
        registry_->api->feed_.accept(stream_.release_socket(), exchange_.parser().release());
        return;
      case HttpExchange::Next::Wait:
        // The endpoint's own work is bounded (a GRIB decode by its
        // decoder's timeout); the client's deadline applies again to the
        // answer's write.
        stream_.expires_never();
        return;
      case HttpExchange::Next::Close: return;
    }
  }

  void linger() {
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    stream_.expires_after(kLingerTime);
    drain();
  }

  void drain() {
    stream_.async_read_some(asio::buffer(discard_), [self = shared_from_this()](beast::error_code ec, std::size_t n) {
      self->lingered_ += n;
      if (!ec && self->lingered_ < kLinger_bytes && !self->stopped_) self->drain();
    });
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::shared_ptr<HttpApi::Registry> registry_;
  std::uint64_t id_;
  HttpExchange exchange_;
  std::array<char, 4096> discard_;
  std::size_t lingered_ = 0;
  bool headerDone_ = false;
  bool stopped_ = false;
};

HttpApi::HttpApi(asio::io_context& io, HttpApiOptions options, LiveWeather& weather, HttpApiHooks hooks)
    : options_(std::move(options)),
      weather_(weather),
      hooks_(std::move(hooks)),
      feed_(io, options_.feed,
            ConsoleFeedSource{options_.serverId, [this] { return apiStateJson(weather_); },
                              [this] { return hooks_.renderers ? hooks_.renderers() : nlohmann::json::array(); },
                              [this] { return healthJson(); },
                              [this] {
                                const double now = weather_.clockNow();
                                return weather_.rampRunning(now) || weather_.drifting(now);
                              }},
            options_.log),
      acceptor_(io),
      acceptRetry_(io),
      registry_(std::make_shared<Registry>()),
      gribDecodes_(io, kGribDecodeSlots) {
  registry_->api = this;
  // Every accepted change, from whichever input, goes to the console.
  weatherListener_ = weather_.addListener([this](const ChangeEvent& e) { feed_.changeAccepted(e); });
}

HttpApi::~HttpApi() {
  close();
  weather_.removeListener(weatherListener_);
}

nlohmann::json HttpApi::healthJson() const {
  return {{"subscribers", hooks_.subscribers ? hooks_.subscribers() : 0},
          {"changes_applied", weather_.accepted()},
          {"rejected", hooks_.rejections ? hooks_.rejections->json() : nlohmann::json::object()}};
}

std::size_t HttpApi::connectionsInFlight() const { return registry_->open.size(); }

Result<std::unique_ptr<HttpApi>> HttpApi::create(asio::io_context& io, HttpApiOptions options, LiveWeather& weather,
                                                 HttpApiHooks hooks) {
  std::unique_ptr<HttpApi> api(new HttpApi(io, std::move(options), weather, std::move(hooks)));
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(api->options_.listenAddress, ec);
  if (ec) return fail(ErrorCode::InvalidArgument, "HTTP listen address '" + api->options_.listenAddress + "': " + ec.message());
  if (api->options_.maxConnections == 0) return fail(ErrorCode::InvalidArgument, "HTTP maxConnections: 0");
  const tcp::endpoint endpoint(address, api->options_.port);
  api->acceptor_.open(endpoint.protocol(), ec);
  if (!ec) api->acceptor_.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) api->acceptor_.bind(endpoint, ec);
  if (!ec) api->acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec)
    return fail(ErrorCode::Io, "HTTP API on " + api->options_.listenAddress + ":" + std::to_string(api->options_.port) +
                                   ": " + ec.message());
  api->port_ = api->acceptor_.local_endpoint().port();
  api->hostRules_ = {api->port_, address.to_string(), api->options_.allowedHosts, api->options_.allowedOrigins};
  api->accept();
  return api;
}

void HttpApi::close() {
  if (closed_) return;
  closed_ = true;
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  acceptRetry_.cancel();
  gribDecodes_.close();
  registry_->api = nullptr;
  const auto open = registry_->open;  // a copy: stopping may end a connection
  for (auto& [id, weak] : open)
    if (auto c = weak.lock()) c->stop();
  feed_.close();
}

void HttpApi::accept() {
  acceptor_.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (closed_) return;
    if (!ec) {
      acceptErrorLogged_ = false;
      admit(std::move(socket));
      accept();
      return;
    }
    if (!acceptErrorLogged_ && options_.log)
      options_.log->warn("event=http_accept_failed error={:?}; retrying every {} ms", ec.message(),
                         std::chrono::duration_cast<std::chrono::milliseconds>(kAcceptRetry).count());
    acceptErrorLogged_ = true;
    acceptRetry_.expires_after(kAcceptRetry);
    acceptRetry_.async_wait([this](const boost::system::error_code& e) {
      if (!e && !closed_) accept();
    });
  });
}

void HttpApi::admit(tcp::socket socket) {
  if (registry_->open.size() >= options_.maxConnections) {
    // The slot of the connection that has waited longest without sending a
    // whole header (an idle or trickling client) goes to the new one; when
    // every slot is past its header, the new one is refused.
    std::shared_ptr<HttpConnection> idle;
    for (auto& [id, weak] : registry_->open)
      if (auto c = weak.lock(); c && c->waitingForHeader()) {
        idle = std::move(c);
        registry_->open.erase(id);
        break;
      }
    refused(RejectReason::HttpBusy, "over " + std::to_string(options_.maxConnections) + " HTTP connections in flight");
    if (idle) {
      idle->evict();
    } else {
      refuseBusy(socket);
      return;
    }
  }
  const std::uint64_t id = registry_->nextId++;
  auto c = std::make_shared<HttpConnection>(std::move(socket), registry_, id);
  registry_->open[id] = c;
  c->start();
}

void HttpApi::refused(RejectReason reason, std::string_view detail) {
  if (hooks_.rejections) hooks_.rejections->count(reason);
  auto& logged = logged_[static_cast<std::size_t>(reason)];
  if (logged || !options_.log) return;
  logged = true;
  options_.log->warn("event=http_refused reason={} detail={:?} (the first; later ones are counted in /metrics)",
                     toString(reason), utf8::sanitiseAndCut(detail, 300));
}

}  // namespace sky::server
