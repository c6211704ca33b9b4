// End-to-end through real processes on loopback: skyshell-weatherd streams a
// scenario, skyshell-render subscribes and renders headless on Vulkan, and
// skyshell-replay flies a recorded flight into it over CIGI. Checks the frames
// exist, the camera followed the flight, the radiance is finite, and clouds
// appear exactly when the scenario has them.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "frame_files.hpp"
#include "sky/flight/flight.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

struct PipelineRun {
  fs::path dir;
  std::vector<nlohmann::json> frames;
  std::string pfm(std::size_t i, const char* suffix) const {
    return (dir / "frames" / fs::path(frames[i]["file"].get<std::string>()).replace_extension(suffix)).string();
  }
};

// Runs the three processes with a scenario and returns the frame metadata.
PipelineRun runPipeline(const std::string& name, const std::string& scenario) {
  PipelineRun run;
  run.dir = fs::path(SKY_TEST_OUTPUT_DIR) / name;
  fs::remove_all(run.dir);
  fs::create_directories(run.dir);
  const std::string d = run.dir.string();

  ChildProcess weatherd({SKY_WEATHERD, "--scenario", scenario, "--port", "0", "--port-file",
                         d + "/weatherd.port", "--heartbeat-ms", "200"},
                        d + "/weatherd.log");
  const unsigned weatherPort = waitForPortFile(d + "/weatherd.port", 20s);
  EXPECT_GT(weatherPort, 0u) << weatherd.log();
  if (weatherPort == 0) return run;

  // The Vulkan driver (lavapipe's LLVM JIT) leaves allocations whose stacks
  // end in unloaded JIT code, which no suppression can name: leak checking is
  // off for the renderer process only (its own code is leak-checked through
  // the gpu and unit tests, where the driver stays loaded).
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(weatherPort),
                       "--cigi-port", "0", "--port-file", d + "/render.port", "--out", d + "/frames",
                       "--width", "160", "--height", "90", "--write-float", "--idle-exit", "3",
                       "--weather-timeout", "60"},
                      d + "/render.log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const unsigned cigiPort = waitForPortFile(d + "/render.port", 60s);
  EXPECT_GT(cigiPort, 0u) << render.log();
  if (cigiPort == 0) return run;

  // The replay also asks the renderer for the weather at the ownship (CIGI
  // Environmental Conditions Request) 4 times per flight second.
  ChildProcess replay({SKY_REPLAY, SKY_TEST_FLIGHT, "--port", std::to_string(cigiPort), "--rate", "60",
                       "--conditions-rate", "4", "--conditions-csv", d + "/conditions.csv"},
                      d + "/replay.log");
  EXPECT_EQ(replay.wait(60s), std::optional<int>(0)) << replay.log();
  EXPECT_EQ(render.wait(120s), std::optional<int>(0)) << render.log();
  EXPECT_EQ(weatherd.stop(), 0) << weatherd.log();

  std::istringstream lines(readText(d + "/frames/frames.jsonl"));
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) run.frames.push_back(nlohmann::json::parse(line));
  return run;
}

std::size_t nonFinite(const Pfm& img) {
  std::size_t n = 0;
  for (float v : img.data) n += !std::isfinite(v);
  return n;
}

double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

// The frame of `run` whose host time is closest to t.
std::size_t nearestFrame(const PipelineRun& run, double t) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < run.frames.size(); ++i)
    if (std::abs(run.frames[i]["host_time_s"].get<double>() - t) <
        std::abs(run.frames[best]["host_time_s"].get<double>() - t))
      best = i;
  return best;
}

// The host's conditions requests came back answered with the weather the
// renderer held: the cumulus layer's wind (10 m/s from 270; the flight is
// below the layer, where its wind applies), standard-atmosphere temperature,
// clear air (the flight stays 500 m below the base), no cloud water.
TEST(Skeleton, ReplayHostGetsTheWeatherAtTheOwnship) {
  const PipelineRun cloudy = runPipeline("conditions", SKY_SCENARIO_CLOUDY);
  std::istringstream csv(readText((cloudy.dir / "conditions.csv").string()));
  std::string header;
  ASSERT_TRUE(std::getline(csv, header));
  EXPECT_EQ(header.rfind("flight_time_s,lat_deg,lon_deg,alt_m,answered_after_s,wind_mps,wind_from_deg", 0), 0u);
  std::size_t rows = 0, answered = 0;
  for (std::string line; std::getline(csv, line);) {
    ++rows;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) f.push_back(cell);
    ASSERT_GE(f.size(), 13u) << line;
    // Before the first weather arrived the renderer knows no layer: calm, and
    // no cloud layer answers (empty cloud columns).
    if (f[12].empty()) continue;
    ++answered;
    const double alt = std::stod(f[3]);
    EXPECT_NEAR(std::stod(f[5]), 10.0, 0.01) << line;
    EXPECT_NEAR(std::stod(f[6]), 270.0, 0.1) << line;
    EXPECT_NEAR(std::stod(f[9]), 15.0 - 0.0065 * alt, 0.06) << line;  // ISA, printed to 0.1
    EXPECT_EQ(std::stod(f[12]), 0.0) << "cloud water in clear air: " << line;
  }
  // 6 s of flight at 4 requests per second.
  EXPECT_GE(rows, 20u);
  EXPECT_GE(answered, rows / 2) << "most requests must be answered";
}

TEST(Skeleton, ThreeProcessesRenderTheStreamedWeatherAlongTheReplayedFlight) {
  const PipelineRun clear = runPipeline("clear", SKY_SCENARIO_CLEAR);
  const PipelineRun cloudy = runPipeline("cloudy", SKY_SCENARIO_CLOUDY);
  ASSERT_GE(clear.frames.size(), 3u) << "too few frames in " << clear.dir;
  ASSERT_GE(cloudy.frames.size(), 3u) << "too few frames in " << cloudy.dir;
  auto parsed = flight::parseCsv(readText(SKY_TEST_FLIGHT), SKY_TEST_FLIGHT);
  ASSERT_TRUE(parsed) << parsed.error().detail;
  const flight::Flight& flight = *parsed;

  for (const PipelineRun* run : {&clear, &cloudy}) {
    double lastTime = -1;
    for (const auto& fr : run->frames) {
      EXPECT_TRUE(fs::exists(run->dir / "frames" / fr["file"].get<std::string>())) << fr["file"];
      // The camera is where the replayed flight put the ownship at that host time.
      const double t = fr["host_time_s"].get<double>();
      EXPECT_GE(t, lastTime) << "frames went back in flight time";
      lastTime = t;
      const geo::GeodeticPose want = flight::sample(flight, t);
      EXPECT_NEAR(fr["lat_deg"].get<double>(), want.position.lat_deg, 1e-7) << run->dir << " frame " << fr["frame"];
      EXPECT_NEAR(fr["lon_deg"].get<double>(), want.position.lon_deg, 1e-7) << run->dir << " frame " << fr["frame"];
      EXPECT_NEAR(fr["alt_m"].get<double>(), want.position.alt_m, 1e-3) << run->dir << " frame " << fr["frame"];
      EXPECT_NEAR(fr["yaw_deg"].get<double>(), want.yaw_deg, 1e-3);
    }
    // The frames span the flight: the first soon after the start, the last at
    // the final fix, which the replay sends last.
    EXPECT_LT(run->frames.front()["host_time_s"].get<double>(), 2.0) << run->dir;
    EXPECT_NEAR(run->frames.back()["host_time_s"].get<double>(), flight.duration_s(), 1e-3) << run->dir;
  }

  // Clear scenario: finite radiance, and nothing attenuates any view ray.
  for (std::size_t i = 0; i < clear.frames.size(); ++i) {
    const Pfm rgb = readPfm(clear.pfm(i, ".pfm"));
    const Pfm t = readPfm(clear.pfm(i, ".transmittance.pfm"));
    EXPECT_EQ(nonFinite(rgb), 0u) << clear.pfm(i, ".pfm");
    float minT = 1;
    for (float v : t.data) minT = std::min(minT, v);
    EXPECT_GE(minT, 0.9999f) << "cloud in a clear sky: " << clear.pfm(i, ".transmittance.pfm");
  }

  // Cumulus scenario: nose up 15 deg, 600 m under a 60 % cumulus base, so the
  // top third of the view looks into the layer: many view rays are mostly
  // blocked there, and those pixels differ visibly from the clear sky seen
  // at the same moment of the flight.
  for (std::size_t i = 0; i < cloudy.frames.size(); ++i) {
    const Pfm rgb = readPfm(cloudy.pfm(i, ".pfm"));
    const Pfm t = readPfm(cloudy.pfm(i, ".transmittance.pfm"));
    EXPECT_EQ(nonFinite(rgb), 0u) << cloudy.pfm(i, ".pfm");
    const std::size_t j = nearestFrame(clear, cloudy.frames[i]["host_time_s"].get<double>());
    const Pfm sky = readPfm(clear.pfm(j, ".pfm"));
    std::size_t total = 0, blocked = 0, differs = 0;
    for (int y = 0; y < rgb.height / 3; ++y)
      for (int x = 0; x < rgb.width; ++x) {
        ++total;
        if (*t.at(x, y) < 0.5f) ++blocked;
        const double lc = luminance(rgb.at(x, y)), ls = luminance(sky.at(x, y));
        if (std::abs(lc - ls) > 0.05 * ls) ++differs;
      }
    EXPECT_GT(blocked, total / 5) << cloudy.pfm(i, ".transmittance.pfm");
    EXPECT_GT(differs, total / 5) << cloudy.pfm(i, ".pfm") << " vs " << clear.pfm(j, ".pfm");
  }
}

}  // namespace
}  // namespace sky::test
