// End-to-end through real processes on loopback: skyshell-weatherd streams a
// scenario, skyshell-render subscribes and renders headless on Vulkan, and
// skyshell-replay flies a recorded flight into it over CIGI. Checks the frames
// exist, the camera followed the flight, the radiance is finite, and clouds
// appear exactly when the scenario has them.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/flight/flight.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

struct Pfm {
  int width = 0, height = 0;
  std::vector<float> rgb;  // top row first after loading
};

Pfm readPfm(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::string magic;
  float scale = 0;
  Pfm p;
  f >> magic >> p.width >> p.height >> scale;
  f.get();
  EXPECT_EQ(magic, "PF") << path;
  EXPECT_LT(scale, 0) << "little-endian PFM expected: " << path;
  p.rgb.resize(static_cast<std::size_t>(p.width) * p.height * 3);
  std::vector<float> rows(p.rgb.size());
  f.read(reinterpret_cast<char*>(rows.data()), static_cast<std::streamsize>(rows.size() * sizeof(float)));
  EXPECT_TRUE(f) << "short PFM " << path;
  const std::size_t rowLen = static_cast<std::size_t>(p.width) * 3;
  for (int y = 0; y < p.height; ++y)  // PFM stores the bottom row first
    std::copy_n(rows.begin() + static_cast<std::ptrdiff_t>((p.height - 1 - y) * rowLen), rowLen,
                p.rgb.begin() + static_cast<std::ptrdiff_t>(y * rowLen));
  return p;
}

// A clear sky scatters blue far more than red (Rayleigh); cloud droplets
// scatter all colours alike. So a sky pixel whose red is close to its blue is
// cloud. The threshold sits between the sky gradient's bluest-to-palest ratio
// and the grey of lit or shaded cloud.
constexpr float kCloudRedOverBlue = 0.85f;

double cloudFractionOfTopThird(const Pfm& img) {
  std::size_t cloud = 0, total = 0;
  for (int y = 0; y < img.height / 3; ++y)
    for (int x = 0; x < img.width; ++x) {
      const float* px = &img.rgb[(static_cast<std::size_t>(y) * img.width + x) * 3];
      ++total;
      if (px[2] > 0 && px[0] / px[2] > kCloudRedOverBlue) ++cloud;
    }
  return static_cast<double>(cloud) / static_cast<double>(total);
}

std::string readText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

struct RunResult {
  std::vector<nlohmann::json> frames;
  fs::path dir;
};

// Runs the three processes with a scenario and returns the frame metadata.
RunResult runPipeline(const std::string& name, const std::string& scenario) {
  RunResult result;
  result.dir = fs::path(SKY_TEST_OUTPUT_DIR) / name;
  fs::remove_all(result.dir);
  fs::create_directories(result.dir);
  const std::string d = result.dir.string();

  ChildProcess weatherd({SKY_WEATHERD, "--scenario", scenario, "--port", "0", "--port-file",
                         d + "/weatherd.port", "--heartbeat-ms", "200"},
                        d + "/weatherd.log");
  const unsigned weatherPort = waitForPortFile(d + "/weatherd.port", 20s);
  EXPECT_GT(weatherPort, 0u) << weatherd.log();
  if (weatherPort == 0) return result;

  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(weatherPort),
                       "--cigi-port", "0", "--port-file", d + "/render.port", "--out", d + "/frames",
                       "--width", "160", "--height", "90", "--write-float", "--idle-exit", "3",
                       "--weather-timeout", "60"},
                      d + "/render.log");
  const unsigned cigiPort = waitForPortFile(d + "/render.port", 60s);
  EXPECT_GT(cigiPort, 0u) << render.log();
  if (cigiPort == 0) return result;

  ChildProcess replay({SKY_REPLAY, SKY_TEST_FLIGHT, "--port", std::to_string(cigiPort), "--rate", "60"},
                      d + "/replay.log");
  const auto replayExit = replay.wait(60s);
  EXPECT_EQ(replayExit, std::optional<int>(0)) << replay.log();
  const auto renderExit = render.wait(120s);
  EXPECT_EQ(renderExit, std::optional<int>(0)) << render.log();
  EXPECT_EQ(weatherd.stop(), 0) << weatherd.log();

  std::istringstream lines(readText(d + "/frames/frames.jsonl"));
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) result.frames.push_back(nlohmann::json::parse(line));
  return result;
}

flight::Flight testFlight() {
  auto f = flight::parseCsv(readText(SKY_TEST_FLIGHT), SKY_TEST_FLIGHT);
  EXPECT_TRUE(f) << f.error().detail;
  return *f;
}

TEST(Skeleton, CloudyRunFollowsTheFlightAndShowsClouds) {
  const RunResult run = runPipeline("cloudy", SKY_SCENARIO_CLOUDY);
  const flight::Flight flight = testFlight();
  ASSERT_GE(run.frames.size(), 3u) << "too few frames rendered in " << run.dir;

  double lastTime = -1;
  for (const auto& fr : run.frames) {
    const std::string file = (run.dir / "frames" / fr["file"].get<std::string>()).string();
    EXPECT_TRUE(fs::exists(file)) << file;
    // The camera is where the replay said the ownship was at that host time.
    const double t = fr["host_time_s"].get<double>();
    EXPECT_GE(t, lastTime) << "frames went back in flight time";
    lastTime = t;
    const geo::GeodeticPose want = flight::sample(flight, t);
    EXPECT_NEAR(fr["lat_deg"].get<double>(), want.position.lat_deg, 1e-7) << "frame " << fr["frame"];
    EXPECT_NEAR(fr["lon_deg"].get<double>(), want.position.lon_deg, 1e-7) << "frame " << fr["frame"];
    EXPECT_NEAR(fr["alt_m"].get<double>(), want.position.alt_m, 1e-3) << "frame " << fr["frame"];
    EXPECT_NEAR(fr["yaw_deg"].get<double>(), want.yaw_deg, 1e-3);
    EXPECT_EQ(fr["layers"].get<int>(), 1);
  }
  // The frames span the flight: the first soon after the start, the last at
  // the final fix the replay holds at the end.
  EXPECT_LT(run.frames.front()["host_time_s"].get<double>(), 2.0);
  EXPECT_NEAR(run.frames.back()["host_time_s"].get<double>(), flight.duration_s(), 1e-3);

  for (const auto& fr : run.frames) {
    const std::string pfm = (run.dir / "frames" / fr["file"].get<std::string>()).replace_extension(".pfm").string();
    const Pfm img = readPfm(pfm);
    std::size_t nonFinite = 0;
    for (float v : img.rgb) nonFinite += !std::isfinite(v);
    EXPECT_EQ(nonFinite, 0u) << pfm;
    // Nose up 15 deg, 600 m under a 60 % cumulus base: the top third of the
    // view looks into the cloud layer.
    EXPECT_GT(cloudFractionOfTopThird(img), 0.2) << pfm;
  }
}

TEST(Skeleton, ClearScenarioRendersClearSky) {
  const RunResult run = runPipeline("clear", SKY_SCENARIO_CLEAR);
  ASSERT_GE(run.frames.size(), 3u) << "too few frames rendered in " << run.dir;
  for (const auto& fr : run.frames) {
    const Pfm img = readPfm((run.dir / "frames" / fr["file"].get<std::string>()).replace_extension(".pfm").string());
    for (float v : img.rgb) ASSERT_TRUE(std::isfinite(v));
    EXPECT_LT(cloudFractionOfTopThird(img), 0.005) << fr["file"];
  }
}

}  // namespace
}  // namespace sky::test
