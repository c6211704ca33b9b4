// Relay benchmark (issue 27): one skyshell-weatherd --nats leading, N
// skyshell-relay processes taking its weather from NATS (by cell, or the
// whole log with --follow log), and many subscribers
// spread over the relays, each with its own area, under a storm of changes
// sent to the leader's HTTP API. Real processes (a one-node nats-server with
// JetStream, the server, the relays) on loopback; the subscribers share one
// client thread of this process. Not a timed test (ctest runs it briefly,
// label bench); the numbers come from running it by hand:
//   build/release/tests/bench/sky_weatherd_relay_bench --relays 4 --subscribers 1000 --rate 50 --seconds 10
// It measures
// * change-to-delivery latency from sending the change (POST /api/changes,
//   answered once JetStream stored it) to a subscriber on a relay holding a
//   frame that has it (p50/p99 over every delivery; a subscriber that is
//   behind gets the newest state, the changes it skipped are counted as
//   coalesced), and the POST's own time to its 200;
// * each process's CPU (utime + stime from /proc) at idle and in the storm,
//   as a percentage of one core;
// * bytes per change on NATS (nats-server's /varz out_bytes: the leader's
//   appends acknowledged, each entry delivered to every relay) and on the
//   relays' sockets (skyshell_stream_bytes_total).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/sim/http_client.hpp"
#include "sky/weather/tiling.hpp"
#include "weatherd_bench_clients.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace sky::bench;
using sky::test::ChildProcess;

namespace {

constexpr const char* kToken = "relay-bench-token";
// Every subscriber gets a snapshot within this, or the run stops: 1000
// subscribers on 4 relays on this 2-core machine connect in a few seconds.
constexpr auto kConnectWait = 60s;

struct Options {
  int relays = 4;
  int subscribers = 1000;
  double rate = 50;          // changes per second
  double seconds = 10;       // storm length
  double idleSeconds = 3;    // idle measurement
  double radius_m = 120000;  // each subscriber's area (the renderer's)
  std::size_t maxTiles = 4096;
  std::string out = "/tmp/sky_weatherd_relay_bench";
  std::string json;
  bool regional = false;  // a region over every area (tiles in every snapshot), the storm a moving cell
  std::string follow = "cells";  // the relays' --follow
  int stations = 0;  // regions far from every subscriber (a continent of METAR stations), set before the storm
};

// One of our processes or nats-server, its CPU read from /proc.
struct Process {
  std::string name;
  std::unique_ptr<ChildProcess> child;
  unsigned httpPort = 0, streamPort = 0;
  double cpu0_s = 0;
};

double processCpu_s(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto close = stat.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream in(stat.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  // Fields 3..13 (state .. cmajflt) come before utime (14) and stime (15).
  for (int i = 3; i <= 13; ++i) in >> field;
  in >> utime >> stime;
  return double(utime + stime) / double(::sysconf(_SC_CLK_TCK));
}

double selfCpu_s() { return processCpu_s(::getpid()); }

std::optional<sky::sim::HttpResponse> get(unsigned port, const std::string& target) {
  sky::sim::HttpRequest r;
  r.port = static_cast<unsigned short>(port);
  r.target = target;
  auto response = sky::sim::httpRequest(r);
  if (!response || response->status != 200) return std::nullopt;
  return *response;
}

// A counter or gauge of /metrics; -1 when unreadable.
double metric(unsigned port, const std::string& name) {
  const auto r = get(port, "/metrics");
  if (!r) return -1;
  std::istringstream in(r->body);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(name + " ", 0) == 0) return std::stod(line.substr(name.size() + 1));
  return -1;
}

std::string stateHash(unsigned port) {
  const auto r = get(port, "/metrics");
  const std::string key = "skyshell_state_hash_info{hash=\"";
  if (!r) return "";
  const auto at = r->body.find(key);
  return at == std::string::npos ? "" : r->body.substr(at + key.size(), 16);
}

// nats-server's monitoring: bytes it has sent to all its clients.
double natsOutBytes(unsigned monitorPort) {
  const auto r = get(monitorPort, "/varz");
  if (!r) return -1;
  const auto j = nlohmann::json::parse(r->body, nullptr, false);
  return j.is_object() ? j.value("out_bytes", -1.0) : -1;
}

template <class F>
bool waitUntil(std::chrono::milliseconds timeout, F&& f) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (f()) return true;
    std::this_thread::sleep_for(50ms);
  }
  return f();
}

// The change of index i: layer 1 (the marker) at base kMarkerBase + i.
std::string markerChange(std::size_t i) {
  return R"({"author": "relay-bench", "changes": [{"op": "set_layer", "ramp_s": 0, "layer": {"id": 1, "type": "cumulus",
      "base_m": )" + std::to_string(kMarkerBase + double(i)) + R"(, "thickness_m": 800, "transition_band_m": 50,
      "coverage": )" + std::to_string(0.2 + 0.6 * double(i % 10) / 10) + R"(, "density": 0.8,
      "wind": {"speed_mps": 10, "from_deg": 250, "vertical_mps": 0}}}]})";
}

// A region over every subscriber's area, so every snapshot carries tiles
// (the regional storm of weatherd_bench.cpp).
std::string everywhereRegion() {
  return R"({"author": "relay-bench", "changes": [{"op": "set_region", "region": {"id": 1, "center_lat_deg": 46.0,
      "center_lon_deg": 13.0, "size_x_m": 800000, "size_y_m": 800000, "corner_radius_m": 0, "transition_m": 20000,
      "drifts_with_wind": false, "layers": [{"id": 1, "type": "cumulus", "base_m": 600, "thickness_m": 800,
      "transition_band_m": 50, "coverage": 0.9, "density": 0.8,
      "wind": {"speed_mps": 10, "from_deg": 250, "vertical_mps": 0}}]}}]})";
}

// The regional change of index i: a storm cell 60 km across moving east
// 300 m per change, its layer 9 the marker (as weatherd_bench.cpp's).
std::string stormCellChange(std::size_t i) {
  return R"({"author": "relay-bench", "changes": [{"op": "set_region", "region": {"id": 9, "center_lat_deg": 46.0,
      "center_lon_deg": )" + std::to_string(12.0 + 0.004 * double(i)) + R"(, "size_x_m": 60000, "size_y_m": 60000,
      "corner_radius_m": 30000, "transition_m": 5000, "drifts_with_wind": false, "layers": [{"id": 9,
      "type": "cumulonimbus", "base_m": )" + std::to_string(kMarkerBase + double(i)) + R"(, "thickness_m": 8000,
      "transition_band_m": 100, "coverage": 0.9, "density": 0.8,
      "wind": {"speed_mps": 10, "from_deg": 250, "vertical_mps": 0}}]}}]})";
}

// Stations `first`..`first + count - 1` (ids from 100): 20 km regions on a
// grid of 0.5 x 0.9 degrees over North America, 7000 km from every
// subscriber, each ~450 bytes of state.
std::string stationsChange(int first, int count) {
  std::string body = R"({"author": "relay-bench", "changes": [)";
  for (int k = first; k < first + count; ++k) {
    body += std::string(k > first ? "," : "") + R"({"op": "set_region", "region": {"id": )" + std::to_string(100 + k) +
            R"(, "center_lat_deg": )" + std::to_string(25 + 0.5 * (k / 60)) + R"(, "center_lon_deg": )" +
            std::to_string(-125 + 0.9 * (k % 60)) +
            R"(, "size_x_m": 20000, "size_y_m": 20000, "transition_m": 5000, "layers": [{"id": 3, "type": "cumulus",
            "base_m": 1200, "thickness_m": 900, "transition_band_m": 50, "coverage": 0.5, "density": 0.6,
            "wind": {"speed_mps": 5, "from_deg": 200, "vertical_mps": 0}}]}})";
  }
  return body + "]}";
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--relays") o.relays = std::stoi(v);
    else if (k == "--subscribers") o.subscribers = std::stoi(v);
    else if (k == "--rate") o.rate = std::stod(v);
    else if (k == "--seconds") o.seconds = std::stod(v);
    else if (k == "--idle-seconds") o.idleSeconds = std::stod(v);
    else if (k == "--radius-m") o.radius_m = std::stod(v);
    else if (k == "--out") o.out = v;
    else if (k == "--json") o.json = v;
    else if (k == "--regional") o.regional = v == "1";
    else if (k == "--follow") o.follow = v;
    else if (k == "--stations") o.stations = std::stoi(v);
    else return false;
  }
  return argc % 2 == 1 && o.relays >= 1 && o.subscribers >= 1 && o.rate > 0 && o.stations >= 0 &&
         o.stations <= 60000 && (o.follow == "cells" || o.follow == "log");
}

// A one-node nats-server with JetStream and its monitoring port.
Process startNats(const fs::path& dir, unsigned& clientPort, unsigned& monitorPort) {
  // Ports the kernel handed out and took back: free now.
  auto freePort = [] {
    asio::io_context io;
    tcp::acceptor a(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    return static_cast<unsigned>(a.local_endpoint().port());
  };
  clientPort = freePort();
  monitorPort = freePort();
  std::ofstream(dir / "nats.conf") << "listen: 127.0.0.1:" << clientPort << "\nhttp: 127.0.0.1:" << monitorPort
                                   << "\njetstream { store_dir: \"" << (dir / "store").string()
                                   << "\", max_memory_store: 64MB, max_file_store: 1GB }\n";
  Process p{"nats-server", std::make_unique<ChildProcess>(std::vector<std::string>{SKY_NATS_SERVER, "-c",
                                                                                     (dir / "nats.conf").string()},
                                                            (dir / "nats.log").string())};
  return p;
}

Process startOurs(const std::string& name, std::vector<std::string> args, const fs::path& dir) {
  args.insert(args.end(), {"--port", "0", "--port-file", (dir / (name + ".port")).string(), "--http-port", "0",
                           "--http-port-file", (dir / (name + ".http")).string(), "--max-subscribers", "4096",
                           "--log-level", "warn"});
  Process p{name, std::make_unique<ChildProcess>(args, (dir / (name + ".log")).string())};
  p.streamPort = sky::test::waitForPortFile((dir / (name + ".port")).string(), 60s);
  p.httpPort = sky::test::waitForPortFile((dir / (name + ".http")).string(), 60s);
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  const char* usage = "usage: sky_weatherd_relay_bench [--relays N] [--subscribers N] [--rate HZ] [--seconds S] "
                      "[--idle-seconds S] [--radius-m M] [--regional 0|1] [--follow cells|log] [--stations N] "
                      "[--out DIR] [--json FILE]\n";
  if (argc == 2 && std::string(argv[1]) == "--help") {
    std::printf("%s", usage);
    return 0;
  }
  if (!parse(argc, argv, o)) {
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  if (std::string(SKY_NATS_SERVER).empty() || !fs::exists(SKY_NATS_SERVER)) {
    std::fprintf(stderr, "nats-server not installed (deploy/setup installs it)\n");
    return 77;
  }
  const fs::path dir = o.out;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "token") << kToken << "\n";

  unsigned natsPort = 0, monitorPort = 0;
  // Stopped in the reverse of their start, also on an early return: the
  // relays and the server before nats-server, or they would spend their
  // shutdown waiting for it.
  struct Processes : std::vector<Process> {
    ~Processes() {
      while (!empty()) pop_back();
    }
  } procs;
  procs.push_back(startNats(dir, natsPort, monitorPort));
  // The server's NATS client gives up when nothing listens yet.
  if (!waitUntil(20s, [&] {
        asio::io_context io;
        tcp::socket socket(io);
        boost::system::error_code ec;
        socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<std::uint16_t>(natsPort)), ec);
        return !ec;
      })) {
    std::fprintf(stderr, "nats-server did not listen (logs in %s)\n", dir.c_str());
    return 1;
  }
  const std::string url = "nats://127.0.0.1:" + std::to_string(natsPort);
  procs.push_back(startOurs("weatherd", {SKY_WEATHERD, "--scenario", SKY_SCENARIO, "--nats", url, "--token-file",
                                         (dir / "token").string()},
                            dir));
  const unsigned leaderHttp = procs.back().httpPort;
  Process& leader = procs.back();
  if (leaderHttp == 0 || !waitUntil(60s, [&] {
        return metric(leaderHttp, "skyshell_nats_leader") == 1 || leader.child->wait(0ms).has_value();
      }) || leader.child->wait(0ms)) {
    std::fprintf(stderr, "the server did not lead (logs in %s)\n", dir.c_str());
    return 1;
  }
  if (o.regional) {
    sky::sim::HttpRequest post;
    post.method = "POST";
    post.port = static_cast<unsigned short>(leaderHttp);
    post.target = "/api/changes";
    post.body = everywhereRegion();
    post.bearerToken = kToken;
    const auto answer = sky::sim::httpRequest(post);
    if (!answer || answer->status != 200) {
      std::fprintf(stderr, "region refused: %s\n", answer ? answer->body.c_str() : "no answer");
      return 1;
    }
  }
  for (int first = 0; first < o.stations; first += 100) {
    sky::sim::HttpRequest post;
    post.method = "POST";
    post.port = static_cast<unsigned short>(leaderHttp);
    post.target = "/api/changes";
    post.body = stationsChange(first, std::min(100, o.stations - first));
    post.bearerToken = kToken;
    const auto answer = sky::sim::httpRequest(post);
    if (!answer || answer->status != 200) {
      std::fprintf(stderr, "stations refused: %s\n", answer ? answer->body.c_str() : "no answer");
      return 1;
    }
  }
  for (int r = 0; r < o.relays; ++r)
    procs.push_back(startOurs("relay" + std::to_string(r), {SKY_RELAY, "--nats", url, "--follow", o.follow}, dir));
  // A relay by cell holds only its subscribers' cells of the stations (none
  // before they subscribe): it has caught up once it folded the leader's
  // sequence.
  const bool partial = o.follow == "cells" && o.stations > 0;
  const std::string hash = stateHash(leaderHttp);
  const double leaderSequence = metric(leaderHttp, "skyshell_nats_applied_sequence");
  for (std::size_t p = 2; p < procs.size(); ++p)
    if (procs[p].httpPort == 0 || !waitUntil(30s, [&] {
          return partial ? metric(procs[p].httpPort, "skyshell_nats_applied_sequence") >= leaderSequence
                         : stateHash(procs[p].httpPort) == hash;
        })) {
      std::fprintf(stderr, "%s did not follow the log (logs in %s)\n", procs[p].name.c_str(), dir.c_str());
      return 1;
    }

  // Subscribers spread over the relays, areas jittered over +-2 degrees.
  Shared shared;
  const std::size_t changes = static_cast<std::size_t>(o.rate * o.seconds);
  shared.submitted.resize(changes);
  asio::io_context clientIo;
  auto guard = asio::make_work_guard(clientIo);
  std::vector<std::shared_ptr<Subscriber>> subs;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-2.0, 2.0);
  sky::stream::Subscribe area;
  area.area = {46.0, 13.0, o.radius_m};
  area.tileLevel = sky::weather::levelForRadius(o.radius_m, o.maxTiles);
  for (int i = 0; i < o.subscribers; ++i) {
    auto s = std::make_shared<Subscriber>(clientIo, shared);
    area.area.centerLat_deg = 46.0 + jitter(rng);
    area.area.centerLon_deg = 13.0 + jitter(rng);
    s->start(static_cast<std::uint16_t>(procs[2 + i % o.relays].streamPort), area);
    subs.push_back(s);
  }
  std::thread clientThread([&] { clientIo.run(); });
  waitUntil(kConnectWait, [&] { return std::all_of(subs.begin(), subs.end(), [](const auto& s) { return s->ready(); }); });
  const auto served = std::count_if(subs.begin(), subs.end(), [](const auto& s) { return s->ready(); });

  auto cpuMark = [&] {
    for (auto& p : procs) p.cpu0_s = processCpu_s(p.child->pid());
    return selfCpu_s();
  };
  auto cpuPct = [](double used_s, double wall_s) { return 100.0 * used_s / wall_s; };
  double self0 = cpuMark();
  std::this_thread::sleep_for(std::chrono::duration<double>(o.idleSeconds));
  std::vector<double> idlePct;
  for (auto& p : procs) idlePct.push_back(cpuPct(processCpu_s(p.child->pid()) - p.cpu0_s, o.idleSeconds));
  const double selfIdlePct = cpuPct(selfCpu_s() - self0, o.idleSeconds);

  std::vector<double> relayBytes0;
  for (int r = 0; r < o.relays; ++r) relayBytes0.push_back(metric(procs[2 + r].httpPort, "skyshell_stream_bytes_total"));
  const double natsBytes0 = natsOutBytes(monitorPort);

  // The storm: one change every 1/rate s, sent one after another.
  self0 = cpuMark();
  std::vector<double> ack_ms;
  std::size_t refused = 0;
  const auto stormStart = Clock::now();
  for (std::size_t i = 0; i < changes; ++i) {
    std::this_thread::sleep_until(stormStart + std::chrono::duration_cast<Clock::duration>(
                                                   std::chrono::duration<double>(double(i) / o.rate)));
    sky::sim::HttpRequest post;
    post.method = "POST";
    post.port = static_cast<unsigned short>(leaderHttp);
    post.target = "/api/changes";
    post.body = o.regional ? stormCellChange(i) : markerChange(i);
    post.bearerToken = kToken;
    const auto sent = Clock::now();
    {
      std::lock_guard lock(shared.mutex);
      shared.submitted[i] = sent;
    }
    const auto answer = sky::sim::httpRequest(post);
    if (!answer || answer->status != 200) ++refused;
    else ack_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - sent).count());
  }
  std::this_thread::sleep_for(1s);  // let the last deliveries land
  const double stormWall_s = std::chrono::duration<double>(Clock::now() - stormStart).count();
  std::vector<double> stormPct;
  for (auto& p : procs) stormPct.push_back(cpuPct(processCpu_s(p.child->pid()) - p.cpu0_s, stormWall_s));
  const double selfStormPct = cpuPct(selfCpu_s() - self0, stormWall_s);
  double relayBytes = 0;
  for (int r = 0; r < o.relays; ++r)
    relayBytes += metric(procs[2 + r].httpPort, "skyshell_stream_bytes_total") - relayBytes0[r];
  const double natsBytes = natsOutBytes(monitorPort) - natsBytes0;
  std::vector<std::string> hashes, names;
  std::vector<double> sequences;
  for (std::size_t p = 1; p < procs.size(); ++p) {
    hashes.push_back(stateHash(procs[p].httpPort));
    sequences.push_back(metric(procs[p].httpPort, "skyshell_nats_applied_sequence"));
  }
  for (const auto& p : procs) names.push_back(p.name);

  for (auto& s : subs) asio::post(clientIo, [s] { s->close(); });
  guard.reset();
  clientThread.join();
  while (!procs.empty()) procs.pop_back();  // in the reverse of their start, as ~Processes

  std::lock_guard lock(shared.mutex);
  const double p50 = percentile(shared.latencies_ms, 50), p99 = percentile(shared.latencies_ms, 99);
  std::printf("relay bench: %d subscribers (%lld served a snapshot) over %d relays, radius %.0f km (level %d), "
              "%zu changes at %.0f/s to the leader (%zu refused), %s weather, %d stations far away, relays follow by "
              "%s, one-node nats-server with JetStream\n",
              o.subscribers, static_cast<long long>(served), o.relays, o.radius_m / 1000, area.tileLevel, changes,
              o.rate, refused, o.regional ? "regional (tiles in every snapshot; a storm cell moves)" : "uniform",
              o.stations, o.follow.c_str());
  std::printf("  change-to-delivery latency  p50 %.2f ms  p99 %.2f ms  from sending the change (%llu deliveries, "
              "%llu coalesced of %.0f)\n",
              p50, p99, static_cast<unsigned long long>(shared.deliveries),
              static_cast<unsigned long long>(shared.coalesced), double(changes) * o.subscribers);
  std::printf("  POST /api/changes to 200    p50 %.2f ms  p99 %.2f ms\n", percentile(ack_ms, 50),
              percentile(ack_ms, 99));
  for (std::size_t p = 0; p < names.size(); ++p)
    std::printf("  CPU %-22s idle %5.1f %%  storm %5.1f %% of a core\n", names[p].c_str(), idlePct[p],
                stormPct[p]);
  std::printf("  CPU %-22s idle %5.1f %%  storm %5.1f %% of a core\n", "subscribers (bench)", selfIdlePct,
              selfStormPct);
  std::printf("  bytes per change            NATS out %.0f (all clients), relays' sockets %.0f (%.0f per subscriber)\n",
              natsBytes / double(changes), relayBytes / double(changes), relayBytes / double(changes) / o.subscribers);
  bool same = true;
  for (std::size_t k = 0; k < hashes.size(); ++k)
    same = same && (partial ? sequences[k] == sequences.front() && sequences[k] > 0
                            : hashes[k] == hashes.front() && !hashes[k].empty());
  if (partial)
    std::printf("  after the storm             %s applied sequence %.0f on the server and every relay\n",
                same ? "the same" : "NOT the same", sequences.front());
  else
    std::printf("  state hash after the storm  %s on the server and every relay\n",
                same ? hashes.front().c_str() : "NOT the same");
  if (!o.json.empty()) {
    nlohmann::json cpu = nlohmann::json::object();
    for (std::size_t p = 0; p < names.size(); ++p)
      cpu[names[p]] = {{"idle_pct", idlePct[p]}, {"storm_pct", stormPct[p]}};
    cpu["subscribers"] = {{"idle_pct", selfIdlePct}, {"storm_pct", selfStormPct}};
    const nlohmann::json j = {{"relays", o.relays}, {"subscribers", o.subscribers}, {"served", served},
                              {"rate_hz", o.rate}, {"regional", o.regional}, {"follow", o.follow},
                              {"stations", o.stations}, {"changes", changes}, {"refused", refused},
                              {"latency_p50_ms", p50}, {"latency_p99_ms", p99}, {"deliveries", shared.deliveries},
                              {"coalesced", shared.coalesced}, {"ack_p50_ms", percentile(ack_ms, 50)},
                              {"ack_p99_ms", percentile(ack_ms, 99)}, {"cpu", cpu},
                              {"nats_out_bytes_per_change", natsBytes / double(changes)},
                              {"relay_stream_bytes_per_change", relayBytes / double(changes)}, {"same_state", same}};
    std::ofstream(o.json) << j.dump(2) << "\n";
  }
  return shared.deliveries > 0 && served == o.subscribers && refused == 0 && same ? 0 : 1;
}
