// The weather server's HTTP API through real sockets, and a change travelling
// from a skyshell-scenario action through the API and the weather stream into
// a renderer's frames.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <span>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "weatherd_process.hpp"
#include "sky/cigi/codec.hpp"
#include "sky/sim/http_client.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

const char* kAddStratus = R"({"author": "test", "changes": [{"op": "set_layer", "ramp_s": 0, "layer": {
  "id": 2, "type": "stratus", "base_m": 400, "thickness_m": 300, "transition_band_m": 50, "coverage": 0.8,
  "density": 0.7, "wind": {"speed_mps": 5, "from_deg": 200, "vertical_mps": 0}}}]})";

TEST(WeatherdApi, ChangesNeedTheTokenAreCheckedAndApply) {
  Weatherd w("weatherd-api");
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  EXPECT_EQ(w.request("GET", "/healthz").body, "ok\n");
  auto state = nlohmann::json::parse(w.request("GET", "/api/state").body);
  ASSERT_EQ(state["layers"].size(), 1u);
  EXPECT_EQ(state["layers"][0]["coverage"], 0.6);

  // Without the token: 401, nothing changes.
  EXPECT_EQ(w.request("POST", "/api/changes", kAddStratus, "").status, 401);
  EXPECT_EQ(w.request("POST", "/api/changes", kAddStratus, "wrong").status, 401);
  // Invalid: 400 naming the field; a batch is all or nothing.
  std::string bad = kAddStratus;
  bad.replace(bad.find("\"coverage\": 0.8"), 15, "\"coverage\": 1.4");
  const auto refused = w.request("POST", "/api/changes", bad);
  EXPECT_EQ(refused.status, 400);
  const auto err = nlohmann::json::parse(refused.body);
  EXPECT_EQ(err["field"], "changes[0].layer");
  EXPECT_NE(err["error"].get<std::string>().find("coverage 1.4"), std::string::npos) << refused.body;
  const auto typo = w.request("POST", "/api/changes", R"({"changes": [{"op": "set_clock", "rat": 60}]})");
  EXPECT_EQ(typo.status, 400);
  EXPECT_EQ(nlohmann::json::parse(typo.body)["field"], "changes[0].rat");
  EXPECT_EQ(nlohmann::json::parse(w.request("GET", "/api/state").body)["layers"].size(), 1u);

  // Valid: applied, visible in the state, the event log and the metrics.
  const auto ok = w.request("POST", "/api/changes", kAddStratus);
  ASSERT_EQ(ok.status, 200) << ok.body;
  EXPECT_EQ(nlohmann::json::parse(ok.body)["sequence"], 1);
  state = nlohmann::json::parse(w.request("GET", "/api/state").body);
  ASSERT_EQ(state["layers"].size(), 2u);
  EXPECT_EQ(state["layers"][1]["type"], "stratus");
  const auto events = nlohmann::json::parse(w.request("GET", "/api/events?limit=5").body)["events"];
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0]["author"], "test");
  EXPECT_EQ(events[0]["summary"], "layer 2 (stratus) added, coverage 0.00 -> 0.80");
  const std::string metrics = w.request("GET", "/metrics").body;
  EXPECT_NE(metrics.find("skyshell_changes_applied_total 1\n"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("skyshell_changes_rejected_total 2\n"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("skyshell_changes_unauthorized_total 2\n"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("skyshell_stream_frames_total "), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("skyshell_subscribers_dropped_total 0\n"), std::string::npos) << metrics;
  EXPECT_EQ(w.request("GET", "/nowhere").status, 404);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

// skyshell-scenario flies the 6 s test flight into a renderer and, 1.5 s in,
// adds a stratus layer through the API: the renderer's frames go from one
// layer to two, without a restart.
TEST(WeatherdApi, ScenarioActionReachesTheRendererThroughTheStream) {
  Weatherd w("weatherd-scenario");
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  const fs::path d = w.dir;
  nlohmann::json request = nlohmann::json::parse(kAddStratus);
  std::ofstream(d / "scenario.toml") << "[flight]\nfile = \"" << SKY_TEST_FLIGHT << "\"\n\n"
                                     << "[[action]]\nat_s = 1.5\nwhat = \"a stratus deck forms\"\n"
                                     << "[action.request]\nauthor = \"scenario-test\"\n"
                                     << "[[action.request.changes]]\nop = \"set_layer\"\n"
                                     << "layer = { id = 2, type = \"stratus\", base_m = 400, thickness_m = 300, "
                                        "transition_band_m = 50, coverage = 0.8, density = 0.7, wind = { speed_mps = "
                                        "5, from_deg = 200, vertical_mps = 0 } }\n";
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(w.streamPort),
                       "--cigi-port", "0", "--port-file", (d / "render.port").string(), "--out",
                       (d / "frames").string(), "--width", "96", "--height", "54", "--idle-exit", "3",
                       "--weather-timeout", "60", "--channel", "left-seat"},
                      (d / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const unsigned cigiPort = waitForPortFile((d / "render.port").string(), 60s);
  ASSERT_GT(cigiPort, 0u) << render.log();
  ChildProcess scenario({SKY_SCENARIO, (d / "scenario.toml").string(), "--port", std::to_string(cigiPort), "--api",
                         "http://127.0.0.1:" + std::to_string(w.httpPort), "--token-file", (d / "token").string()},
                        (d / "scenario.log").string());
  // While it flies, the renderer reports its camera: the console's list
  // shows the channel at the flight's position (46.2 N, 12.80-12.81 E, 900-930 m).
  nlohmann::json channel;
  for (int i = 0; i < 600 && channel.is_null(); ++i) {
    const auto list = nlohmann::json::parse(w.request("GET", "/api/renderers").body)["renderers"];
    for (const auto& r : list)
      if (!r["lat_deg"].is_null()) channel = r;
    if (channel.is_null()) std::this_thread::sleep_for(100ms);
  }
  ASSERT_FALSE(channel.is_null()) << "no camera report from the renderer\n" << render.log();
  EXPECT_EQ(channel["channel"], "left-seat");
  EXPECT_NEAR(channel["lat_deg"].get<double>(), 46.2, 1e-3);
  EXPECT_NEAR(channel["lon_deg"].get<double>(), 12.802, 0.003);
  EXPECT_NEAR(channel["alt_m"].get<double>(), 915, 20);
  EXPECT_NEAR(channel["heading_deg"].get<double>(), 92, 4);
  EXPECT_NEAR(channel["pitch_deg"].get<double>(), 15, 0.5);
  EXPECT_GE(channel["weather_version"].get<int>(), 1);
  EXPECT_NEAR(channel["area"]["center_lat_deg"].get<double>(), 46.2, 0.01) << "the area it subscribed to";
  EXPECT_EQ(scenario.wait(60s), std::optional<int>(0)) << scenario.log();
  EXPECT_NE(scenario.log().find("a stratus deck forms: accepted"), std::string::npos) << scenario.log();
  EXPECT_EQ(render.wait(120s), std::optional<int>(0)) << render.log();

  std::ifstream jsonl(d / "frames" / "frames.jsonl");
  std::vector<std::pair<double, int>> layersAt;
  for (std::string line; std::getline(jsonl, line);) {
    const auto f = nlohmann::json::parse(line);
    layersAt.push_back({f["host_time_s"].get<double>(), f["layers"].get<int>()});
  }
  ASSERT_GE(layersAt.size(), 3u);
  EXPECT_EQ(layersAt.front().second, 1) << "the first frames have the scenario's one layer";
  EXPECT_EQ(layersAt.back().second, 2) << "the last frames have the stratus layer the action added";
  for (const auto& [t, n] : layersAt)
    if (t < 1.4) {
      EXPECT_EQ(n, 1) << "a layer before the action at 1.5 s (frame at " << t << " s)";
    }
  const auto events = nlohmann::json::parse(w.request("GET", "/api/events").body)["events"];
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0]["author"], "scenario-test");
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// One UDP datagram to 127.0.0.1:port from a fixed local socket (one "host").
class UdpHost {
 public:
  UdpHost() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {}
  ~UdpHost() { ::close(fd_); }
  void send(unsigned port, std::span<const std::uint8_t> bytes) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to),
              static_cast<ssize_t>(bytes.size()));
  }

 private:
  int fd_;
};

std::vector<std::uint8_t> hostDatagram(const std::vector<cigi::Packet>& packets) {
  cigi::DatagramWriter w(cigi::ByteOrder::Big);
  w.add(cigi::IgControl{});
  for (const auto& p : packets) w.add(p);
  return w.bytes();
}

cigi::WeatherControl cloudLayer1(float coverage_pct) {
  cigi::WeatherControl wc;
  wc.layerId = cigi::LayerId::CloudLayer1;
  wc.cloudType = weather::CloudType::Stratocumulus;
  wc.coverage_pct = coverage_pct;
  wc.baseElevation_m = 1200;
  wc.thickness_m = 800;
  wc.transitionBand_m = 100;
  wc.horizontalWind_mps = 8;
  wc.windDirection_deg = 240;
  return wc;
}

// Polls GET /api/state until pred holds (the UDP input is asynchronous).
template <typename Pred>
nlohmann::json waitForState(Weatherd& w, Pred pred) {
  nlohmann::json state;
  for (int i = 0; i < 100; ++i) {
    state = nlohmann::json::parse(w.request("GET", "/api/state").body);
    if (pred(state)) break;
    std::this_thread::sleep_for(50ms);
  }
  return state;
}

std::uint64_t metric(Weatherd& w, const std::string& name) {
  const std::string m = w.request("GET", "/metrics").body;
  const auto at = m.find("\n" + name + " ");
  return at == std::string::npos ? ~0ull : std::stoull(m.substr(at + name.size() + 2));
}

// A CIGI host drives the weather: Weather Control changes the global layer,
// Environmental Region Control plus a regional Weather Control place a storm
// cell; 20 identical resends change nothing; a malformed datagram is dropped
// and counted; an out-of-range layer is refused and leaves the state alone.
TEST(WeatherdCigi, AHostDrivesTheWeatherOverUdp) {
  Weatherd w("weatherd-cigi", SKY_SCENARIO_CLOUDY, true);
  ASSERT_GT(w.cigiPort, 0u) << w.process->log();
  UdpHost host;
  cigi::EnvironmentalRegionControl erc;
  erc.regionId = 5;
  erc.state = cigi::RegionState::Active;
  erc.lat_deg = 46.1;
  erc.lon_deg = 13.2;
  erc.sizeX_m = 8000;
  erc.sizeY_m = 6000;
  erc.transitionPerimeter_m = 2000;
  cigi::WeatherControl storm = cloudLayer1(90);
  storm.layerId = cigi::LayerId::CloudLayer2;
  storm.cloudType = weather::CloudType::Cumulonimbus;
  storm.scope = cigi::WeatherScope::Regional;
  storm.entityOrRegionId = 5;
  storm.thickness_m = 7000;
  const auto weatherDatagram = hostDatagram({cloudLayer1(70), erc, storm});
  host.send(w.cigiPort, weatherDatagram);
  auto state = waitForState(w, [](const nlohmann::json& s) { return s["regions"].size() == 1; });
  ASSERT_EQ(state["regions"].size(), 1u) << state.dump() << w.process->log();
  ASSERT_EQ(state["layers"].size(), 1u);
  EXPECT_EQ(state["layers"][0]["type"], "stratocumulus");
  EXPECT_NEAR(state["layers"][0]["coverage"].get<double>(), 0.70, 1e-6);
  EXPECT_NEAR(state["layers"][0]["wind"]["from_deg"].get<double>(), 240, 1e-6);
  const auto& region = state["regions"][0];
  EXPECT_EQ(region["id"], 5);
  EXPECT_NEAR(region["center_lat_deg"].get<double>(), 46.1, 1e-9);
  EXPECT_NEAR(region["size_x_m"].get<double>(), 8000, 1e-6);
  ASSERT_EQ(region["layers"].size(), 1u);
  EXPECT_EQ(region["layers"][0]["type"], "cumulonimbus");
  const auto events = nlohmann::json::parse(w.request("GET", "/api/events?limit=10").body)["events"];
  ASSERT_EQ(events.size(), 1u) << "one datagram, one change request";
  EXPECT_EQ(events[0]["source"], "cigi");
  EXPECT_EQ(events[0]["author"].get<std::string>().rfind("cigi:127.0.0.1:", 0), 0u) << events[0].dump();

  // A host resends its weather every frame: nothing new.
  for (int frame = 0; frame < 20; ++frame) host.send(w.cigiPort, weatherDatagram);
  // Malformed: the Weather Control's size byte cut short.
  auto broken = weatherDatagram;
  broken.resize(broken.size() - 10);
  host.send(w.cigiPort, broken);
  // Refused: a layer with no thickness.
  auto flat = cloudLayer1(70);
  flat.thickness_m = 0;
  host.send(w.cigiPort, hostDatagram({flat}));
  // Then a real change, which also proves everything before it was handled.
  host.send(w.cigiPort, hostDatagram({cloudLayer1(30)}));
  state = waitForState(w, [](const nlohmann::json& s) {
    return std::abs(s["layers"][0]["coverage"].get<double>() - 0.3) < 1e-6;
  });
  EXPECT_NEAR(state["layers"][0]["coverage"].get<double>(), 0.30, 1e-6);
  EXPECT_EQ(state["regions"].size(), 1u);
  EXPECT_EQ(state["sequence"], 2) << "the resends and the refused layer added no change";
  EXPECT_EQ(metric(w, "skyshell_cigi_datagrams_total"), 24u);
  EXPECT_EQ(metric(w, "skyshell_cigi_malformed_total"), 1u);
  EXPECT_EQ(metric(w, "skyshell_cigi_rejected_total"), 1u);
  EXPECT_EQ(metric(w, "skyshell_cigi_applied_total"), 2u);
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// METAR through the API: a preview (no token) lists each report's layers and
// the groups skipped (a report whose only cloud group is malformed has its
// sky not observed), and changes nothing; applying needs the token and puts a
// region at each station whose sky was read.
TEST(WeatherdApi, MetarPreviewThenApply) {
  Weatherd w("weatherd-metar");
  const std::string body = R"({"reports": ["METAR LIPQ 221150Z 09012KT 9999 BKN020 15/10 Q1015",
      "METAR LJLJ 221150Z 27005KT 9999 BKN0x5 12/05 Q1018"],
      "stations": [{"icao": "LIPQ", "lat_deg": 45.8275, "lon_deg": 13.4722, "elevation_m": 12},
                   {"icao": "LJLJ", "lat_deg": 46.2237, "lon_deg": 14.4576, "elevation_m": 388}])";
  const auto preview = w.request("POST", "/api/metar", body + ", \"apply\": false}", "");
  ASSERT_EQ(preview.status, 200) << preview.body;
  const auto p = nlohmann::json::parse(preview.body);
  ASSERT_EQ(p["reports"].size(), 2u);
  EXPECT_EQ(p["reports"][0]["ok"], true);
  EXPECT_EQ(p["reports"][0]["layers"][0]["type"], "stratocumulus");
  EXPECT_EQ(p["reports"][1]["ok"], true);
  EXPECT_EQ(p["reports"][1]["sky"], "not_observed");
  EXPECT_EQ(p["reports"][1]["skipped"][0]["text"], "BKN0x5") << preview.body;
  ASSERT_EQ(p["changes"].size(), 1u);
  EXPECT_TRUE(p["applied"].is_null());
  EXPECT_TRUE(nlohmann::json::parse(w.request("GET", "/api/state").body)["regions"].empty());

  EXPECT_EQ(w.request("POST", "/api/metar", body + ", \"apply\": true}", "").status, 401);
  const auto applied = w.request("POST", "/api/metar", body + ", \"apply\": true}");
  ASSERT_EQ(applied.status, 200) << applied.body;
  EXPECT_EQ(nlohmann::json::parse(applied.body)["applied"]["sequence"], 1);
  const auto state = nlohmann::json::parse(w.request("GET", "/api/state").body);
  ASSERT_EQ(state["regions"].size(), 1u);
  EXPECT_NEAR(state["regions"][0]["center_lat_deg"].get<double>(), 45.8275, 1e-9);
  const auto events = nlohmann::json::parse(w.request("GET", "/api/events").body)["events"];
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0]["source"], "metar");
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

}  // namespace
}  // namespace sky::test
