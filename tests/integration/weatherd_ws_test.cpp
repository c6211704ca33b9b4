// The console's WebSocket feed of a real skyshell-weatherd, read by a Beast
// WebSocket client through a real socket: hello, state, renderers and health
// on connect; a change posted over HTTP comes back as its event and the new
// state; a weather-stream client that reports its camera appears in the
// renderer list with its position and leaves it when it disconnects; the
// number of clients is bounded (503 past it).
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "weatherd_console_client.hpp"
#include "weatherd_process.hpp"

namespace sky::test {
namespace {

const char* kAddStratus = R"({"author": "ws-test", "changes": [{"op": "set_layer", "layer": {
  "id": 2, "type": "stratus", "base_m": 400, "thickness_m": 300, "transition_band_m": 50, "coverage": 0.8,
  "density": 0.7, "wind": {"speed_mps": 5, "from_deg": 200, "vertical_mps": 0}}}]})";

TEST(WeatherdWs, TheConsoleFeedPushesStateEventsRenderersAndHealth) {
  Weatherd w("weatherd-ws");
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  Console console(w.httpPort);
  ASSERT_TRUE(console.open()) << w.process->log();

  // On connect, in this order: hello, state, renderers, health.
  auto hello = console.read();
  ASSERT_TRUE(hello);
  EXPECT_EQ((*hello)["type"], "hello");
  EXPECT_EQ((*hello)["api_version"], 1);
  EXPECT_EQ((*hello)["server_id"].get<std::string>().rfind("skyshell-weatherd@", 0), 0u) << hello->dump();
  auto state = console.read();
  ASSERT_TRUE(state);
  ASSERT_EQ((*state)["type"], "state");
  // The state is exactly GET /api/state (the clock aside, which runs).
  auto viaHttp = nlohmann::json::parse(w.request("GET", "/api/state").body);
  for (auto* j : {&(*state)["state"], &viaHttp}) {
    j->erase("clock_s");
  }
  EXPECT_EQ((*state)["state"], viaHttp);
  EXPECT_EQ((*state)["state"]["layers"].size(), 1u);
  auto renderers = console.read();
  ASSERT_TRUE(renderers);
  ASSERT_EQ((*renderers)["type"], "renderers");
  EXPECT_TRUE((*renderers)["renderers"].empty());
  auto health = console.read();
  ASSERT_TRUE(health);
  ASSERT_EQ((*health)["type"], "health");
  EXPECT_EQ((*health)["subscribers"], 0);
  EXPECT_EQ((*health)["ws_clients"], 1);
  EXPECT_EQ((*health)["changes_applied"], 0);
  EXPECT_EQ((*health)["rejected"]["unauthorized"], 0);

  // A change over HTTP: its event, then the new state.
  const auto posted = w.request("POST", "/api/changes", kAddStratus);
  ASSERT_EQ(posted.status, 200) << posted.body;
  auto event = console.readType("event");
  ASSERT_TRUE(event);
  EXPECT_EQ((*event)["event"]["sequence"], 1);
  EXPECT_EQ((*event)["event"]["author"], "ws-test");
  const auto events = nlohmann::json::parse(w.request("GET", "/api/events").body)["events"];
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ((*event)["event"], events[0]) << "exactly one element of GET /api/events";
  auto changed = console.readType("state");
  ASSERT_TRUE(changed);
  EXPECT_EQ((*changed)["state"]["sequence"], 1);
  EXPECT_EQ((*changed)["state"]["layers"].size(), 2u);

  // A refused change shows in the health counters (pushed every 2 s).
  EXPECT_EQ(w.request("POST", "/api/changes", kAddStratus, "wrong-token").status, 401);
  auto counted = console.readUntil("health", [](const nlohmann::json& h) {
    return h["rejected"]["unauthorized"] == 1 && h["changes_applied"] == 1;
  });
  ASSERT_TRUE(counted) << "no health message counting the refused change";

  // A renderer subscribes and reports its camera: listed with its position
  // and area, and gone when it disconnects.
  std::optional<StreamPeer> renderer;
  renderer.emplace(w.streamPort);
  stream::Subscribe subscribe;
  subscribe.area = {46.2, 12.8, 80000};
  renderer->send(subscribe);
  stream::CameraReport report;
  report.channel = "right-seat";
  report.lat_deg = 46.21;
  report.lon_deg = 12.81;
  report.alt_m = 950;
  report.heading_deg = 93;
  report.pitch_deg = 2;
  report.roll_deg = -5;
  report.frame = 17;
  report.weatherVersion = 2;
  report.weatherClock_s = 12;
  const auto sentAt = std::chrono::steady_clock::now();
  renderer->send(report);
  auto listed = console.readUntil("renderers", [](const nlohmann::json& m) {
    return m["renderers"].size() == 1 && !m["renderers"][0]["lat_deg"].is_null();
  });
  ASSERT_TRUE(listed) << w.process->log();
  const auto& r = (*listed)["renderers"][0];
  EXPECT_EQ(r["channel"], "right-seat");
  EXPECT_EQ(r["peer"].get<std::string>().rfind("127.0.0.1:", 0), 0u);
  EXPECT_EQ(r["lat_deg"], 46.21);
  EXPECT_EQ(r["lon_deg"], 12.81);
  EXPECT_EQ(r["alt_m"], 950);
  EXPECT_EQ(r["heading_deg"], 93);
  EXPECT_EQ(r["frame"], 17);
  EXPECT_EQ(r["weather_version"], 2);
  EXPECT_EQ(r["area"]["radius_m"], 80000);
  // The server clamps the age at 0, so only the upper bound can fail: the
  // report is at most as old as the time since it was sent.
  const double sinceSent_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - sentAt).count();
  EXPECT_LE(r["last_report_age_s"].get<double>(), sinceSent_s);
  const auto viaGet = nlohmann::json::parse(w.request("GET", "/api/renderers").body)["renderers"];
  ASSERT_EQ(viaGet.size(), 1u);
  EXPECT_EQ(viaGet[0]["channel"], "right-seat");
  renderer->close();
  auto gone = console.readUntil("renderers", [](const nlohmann::json& m) { return m["renderers"].empty(); });
  ASSERT_TRUE(gone) << "the renderer is still listed after it disconnected";

  const std::string metrics = w.request("GET", "/metrics").body;
  EXPECT_NE(metrics.find("skyshell_ws_clients 1\n"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("skyshell_rejected_inputs_total{reason=\"unauthorized\"} 1\n"), std::string::npos)
      << metrics;
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

// 32 consoles at once; the 33rd is refused with 503 and counted; closing
// one makes room again.
TEST(WeatherdWs, ConsoleClientsAreBounded) {
  Weatherd w("weatherd-ws-bound");
  ASSERT_GT(w.httpPort, 0u) << w.process->log();
  std::vector<std::unique_ptr<Console>> consoles;
  for (int i = 0; i < 32; ++i) {
    consoles.push_back(std::make_unique<Console>(w.httpPort));
    ASSERT_TRUE(consoles.back()->open()) << i;
    ASSERT_TRUE(consoles.back()->readType("hello"));
  }
  Console extra(w.httpPort);
  EXPECT_FALSE(extra.open());
  EXPECT_EQ(upgradeStatus(w.httpPort), "HTTP/1.1 503 Service Unavailable");
  consoles.pop_back();
  std::optional<Console> again;
  for (int i = 0; i < 100; ++i) {
    again.emplace(w.httpPort);
    if (again->open()) break;
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(again->open()) << "no room after a console left";
  const std::string metrics = w.request("GET", "/metrics").body;
  EXPECT_NE(metrics.find("skyshell_rejected_inputs_total{reason=\"ws_refused\"} "), std::string::npos);
  // Shutdown with 32 consoles connected is clean.
  EXPECT_EQ(w.process->stop(), 0) << w.process->log();
}

}  // namespace
}  // namespace sky::test
