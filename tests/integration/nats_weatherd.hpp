// skyshell-weatherd --nats, skyshell-relay and a headless skyshell-render as
// child processes for the NATS integration tests (weatherd_nats_test.cpp,
// relay_nats_test.cpp, cluster_fault_test.cpp): started on ephemeral ports,
// and what the tests read from their HTTP endpoints (/metrics gauges, the
// state, the state hash) and from a renderer's frames.
#pragma once

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "nats_cluster.hpp"
#include "sky/core/result.hpp"
#include "sky/sim/http_client.hpp"

namespace sky::test {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

inline constexpr const char* kNatsToken = "s3cret-nats-token";
// The servers' lease: short, so that a failover fits a test; the default
// (3 s) is what docs/weather-server-scaling.md measures.
inline constexpr const char* kLeaseMs = "2000";
// Time allowed for a three-node cluster to start and elect JetStream's meta
// leader, and for a first server to take the lead (measured: 2-4 s).
inline constexpr auto kFirstLeaderWait = 25s;

inline std::string layerChange(int id, double coverage) {
  return R"({"author": "nats-test", "changes": [{"op": "set_layer", "ramp_s": 0, "layer": {"id": )" +
         std::to_string(id) + R"(, "type": "stratus", "base_m": 400, "thickness_m": 300, "transition_band_m": 50,
         "coverage": )" + std::to_string(coverage) +
         R"(, "density": 0.7, "wind": {"speed_mps": 5, "from_deg": 200, "vertical_mps": 0}}}]})";
}

// A change request setting `count` regions of cumulus from id `first` on,
// on a grid of 60 columns from (lat0, lon0) by id, 0.5 degrees north and 0.9
// east apart (North America by default; each ~450 bytes of state).
inline std::string regionsRequest(int first, int count, double lat0 = 30, double lon0 = -120,
                                  double coverage = 0.5) {
  std::string body = R"({"author": "nats-test", "changes": [)";
  for (int id = first; id < first + count; ++id) {
    body += std::string(id > first ? "," : "") + R"({"op": "set_region", "region": {"id": )" + std::to_string(id) +
            R"(, "center_lat_deg": )" + std::to_string(lat0 + 0.5 * (id / 60)) + R"(, "center_lon_deg": )" +
            std::to_string(lon0 + 0.9 * (id % 60)) +
            R"(, "size_x_m": 20000, "size_y_m": 20000, "transition_m": 5000, "layers": [{"id": 3, "type": "cumulus",
            "base_m": 1200, "thickness_m": 900, "transition_band_m": 50, "coverage": )" + std::to_string(coverage) +
            R"(, "density": 0.6, "wind": {"speed_mps": 5, "from_deg": 200, "vertical_mps": 0}}]}})";
  }
  return body + "]}";
}

// One request to a weather server's (or relay's) HTTP API on loopback, with
// the tests' token; 10 s for the answer, twice a JetStream append's wait
// (NatsLogOptions::requestWait), so a leader's answer is not given up on.
inline Result<sim::HttpResponse> natsApiRequest(unsigned port, const std::string& method, const std::string& target,
                                                const std::string& body = "") {
  return sim::httpRequest(sim::HttpRequest{.method = method,
                                           .host = "127.0.0.1",
                                           .port = static_cast<unsigned short>(port),
                                           .target = target,
                                           .body = body,
                                           .bearerToken = kNatsToken,
                                           .timeout = 10s});
}

// A weather process with an HTTP endpoint: what the tests ask it.
struct HttpPeer {
  std::filesystem::path dir;
  std::optional<PausableProcess> process;
  unsigned httpPort = 0;

  std::optional<sim::HttpResponse> request(const std::string& method, const std::string& target,
                                           const std::string& body = "") const {
    auto response = natsApiRequest(httpPort, method, target, body);
    if (!response) return std::nullopt;
    return *response;
  }
  // A gauge or counter of /metrics, or -1 when unreadable.
  double metric(const std::string& name) const {
    auto r = request("GET", "/metrics");
    if (!r || r->status != 200) return -1;
    std::istringstream in(r->body);
    for (std::string line; std::getline(in, line);)
      if (line.rfind(name + " ", 0) == 0) return std::stod(line.substr(name.size() + 1));
    return -1;
  }
  // The weather's state hash (skyshell_state_hash_info's label), "" when
  // unreadable.
  std::string stateHash() const {
    auto r = request("GET", "/metrics");
    if (!r || r->status != 200) return "";
    const std::string key = "skyshell_state_hash_info{hash=\"";
    const auto at = r->body.find(key);
    if (at == std::string::npos) return "";
    const auto end = r->body.find('"', at + key.size());
    return end == std::string::npos ? "" : r->body.substr(at + key.size(), end - at - key.size());
  }
  bool leads() const { return metric("skyshell_nats_leader") == 1; }
  nlohmann::json state() const {
    auto r = request("GET", "/api/state");
    if (!r || r->status != 200) return nullptr;
    return nlohmann::json::parse(r->body, nullptr, false);
  }
  bool hasLayer(int id) const {
    const auto j = state();
    if (!j.is_object() || !j.contains("layers")) return false;
    for (const auto& l : j["layers"])
      if (l.value("id", -1) == id) return true;
    return false;
  }
  std::string log() const { return process->log(); }
};

// One skyshell-weatherd with --nats, on ephemeral ports.
struct NatsWeatherd : HttpPeer {
  // natsUrls: --nats's value (empty: none); more: more options (the lease,
  // or options of a server without NATS, e.g. --db FILE).
  NatsWeatherd(const std::filesystem::path& root, const std::string& name, const std::string& natsUrls,
               std::vector<std::string> more = {"--nats-lease-ms", kLeaseMs}) {
    dir = root / name;
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "token") << kNatsToken << "\n";
    std::vector<std::string> args{SKY_WEATHERD, "--scenario", SKY_SCENARIO_CLOUDY, "--port", "0", "--port-file",
                                  (dir / "stream.port").string(), "--http-port", "0",
                                  "--http-port-file", (dir / "http.port").string(), "--token-file",
                                  (dir / "token").string(), "--heartbeat-ms", "200"};
    if (!natsUrls.empty()) args.insert(args.end(), {"--nats", natsUrls});
    args.insert(args.end(), more.begin(), more.end());
    process.emplace(args, (dir / "weatherd.log").string());
    httpPort = waitForPortFile((dir / "http.port").string(), 40s);
  }
};

#ifdef SKY_RELAY
// One skyshell-relay following the cluster's log, on ephemeral ports, its
// options in a config file as the systemd unit gives them
// (deploy/skyshell-relay.service; the port file on the command line).
struct NatsRelay : HttpPeer {
  unsigned streamPort = 0;
  // moreConfig: more lines of its config file.
  NatsRelay(const std::filesystem::path& root, const std::string& name, const std::string& natsUrls,
            const std::string& moreConfig = "") {
    dir = root / name;
    std::filesystem::create_directories(dir);
    const std::filesystem::path config = dir / "relay.toml";
    std::ofstream(config) << "nats = \"" << natsUrls << "\"\nport = 0\nhttp-port = 0\nhttp-port-file = \""
                          << (dir / "http.port").string() << "\"\nheartbeat-ms = 200\n" << moreConfig;
    process.emplace(std::vector<std::string>{SKY_RELAY, "--config", config.string(), "--port-file",
                                             (dir / "stream.port").string()},
                    (dir / "relay.log").string());
    streamPort = waitForPortFile((dir / "stream.port").string(), 40s);
    httpPort = waitForPortFile((dir / "http.port").string(), 40s);
  }
};
#endif

#ifdef SKY_RENDER
// Frames of the tests' renderers: tiny, paced at flight speed, a hover long
// enough to outlast a test (the renderer is stopped with it).
inline constexpr const char* kRenderWidth = "64";
inline constexpr const char* kRenderHeight = "36";
inline constexpr double kRenderStep_s = 0.25;
inline constexpr int kRenderHover_s = 600;

// The frames of a frames.jsonl, in order.
inline std::vector<nlohmann::json> framesOf(const std::filesystem::path& jsonl) {
  std::vector<nlohmann::json> v;
  std::ifstream f(jsonl);
  for (std::string line; std::getline(f, line);) {
    auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object()) v.push_back(std::move(j));  // the last line may be half written
  }
  return v;
}

// A headless skyshell-render hovering near 46.2N 12.8E, its weather from a
// server's or a relay's stream `port`.
struct Renderer {
  std::filesystem::path out;
  std::optional<ChildProcess> process;
  Renderer(const std::filesystem::path& dir, unsigned port) {
    std::filesystem::create_directories(dir);
    {
      std::ofstream csv(dir / "hover.csv");
      csv << "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n";
      for (int t = 0; t <= kRenderHover_s; t += 10) csv << t << ",46.2,12.8,900,90,20,0\n";
    }
    out = dir / "out";
    const std::vector<std::string> args{SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(port),
                                  "--replay", (dir / "hover.csv").string(), "--step", std::to_string(kRenderStep_s),
                                  "--replay-pace", "1", "--no-exr", "--no-video", "--out", out.string(), "--width",
                                  kRenderWidth, "--height", kRenderHeight};
    process.emplace(args, (dir / "render.log").string(),
                    std::vector<std::string>{"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  }
  std::filesystem::path framesFile() const { return out / "frames" / "frames.jsonl"; }
  std::vector<nlohmann::json> written() const { return framesOf(framesFile()); }
  std::uint64_t lastVersion() const {
    const auto f = written();
    return f.empty() ? 0 : f.back().value("weather_version", std::uint64_t{0});
  }
  // The newest whole frame, read from the file's tail (cheap enough to poll);
  // null before the first.
  nlohmann::json lastFrame() const {
    constexpr std::streamoff kTail_bytes = 16384;  // several frames' lines
    std::ifstream f(framesFile(), std::ios::binary | std::ios::ate);
    if (!f) return nullptr;
    const std::streamoff size = f.tellg();
    f.seekg(std::max<std::streamoff>(0, size - kTail_bytes));
    std::string tail((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    const auto end = tail.rfind('\n');
    if (end == std::string::npos || end == 0) return nullptr;
    const auto previous = tail.rfind('\n', end - 1);
    const std::size_t begin = previous == std::string::npos ? 0 : previous + 1;
    auto j = nlohmann::json::parse(tail.substr(begin, end - begin), nullptr, false);
    return j.is_object() ? j : nlohmann::json(nullptr);
  }
};
#endif

template <class F>
bool waitUntil(std::chrono::milliseconds timeout, F&& f) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (f()) return true;
    std::this_thread::sleep_for(50ms);
  }
  return f();
}

inline double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace sky::test
