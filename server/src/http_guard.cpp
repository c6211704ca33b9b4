// Host and Origin rules of the HTTP API (see http_guard.hpp).
#include "sky/server/http_guard.hpp"

#include <algorithm>
#include <charconv>
#include <optional>

#include <boost/asio/ip/address.hpp>

namespace sky::server {

namespace {

struct Authority {
  std::string host;  // lower case; an IPv6 literal without its brackets
  std::optional<std::uint16_t> port;
  bool ipv6Literal = false;
};

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
  return out;
}

// "name", "name:port", "[v6]", "[v6]:port" (RFC 9110 section 7.2, the
// authority of RFC 3986 without userinfo).
std::optional<Authority> parseAuthority(std::string_view text) {
  Authority a;
  std::string_view rest;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos) return std::nullopt;
    a.host = lower(text.substr(1, close - 1));
    a.ipv6Literal = true;
    rest = text.substr(close + 1);
  } else {
    const auto colon = text.find(':');
    a.host = lower(text.substr(0, colon));
    rest = colon == std::string_view::npos ? std::string_view{} : text.substr(colon);
  }
  if (a.host.empty()) return std::nullopt;
  for (char c : a.host)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '.' || c == '_' ||
          (a.ipv6Literal && c == ':')))
      return std::nullopt;
  if (!rest.empty()) {
    if (rest.front() != ':' || rest.size() < 2 || rest.size() > 6) return std::nullopt;
    unsigned port = 0;
    const auto [end, err] = std::from_chars(rest.data() + 1, rest.data() + rest.size(), port);
    if (err != std::errc() || end != rest.data() + rest.size() || port == 0 || port > 65535) return std::nullopt;
    a.port = static_cast<std::uint16_t>(port);
  }
  return a;
}

bool isIpLiteral(const Authority& a) {
  boost::system::error_code ec;
  if (a.ipv6Literal) {
    boost::asio::ip::make_address_v6(a.host, ec);
  } else {
    boost::asio::ip::make_address_v4(a.host, ec);
  }
  return !ec;
}

bool unspecified(const std::string& address) {
  boost::system::error_code ec;
  const auto a = boost::asio::ip::make_address(address, ec);
  return !ec && a.is_unspecified();
}

bool namesThisServer(const Authority& a, const HostRules& rules) {
  if (a.host == "localhost" || a.host == "127.0.0.1" || a.host == "::1") return true;
  if (a.host == lower(rules.listenAddress)) return true;
  for (const auto& n : rules.names)
    if (a.host == lower(n)) return true;
  return unspecified(rules.listenAddress) && isIpLiteral(a);
}

}  // namespace

Result<void> checkHost(std::string_view host, const HostRules& rules) {
  if (host.empty()) return fail(ErrorCode::Malformed, "host: missing (HTTP/1.1 requires it)");
  const auto a = parseAuthority(host);
  if (!a) return fail(ErrorCode::Malformed, "host: not a host[:port]");
  if (!namesThisServer(*a, rules))
    return fail(ErrorCode::Malformed, "host: '" + a->host +
                                          "' is not this server's name (localhost, 127.0.0.1, [::1], the listen "
                                          "address or a configured name)");
  if (a->port && *a->port != rules.port)
    return fail(ErrorCode::Malformed, "host: port " + std::to_string(*a->port) + " is not this server's (" +
                                          std::to_string(rules.port) + ")");
  return {};
}

Result<void> checkOrigin(std::string_view origin, std::string_view host, const HostRules& rules) {
  if (origin.empty()) return {};
  for (const auto& o : rules.origins)
    if (lower(origin) == lower(o)) return {};
  constexpr std::string_view kHttp = "http://";
  if (lower(origin.substr(0, kHttp.size())) != kHttp)
    return fail(ErrorCode::Malformed, "origin: not this server's page (only http://<this host>:<port>)");
  const auto o = parseAuthority(origin.substr(kHttp.size()));
  const auto h = parseAuthority(host);
  if (!o || !h) return fail(ErrorCode::Malformed, "origin: not this server's page");
  // Same origin: the page was loaded from the host:port this request goes to.
  constexpr std::uint16_t kHttpDefaultPort = 80;
  if (o->host != h->host || o->port.value_or(kHttpDefaultPort) != h->port.value_or(kHttpDefaultPort))
    return fail(ErrorCode::Malformed, "origin: a page of another site (cross-origin requests are refused)");
  if (!checkHost(host, rules)) return fail(ErrorCode::Malformed, "origin: not this server's page");
  return {};
}

bool constantTimeEqual(std::string_view given, std::string_view expected) {
  // Every byte of `given` is compared (against `expected` repeated), without
  // an early exit: the time depends on `given`'s length only.
  unsigned difference = given.size() == expected.size() ? 0u : 1u;
  if (expected.empty()) return given.empty();
  for (std::size_t i = 0; i < given.size(); ++i)
    difference |= static_cast<unsigned char>(given[i]) ^ static_cast<unsigned char>(expected[i % expected.size()]);
  return difference == 0;
}

}  // namespace sky::server
