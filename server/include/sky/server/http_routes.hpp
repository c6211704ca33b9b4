// The HTTP API's routes, as one table: each states its path, methods, body
// limit and whether it needs the token, so the rules are enforced once, by
// the request handling (http_exchange.hpp), for every route, and a new
// endpoint cannot forget them. What each endpoint does is in http_api.hpp
// and server/API.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

namespace sky::server {

enum class Endpoint {
  Healthz,
  Metrics,
  State,
  Renderers,
  Conditions,
  Conformance,
  Wind,  // GET /api/wind (wind_api.hpp)
  Radar,  // GET /api/radar (radar_api.hpp)
  Cluster,  // GET /api/cluster: the NATS cluster's registry (cluster_registry.hpp)
  Events,
  Changes,
  Scenario,
  Metar,
  MetarStations,  // GET /api/metar/stations (metar_stations.hpp)
  Grib,
  Feed,  // GET /api/ws: the console's WebSocket (an upgrade, never a plain answer)
};

// Which requests to an endpoint need "Authorization: Bearer <token>".
enum class TokenRule {
  None,          // reads
  Always,        // checked after the header, before the body is read: 401 without reading it
  WhenApplying,  // POST /api/metar: a preview reads, "apply": true changes the weather; the
                 // body decides, so the endpoint checks it after parsing (ApiRequest::hasToken)
  WhenPosting,   // /api/events: GET reads, POST asks for a flash (checked like Always for a POST)
};

// Methods as a bit set.
inline constexpr unsigned kGet = 1, kPost = 2;

struct Route {
  std::string_view path;
  Endpoint endpoint;
  unsigned methods;               // kGet, kPost
  std::size_t bodyLimit_bytes;    // larger bodies are refused (413) before they are read
  TokenRule token;
};

// Every route (the console's files are served after them, to GETs of any
// other path).
std::span<const Route> httpRoutes();

// The route of `path` (no query), or null.
const Route* findRoute(std::string_view path);

// "GET", "POST" -> kGet, kPost; anything else 0.
unsigned methodBit(std::string_view method);

// "GET, POST": for a 405's Allow header.
std::string allowedMethods(const Route& route);

// The largest body any route takes: the limit while the header is read
// (the route's own applies once the path is known).
std::size_t maxBodyBytes();

// An endpoint's answer.
struct HttpReply {
  int status = 200;
  std::string contentType = "application/json";
  std::string body;
  int retryAfter_s = 0;  // > 0: a Retry-After header (a 503 for being busy)
};

// An answer an endpoint gives later, once work it started off the io thread
// has ended (POST /api/grib's decode). Called once, on the io thread, with
// what makes the reply: the transport runs that under the same guard as an
// endpoint (an exception is a 500 for this request) and sends the reply. When
// the API has closed meanwhile, it runs nothing. A client that left is found
// out when the reply is written.
using LaterAnswer = std::function<void(std::function<HttpReply()> reply)>;

// One request, as an endpoint sees it.
struct ApiRequest {
  std::string_view method, path, query, body;
  bool hasToken = false;  // the Authorization header carried the token (TokenRule::WhenApplying reads it)
  // Set when the transport can wait for an answer (the API's sockets; not
  // HttpExchange::feed, whose caller takes the answer when it returns). An
  // endpoint that keeps it returns no reply and calls it later, from a
  // handler of its own (never before it has returned).
  LaterAnswer later;
};

}  // namespace sky::server
