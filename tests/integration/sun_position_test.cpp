// The host's time of day reaches the picture (issue 19), through real
// processes on loopback: skyshell-replay flies 90 s of a dated glider flight
// (HFDTE030416, first fix 12:00:00: 2016-04-03T12:00:00Z) at 10x into a live
// skyshell-render over CIGI; every frame's recorded sun must be the
// ephemeris' sun for the datagram's date and time (the flight's start plus
// the IG Control timestamp, the replay's flight time) at the ownship, and
// not the default --sun-azimuth/--sun-elevation (135, 40).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/render/ephemeris.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// 2016-04-03T12:00:00Z, the flight's first fix (Python calendar.timegm).
constexpr double kFlightStartUtc_s = 1459684800;
// Angle between two sky directions, deg.
double angleBetween_deg(double az1, double el1, double az2, double el2) {
  constexpr double d = 3.14159265358979323846 / 180;
  const double c = std::sin(el1 * d) * std::sin(el2 * d) + std::cos(el1 * d) * std::cos(el2 * d) * std::cos((az1 - az2) * d);
  return std::acos(std::clamp(c, -1.0, 1.0)) / d;
}

TEST(SunPosition, LiveFramesAreLitByTheHostsDateAndTime) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "sun-position";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string d = dir.string();
  ChildProcess weatherd({SKY_WEATHERD, "--scenario", SKY_SCENARIO_CLEAR, "--port", "0", "--port-file",
                         d + "/weatherd.port", "--heartbeat-ms", "200"},
                        d + "/weatherd.log");
  const unsigned weatherPort = waitForPortFile(d + "/weatherd.port", 20s);
  ASSERT_GT(weatherPort, 0u) << weatherd.log();
  // Small frames: the test is about the sun's direction, not the image.
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(weatherPort),
                       "--cigi-port", "0", "--port-file", d + "/render.port", "--out", d + "/frames", "--width", "64",
                       "--height", "36", "--no-exr", "--idle-exit", "3", "--weather-timeout", "60"},
                      d + "/render.log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const unsigned cigiPort = waitForPortFile(d + "/render.port", 60s);
  ASSERT_GT(cigiPort, 0u) << render.log();
  ChildProcess replay({SKY_REPLAY, std::string(SKY_TEST_DATA_DIR) + "/flights/glider-thermalling-ne-italy.igc",
                       "--port", std::to_string(cigiPort), "--rate", "30", "--speed", "10", "--end", "90", "--quiet"},
                      d + "/replay.log");
  EXPECT_EQ(replay.wait(60s), std::optional<int>(0)) << replay.log();
  EXPECT_EQ(render.wait(120s), std::optional<int>(0)) << render.log();
  EXPECT_EQ(weatherd.stop(), 0) << weatherd.log();

  std::ifstream f(d + "/frames/frames.jsonl");
  std::size_t frames = 0;
  double worst_deg = 0, worstTime_s = 0, closestToDefault_deg = 180, lastHostTime_s = 0;
  for (std::string line; std::getline(f, line);) {
    if (line.empty()) continue;
    const auto j = nlohmann::json::parse(line);
    ++frames;
    ASSERT_TRUE(j.contains("utc_s")) << line;
    EXPECT_EQ(j["utc_source"], "cigi") << line;
    EXPECT_EQ(j["atmosphere"]["source"], "default") << line;
    const double hostTime_s = j["host_time_s"].get<double>();
    lastHostTime_s = hostTime_s;
    const double expectedUtc_s = kFlightStartUtc_s + hostTime_s;
    worstTime_s = std::max(worstTime_s, std::abs(j["utc_s"].get<double>() - expectedUtc_s));
    const auto sun = render::sunDirection(expectedUtc_s, j["lat_deg"], j["lon_deg"]);
    const double az = j["sun_azimuth_deg"], el = j["sun_elevation_deg"];
    worst_deg = std::max(worst_deg, angleBetween_deg(az, el, sun.azimuth_deg, sun.elevation_deg));
    closestToDefault_deg = std::min(closestToDefault_deg, angleBetween_deg(az, el, 135, 40));
  }
  std::printf("[ sun      ] %zu frames to host time %.1f s: worst sun direction error %.2e deg, worst UTC error "
              "%.2e s, nearest to the default 135/40: %.1f deg\n",
              frames, lastHostTime_s, worst_deg, worstTime_s, closestToDefault_deg);
  EXPECT_GE(frames, 10u) << render.log();
  // The replay's minutes cross 12:01 at flight time 60: the frames past it
  // show the host time kept advancing the seconds between packets.
  EXPECT_GT(lastHostTime_s, 60.0);
  // The frame's UTC comes from the same datagram as its recorded host time,
  // so no host->frame latency enters. Measured on an idle machine: 1.2e-6
  // deg, 9e-5 s over 235 frames (lavapipe, 2 cores shared); beside the
  // suite's other tests, up to 4.6e-4 s, and one full run failed a 1 ms
  // bound without its output kept. The bound is 10 ms: a clock or time-zone
  // error would be seconds or hours, and the sun's direction (0.25 deg/min,
  // bound 1e-3 deg = 0.24 s of its motion) is what the picture shows.
  EXPECT_LT(worstTime_s, 1e-2);
  EXPECT_LT(worst_deg, 1e-3);
  // 12:00 UTC at 12.8E in April: the sun stands ~48 deg high in the south,
  // far from the default light (135, 40).
  EXPECT_GT(closestToDefault_deg, 20.0);
}

}  // namespace
}  // namespace sky::test
