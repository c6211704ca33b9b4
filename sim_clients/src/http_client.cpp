// Blocking HTTP client over Boost.Beast (see http_client.hpp).
#include "sky/sim/http_client.hpp"

#include <charconv>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>

namespace sky::sim {

namespace beast = boost::beast;
namespace http = beast::http;
namespace asio = boost::asio;

namespace {

// Largest response body read, bytes: the API's answers are small JSON.
constexpr std::size_t kMaxResponseBody = 4u << 20;

}  // namespace

Result<HttpResponse> httpRequest(const HttpRequest& r) {
  asio::io_context io;
  beast::tcp_stream stream(io);
  const std::string where = r.method + " http://" + r.host + ":" + std::to_string(r.port) + r.target;
  beast::error_code ec;
  asio::ip::tcp::resolver resolver(io);
  const auto endpoints = resolver.resolve(r.host, std::to_string(r.port), ec);
  if (ec) return fail(ErrorCode::Io, where + ": resolve: " + ec.message());
  stream.expires_after(r.timeout);

  // The tcp_stream deadline applies to async operations: run them on our own
  // io_context until they finish.
  stream.async_connect(endpoints, [&](beast::error_code e, const asio::ip::tcp::endpoint&) { ec = e; });
  io.run();
  if (ec) return fail(ec == beast::error::timeout ? ErrorCode::Timeout : ErrorCode::Io, where + ": connect: " + ec.message());

  http::request<http::string_body> req{r.method == "POST" ? http::verb::post : http::verb::get, r.target, 11};
  req.set(http::field::host, r.host);
  req.set(http::field::user_agent, "skyshell-sim");
  if (!r.bearerToken.empty()) req.set(http::field::authorization, "Bearer " + r.bearerToken);
  if (!r.body.empty()) {
    req.set(http::field::content_type, "application/json");
    req.body() = r.body;
  }
  req.prepare_payload();
  io.restart();
  http::async_write(stream, req, [&](beast::error_code e, std::size_t) { ec = e; });
  io.run();
  if (ec) return fail(ec == beast::error::timeout ? ErrorCode::Timeout : ErrorCode::Io, where + ": send: " + ec.message());

  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(kMaxResponseBody);
  io.restart();
  http::async_read(stream, buffer, parser, [&](beast::error_code e, std::size_t) { ec = e; });
  io.run();
  if (ec) return fail(ec == beast::error::timeout ? ErrorCode::Timeout : ErrorCode::Io, where + ": receive: " + ec.message());
  beast::error_code ignored;
  stream.socket().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  HttpResponse out;
  out.status = static_cast<int>(parser.get().result_int());
  out.body = parser.get().body();
  return out;
}

Result<std::pair<std::string, unsigned short>> parseHttpEndpoint(const std::string& url) {
  std::string rest = url;
  if (rest.rfind("http://", 0) == 0) rest = rest.substr(7);
  while (!rest.empty() && rest.back() == '/') rest.pop_back();
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0)
    return fail(ErrorCode::InvalidArgument, "'" + url + "': expected http://HOST:PORT");
  unsigned port = 0;
  const char* b = rest.data() + colon + 1;
  const char* e = rest.data() + rest.size();
  const auto [end, err] = std::from_chars(b, e, port);
  if (err != std::errc() || end != e || port == 0 || port > 65535)
    return fail(ErrorCode::InvalidArgument, "'" + url + "': port is not in 1..65535");
  return std::pair<std::string, unsigned short>{rest.substr(0, colon), static_cast<unsigned short>(port)};
}

}  // namespace sky::sim
