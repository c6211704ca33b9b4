// The weather server goes away in the middle of a headless replay: it is
// SIGKILLed and restarted on the same --db and the same port. The renderer
// keeps drawing the weather it had, still advected on the weather clock,
// reconnects with backoff and resynchronises without a visible jump. The
// camera hovers, so everything that changes between frames is the clouds'
// motion (a 30 m/s layer wind and a storm region drifting with it): every
// consecutive frame difference, across the outage and the resync, must stay
// within what that motion gives before the kill; frames stay finite; the
// weather version never goes back and grows after the restart.
#include <cstdio>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/sim/http_client.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

constexpr const char* kToken = "reconnect-test-token";
constexpr int kWidth = 96, kHeight = 54;
// 24 s of hovering at one frame per 0.5 s, paced at flight speed: the
// outage fits in the middle with room on both sides.
constexpr double kFlight_s = 24, kStep_s = 0.5;
// A frame-to-frame change larger than this many times the largest one seen
// before the kill is a jump (motion varies a little with what moves through
// the view; a lost or mis-advected weather changes a large part of it).
constexpr double kJumpFactor = 2.0;
// Frames drawn without the server before it is restarted (3 s of flight).
constexpr long kOutageFrames = 6;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<nlohmann::json> frames(const fs::path& jsonl) {
  std::vector<nlohmann::json> out;
  std::ifstream in(jsonl);
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    try {
      out.push_back(nlohmann::json::parse(line));
    } catch (const nlohmann::json::exception&) {
      break;  // the line being written
    }
  }
  return out;
}

template <class Pred>
bool waitFor(Pred pred, std::chrono::seconds timeout) {
  for (auto until = std::chrono::steady_clock::now() + timeout; std::chrono::steady_clock::now() < until;) {
    if (pred()) return true;
    std::this_thread::sleep_for(50ms);
  }
  return pred();
}

// PFM radiance, top row first.
std::vector<float> readPfm(const fs::path& path) {
  std::ifstream f(path, std::ios::binary);
  std::string magic;
  int w = 0, h = 0;
  float scale = 0;
  f >> magic >> w >> h >> scale;
  f.get();
  std::vector<float> v(std::size_t(w) * h * 3);
  f.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
  EXPECT_TRUE(f && magic == "PF" && w == kWidth && h == kHeight) << path;
  return v;  // row order does not matter for a difference
}

double meanAbsDiff(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) sum += std::abs(double(a[i]) - double(b[i]));
  return sum / double(std::max<std::size_t>(1, a.size()));
}

TEST(HeadlessReconnect, ServerKilledAndRestartedMidReplayCausesNoJump) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "reconnect";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "token") << kToken << "\n";
  // Hovering at 900 m near 46.2N 12.8E, looking east and up at a cumulus
  // base of 1500 m.
  {
    std::ofstream csv(dir / "hover.csv");
    csv << "time_s,lat_deg,lon_deg,alt_m,yaw_deg,pitch_deg,roll_deg\n";
    for (int t = 0; t <= int(kFlight_s); t += 4) csv << t << ",46.2,12.8,900,90,20,0\n";
  }
  // The bundled cumulus scenario with a 30 m/s westerly, clock at x1.
  std::string scenario = readAll(SKY_SCENARIO_CLOUDY);
  const auto wind = scenario.find("speed_mps = 10.0");
  ASSERT_NE(wind, std::string::npos);
  scenario.replace(wind, 16, "speed_mps = 30.0");
  std::ofstream(dir / "windy.toml") << scenario;

  const std::string db = (dir / "weather.db").string();
  auto startServer = [&](const std::string& port, const std::string& tag) {
    return std::make_unique<ChildProcess>(
        std::vector<std::string>{SKY_WEATHERD, "--scenario", (dir / "windy.toml").string(), "--port", port,
                                 "--port-file", (dir / (tag + ".port")).string(), "--http-port", "0",
                                 "--http-port-file", (dir / (tag + ".http")).string(), "--token-file",
                                 (dir / "token").string(), "--db", db, "--heartbeat-ms", "200"},
        (dir / (tag + ".log")).string());
  };
  auto server = startServer("0", "first");
  const unsigned port = waitForPortFile((dir / "first.port").string(), 20s);
  const unsigned http = waitForPortFile((dir / "first.http").string(), 20s);
  ASSERT_GT(port, 0u) << server->log();
  ASSERT_GT(http, 0u) << server->log();
  // A storm region drifting with the wind 2 km east of the camera: its edge
  // moves through the view, and its tiles make the snapshot carry a field
  // that the renderer advects from the snapshot's clock.
  const std::string region = R"({"changes": [{"op": "set_region", "region": {
      "id": 7, "center_lat_deg": 46.2, "center_lon_deg": 12.826, "size_x_m": 3000, "size_y_m": 3000,
      "corner_radius_m": 1000, "transition_m": 500, "drifts_with_wind": true,
      "layers": [{"id": 1, "type": "cumulus", "base_m": 1500, "thickness_m": 1500, "transition_band_m": 100,
                  "coverage": 0.95, "density": 1,
                  "wind": {"speed_mps": 30, "from_deg": 270, "vertical_mps": 0}}]}}]})";
  sim::HttpRequest post;
  post.method = "POST";
  post.port = static_cast<unsigned short>(http);
  post.target = "/api/changes";
  post.body = region;
  post.bearerToken = kToken;
  const auto posted = sim::httpRequest(post);
  ASSERT_TRUE(posted && posted->status == 200) << (posted ? posted->body : describe(posted.error()));

  const fs::path out = dir / "out";
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(port), "--replay",
                       (dir / "hover.csv").string(), "--step", std::to_string(kStep_s), "--replay-pace", "1",
                       "--write-float", "--no-exr", "--no-video", "--out", out.string(), "--width",
                       std::to_string(kWidth), "--height", std::to_string(kHeight)},
                      (dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const fs::path jsonl = out / "frames" / "frames.jsonl";

  // Kill once a few frames are out, restart once the renderer has drawn
  // frames without the server, on the same port and file.
  ASSERT_TRUE(waitFor([&] { return frames(jsonl).size() >= 8; }, 120s)) << render.log();
  const std::size_t killedAfter = frames(jsonl).size();
  const std::uint64_t versionAtKill = frames(jsonl).back()["weather_version"];
  server->killNow();
  ASSERT_TRUE(waitFor(
      [&] {
        const auto f = frames(jsonl);
        return std::count_if(f.begin(), f.end(), [](const auto& j) { return j["weather_connected"] == false; }) >=
               kOutageFrames;
      },
      60s))
      << render.log();
  server = startServer(std::to_string(port), "second");
  ASSERT_EQ(waitForPortFile((dir / "second.port").string(), 20s), port) << server->log();

  const auto code = render.wait(300s);
  ASSERT_EQ(code.value_or(-1), 0) << render.log();
  EXPECT_EQ(server->stop(), 0) << server->log();
  const auto all = frames(jsonl);
  ASSERT_EQ(all.size(), std::size_t(kFlight_s / kStep_s) + 1);

  // Finite; the version never goes back and grows after the restart; the
  // outage was seen and ended.
  std::size_t disconnected = 0, firstBack = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i]["non_finite"], 0) << "frame " << i;
    EXPECT_EQ(all[i]["layers"], 1) << "frame " << i << ": the last weather is kept";
    if (i > 0) {
      EXPECT_GE(all[i]["weather_version"], all[i - 1]["weather_version"]) << "frame " << i;
    }
    if (all[i]["weather_connected"] == false) ++disconnected;
    if (i >= killedAfter && firstBack == 0 && all[i]["weather_connected"] == true &&
        all[i]["weather_version"].get<std::uint64_t>() > versionAtKill)
      firstBack = i;
  }
  EXPECT_GE(disconnected, std::size_t(kOutageFrames));
  ASSERT_GT(firstBack, 0u) << "no new weather after the restart:\n" << render.log();
  EXPECT_LT(firstBack + 2, all.size()) << "the resync came too late to look at the frames after it";
  EXPECT_NE(render.log().find("weather server connection lost"), std::string::npos) << render.log();

  // No jump: consecutive differences stay within the motion before the kill.
  std::vector<double> diffs;
  std::vector<float> previous = readPfm(out / "frames" / "frame_000000.pfm");
  for (std::size_t i = 1; i < all.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06zu.pfm", i);
    std::vector<float> next = readPfm(out / "frames" / name);
    diffs.push_back(meanAbsDiff(previous, next));
    previous = std::move(next);
  }
  // Pairs (i-1, i) with i < killedAfter were drawn with the server up.
  const double before = *std::max_element(diffs.begin(), diffs.begin() + std::ptrdiff_t(killedAfter - 1));
  const double quietest = *std::min_element(diffs.begin(), diffs.begin() + std::ptrdiff_t(killedAfter - 1));
  ASSERT_GT(quietest, 0.0) << "the clouds must move between frames for this test to see a jump";
  for (std::size_t i = 0; i < diffs.size(); ++i) {
    EXPECT_LE(diffs[i], kJumpFactor * before)
        << "frames " << i << "-" << i + 1 << " (connected " << all[i + 1]["weather_connected"] << ", version "
        << all[i + 1]["weather_version"] << ") differ by " << diffs[i] << ", motion before the kill at most "
        << before;
    // Still advected while the server is away: the clouds keep moving.
    if (all[i + 1]["weather_connected"] == false) {
      EXPECT_GT(diffs[i], 0.0) << "frames " << i << "-" << i + 1;
    }
  }
  std::printf("[ reconnect] %zu frames, %zu without the server, resync at frame %zu; motion before the kill "
              "%.5f-%.5f, largest change after %.5f\n",
              all.size(), disconnected, firstBack, quietest, before,
              *std::max_element(diffs.begin() + std::ptrdiff_t(killedAfter - 1), diffs.end()));
}

}  // namespace
}  // namespace sky::test
