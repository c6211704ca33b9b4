// skyshell-relay: serves the weather stream near the renderers. It takes the
// weather servers' weather from NATS (NatsWeather in relay mode: never leads,
// refuses every change): by default only the global part and the S2 cells its
// renderers' areas cover (nats_cells.hpp), or with --follow log every whole
// state of the log. It serves the same TCP stream as skyshell-weatherd, so a
// renderer's --server may name either.
// This file is the edge: command line, logging to stderr, exit codes.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "sky/server/console_feed.hpp"
#include "sky/server/grib_isolated.hpp"
#include "sky/server/http_api.hpp"
#include "sky/server/main_support.hpp"
#include "sky/server/nats_weather.hpp"
#include "sky/server/server.hpp"
#include "sky/server/weather_state.hpp"

namespace {

// Exit codes as skyshell-weatherd's: 0 clean shutdown, 1 runtime failure
// (bind, port file, NATS unusable), 2 bad command line.
constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;

struct RelayOptions {
  sky::server::ServerOptions stream;
  std::string portFile;
  int heartbeatMs = 1000;
  std::string httpListen = "127.0.0.1";
  int httpPort = -1;
  std::string httpPortFile;
  std::string natsUrls;
  std::string logLevel = "info";
  std::string gribDecoder;
  std::string follow = "cells";
};

void addOptions(CLI::App& app, RelayOptions& o) {
  app.add_option("--nats", o.natsUrls,
                 "NATS servers (nats://host:port, comma-separated) of the weather servers' cluster: the relay "
                 "follows their weather log")
      ->required();
  app.add_option("--listen", o.stream.listenAddress, "Address the weather stream listens on")->capture_default_str();
  app.add_option("--port", o.stream.port, "TCP port of the weather stream; 0 picks a free one")->capture_default_str();
  app.add_option("--port-file", o.portFile, "Write the stream's port number here once listening");
  app.add_option("--max-subscribers", o.stream.maxSubscribers,
                 "stream subscribers served at once; past it a connection is told \"server full\" and closed")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, sky::server::kMaxSubscribersOption));
  app.add_option("--heartbeat-ms", o.heartbeatMs, "Heartbeat period, ms")
      ->check(CLI::Range(1, 3'600'000))
      ->capture_default_str();
  app.add_option("--http-listen", o.httpListen, "Address of the read-only HTTP endpoint")->capture_default_str();
  app.add_option("--http-port", o.httpPort,
                 "Port of the read-only HTTP endpoint (/healthz, /metrics, GET /api/state, /api/renderers, "
                 "/api/cluster; "
                 "0 picks a free one; default: none)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--http-port-file", o.httpPortFile, "Write the HTTP port here once listening");
  app.add_option("--grib-decoder", o.gribDecoder,
                 "The GRIB decoder executable for the forecasts the log names (default: skyshell-grib-decode "
                 "beside this executable)");
  app.add_option("--follow", o.follow,
                 "cells: take the global part of the weather and the S2 cells (level 6) the renderers' areas "
                 "cover; log: every whole state of the weather's log, as a standby server does")
      ->check(CLI::IsMember({"cells", "log"}))
      ->capture_default_str();
  app.add_option("--log-level", o.logLevel, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->capture_default_str();
}

std::vector<std::string> splitUrls(const std::string& list) {
  std::vector<std::string> urls;
  std::stringstream in(list);
  for (std::string url; std::getline(in, url, ',');)
    if (!url.empty()) urls.push_back(url);
  return urls;
}

std::string hostForUrl(const std::string& address) {
  return address.find(':') != std::string::npos ? "[" + address + "]" : address;
}

// The read-only HTTP endpoint: no token, so the API refuses every change
// (the relay's committer would refuse them too).
sky::Result<std::unique_ptr<sky::server::HttpApi>> startHttp(sky::server::Server& s, const RelayOptions& o,
                                                             sky::server::NatsWeather& nats,
                                                             const std::shared_ptr<spdlog::logger>& log) {
  sky::server::HttpApiOptions http;
  http.listenAddress = o.httpListen;
  http.port = static_cast<std::uint16_t>(o.httpPort);
  http.serverId = o.stream.serverId;
  http.log = log;
  sky::server::HttpApiHooks hooks;
  hooks.subscribers = [&s] { return s.subscribers(); };
  hooks.extraMetrics = [&s, &nats] { return s.streamMetrics() + nats.metrics(); };
  hooks.renderers = [&s] { return sky::server::renderersJson(s.renderers()); };
  hooks.rejections = &s.rejections();
  hooks.cluster = [&nats] { return nats.cluster(); };
  return sky::server::HttpApi::create(s.io(), std::move(http), s.weather(), std::move(hooks));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"skyshell-relay: serves the Skyshell weather stream to nearby renderers from the weather servers' "
               "NATS log (read-only)"};
  app.set_config("--config", "",
                 "TOML file whose keys are these options without the dashes "
                 "(see deploy/relay.example.toml); the command line wins");
  // A misspelt key in the config must be an error, not silently ignored.
  app.allow_config_extras(CLI::config_extras_mode::error);
  RelayOptions o;
  addOptions(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  auto log = sky::server::stderrLogger("relay", o.logLevel);

  o.stream.heartbeatInterval = std::chrono::milliseconds(o.heartbeatMs);
  // Unique among the relays of one host: the registry and the logs name it.
  o.stream.serverId = "skyshell-relay@" + sky::server::hostName() + ":" + std::to_string(::getpid());
  o.stream.log = log;
  // An empty weather until the log's newest entry replaces it (a relay has
  // no scenario of its own; with an empty log it serves no clouds).
  sky::server::WeatherState state(sky::server::Scenario{}, sky::server::WallClock::now());
  auto server = sky::server::Server::create(o.stream, std::move(state));
  if (!server) {
    log->error("{}", sky::describe(server.error()));
    return kExitRuntime;
  }
  sky::server::Server& s = **server;

  sky::server::NatsWeatherOptions natsOptions;
  natsOptions.log.urls = splitUrls(o.natsUrls);
  natsOptions.serverId = o.stream.serverId;
  natsOptions.relay = true;
  natsOptions.followCells = o.follow == "cells";
  natsOptions.log.sharedDelivery = natsOptions.followCells;
  natsOptions.logger = log;
  natsOptions.gribDecoder.executable =
      o.gribDecoder.empty() ? sky::server::defaultGribDecoder() : std::filesystem::path(o.gribDecoder);
  auto started = sky::server::NatsWeather::start(s, std::move(natsOptions));
  if (!started) {
    log->error("event=nats_unusable nats={:?} detail={:?}", o.natsUrls, sky::describe(started.error()));
    return kExitRuntime;
  }
  std::unique_ptr<sky::server::NatsWeather> nats = std::move(*started);
  s.onShutdown([&nats] { nats->close(); });

  const std::string host = hostForUrl(o.stream.listenAddress);
  std::cout << "skyshell-relay listening on " << host << ":" << s.port() << std::endl;
  if (!o.portFile.empty()) {
    if (auto r = sky::server::writePortFile(o.portFile, s.port()); !r) {
      log->error("{}", sky::describe(r.error()));
      return kExitRuntime;
    }
  }
  log->info("event=listening stream={}:{} nats={:?} state_hash={:016x}", host, s.port(), o.natsUrls,
            s.weather().stateHash());

  std::unique_ptr<sky::server::HttpApi> api;
  if (o.httpPort >= 0) {
    auto created = startHttp(s, o, *nats, log);
    if (!created) {
      log->error("{}", sky::describe(created.error()));
      return kExitRuntime;
    }
    api = std::move(*created);
    s.onShutdown([&api] { api->close(); });
    s.onRenderersChanged([&api] { api->renderersChanged(); });
    std::cout << "skyshell-relay HTTP (read-only) on " << o.httpListen << ":" << api->port() << std::endl;
    if (!o.httpPortFile.empty()) {
      if (auto r = sky::server::writePortFile(o.httpPortFile, api->port()); !r) {
        log->error("{}", sky::describe(r.error()));
        return kExitRuntime;
      }
    }
  }
  nats->elect(api ? "http://" + hostForUrl(o.httpListen) + ":" + std::to_string(api->port()) : std::string(),
              host + ":" + std::to_string(s.port()));
  s.run();
  return EXIT_SUCCESS;
}
