// The host sets the cameras' exposure over CIGI (issue 26): Skyshell's
// camera exposure component (Component Control, class View, component id
// 100) through a real skyshell-render channel and a real UDP socket on
// loopback, synchronous (--cigi-sync), so every host frame is drawn once and
// its frames.jsonl line says what exposed it. The host's fixed EV100 holds
// from the frame that carries it until the host gives the exposure back to
// the meter (auto); a malformed exposure component drops its datagram
// (counted, never answered), one for another view and an unknown component
// change nothing (counted).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "sky/cigi/codec.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// The host: one UDP socket on loopback that sends a datagram and waits for
// the channel's Start of Frame.
class Host {
 public:
  Host() : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in self{};
    self.sin_family = AF_INET;
    self.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<const sockaddr*>(&self), sizeof self);
  }
  ~Host() { ::close(fd_); }
  void send(unsigned port, const std::vector<std::uint8_t>& bytes) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
  // The last host frame a Start of Frame answered within the timeout.
  std::optional<std::uint32_t> answer(std::chrono::milliseconds timeout) const {
    std::vector<std::uint8_t> buf(65536);
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return std::nullopt;
    const auto n = ::recv(fd_, buf.data(), buf.size(), 0);
    if (n <= 0) return std::nullopt;
    buf.resize(static_cast<std::size_t>(n));
    const auto d = cigi::decodeDatagram(buf);
    if (!d) return std::nullopt;
    const auto* sof = std::get_if<cigi::StartOfFrame>(&d->packets.front());
    if (!sof) return std::nullopt;
    return sof->lastHostFrame;
  }

 private:
  int fd_;
};

// Host frame k: 0.1 s of host time apart, the ownship level at 1500 m
// heading east, nose up 10 deg; plus `extra` packets.
std::vector<std::uint8_t> hostFrame(std::uint32_t k, std::vector<cigi::Packet> extra = {}) {
  cigi::IgControl ig;
  ig.hostFrame = k;
  ig.timestampValid = true;
  ig.timestamp_10us = 10000 * k;
  cigi::EntityControl e;
  e.lat_deg = 46.2;
  e.lon_deg = 12.8 + 0.00007 * k;
  e.alt_m = 1500;
  e.yaw_deg = 90;
  e.pitch_deg = 10;
  cigi::DatagramWriter w(cigi::ByteOrder::Big);
  w.add(ig).add(e);
  for (const auto& p : extra) w.add(p);
  return w.bytes();
}

cigi::CameraExposureControl exposure(cigi::ExposureMode mode, float ev100, float compensation_ev,
                                     std::uint16_t view = cigi::CameraExposureControl::kAllViews) {
  cigi::CameraExposureControl c;
  c.viewId = view;
  c.mode = mode;
  c.ev100 = ev100;
  c.compensation_ev = compensation_ev;
  return c;
}

TEST(HostExposure, TheHostFixesTheEv100AndGivesItBackToTheMeter) {
  const fs::path dir = fs::path(SKY_TEST_OUTPUT_DIR) / "host-exposure";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // No weather server (port 1 refuses): the channel draws the clear
  // scenario file after 1 s, as a channel without a server does.
  ChildProcess render({SKY_RENDER, "--headless", "--cigi-sync", "--server", "127.0.0.1:1", "--weather-file",
                       SKY_SCENARIO_CLEAR, "--cigi-port", "0", "--port-file", (dir / "cigi.port").string(), "--out",
                       (dir / "frames").string(), "--width", "32", "--height", "18", "--no-exr", "--idle-exit", "2"},
                      (dir / "render.log").string(), {"ASAN_OPTIONS=detect_leaks=0:abort_on_error=1"});
  const unsigned port = waitForPortFile((dir / "cigi.port").string(), 90s);
  ASSERT_GT(port, 0u) << render.log();
  Host host;
  // Sends host frame k and waits for its Start of Frame (sent once it is drawn).
  const auto drawn = [&](std::uint32_t k, std::vector<cigi::Packet> extra = {}) {
    host.send(port, hostFrame(k, std::move(extra)));
    return host.answer(k == 0 ? 90000ms : 30000ms) == std::optional<std::uint32_t>(k);
  };
  using cigi::ExposureMode;
  for (std::uint32_t k = 0; k < 3; ++k) ASSERT_TRUE(drawn(k)) << "host frame " << k << "\n" << render.log();
  ASSERT_TRUE(drawn(3, {exposure(ExposureMode::Fixed, 13.0f, 0.5f)})) << render.log();
  ASSERT_TRUE(drawn(4)) << render.log();
  // A malformed exposure component (state 7): the datagram is dropped, not answered.
  auto bad = hostFrame(5, {exposure(ExposureMode::Fixed, 3.0f, 0.0f)});
  bad[bad.size() - 32 + 7] = 7;
  host.send(port, bad);
  EXPECT_EQ(host.answer(500ms), std::nullopt) << "a malformed datagram was answered";
  // Another view's exposure, and a component that is not ours (View class, id 101).
  ASSERT_TRUE(drawn(5, {exposure(ExposureMode::Fixed, 3.0f, 0.0f, 7)})) << render.log();
  auto unknown = hostFrame(6, {exposure(ExposureMode::Fixed, 3.0f, 0.0f)});
  unknown[unknown.size() - 32 + 3] = 101;  // big-endian component id 101
  host.send(port, unknown);
  ASSERT_EQ(host.answer(30000ms), std::optional<std::uint32_t>(6)) << render.log();
  ASSERT_TRUE(drawn(7, {exposure(ExposureMode::Auto, 0.0f, 0.0f)})) << render.log();
  ASSERT_TRUE(drawn(8)) << render.log();
  ASSERT_EQ(render.wait(60s), std::optional<int>(0)) << render.log();

  std::map<std::uint32_t, nlohmann::json> byHostFrame;
  std::ifstream jsonl(dir / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) {
      const auto j = nlohmann::json::parse(line);
      byHostFrame[j["host_frame"].get<std::uint32_t>()] = j["camera_exposure"];
    }
  ASSERT_EQ(byHostFrame.size(), 9u) << render.log();
  // Lagarde & de Rousiers' exposure of EV100 13 with +0.5 EV, per renderer unit
  // (6400 cd/m^2): 6400 / (1.2 x 2^(13 - 0.5)).
  const double fixedExposure = 6400.0 / (1.2 * std::pow(2.0, 12.5));
  for (const auto& [k, e] : byHostFrame) {
    SCOPED_TRACE("host frame " + std::to_string(k) + ": " + e.dump());
    if (k < 3) {
      EXPECT_EQ(e["source"], "channel");
      EXPECT_EQ(e["mode"], "auto");
    } else if (k < 7) {
      EXPECT_EQ(e["source"], "host");
      EXPECT_EQ(e["mode"], "fixed");
      EXPECT_EQ(e["ev100"], 13.0);
      EXPECT_EQ(e["compensation_ev"], 0.5);
      EXPECT_NEAR(e["exposure"].get<double>(), fixedExposure, 1e-12 * fixedExposure);
    } else {
      EXPECT_EQ(e["source"], "host");
      EXPECT_EQ(e["mode"], "auto");
      EXPECT_EQ(e["compensation_ev"], 0.0);
      EXPECT_TRUE(e["metered_ev100"].is_number());
    }
  }
  const std::string log = render.log();
  EXPECT_NE(log.find("dropped 1 (out of range 1)"), std::string::npos) << log;
  EXPECT_NE(log.find("ignored packets by id: Component Control (4) 1"), std::string::npos) << log;
  EXPECT_NE(log.find("camera exposure: 2 host settings applied, 1 for other views ignored"), std::string::npos) << log;
}

}  // namespace
}  // namespace sky::test
