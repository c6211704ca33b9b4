// skyshell-weatherd --nats and skyshell-relay as child processes for the NATS
// integration tests (weatherd_nats_test.cpp, relay_nats_test.cpp): started
// on ephemeral ports, and what the tests read from their HTTP endpoints
// (/metrics gauges, the state, the state hash).
#pragma once

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "nats_cluster.hpp"
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

// A weather process with an HTTP endpoint: what the tests ask it.
struct HttpPeer {
  std::filesystem::path dir;
  std::optional<PausableProcess> process;
  unsigned httpPort = 0;

  std::optional<sim::HttpResponse> request(const std::string& method, const std::string& target,
                                           const std::string& body = "") const {
    sim::HttpRequest r;
    r.method = method;
    r.port = static_cast<unsigned short>(httpPort);
    r.target = target;
    r.body = body;
    r.bearerToken = kNatsToken;
    r.timeout = 10s;
    auto response = sim::httpRequest(r);
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
// One skyshell-relay following the cluster's log, on ephemeral ports.
struct NatsRelay : HttpPeer {
  unsigned streamPort = 0;
  NatsRelay(const std::filesystem::path& root, const std::string& name, const std::string& natsUrls) {
    dir = root / name;
    std::filesystem::create_directories(dir);
    process.emplace(std::vector<std::string>{SKY_RELAY, "--nats", natsUrls, "--port", "0", "--port-file",
                                             (dir / "stream.port").string(), "--http-port", "0", "--http-port-file",
                                             (dir / "http.port").string(), "--heartbeat-ms", "200"},
                    (dir / "relay.log").string());
    streamPort = waitForPortFile((dir / "stream.port").string(), 40s);
    httpPort = waitForPortFile((dir / "http.port").string(), 40s);
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
