// One HTTP request to the API, socket-independent (see http_exchange.hpp).
#include "sky/server/http_exchange.hpp"

#include <new>
#include <optional>

#include <boost/asio/buffer.hpp>
#include <boost/asio/error.hpp>
#include <boost/beast/core/error.hpp>
#include <boost/beast/websocket/rfc6455.hpp>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/http_api.hpp"

namespace sky::server {

namespace http = boost::beast::http;

namespace {

std::string_view view(boost::beast::string_view s) { return {s.data(), s.size()}; }

}  // namespace

HttpExchange::HttpExchange(HttpApi& api) : api_(api) {
  parser_.header_limit(kMaxHeader_bytes);
  // While the header is read the path is unknown: Beast refuses a declared
  // length over the largest route's limit already; the route's own limit is
  // applied once the header is in.
  parser_.body_limit(maxBodyBytes());
}

template <class F>
HttpExchange::Next HttpExchange::guarded(F&& step) {
  // The boundary of issue 18: whatever a request makes the handling throw
  // (a JSON library refusing a string, memory, a bug) ends this request,
  // never the process.
  try {
    return step();
  } catch (const std::bad_alloc&) {
    return refuse(RejectReason::HttpInternal, 503, "server: out of memory for this request");
  } catch (const std::exception& e) {
    api_.refused(RejectReason::HttpInternal, e.what());
    return answer({500, "application/json", errorJson("server: this request failed inside the server")});
  }
}

HttpExchange::Next HttpExchange::afterHeader() {
  return guarded([this] { return headerChecks(); });
}

HttpExchange::Next HttpExchange::afterBody() {
  return guarded([this] { return bodyChecks(); });
}

HttpExchange::Next HttpExchange::afterLater(const std::function<HttpReply()>& reply) {
  return guarded([&] { return answer(reply()); });
}

HttpExchange::Next HttpExchange::afterError(boost::beast::error_code ec) {
  return guarded([&]() -> Next {
    if (ec == http::error::header_limit)
      return refuse(RejectReason::HttpHeaderTooLarge, 431,
                    "header: over " + std::to_string(kMaxHeader_bytes / 1024) + " KiB");
    if (ec == http::error::body_limit)
      return refuse(RejectReason::HttpTooLarge, 413,
                    "body: over " + std::to_string((route_ ? route_->bodyLimit_bytes : maxBodyBytes()) / 1024) +
                        " KiB");
    if (ec == boost::beast::error::timeout) {
      api_.refused(RejectReason::HttpTimeout, "client: request not complete within the deadline");
      return Next::Close;
    }
    // The client left (before or inside its request): nobody to answer.
    if (ec == http::error::end_of_stream || ec == http::error::partial_message || ec == http::error::need_more ||
        ec.category() != boost::beast::error_code(http::error::end_of_stream).category())
      return Next::Close;
    // The bytes are not HTTP (a bad method, target, field, length, chunk...).
    return refuse(RejectReason::HttpMalformed, 400, "request: " + ec.message());
  });
}

HttpExchange::Next HttpExchange::headerChecks() {
  ++api_.counters_.requests;
  const auto& req = parser_.get();
  const std::string_view target = view(req.target());
  // Issue 18: a byte 0x80-0xFF in the target was echoed into an error's JSON,
  // which the JSON writer refused by throwing, and the process aborted.
  if (!utf8::valid(target)) return refuse(RejectReason::HttpMalformed, 400, "target: not valid UTF-8");
  for (const auto& field : req)
    if (!utf8::valid(view(field.value())))
      return refuse(RejectReason::HttpMalformed, 400,
                    "header " + utf8::sanitise(view(field.name_string())) + ": not valid UTF-8");
  const std::string_view host = view(req[http::field::host]);
  if (auto ok = checkHost(host, api_.hostRules_); !ok)
    return refuse(RejectReason::HttpForbidden, 403, ok.error().detail);
  if (auto ok = checkOrigin(view(req[http::field::origin]), host, api_.hostRules_); !ok)
    return refuse(RejectReason::HttpForbidden, 403, ok.error().detail);

  const std::string_view path = target.substr(0, target.find('?'));
  const std::string_view method = view(req.method_string());
  route_ = findRoute(path);
  if (route_ && !(route_->methods & methodBit(method))) {
    const std::string allow = allowedMethods(*route_);
    Next n = answer({405, "application/json", errorJson("method: use " + allow)});
    response_.set(http::field::allow, allow);
    return n;
  }
  const std::string expected = "Bearer " + api_.options_.token;
  hasToken_ = !api_.options_.token.empty() && constantTimeEqual(view(req[http::field::authorization]), expected);
  // Before the body: a request that cannot be applied is not read.
  const bool needsToken = route_ && (route_->token == TokenRule::Always ||
                                     (route_->token == TokenRule::WhenPosting && method == "POST"));
  if (needsToken && !hasToken_) {
    Next n = answer(api_.unauthorized(route_->endpoint == Endpoint::Scenario ? "loading a scenario needs the token"
                                      : route_->endpoint == Endpoint::Events ? "asking for a flash needs the token"
                                                                               : "changes need the token"));
    response_.set(http::field::www_authenticate, "Bearer");
    return n;
  }
  const std::size_t limit = route_ ? route_->bodyLimit_bytes : 0;
  if (const auto length = parser_.content_length(); length && *length > limit)
    return refuse(RejectReason::HttpTooLarge, 413,
                  limit == 0 ? std::string("body: this request takes none")
                             : "body: " + std::to_string(*length) + " bytes, at most " + std::to_string(limit));
  parser_.body_limit(limit);
  if (route_ && route_->endpoint == Endpoint::Feed) {
    if (!boost::beast::websocket::is_upgrade(req))
      return answer({426, "application/json",
                     errorJson("upgrade: GET /api/ws is a WebSocket (send Upgrade: websocket)")});
    if (api_.feed_.full()) return answer(api_.refuseFeed());
    if (parser_.is_done()) return Next::Upgrade;
  }
  return parser_.is_done() ? bodyChecks() : Next::ReadBody;
}

HttpExchange::Next HttpExchange::bodyChecks() {
  const auto& req = parser_.get();
  const std::string_view target = view(req.target());
  const auto question = target.find('?');
  const std::string_view path = target.substr(0, question);
  const std::string_view method = view(req.method_string());
  if (!route_) return answer(api_.consoleFile(method, path));
  if (route_->endpoint == Endpoint::Feed) return Next::Upgrade;  // a chunked upgrade with an empty body
  ApiRequest request;
  request.method = method;
  request.path = path;
  request.query = question == std::string_view::npos ? std::string_view{} : target.substr(question + 1);
  request.body = req.body();
  request.hasToken = hasToken_;
  if (later_) request.later = later_();
  std::optional<HttpReply> reply = api_.serve(route_->endpoint, request);
  return reply ? answer(std::move(*reply)) : Next::Wait;
}

HttpExchange::Next HttpExchange::refuse(RejectReason reason, int status, std::string_view detail) {
  api_.refused(reason, detail);
  return answer({status, "application/json", errorJson(detail)});
}

HttpExchange::Next HttpExchange::answer(HttpReply reply) {
  response_ = {};
  response_.result(static_cast<unsigned>(reply.status));
  response_.version(11);
  response_.set(http::field::content_type, reply.contentType);
  response_.set(http::field::server, "skyshell-weatherd");
  // Browser safety: no content-type guessing, and no page may frame ours
  // (clickjacking the console's buttons).
  response_.set("X-Content-Type-Options", "nosniff");
  response_.set("X-Frame-Options", "DENY");
  response_.set("Content-Security-Policy", "frame-ancestors 'none'");
  if (reply.retryAfter_s > 0) response_.set(http::field::retry_after, std::to_string(reply.retryAfter_s));
  response_.keep_alive(false);
  response_.body() = std::move(reply.body);
  response_.prepare_payload();
  return Next::Answer;
}

HttpExchange::Next HttpExchange::feed(std::string_view bytes) {
  // As Beast's read loop does with a socket: present every byte not yet
  // parsed; when the parser wants more and there is none, the client's end
  // of stream.
  auto parse = [&](auto done) -> boost::beast::error_code {
    boost::beast::error_code ec;
    while (!done()) {
      if (!bytes.empty()) {
        const std::size_t used = parser_.put(boost::asio::buffer(bytes.data(), bytes.size()), ec);
        bytes.remove_prefix(used);
        if (ec && ec != http::error::need_more) return ec;
        if (used > 0 || (!ec && done())) continue;
      }
      if (!parser_.got_some()) return http::error::end_of_stream;
      ec = {};
      parser_.put_eof(ec);
      if (ec) return ec;
      return done() ? boost::beast::error_code{} : boost::beast::error_code(http::error::partial_message);
    }
    return ec = {};
  };
  if (auto ec = parse([this] { return parser_.is_header_done(); })) return afterError(ec);
  const Next next = afterHeader();
  if (next != Next::ReadBody) return next;
  if (auto ec = parse([this] { return parser_.is_done(); })) return afterError(ec);
  return afterBody();
}

}  // namespace sky::server
