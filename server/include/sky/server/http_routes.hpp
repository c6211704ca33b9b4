// The HTTP API's routes, as one table: each states its path, methods, body
// limit and whether it needs the token, so the rules are enforced once, by
// the request handling (http_exchange.hpp), for every route, and a new
// endpoint cannot forget them. What each endpoint does is in http_api.hpp
// and server/API.md.
#pragma once

#include <cstddef>
#include <cstdint>
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

// One request, as an endpoint sees it.
struct ApiRequest {
  std::string_view method, path, query, body;
  bool hasToken = false;  // the Authorization header carried the token (TokenRule::WhenApplying reads it)
};

// An endpoint's answer.
struct HttpReply {
  int status = 200;
  std::string contentType = "application/json";
  std::string body;
};

}  // namespace sky::server
