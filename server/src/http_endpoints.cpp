// The HTTP API's endpoints (see http_api.hpp): what each route does once
// HttpExchange has checked Host, Origin, the token rule and the body limit.
#include <charconv>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <stop_token>

#include <spdlog/spdlog.h>

#include "sky/core/utf8.hpp"
#include "sky/server/api_json.hpp"
#include "sky/server/conditions_api.hpp"
#include "sky/server/conformance.hpp"
#include "sky/server/console_files.hpp"
#include "sky/server/forecast_files.hpp"
#include "sky/server/http_api.hpp"
#include "sky/server/metar_api.hpp"
#include "sky/server/metrics_text.hpp"
#include "sky/server/radar_api.hpp"
#include "sky/server/scenario_api.hpp"
#include "sky/server/wind_api.hpp"

namespace sky::server {

namespace {

constexpr std::size_t kDefaultEvents = 100, kMaxEvents = 10000;

HttpReply json(const nlohmann::json& body) { return {200, "application/json", dumpJson(body)}; }
HttpReply error(int status, std::string_view detail) { return {status, "application/json", errorJson(detail)}; }

}  // namespace

std::optional<HttpReply> HttpApi::serve(Endpoint endpoint, const ApiRequest& r) {
  switch (endpoint) {
    case Endpoint::Healthz: return HttpReply{200, "text/plain", "ok\n"};
    case Endpoint::Metrics: return metrics();
    case Endpoint::State: return json(apiStateJson(weather_));
    case Endpoint::Renderers:
      return json({{"renderers", hooks_.renderers ? hooks_.renderers() : nlohmann::json::array()}});
    case Endpoint::Conditions: {
      auto q = parseConditionsQuery(r.query);
      if (!q) return error(400, q.error().detail);
      return json(conditionsJson(weather_, *q));
    }
    case Endpoint::Conformance: {
      auto q = parseConformanceQuery(r.query);
      if (!q) return error(400, q.error().detail);
      return json(conformanceJson(weather_, metarStations_.known(options_.stations), *q));
    }
    case Endpoint::Wind: {
      auto q = parseWindQuery(r.query);
      if (!q) return error(400, q.error().detail);
      return json(windJson(weather_, *q));
    }
    case Endpoint::Cluster:
      // 200 either way: the console asks every server, and a 404 would be
      // an error in every page's log on a server alone.
      if (!hooks_.cluster) return json({{"nats", false}, {"members", nlohmann::json::array()}});
      return json(hooks_.cluster());
    case Endpoint::Radar: {
      auto q = parseRadarQuery(r.query);
      if (!q) return error(400, q.error().detail);
      return json(radarJson(weather_, *q));
    }
    case Endpoint::Events: return r.method == "POST" ? lightning(r) : events(r.query);
    case Endpoint::Changes: return changes(r);
    case Endpoint::Scenario: return scenario(r);
    case Endpoint::Metar: return metar(r);
    case Endpoint::MetarStations: return json(metarStations_.list(options_.stations, weather_.view()));
    case Endpoint::Grib: return grib(r);
    case Endpoint::Feed: break;  // an upgrade: HttpExchange hands it to the feed
  }
  return error(426, "upgrade: GET /api/ws is a WebSocket (send Upgrade: websocket)");
}

HttpReply HttpApi::metrics() {
  std::string m;
  auto line = [&m](const char* name, const char* help, const char* type, std::uint64_t v) {
    appendMetric(m, name, type, help, v);
  };
  line("skyshell_http_requests_total", "HTTP requests handled", "counter", counters_.requests);
  line("skyshell_http_connections", "HTTP connections in flight", "gauge", connectionsInFlight());
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

HttpReply HttpApi::events(std::string_view query) {
  std::size_t limit = kDefaultEvents;
  if (query.rfind("limit=", 0) == 0) {
    const std::string_view v = query.substr(6);
    std::size_t n = 0;
    const auto [end, err] = std::from_chars(v.data(), v.data() + v.size(), n);
    if (err != std::errc() || end != v.data() + v.size() || n == 0 || n > kMaxEvents)
      return error(400, "limit: '" + std::string(utf8::cut(v, 64)) + "' is not in 1..10000");
    limit = n;
  }
  nlohmann::json list = nlohmann::json::array();
  for (const auto& e : weather_.events(limit)) list.push_back(toJson(e));
  nlohmann::json flashes = nlohmann::json::array();
  if (hooks_.flashes)
    for (const auto& f : hooks_.flashes(std::min(limit, kMaxRecentFlashes))) flashes.push_back(toJson(f));
  return json({{"events", list}, {"lightning", flashes}});
}

HttpReply HttpApi::lightning(const ApiRequest& r) {
  auto request = parseFlashRequest(r.body);
  if (!request) {
    ++counters_.rejected;
    refused(RejectReason::HttpInvalid, request.error().detail);
    return error(400, request.error().detail);
  }
  if (!hooks_.triggerLightning) return error(501, "lightning: this server has no stream to send a flash on");
  return {201, "application/json", dumpJson({{"lightning", toJson(hooks_.triggerLightning(*request))}})};
}

HttpReply HttpApi::unauthorized(const char* what) {
  ++counters_.unauthorized;
  refused(RejectReason::Unauthorized, what);
  return error(401, std::string("authorization: ") +
                        (options_.token.empty() ? "this server has no token: read-only" : what));
}

HttpReply HttpApi::changes(const ApiRequest& r) {
  auto request = parseChangeRequest(r.body);
  if (!request) {
    ++counters_.rejected;
    refused(RejectReason::HttpInvalid, request.error().detail);
    return error(400, request.error().detail);
  }
  request->source = "api";
  if (request->author.empty()) request->author = "api";
  auto applied = weather_.submit(*request);
  if (!applied) {
    ++counters_.rejected;
    refused(RejectReason::HttpInvalid, applied.error().detail);
    if (options_.log)
      options_.log->info("event=change_refused source=api author={:?} detail={:?}", request->author,
                         applied.error().detail);
    // Io and Timeout: the change was fine but could not be stored now (a
    // follower of a NATS cluster, a store that failed): worth a retry, there
    // or at the leader the detail names.
    const ErrorCode code = applied.error().code;
    return error(code == ErrorCode::Unsupported                        ? 501
                 : code == ErrorCode::Io || code == ErrorCode::Timeout ? 503
                                                                       : 400,
                 applied.error().detail);
  }
  ++counters_.applied;
  if (options_.log)
    options_.log->info("event=change_applied source=api sequence={} author={:?} summary={:?}", applied->sequence,
                       request->author, applied->summary);
  return json({{"sequence", applied->sequence}, {"clock_s", applied->clock_s}, {"summary", applied->summary}});
}

HttpReply HttpApi::scenario(const ApiRequest& r) {
  auto upload = parseScenarioUpload(r.body);
  if (!upload) {
    refused(RejectReason::ScenarioInvalid, upload.error().detail);
    return error(400, upload.error().detail);
  }
  auto parsed = parseScenario(upload->toml, upload->name);
  Result<AppliedChange> applied =
      parsed ? weather_.loadScenario(*parsed, upload->name, upload->author.empty() ? "api" : upload->author)
             : Result<AppliedChange>(tl::unexpected(parsed.error()));
  if (!applied) {
    refused(RejectReason::ScenarioInvalid, applied.error().detail);
    if (options_.log)
      options_.log->info("event=scenario_refused name={:?} detail={:?}", upload->name, applied.error().detail);
    // The detail may quote the TOML, which is not JSON and may be any bytes.
    return {400, "application/json",
            dumpJson(scenarioErrorJson(utf8::sanitiseAndCut(applied.error().detail, 1024), upload->name))};
  }
  if (options_.log)
    options_.log->info("event=change_applied source=scenario sequence={} author={:?} summary={:?}", applied->sequence,
                       upload->author, applied->summary);
  return json({{"sequence", applied->sequence},
               {"clock_s", applied->clock_s},
               {"summary", applied->summary},
               {"layers", parsed->layers.size()},
               {"timeline", parsed->timeline.size()}});
}

HttpReply HttpApi::metar(const ApiRequest& r) {
  auto request = parseMetarRequest(r.body);
  if (!request) {
    ++counters_.rejected;
    refused(RejectReason::HttpInvalid, request.error().detail);
    return error(400, request.error().detail);
  }
  // The route's TokenRule::WhenApplying: a preview reads; applying changes
  // the weather and needs the token.
  if (request->apply && !r.hasToken) return unauthorized("applying METAR needs the token");
  const MetarReply reply = handleMetar(*request, options_.stations, weather_);
  if (reply.body.contains("reports"))
    for (const auto& report : reply.body["reports"])
      if (report.value("ok", true) == false) refused(RejectReason::MetarUnparsed, "a METAR report did not parse");
  if (request->apply) {
    if (reply.status == 200) {
      ++counters_.applied;
      metarStations_.remember(*request, reply.body, options_.stations);
      if (options_.log)
        options_.log->info("event=change_applied source=metar sequence={} summary={:?}",
                           reply.body["applied"]["sequence"].get<std::uint64_t>(),
                           reply.body["applied"]["summary"].get<std::string>());
    } else {
      ++counters_.rejected;
      refused(RejectReason::HttpInvalid, "METAR not applied");
    }
  }
  return {reply.status, "application/json", dumpJson(reply.body)};
}

HttpReply HttpApi::consoleFile(std::string_view method, std::string_view path) const {
  if (method == "GET" && options_.console)
    if (const ConsoleFile* f = options_.console->find(std::string(path))) return {200, f->contentType, f->body};
  return error(404, "path: no " + std::string(method) + " " + std::string(path));
}

HttpReply HttpApi::refuseFeed() {
  refused(RejectReason::WsRefused, "console feed full");
  return error(503, "ws: " + std::to_string(feed_.clients()) + " console clients connected, at most " +
                        std::to_string(options_.feed.maxClients));
}

namespace {

// A name the operator gave an uploaded file (?name=...): letters, digits,
// '.', '-', '_', at most 100 of them; anything else is the default.
std::string uploadName(std::string_view query) {
  constexpr std::string_view key = "name=";
  std::string name;
  for (std::size_t at = 0; at <= query.size();) {
    const std::size_t amp = std::min(query.find('&', at), query.size());
    const std::string_view pair = query.substr(at, amp - at);
    if (pair.substr(0, key.size()) == key) name = std::string(pair.substr(key.size()));
    at = amp + 1;
  }
  const bool ok = !name.empty() && name.size() <= 100 && name.find_first_not_of(
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-") == std::string::npos;
  return ok ? name : "upload.grib2";
}

}  // namespace

HttpReply HttpApi::gribRefused(int status, const std::string& detail) {
  ++counters_.rejected;
  refused(RejectReason::HttpInvalid, detail);
  if (options_.log) options_.log->info("event=grib_refused detail={:?}", detail);
  return error(status, utf8::sanitiseAndCut(detail, 1024));
}

std::optional<HttpReply> HttpApi::grib(const ApiRequest& r) {
  // What runs off the io thread: reading and decoding the files, building
  // the forecast. `stop` is asked when the API closes.
  std::function<Result<DecodedForecast>(std::stop_token stop)> decode;
  // The forecast's first valid time goes where the weather clock is when it
  // is asked for, however long the decode takes.
  const double anchor_s = weather_.clockNow();
  if (r.body.size() >= 4 && r.body.substr(0, 4) == "GRIB") {
    decode = [bytes = std::string(r.body), name = uploadName(r.query), anchor_s,
              decoder = options_.gribDecoder](std::stop_token stop) mutable {
      decoder.stop = std::move(stop);
      return decodeUploadedForecast(std::as_bytes(std::span(bytes.data(), bytes.size())), name, anchor_s, decoder);
    };
  } else {
    const nlohmann::json body = nlohmann::json::parse(r.body, nullptr, false);
    if (body.is_discarded() || !body.is_object())
      return gribRefused(400, "body: a GRIB2 file (starting 'GRIB') or a JSON object {\"path\": ...} or {\"remove\": true}");
    if (body.value("remove", false) == true) {
      auto removed = weather_.removeForecast("api", "grib");
      if (!removed) return gribRefused(400, removed.error().detail);
      ++counters_.applied;
      return json({{"sequence", removed->sequence}, {"summary", removed->summary}});
    }
    if (!body.contains("path") || !body["path"].is_string())
      return gribRefused(400, "path: missing (a file or directory inside --grib-dir)");
    if (options_.gribDir.empty()) return gribRefused(403, "path: this server takes no GRIB paths (start it with --grib-dir)");
    auto where = pathInside(options_.gribDir, body["path"].get<std::string>());
    if (!where) return gribRefused(400, where.error().detail);
    auto found = gribInputs(*where);
    if (!found) return gribRefused(404, "path: " + body["path"].get<std::string>() + ": no GRIB file there");
    decode = [inputs = std::move(*found), name = where->filename().string(), anchor_s,
              decoder = options_.gribDecoder](std::stop_token stop) mutable {
      decoder.stop = std::move(stop);
      return decodeForecast(inputs, name, anchor_s, decoder);
    };
  }
  // Without a transport that waits (HttpExchange::feed), decoded here.
  if (!r.later) return gribDecoded(decode({}));
  const bool started = gribDecodes_.tryStart([this, decode = std::move(decode), later = r.later](std::stop_token stop) {
    try {
      auto decoded = std::make_shared<Result<DecodedForecast>>(decode(std::move(stop)));
      return WorkerSlots::Finish([this, later, decoded] { later([&] { return gribDecoded(std::move(*decoded)); }); });
    } catch (...) {
      // Rethrown where the answer is made, so it is answered as a failure
      // inside any endpoint is (500; 503 out of memory).
      return WorkerSlots::Finish([later, failure = std::current_exception()] {
        later([&]() -> HttpReply { std::rethrow_exception(failure); });
      });
    }
  });
  if (started) return std::nullopt;
  const std::string detail = "grib: another forecast is decoding (at most " + std::to_string(gribDecodes_.slots()) +
                             " at a time); try again once it has loaded";
  refused(RejectReason::GribBusy, detail);
  return HttpReply{503, "application/json", errorJson(detail), kGribBusyRetryAfter_s};
}

HttpReply HttpApi::gribDecoded(Result<DecodedForecast> decoded) {
  if (!decoded) return gribRefused(decoded.error().code == ErrorCode::TooLarge ? 413 : 400, decoded.error().detail);
  const std::vector<std::string> skipped = decoded->skipped;
  auto applied = applyForecast(weather_, std::move(*decoded), "api", "grib");
  if (!applied) return gribRefused(applied.error().code == ErrorCode::Io ? 500 : 400, applied.error().detail);
  ++counters_.applied;
  if (options_.log)
    options_.log->info("event=change_applied source=grib sequence={} summary={:?}", applied->sequence, applied->summary);
  nlohmann::json skips = nlohmann::json::array();
  for (std::size_t k = 0; k < skipped.size() && k < 100; ++k) skips.push_back(utf8::sanitiseAndCut(skipped[k], 300));
  return json({{"sequence", applied->sequence},
               {"clock_s", applied->clock_s},
               {"summary", applied->summary},
               {"forecast", forecastJson(weather_.forecast().get())},
               {"skipped", skips},
               {"skipped_total", skipped.size()}});
}

}  // namespace sky::server
