// The HTTP API's route table (see http_routes.hpp).
#include "sky/server/http_routes.hpp"

#include <algorithm>
#include <array>

namespace sky::server {

namespace {

// Change requests are a few kB; a batch of 256 changes with regions fits
// well within 64 KiB.
constexpr std::size_t kMaxBody_bytes = 64 * 1024;
// A scenario may carry up to 1024 timeline entries of a few hundred bytes.
constexpr std::size_t kMaxScenarioBody_bytes = 1024 * 1024;
// An uploaded GRIB2 file: a regional forecast's cloud and wind fields at a
// few steps are a few MB; larger files go by path (--grib-dir).
constexpr std::size_t kMaxGribBody_bytes = 32 * 1024 * 1024;

constexpr std::array kRoutes = {
    Route{"/healthz", Endpoint::Healthz, kGet, 0, TokenRule::None},
    Route{"/metrics", Endpoint::Metrics, kGet, 0, TokenRule::None},
    Route{"/api/state", Endpoint::State, kGet, 0, TokenRule::None},
    Route{"/api/renderers", Endpoint::Renderers, kGet, 0, TokenRule::None},
    Route{"/api/conditions", Endpoint::Conditions, kGet, 0, TokenRule::None},
    Route{"/api/conformance", Endpoint::Conformance, kGet, 0, TokenRule::None},
    Route{"/api/wind", Endpoint::Wind, kGet, 0, TokenRule::None},
    Route{"/api/radar", Endpoint::Radar, kGet, 0, TokenRule::None},
    Route{"/api/cluster", Endpoint::Cluster, kGet, 0, TokenRule::None},
    // GET: the change log and recent flashes; POST: ask for a flash (token).
    Route{"/api/events", Endpoint::Events, kGet | kPost, kMaxBody_bytes, TokenRule::WhenPosting},
    Route{"/api/changes", Endpoint::Changes, kPost, kMaxBody_bytes, TokenRule::Always},
    Route{"/api/scenario", Endpoint::Scenario, kPost, kMaxScenarioBody_bytes, TokenRule::Always},
    Route{"/api/metar", Endpoint::Metar, kPost, kMaxBody_bytes, TokenRule::WhenApplying},
    Route{"/api/metar/stations", Endpoint::MetarStations, kGet, 0, TokenRule::None},
    Route{"/api/grib", Endpoint::Grib, kPost, kMaxGribBody_bytes, TokenRule::Always},
    Route{"/api/ws", Endpoint::Feed, kGet, 0, TokenRule::None},
};

}  // namespace

std::span<const Route> httpRoutes() { return kRoutes; }

const Route* findRoute(std::string_view path) {
  for (const Route& r : kRoutes)
    if (r.path == path) return &r;
  return nullptr;
}

unsigned methodBit(std::string_view method) {
  if (method == "GET") return kGet;
  if (method == "POST") return kPost;
  return 0;
}

std::string allowedMethods(const Route& route) {
  std::string s;
  if (route.methods & kGet) s += "GET";
  if (route.methods & kPost) s += s.empty() ? "POST" : ", POST";
  return s;
}

std::size_t maxBodyBytes() {
  std::size_t m = 0;
  for (const Route& r : kRoutes) m = std::max(m, r.bodyLimit_bytes);
  return m;
}

}  // namespace sky::server
