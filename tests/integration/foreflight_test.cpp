// A live channel driven by ForeFlight lines as X-Plane sends them: XATT at
// 10 Hz and XGPS at 2 Hz on one UDP socket, with a few garbage datagrams and
// traffic lines between them, to a renderer started with --foreflight-port.
// The frames are drawn from the lines: source "foreflight", the camera on
// the sent track (cross-track within the smoother's slack), the attitude of
// the XATT lines (not a derived one), and the channel stops cleanly at
// --idle-exit.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "input_channel.hpp"
#include "sky/foreflight/foreflight.hpp"
#include "sky/geo/geodetic.hpp"

using namespace std::chrono_literals;

namespace sky::test {
namespace {

const geo::Geodetic kOrigin{21.3, -157.9, 1200};
constexpr double kSpeed_mps = 60.0;  // due east
constexpr double kFeed_s = 5.0;
constexpr double kRoll_deg = 12.0, kPitch_deg = 3.0;

geo::Geodetic eastOf(double metres) {
  const geo::EnuFrame f = geo::enuFrameAt(kOrigin);
  return geo::fromEcef(geo::toEcef(kOrigin) + f.east * metres);
}

TEST(ForeFlightInput, XPlaneLinesDriveALiveChannel) {
  InputChannel channel("foreflight", "2", {"--no-exr"}, InputChannel::Input::ForeFlight);
  ASSERT_GT(channel.weatherPort, 0u) << channel.weatherd->log();
  ASSERT_GT(channel.inputPort, 0u) << channel.render->log();

  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(channel.inputPort));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  auto send = [&](const std::string& text) {
    ::sendto(fd, text.data(), text.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  };
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i <= static_cast<int>(kFeed_s * 10); ++i) {
    std::this_thread::sleep_until(start + i * 100ms);
    const double t = i / 10.0;
    send(foreflight::formatLine(foreflight::Attitude{"X-Plane 12", 90.0, kPitch_deg, kRoll_deg}) + "\n");
    if (i % 5 == 0) {
      const geo::Geodetic p = eastOf(kSpeed_mps * t);
      send(foreflight::formatLine(foreflight::Position{"X-Plane 12", p.lon_deg, p.lat_deg, p.alt_m, 90.0, kSpeed_mps}) +
           "\n");
    }
    if (i % 7 == 3) send("XGPSX-Plane 12,nan,21.3,1200,90,60\n");
    if (i % 11 == 5) send("XTRAFFICX-Plane 12,1,21.31,-157.8,3000,0,1,90,120,N1\n");
  }
  ::close(fd);
  ASSERT_EQ(channel.render->wait(60s), std::optional<int>(0)) << channel.render->log();
  EXPECT_EQ(channel.weatherd->stop(), 0) << channel.weatherd->log();

  std::vector<nlohmann::json> frames;
  std::ifstream jsonl(channel.dir / "frames" / "frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) frames.push_back(nlohmann::json::parse(line));
  ASSERT_GE(frames.size(), 5u) << channel.render->log();
  const geo::EnuFrame f = geo::enuFrameAt(kOrigin);
  double worstCross_m = 0;
  for (const auto& fr : frames) {
    EXPECT_EQ(fr["source"], "foreflight");
    const geo::Geodetic pos{fr["lat_deg"].get<double>(), fr["lon_deg"].get<double>(), fr["alt_m"].get<double>()};
    const geo::Vec3d d = geo::toEcef(pos) - geo::toEcef(kOrigin);
    // Along the track from the origin to its end (plus the 3 s the camera
    // may fly on past the last fix), and off it sideways by no more than the
    // curvature of a 300 m line on a tangent plane and the fixes' rounding.
    const double along = geo::dot(d, f.east);
    EXPECT_GT(along, -1.0);
    EXPECT_LT(along, kSpeed_mps * (kFeed_s + 3.0) + 1.0);
    const double cross = std::abs(geo::dot(d, f.north));
    worstCross_m = std::max(worstCross_m, cross);
    EXPECT_LT(cross, 5.0) << "frame " << fr["frame"];
    EXPECT_NEAR(fr["yaw_deg"].get<double>(), 90.0, 0.01);
    EXPECT_NEAR(fr["pitch_deg"].get<double>(), kPitch_deg, 0.01);
    EXPECT_NEAR(fr["roll_deg"].get<double>(), kRoll_deg, 0.01);
  }
  const std::string log = channel.render->log();
  EXPECT_NE(log.find("ForeFlight positions"), std::string::npos) << log;
  std::printf("foreflight: %zu frames, worst cross-track %.2f m\n", frames.size(), worstCross_m);
}

}  // namespace
}  // namespace sky::test
