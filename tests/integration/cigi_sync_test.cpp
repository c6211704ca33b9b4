// Synchronous CIGI: a renderer with --cigi-sync and skyshell-replay --sync.
// The host sends a frame only when the IG has answered the one before with
// Start of Frame, and the IG answers only once the frame is drawn, so every
// host frame is drawn exactly once, in order, and the host runs at the
// renderer's pace (its flight advancing one 1/rate step per frame).
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "weatherd_process.hpp"

namespace sky::test {
namespace {

TEST(CigiSync, EveryHostFrameIsDrawnExactlyOnceInOrder) {
  Weatherd weatherd("cigi_sync");
  ASSERT_GT(weatherd.streamPort, 0u) << weatherd.process->log();
  const std::string d = weatherd.dir.string();
  ChildProcess render({SKY_RENDER, "--headless", "--cigi-sync", "--server",
                       "127.0.0.1:" + std::to_string(weatherd.streamPort), "--cigi-port", "0", "--port-file",
                       d + "/cigi.port", "--out", d + "/frames", "--width", "64", "--height", "36", "--no-exr",
                       "--idle-exit", "3", "--weather-timeout", "60"},
                      d + "/render.log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const unsigned cigiPort = waitForPortFile(d + "/cigi.port", 90s);
  ASSERT_GT(cigiPort, 0u) << render.log();
  // 3 s of flight at 10 host frames per second of flight: 31 host frames,
  // as fast as the renderer draws them.
  ChildProcess replay({SKY_REPLAY, SKY_TEST_FLIGHT, "--port", std::to_string(cigiPort), "--sync", "--rate", "10",
                       "--end", "3", "--conditions-rate", "0"},
                      d + "/replay.log");
  ASSERT_EQ(replay.wait(300s), std::optional<int>(0)) << replay.log();
  ASSERT_EQ(render.wait(60s), std::optional<int>(0)) << render.log();

  std::vector<std::uint32_t> hostFrames;
  std::ifstream jsonl(d + "/frames/frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) hostFrames.push_back(nlohmann::json::parse(line)["host_frame"].get<std::uint32_t>());
  ASSERT_GE(hostFrames.size(), 30u) << render.log();
  // The first host frame may wait for the server's first weather longer
  // than the host's timeout; from the second on each is drawn once, in order.
  for (std::size_t i = 2; i < hostFrames.size(); ++i)
    EXPECT_EQ(hostFrames[i], hostFrames[i - 1] + 1) << "frame " << i << ": a host frame skipped or drawn twice";
  EXPECT_EQ(hostFrames.back(), 30u) << "the last host frame (31 sent, numbered from 0)";
  const std::string log = replay.log();
  EXPECT_NE(log.find("31 frames sent"), std::string::npos) << log;
  const auto at = log.find("synchronous: ");
  ASSERT_NE(at, std::string::npos) << log;
  const unsigned timeouts = std::stoul(log.substr(at + 13));
  EXPECT_LE(timeouts, 1u) << log;
  std::printf("cigi sync: %zu frames for 31 host frames, %u host timeouts\n", hostFrames.size(), timeouts);
}

}  // namespace
}  // namespace sky::test
