// skyshell-weatherd: the Skyshell weather server. Loads a scenario, listens on
// TCP (loopback by default) and streams the weather to renderers. This file is
// the edge: command line, config file, logging to stderr, exit codes.
#include <unistd.h>

#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "sky/server/cigi_weather_input.hpp"
#include "sky/server/console_files.hpp"
#include "sky/server/forecast_files.hpp"
#include "sky/server/http_api.hpp"
#include "sky/server/main_support.hpp"
#include "sky/server/metar_changes.hpp"
#include "sky/server/nats_weather.hpp"
#include "sky/server/scenario.hpp"
#include "sky/server/server.hpp"
#include "sky/server/weather_store.hpp"
#include "sky/server/weather_state.hpp"

namespace {

// Exit codes: 0 clean shutdown, 1 runtime failure (bind, port file), 2 bad
// input (command line, config file, scenario), 3 the weather database cannot
// be used (corrupt, not a database, locked by another process, unreadable
// saved state). 3 needs an operator: deploy/skyshell-weatherd.service does
// not restart on it (RestartPreventExitStatus=3), where a restart loop would
// only repeat the error.
constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitStorage = 3;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"skyshell-weatherd: streams the Skyshell weather state to renderers"};
  app.set_config("--config", "",
                 "TOML file whose keys are these options without the dashes "
                 "(see deploy/weatherd.example.toml); the command line wins");
  // A misspelt key in the config must be an error, not silently ignored.
  app.allow_config_extras(CLI::config_extras_mode::error);

  std::string scenarioPath;
  sky::server::ServerOptions options;
  std::string portFile;
  int heartbeatMs = 1000;
  std::string logLevel = "info";
  app.add_option("--scenario", scenarioPath, "Scenario TOML file (deploy/scenarios/*.toml)")
      ->required();
  app.add_option("--listen", options.listenAddress, "Address to listen on")->capture_default_str();
  app.add_option("--port", options.port, "TCP port; 0 picks a free one")->capture_default_str();
  app.add_option("--port-file", portFile, "Write the port number here once listening");
  app.add_option("--max-subscribers", options.maxSubscribers,
                 "stream subscribers served at once; past it a connection is told \"server full\" and closed "
                 "(each costs the server its tile cache areas: docs/weather-server-scaling.md has the cost to 512)")
      ->capture_default_str()
      ->check(CLI::Range(std::size_t{1}, sky::server::kMaxSubscribersOption));
  app.add_option("--heartbeat-ms", heartbeatMs, "Heartbeat period, ms")
      ->check(CLI::Range(1, 3'600'000))
      ->capture_default_str();
  sky::server::HttpApiOptions http;
  int httpPort = -1;
  std::string httpPortFile, tokenFile;
  app.add_option("--http-listen", http.listenAddress, "Address of the HTTP API")->capture_default_str();
  app.add_option("--http-port", httpPort, "HTTP API port (0 picks a free one; default: no HTTP API)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--http-port-file", httpPortFile, "Write the HTTP port here once listening");
  app.add_option("--token-file", tokenFile,
                 "File whose first line is the token that changes need (without it the API is read-only)");
  app.add_option("--http-allowed-host", http.allowedHosts,
                 "A host name that reaches the HTTP API besides localhost and the listen address (repeatable; "
                 "other Host headers get 403, see server/API.md)");
  app.add_option("--http-allowed-origin", http.allowedOrigins,
                 "A browser Origin allowed besides the server's own page, e.g. http://ops-console:8080 (repeatable)");
  std::string stationsPath;
  app.add_option("--metar-stations", stationsPath,
                 "METAR station table for POST /api/metar: CSV icao,lat_deg,lon_deg,elevation_m "
                 "(deploy/metar/stations.csv); requests may also bring their own");
  std::string consoleDir;
  auto* consoleOption = app.add_option(
      "--console-dir", consoleDir,
      "Folder of the operator console's files, served at http://<http-listen>:<http-port>/ (default: "
      "<executable's folder>/" SKY_CONSOLE_RELATIVE_DIR ", where the build and the install put it)");
  std::string dbPath;
  app.add_option("--db", dbPath,
                 "SQLite file of the live weather: restored at start when it holds a state, every accepted change "
                 "committed to it (default: none, the weather lives in memory)");
  std::string cigiListen = "127.0.0.1", cigiPortFile;
  int cigiPort = -1;
  app.add_option("--cigi-listen", cigiListen, "Address of the CIGI weather input (UDP)")->capture_default_str();
  app.add_option("--cigi-port", cigiPort,
                 "UDP port taking CIGI 3.3 Weather Control and Environmental Region Control from a host "
                 "(0 picks a free one; default: no CIGI input)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--cigi-port-file", cigiPortFile, "Write the CIGI UDP port here once listening");
  std::string gribPath, gribDir, gribDecoder;
  app.add_option("--grib", gribPath,
                 "GRIB2 forecast to load at start: a file, or a directory of files (one per forecast step); "
                 "its layers take slots 30-34 and its first valid time starts at the weather clock's now");
  app.add_option("--grib-dir", gribDir,
                 "Directory POST /api/grib may load files from by path (default: none, only uploaded files)");
  app.add_option("--grib-decoder", gribDecoder,
                 "The GRIB decoder executable (default: skyshell-grib-decode beside this executable)");
  app.add_option("--lightning-rate", options.lightning.rate_perMin100km2,
                 "Lightning flashes a minute per 100 km^2 of cumulonimbus at density 1 (0: only asked-for flashes)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--lightning-seed", options.lightning.seed, "Seed of the lightning process (same seed, same flashes)")
      ->capture_default_str();
  std::string natsUrls;
  int natsLeaseMs = 3000;
  app.add_option("--nats", natsUrls,
                 "NATS servers (nats://host:port, comma-separated) whose JetStream holds the weather: every accepted "
                 "change is stored on a stream replicated on three servers before it is acknowledged, and servers "
                 "started with the same --nats share one weather, one leading (default: none, one server alone)");
  app.add_option("--nats-lease-ms", natsLeaseMs,
                 "With --nats: the leader's lease lasts this long unless renewed (a follower takes over this long "
                 "after the leader is lost)")
      ->check(CLI::Range(500, 60000))
      ->capture_default_str();
  std::string natsCells = "on";
  app.add_option("--nats-cells", natsCells,
                 "With --nats: while leading, publish each state cut by S2 cell for the relays that take the weather "
                 "by cell (on); off spares the leader that work when every relay follows the log (relays by cell "
                 "then read whole states from the log)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app.add_option("--log-level", logLevel, "trace, debug, info, warn, error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}))
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }

  // Logs go to stderr; stdout carries only the "listening on" lines that
  // scripts wait for.
  auto log = sky::server::stderrLogger("weatherd", logLevel);

  auto scenario = sky::server::loadScenario(scenarioPath);
  if (!scenario) {
    log->error("event=bad_scenario detail={:?}", sky::describe(scenario.error()));
    return kExitBadInput;
  }

  options.heartbeatInterval = std::chrono::milliseconds(heartbeatMs);
  options.serverId = "skyshell-weatherd@" + sky::server::hostName();
  options.log = log;
  sky::server::WeatherState state(*scenario, sky::server::WallClock::now());
  auto server = sky::server::Server::create(options, std::move(state));
  if (!server) {
    log->error("{}", sky::describe(server.error()));
    return kExitRuntime;
  }

  const bool v6 = options.listenAddress.find(':') != std::string::npos;
  const std::string host = v6 ? "[" + options.listenAddress + "]" : options.listenAddress;
  std::cout << "skyshell-weatherd listening on " << host << ":" << (*server)->port() << std::endl;
  if (!portFile.empty()) {
    if (auto r = sky::server::writePortFile(portFile, (*server)->port()); !r) {
      log->error("{}", sky::describe(r.error()));
      return kExitRuntime;
    }
  }
  log->info("event=listening scenario={:?} layers={} stream={}:{}", scenarioPath, scenario->layers.size(),
            host, (*server)->port());

  // The scenario's timeline, checked against the weather it will meet (a
  // weather file restored below replaces it with the one it saved).
  if (auto r = (*server)->weather().scheduleTimeline(*scenario, std::filesystem::path(scenarioPath).filename().string());
      !r) {
    log->error("event=bad_scenario detail={:?}", sky::describe(r.error()));
    return kExitBadInput;
  }
  if (!scenario->timeline.empty())
    log->info("event=timeline_scheduled scenario={:?} entries={} first_at_s={:.0f}", scenarioPath, scenario->timeline.size(),
              scenario->timeline.front().at_s);

  // With --nats the weather is the NATS log's: it replaces the scenario's
  // (when the log holds one) and no SQLite file is used.
  sky::server::GribDecoder decoder;
  decoder.executable = gribDecoder.empty() ? sky::server::defaultGribDecoder() : std::filesystem::path(gribDecoder);
  std::unique_ptr<sky::server::NatsWeather> nats;
  if (!natsUrls.empty()) {
    if (!dbPath.empty() || !gribPath.empty()) {
      log->error("--nats with {}: with --nats the weather lives in the NATS stream, which holds no SQLite file; "
                 "a forecast is loaded on the leader with POST /api/grib once it leads",
                 !dbPath.empty() ? "--db" : "--grib");
      return kExitBadInput;
    }
    sky::server::NatsWeatherOptions natsOptions;
    std::stringstream list(natsUrls);
    for (std::string url; std::getline(list, url, ',');)
      if (!url.empty()) natsOptions.log.urls.push_back(url);
    natsOptions.log.leaseTtl = std::chrono::milliseconds(natsLeaseMs);
    natsOptions.publishCells = natsCells == "on";
    // Unique among the servers of one host: the lease names its holder.
    natsOptions.serverId = options.serverId + ":" + std::to_string(::getpid());
    natsOptions.logger = log;
    natsOptions.gribDecoder = decoder;
    auto started = sky::server::NatsWeather::start(**server, std::move(natsOptions));
    if (!started) {
      log->error("event=nats_unusable nats={:?} detail={:?}", natsUrls, sky::describe(started.error()));
      return kExitRuntime;
    }
    nats = std::move(*started);
    (*server)->onShutdown([&nats] { nats->close(); });
  }

  std::optional<sky::server::WeatherStore> store;
  if (!dbPath.empty()) {
    auto storageFailed = [&](const sky::Error& e) {
      log->error("event=database_unusable db={:?} detail={:?}; exiting with {} (not restarted)", dbPath,
                 sky::describe(e), kExitStorage);
      std::cerr << "skyshell-weatherd: weather database " << dbPath << ": " << sky::describe(e) << std::endl;
      return kExitStorage;
    };
    auto opened = sky::server::WeatherStore::open(dbPath);
    if (!opened) return storageFailed(opened.error());
    store.emplace(std::move(*opened));
    auto saved = store->load();
    if (!saved) return storageFailed(saved.error());
    auto& weather = (*server)->weather();
    if (*saved) {
      if (auto r = weather.restore((*saved)->state, std::move((*saved)->events),
                                   sky::server::storeForecastLoader(*store, decoder));
          !r)
        return storageFailed(r.error());
      log->info("event=restored db={:?} sequence={} layers={} state_hash={:016x}", dbPath,
                weather.view().lastSequence, weather.view().layers.size(), weather.stateHash());
    } else if (auto r = store->save(weather.toJson(), nullptr); !r) {
      return storageFailed(r.error());
    } else {
      log->info("event=new_db db={:?}", dbPath);
    }
    weather.attachStore(&*store);
  }

  if (!gribPath.empty()) {
    auto& weather = (*server)->weather();
    auto inputs = sky::server::gribInputs(gribPath);
    auto decoded = inputs ? sky::server::decodeForecast(*inputs, std::filesystem::path(gribPath).filename().string(),
                                                        weather.clockNow(), decoder)
                          : sky::Result<sky::server::DecodedForecast>(tl::unexpected(inputs.error()));
    for (const std::string& skip : decoded ? decoded->skipped : std::vector<std::string>{})
      log->warn("event=grib_skipped detail={:?}", skip);
    auto applied = decoded ? sky::server::applyForecast(weather, std::move(*decoded), "cli", "grib")
                           : sky::Result<sky::server::AppliedChange>(tl::unexpected(decoded.error()));
    if (!applied) {
      log->error("event=bad_grib file={:?} detail={:?}", gribPath, sky::describe(applied.error()));
      return kExitBadInput;
    }
    log->info("event=change_applied source=grib sequence={} summary={:?}", applied->sequence, applied->summary);
    for (const std::string& note : weather.forecast()->forecast->notes()) log->info("event=grib_layer detail={:?}", note);
  }

  sky::server::Server& s = **server;
  std::unique_ptr<sky::server::CigiWeatherInput> cigi;
  // (Every accepted change from any input reaches every subscriber and the
  // console through the LiveWeather's listeners.)

  std::unique_ptr<sky::server::HttpApi> api;
  if (httpPort >= 0) {
    if (!tokenFile.empty()) {
      std::ifstream in(tokenFile);
      if (!in || !std::getline(in, http.token) || http.token.empty()) {
        log->error("--token-file {}: cannot read a token from its first line", tokenFile);
        return kExitBadInput;
      }
    }
    if (!stationsPath.empty()) {
      std::ifstream in(stationsPath);
      std::stringstream text;
      text << in.rdbuf();
      if (!in) {
        log->error("--metar-stations {}: cannot read", stationsPath);
        return kExitBadInput;
      }
      auto table = sky::server::parseStationTable(text.str(), stationsPath);
      if (!table) {
        log->error("{}", sky::describe(table.error()));
        return kExitBadInput;
      }
      http.stations = std::move(*table);
      log->info("event=metar_stations file={:?} stations={}", stationsPath, http.stations.size());
    }
    // The console is optional for the API: a missing default folder is a
    // warning, a folder named on the command line that cannot be read is not.
    const bool consoleGiven = consoleOption->count() > 0;
    const std::filesystem::path consolePath =
        consoleGiven ? std::filesystem::path(consoleDir) : sky::server::defaultConsoleDir(SKY_CONSOLE_RELATIVE_DIR);
    if (auto files = sky::server::ConsoleFiles::load(consolePath); files) {
      log->info("console: {} files from {}", files->size(), consolePath.string());
      http.console = std::make_shared<const sky::server::ConsoleFiles>(std::move(*files));
    } else if (consoleGiven) {
      log->error("--console-dir: {}", sky::describe(files.error()));
      return kExitBadInput;
    } else {
      log->warn("no console pages: {}", sky::describe(files.error()));
    }
    http.port = static_cast<std::uint16_t>(httpPort);
    http.serverId = options.serverId;
    http.log = log;
    auto moreMetrics = [&cigi, &s, &nats]() -> std::string {
      std::string m = s.streamMetrics();
      if (nats) m += nats->metrics();
      const auto& commits = s.weather().commitStats();
      m += "# HELP skyshell_commit_seconds time to commit an accepted change (to SQLite, or JetStream with --nats) before acknowledging it\n"
           "# TYPE skyshell_commit_seconds summary\n"
           "skyshell_commit_seconds_sum " + std::to_string(commits.total_s) + "\n"
           "skyshell_commit_seconds_count " + std::to_string(commits.count) + "\n"
           "# HELP skyshell_commit_seconds_max longest commit so far\n# TYPE skyshell_commit_seconds_max gauge\n"
           "skyshell_commit_seconds_max " + std::to_string(commits.max_s) + "\n";
      if (!cigi) return m;
      auto line = [&m](const char* name, const char* help, std::uint64_t v) {
        m += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " counter\n" + name + " " +
             std::to_string(v) + "\n";
      };
      const auto& c = cigi->counters();
      line("skyshell_cigi_datagrams_total", "CIGI weather datagrams received", c.datagrams);
      line("skyshell_cigi_malformed_total", "CIGI weather datagrams dropped as malformed", c.malformed);
      line("skyshell_cigi_rejected_total", "CIGI weather refused by the model", c.rejected);
      line("skyshell_cigi_applied_total", "CIGI weather datagrams that changed the weather", c.applied);
      line("skyshell_cigi_senders_refused_total", "CIGI datagrams dropped: a new sender past the sender cap",
           c.senderRefused);
      line("skyshell_cigi_commits_total", "batched commits of CIGI changes", c.commits);
      return m;
    };
    sky::server::HttpApiHooks hooks;
    hooks.subscribers = [&s] { return s.subscribers(); };
    hooks.extraMetrics = moreMetrics;
    hooks.renderers = [&s] { return sky::server::renderersJson(s.renderers()); };
    hooks.rejections = &s.rejections();
    hooks.triggerLightning = [&s](const sky::server::FlashRequest& r) { return s.triggerLightning(r); };
    hooks.flashes = [&s](std::size_t limit) { return s.recentFlashes(limit); };
    if (nats) hooks.cluster = [&nats] { return nats->cluster(); };
    http.gribDecoder = decoder;
    http.gribDir = gribDir;
    auto created = sky::server::HttpApi::create(s.io(), http, s.weather(), std::move(hooks));
    if (!created) {
      log->error("{}", sky::describe(created.error()));
      return kExitRuntime;
    }
    api = std::move(*created);
    s.onShutdown([&api] { api->close(); });
    s.onRenderersChanged([&api] { api->renderersChanged(); });
    std::cout << "skyshell-weatherd HTTP API on " << http.listenAddress << ":" << api->port()
              << (http.token.empty() ? " (read-only: no --token-file)" : "") << std::endl;
    if (http.console)
      std::cout << "skyshell-weatherd console on http://"
                << (http.listenAddress.find(':') != std::string::npos ? "[" + http.listenAddress + "]"
                                                                      : http.listenAddress)
                << ":" << api->port() << "/" << std::endl;
    if (!httpPortFile.empty()) {
      if (auto r = sky::server::writePortFile(httpPortFile, api->port()); !r) {
        log->error("{}", sky::describe(r.error()));
        return kExitRuntime;
      }
    }
  }

  if (cigiPort >= 0) {
    auto created = sky::server::CigiWeatherInput::create(s.io(), cigiListen, static_cast<std::uint16_t>(cigiPort),
                                                         s.weather(), &s.rejections(), log);
    if (!created) {
      log->error("{}", sky::describe(created.error()));
      return kExitRuntime;
    }
    cigi = std::move(*created);
    s.onShutdown([&cigi] { cigi->close(); });
    std::cout << "skyshell-weatherd CIGI weather input on udp " << cigiListen << ":" << cigi->port() << std::endl;
    if (!cigiPortFile.empty()) {
      if (auto r = sky::server::writePortFile(cigiPortFile, cigi->port()); !r) {
        log->error("{}", sky::describe(r.error()));
        return kExitRuntime;
      }
    }
  }

  if (nats) {
    const std::string apiHost = http.listenAddress.find(':') != std::string::npos ? "[" + http.listenAddress + "]"
                                                                                  : http.listenAddress;
    nats->elect(api ? "http://" + apiHost + ":" + std::to_string(api->port()) : std::string(),
                host + ":" + std::to_string(s.port()));
  }
  (*server)->run();
  return EXIT_SUCCESS;
}
