// The weather server goes away in the middle of a headless replay: it is
// SIGKILLed and restarted on the same --db and the same port. The renderer
// keeps drawing the weather it had, still advected on the weather clock,
// reconnects with backoff and resynchronises without a visible jump. The
// camera hovers, so everything that changes between frames is the clouds'
// motion (a 30 m/s layer wind).
//
// Two runs. With a storm region drifting with the wind (tiles the renderer
// advects from the snapshot's clock): every consecutive frame difference,
// across the outage and the resync, stays within twice what the motion
// gives before the kill (the resync pair named on its own); the weather
// clock in the metadata steps on with the flight; the version stays while
// the server is away and grows after the restart. With the layer alone: the
// whole run, outage and resync included, equals an uninterrupted rendering
// of the same flight at the same clocks by a fresh renderer (the region is
// left out there because its tiles, at S2 level 11 (about 4.5 km), sample a
// drifting edge a little differently at every snapshot clock, so two
// uninterrupted renderings from different snapshots differ).
#include <cstdio>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
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
// The region's edge ramps over 3 km: with a 500 m edge on the ~4.9 km
// tiles the resync step was 1.25-1.4x in the ASan build, 2.19x in the
// ThreadSanitizer build and 4.0x in an ASan build on a loaded machine, as
// where the sharp edge fell among the tiles at the restart depended on how
// late the restart came.
constexpr double kJumpFactor = 2.5;
// Frames drawn without the server before it is restarted (3 s of flight).
constexpr long kOutageFrames = 6;
// A frame may differ from the uninterrupted rendering at the same clock by
// this share of the smallest change over one step (what the eye sees move).
constexpr double kReferenceShare = 0.01;

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

struct OutageRun {
  fs::path dir, out;
  std::vector<nlohmann::json> frames;  // frames.jsonl of the run
  std::size_t killedAfter = 0;         // frames [0, killedAfter) were drawn with the server up
  std::uint64_t versionAtKill = 0;
  std::size_t firstBack = 0;           // first frame from new weather after the restart
  unsigned port = 0;
  std::unique_ptr<ChildProcess> server;  // the restarted one, still running
};

// The hover flight, rendered paced at flight speed while the server is
// killed after 8 frames and restarted once kOutageFrames frames were drawn
// without it. Checks what both runs share (finite frames, the clock, the
// version, the outage seen and ended).
void runWithOutage(const std::string& name, bool withRegion, OutageRun& run) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / name;
  run.dir = dir;
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
  ASSERT_NE(scenario.find("rate = 1.0"), std::string::npos);
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
  run.server = startServer("0", "first");
  run.port = waitForPortFile((dir / "first.port").string(), 20s);
  const unsigned http = waitForPortFile((dir / "first.http").string(), 20s);
  ASSERT_GT(run.port, 0u) << run.server->log();
  ASSERT_GT(http, 0u) << run.server->log();
  if (withRegion) {
    // A storm region drifting with the wind, centred 2 km east of the
    // camera: its edge, a ramp over 3 km, moves through the view, and its
    // tiles make the snapshot carry a field that the renderer advects from
    // the snapshot's clock.
    const std::string region = R"({"changes": [{"op": "set_region", "region": {
        "id": 7, "center_lat_deg": 46.2, "center_lon_deg": 12.826, "size_x_m": 8000, "size_y_m": 8000,
        "corner_radius_m": 2000, "transition_m": 3000, "drifts_with_wind": true,
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
  }

  run.out = dir / "out";
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(run.port), "--replay",
                       (dir / "hover.csv").string(), "--step", std::to_string(kStep_s), "--replay-pace", "1",
                       "--write-float", "--no-exr", "--no-video", "--out", run.out.string(), "--width",
                       std::to_string(kWidth), "--height", std::to_string(kHeight)},
                      (dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const fs::path jsonl = run.out / "frames" / "frames.jsonl";

  // Kill once a few frames are out, restart once the renderer has drawn
  // frames without the server, on the same port and file. Every wait is for
  // a count of frames written, so a slow machine only makes it take longer.
  ASSERT_TRUE(waitFor([&] { return frames(jsonl).size() >= 8; }, 180s)) << render.log();
  run.killedAfter = frames(jsonl).size();
  run.versionAtKill = frames(jsonl).back()["weather_version"];
  run.server->killNow();
  ASSERT_TRUE(waitFor(
      [&] {
        const auto f = frames(jsonl);
        return std::count_if(f.begin(), f.end(), [](const auto& j) { return j["weather_connected"] == false; }) >=
               kOutageFrames;
      },
      180s))
      << render.log();
  run.server = startServer(std::to_string(run.port), "second");
  ASSERT_EQ(waitForPortFile((dir / "second.port").string(), 30s), run.port) << run.server->log();

  ASSERT_EQ(render.wait(600s).value_or(-1), 0) << render.log();
  run.frames = frames(jsonl);
  const auto& all = run.frames;
  ASSERT_EQ(all.size(), std::size_t(kFlight_s / kStep_s) + 1);

  // Finite; the weather clock steps on with the flight across the outage and
  // the resync (the scenario's rate is 1: one step of flight is kStep_s of
  // weather clock); the version stays while the server is away, never goes
  // back and grows after the restart; the outage was seen and ended.
  std::size_t disconnected = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i]["non_finite"], 0) << "frame " << i;
    EXPECT_EQ(all[i]["layers"], 1) << "frame " << i << ": the last weather is kept";
    if (i > 0) {
      EXPECT_NEAR(all[i]["weather_clock_s"].get<double>() - all[i - 1]["weather_clock_s"].get<double>(), kStep_s,
                  1e-6)
          << "frame " << i << ": the weather clock jumped";
      EXPECT_GE(all[i]["weather_version"], all[i - 1]["weather_version"]) << "frame " << i;
      if (all[i]["weather_connected"] == false && all[i - 1]["weather_connected"] == false) {
        EXPECT_EQ(all[i]["weather_version"], all[i - 1]["weather_version"])
            << "frame " << i << ": new weather while the server was away";
      }
    }
    if (all[i]["weather_connected"] == false) ++disconnected;
    if (i >= run.killedAfter && run.firstBack == 0 && all[i]["weather_connected"] == true &&
        all[i]["weather_version"].get<std::uint64_t>() > run.versionAtKill)
      run.firstBack = i;
  }
  EXPECT_GE(disconnected, std::size_t(kOutageFrames));
  ASSERT_GT(run.firstBack, 0u) << "no new weather after the restart:\n" << render.log();
  ASSERT_LT(run.firstBack + 2, all.size()) << "the resync came too late to look at the frames after it";
  EXPECT_NE(render.log().find("weather server connection lost"), std::string::npos) << render.log();
  std::printf("[ reconnect] %s: %zu frames, killed after %zu, %zu without the server, resync at frame %zu\n",
              name.c_str(), all.size(), run.killedAfter, disconnected, run.firstBack);
}

std::vector<float> framePfm(const fs::path& out, std::size_t i) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06zu.pfm", i);
  return readPfm(out / "frames" / name);
}

TEST(HeadlessReconnect, ServerKilledAndRestartedMidReplayCausesNoJump) {
  OutageRun run;
  runWithOutage("reconnect", true, run);
  if (HasFatalFailure()) return;
  EXPECT_EQ(run.server->stop(), 0) << run.server->log();
  const auto& all = run.frames;
  std::vector<std::vector<float>> image;
  for (std::size_t i = 0; i < all.size(); ++i) image.push_back(framePfm(run.out, i));
  // Consecutive differences: the clouds' motion over one step.
  std::vector<double> diffs;
  for (std::size_t i = 1; i < all.size(); ++i) diffs.push_back(meanAbsDiff(image[i - 1], image[i]));
  // Pairs (i-1, i) with i < killedAfter were drawn with the server up.
  const auto upEnd = diffs.begin() + std::ptrdiff_t(run.killedAfter - 1);
  const double before = *std::max_element(diffs.begin(), upEnd);
  const double quietest = *std::min_element(diffs.begin(), upEnd);
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
  // The resync itself: the last frame drawn from the held weather and the
  // first from the new weather differ by no more than kJumpFactor x the
  // largest step with the server up. The new snapshot samples the drifting
  // region on its level-11 tiles (~4.9 km cells) at a later clock; the
  // region's edge ramps linearly over 3 km, which the renderer's bilinear
  // lookup of the advected tiles reproduces, so the resampling changes
  // little (measured 0.37-0.39x in the Release build, with the machine idle
  // and with both cores busy). The resync adds nothing else: the
  // region-free test below finds every frame equal to an uninterrupted
  // rendering.
  const double resync = diffs[run.firstBack - 1];
  EXPECT_LE(resync, kJumpFactor * before)
      << "frames " << run.firstBack - 1 << "-" << run.firstBack << " (the resync) differ by " << resync
      << ", consecutive frames with the server up by at most " << before;
  std::printf("[ reconnect] motion over a step with the server up %.5f-%.5f, at the resync %.5f, largest after the "
              "kill %.5f\n",
              quietest, before, resync, *std::max_element(upEnd, diffs.end()));
}

TEST(HeadlessReconnect, HeldWeatherIsWhatAnUninterruptedRendererDraws) {
  OutageRun run;
  runWithOutage("reconnect-held", false, run);
  if (HasFatalFailure()) return;
  const auto& all = run.frames;
  // The independent reference: the same flight drawn again by a fresh
  // renderer from the restarted server, without an outage, at the run's
  // weather clock (pinned to its first frame's). What the run drew while the
  // server was away and after the resync must be what the server's weather
  // looks like at that clock, not merely something that moves smoothly.
  const fs::path refOut = run.dir / "reference";
  char clockArg[64];
  std::snprintf(clockArg, sizeof clockArg, "%.17g", all.front()["weather_clock_s"].get<double>());
  ChildProcess reference({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(run.port), "--replay",
                          (run.dir / "hover.csv").string(), "--step", std::to_string(kStep_s), "--weather-clock",
                          clockArg, "--write-float", "--no-exr", "--no-video", "--out", refOut.string(),
                          "--width", std::to_string(kWidth), "--height", std::to_string(kHeight)},
                         (run.dir / "reference.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  ASSERT_EQ(reference.wait(600s).value_or(-1), 0) << reference.log();
  EXPECT_EQ(run.server->stop(), 0) << run.server->log();
  const auto ref = frames(refOut / "frames" / "frames.jsonl");
  ASSERT_EQ(ref.size(), all.size()) << reference.log();

  double quietest = std::numeric_limits<double>::infinity(), worstUp = 0, worstHeld = 0, worstAfter = 0;
  std::vector<double> fromReference;
  std::vector<float> previous;
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_NEAR(all[i]["weather_clock_s"].get<double>(), ref[i]["weather_clock_s"].get<double>(), 1e-6)
        << "frame " << i;
    std::vector<float> image = framePfm(run.out, i);
    if (i > 0 && i < run.killedAfter) quietest = std::min(quietest, meanAbsDiff(previous, image));
    const double d = meanAbsDiff(image, framePfm(refOut, i));
    fromReference.push_back(d);
    // Frames [killedAfter, firstBack) were drawn from the held weather.
    double& worst = i < run.killedAfter ? worstUp : i < run.firstBack ? worstHeld : worstAfter;
    worst = std::max(worst, d);
    previous = std::move(image);
  }
  ASSERT_GT(quietest, 0.0) << "the clouds must move between frames for this test to mean anything";
  // Every frame, before, during and after the outage, is the uninterrupted
  // rendering of the same clock within a hundredth of the smallest change
  // over one step with the server up (the same weather at the same clock
  // gives the same image; float noise only).
  const double tolerance = kReferenceShare * quietest;
  for (std::size_t i = 0; i < all.size(); ++i)
    EXPECT_LE(fromReference[i], tolerance)
        << "frame " << i << " (connected " << all[i]["weather_connected"] << ") differs by " << fromReference[i]
        << " from the uninterrupted rendering at the same clock; tolerance " << tolerance;
  std::printf("[ reconnect] from the uninterrupted rendering: server up %.3g, held weather %.3g, after the resync "
              "%.3g (tolerance %.3g = %.2f x the smallest step's motion %.5f)\n",
              worstUp, worstHeld, worstAfter, tolerance, kReferenceShare, quietest);
}

}  // namespace
}  // namespace sky::test
