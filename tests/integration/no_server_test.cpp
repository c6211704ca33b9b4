// A live channel with no weather server: it draws from the host's first
// poses (clear sky, weather_source "clear"), and when skyshell-weatherd
// starts later on the port it was given, it switches to the server's weather
// (weather_source "server", the scenario's layers) without a restart.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/cigi/codec.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// A TCP port free right now on loopback (bound, read back, released).
unsigned freeTcpPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

std::vector<nlohmann::json> readFrames(const fs::path& jsonl) {
  std::vector<nlohmann::json> frames;
  std::ifstream in(jsonl);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) frames.push_back(nlohmann::json::parse(line));
  return frames;
}

TEST(NoServer, ALiveChannelDrawsClearSkyThenTheServersWeatherWhenItComes) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "no_server";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string d = dir.string();
  const unsigned weatherPort = freeTcpPort();
  ChildProcess render({SKY_RENDER, "--headless", "--server", "127.0.0.1:" + std::to_string(weatherPort), "--cigi-port",
                       "0", "--port-file", d + "/cigi.port", "--out", d + "/frames", "--width", "64", "--height", "36",
                       "--no-exr", "--idle-exit", "3"},
                      d + "/render.log", {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const unsigned cigiPort = waitForPortFile(d + "/cigi.port", 90s);
  ASSERT_GT(cigiPort, 0u) << render.log();

  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(cigiPort));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::uint32_t hostFrame = 0;
  auto sendPose = [&] {
    cigi::IgControl ig;
    ig.hostFrame = ++hostFrame;
    cigi::EntityControl e;
    e.lat_deg = 46.2;
    e.lon_deg = 12.8;
    e.alt_m = 900 + hostFrame;  // a new pose every datagram
    cigi::DatagramWriter w;
    w.add(ig).add(e);
    const auto bytes = w.bytes();
    ::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  };
  // Without a server: frames until some are drawn (clear sky).
  const auto jsonl = dir / "frames" / "frames.jsonl";
  for (int i = 0; i < 600 && readFrames(jsonl).size() < 3; ++i) {
    sendPose();
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_GE(readFrames(jsonl).size(), 3u) << render.log();

  // The server comes up on the port the channel was told.
  ChildProcess weatherd({SKY_WEATHERD, "--scenario", SKY_SCENARIO_CLOUDY, "--port", std::to_string(weatherPort),
                         "--heartbeat-ms", "200"},
                        d + "/weatherd.log");
  bool switched = false;
  for (int i = 0; i < 900 && !switched; ++i) {
    sendPose();
    std::this_thread::sleep_for(100ms);
    const auto frames = readFrames(jsonl);
    switched = !frames.empty() && frames.back()["weather_source"] == "server";
  }
  ::close(fd);
  ASSERT_TRUE(switched) << render.log() << weatherd.log();
  ASSERT_EQ(render.wait(60s), std::optional<int>(0)) << render.log();
  EXPECT_EQ(weatherd.stop(), 0) << weatherd.log();

  const auto frames = readFrames(jsonl);
  std::size_t clear = 0, server = 0;
  for (const auto& f : frames) {
    if (f["weather_source"] == "clear") {
      EXPECT_EQ(server, 0u) << "clear sky again after the server's weather, frame " << f["frame"];
      EXPECT_EQ(f["layers"], 0);
      ++clear;
    } else {
      EXPECT_EQ(f["weather_source"], "server");
      EXPECT_GT(f["layers"].get<int>(), 0);
      ++server;
    }
  }
  EXPECT_GE(clear, 3u);
  EXPECT_GE(server, 1u);
  EXPECT_NE(render.log().find("no weather from"), std::string::npos) << render.log();
  std::printf("no server: %zu clear-sky frames, then %zu with the server's weather\n", clear, server);
}

}  // namespace
}  // namespace sky::test
