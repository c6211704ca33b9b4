// A small blocking HTTP/1.1 client for the weather server's JSON API
// (skyshell-scenario's actions): one request per connection, with a deadline.
#pragma once

#include <chrono>
#include <string>

#include "sky/core/result.hpp"

namespace sky::sim {

struct HttpResponse {
  int status = 0;
  std::string body;
};

struct HttpRequest {
  std::string method = "GET";  // GET or POST
  std::string host = "127.0.0.1";
  unsigned short port = 0;
  std::string target = "/";    // path and query
  std::string body;            // sent as application/json when not empty
  std::string bearerToken;     // Authorization: Bearer <token> when not empty
  std::chrono::milliseconds timeout{5000};
};

// Errors: Io (resolve, connect, send, receive), Timeout. Any HTTP status is
// a success here; the caller judges it.
Result<HttpResponse> httpRequest(const HttpRequest& request);

// "http://HOST:PORT" or "HOST:PORT" -> host and port (InvalidArgument otherwise).
Result<std::pair<std::string, unsigned short>> parseHttpEndpoint(const std::string& url);

}  // namespace sky::sim
