// Who may talk to the HTTP API, judged from the request's header before
// anything else: the Host must name this server (a DNS-rebinding defence:
// a page on evil.example whose name now resolves to 127.0.0.1 still sends
// Host: evil.example), and an Origin, when a browser sends one, must be this
// server's own page (a page the operator visits cannot drive the API or
// take the console's WebSocket slots). The token is compared in constant time.
// Pure functions: tests/unit/server/http_guard_test.cpp states the rules.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::server {

struct HostRules {
  std::uint16_t port = 0;          // the port the API listens on
  std::string listenAddress;       // the address it is bound to (0.0.0.0 / :: : every address)
  std::vector<std::string> names;  // more host names that reach it (e.g. behind a DNS name), no port
  std::vector<std::string> origins;  // more allowed Origins, exactly as a browser sends them ("http://ops:8080")
};

// Whether `host` (the Host header's value) names this server: localhost,
// 127.0.0.1, [::1], the listen address, or one of rules.names, case
// insensitive; when bound to every address, any IP literal (an address
// cannot be rebound, only a name can). A port, when given, must be
// rules.port; none is accepted (non-browser clients leave it out; browsers
// send it whenever it is not 80). Error: Malformed with the reason.
Result<void> checkHost(std::string_view host, const HostRules& rules);

// Whether a request carrying `origin` (the Origin header's value; empty when
// absent) may use the API: no Origin (not a browser's cross-site request),
// an http Origin whose host and port are the request's `host` (same origin)
// and that names this server (checkHost), or one of rules.origins.
// "null" (sandboxed frames, file: pages) is refused.
Result<void> checkOrigin(std::string_view origin, std::string_view host, const HostRules& rules);

// a == b in time that depends only on the length of `given`, not on where
// the two first differ (a token compared byte by byte with an early exit
// leaks its prefix through response times).
bool constantTimeEqual(std::string_view given, std::string_view expected);

}  // namespace sky::server
