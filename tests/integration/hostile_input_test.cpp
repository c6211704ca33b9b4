// Issue 18 through a real skyshell-render process and real UDP sockets: a
// FlightGear feed and a CIGI host interleaved with hostile datagrams (CIGI
// size bytes 0, 1 and past the end, NaN and absurd fields; FGNetFDM with NaN,
// infinite and absurd velocities, positions and times, wrong sizes and
// versions) and a second CIGI sender. The channel must keep running and
// drawing frames from the good feed, answer only its CIGI host, and count
// every drop by reason.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "input_channel.hpp"
#include "sky/cigi/codec.hpp"
#include "sky/fgfdm/net_fdm.hpp"
#include "sky/geo/geodetic.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace sky::test {
namespace {

// How long the hostile feed runs, s, and at what rate the good packets come
// (FlightGear's --native-fdm rate 10 gives about this).
constexpr double kFeed_s = 8.0;
constexpr double kRate_hz = 10.0;
// Ground speed of the good track, m/s (due east), and where it starts.
constexpr double kSpeed_mps = 50.0;
const geo::Geodetic kOrigin{46.2, 12.8, 1500};

// One UDP socket on loopback, as one sender; `from` is its own address
// (host order), any of 127/8.
class UdpSender {
 public:
  explicit UdpSender(std::uint32_t from = INADDR_LOOPBACK) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    sockaddr_in self{};
    self.sin_family = AF_INET;
    self.sin_addr.s_addr = htonl(from);
    ::bind(fd_, reinterpret_cast<const sockaddr*>(&self), sizeof self);
  }
  ~UdpSender() { ::close(fd_); }
  void send(unsigned port, std::span<const std::uint8_t> bytes) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
  // Datagrams waiting on this socket (answers), drained.
  std::size_t drain() const {
    std::size_t n = 0;
    std::vector<std::uint8_t> buf(65536);
    pollfd p{fd_, POLLIN, 0};
    while (::poll(&p, 1, 0) > 0 && ::recv(fd_, buf.data(), buf.size(), 0) >= 0) ++n;
    return n;
  }

 private:
  int fd_;
};

geo::Geodetic trackAt(double t_s) {
  const geo::EnuFrame f = geo::enuFrameAt(kOrigin);
  return geo::fromEcef(geo::toEcef(kOrigin) + f.east * (kSpeed_mps * t_s));
}

fgfdm::NetFdm goodFdm(double t_s) {
  constexpr double kRad = 3.14159265358979323846 / 180.0;
  const geo::Geodetic p = trackAt(t_s);
  fgfdm::NetFdm f;
  f.lat_rad = p.lat_deg * kRad;
  f.lon_rad = p.lon_deg * kRad;
  f.alt_m = p.alt_m;
  f.psi_rad = static_cast<float>(90 * kRad);
  f.vEast_fps = static_cast<float>(kSpeed_mps / 0.3048);
  f.curTime_unix = 1795299684;
  f.visibility_m = 32000;
  return f;
}

// The hostile FlightGear packets, one of each kind per good packet.
std::vector<std::vector<std::uint8_t>> hostileFdm(double t_s) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<std::vector<std::uint8_t>> out;
  const auto add = [&](auto spoil) {
    fgfdm::NetFdm f = goodFdm(t_s);
    spoil(f);
    const auto bytes = fgfdm::encodeNetFdm(f);
    out.emplace_back(bytes.begin(), bytes.end());
  };
  add([&](fgfdm::NetFdm& f) { f.vNorth_fps = static_cast<float>(nan); });
  add([&](fgfdm::NetFdm& f) { f.vEast_fps = static_cast<float>(inf); });
  add([&](fgfdm::NetFdm& f) { f.vDown_fps = 1e30f; });
  add([&](fgfdm::NetFdm& f) { f.lat_rad = nan; });
  add([&](fgfdm::NetFdm& f) { f.lat_rad = 1e30; });
  add([&](fgfdm::NetFdm& f) { f.alt_m = -inf; });
  add([&](fgfdm::NetFdm& f) { f.visibility_m = -1; });
  auto shortOne = out.back();
  shortOne.resize(100);
  out.push_back(shortOne);
  add([&](fgfdm::NetFdm& f) { f.version = 25; });
  return out;
}

std::vector<std::uint8_t> cigiDatagram(std::uint32_t frame, double lat_deg) {
  cigi::IgControl ig;
  ig.hostFrame = frame;
  cigi::EntityControl e;
  e.lat_deg = lat_deg;
  e.lon_deg = kOrigin.lon_deg;
  e.alt_m = 900;
  cigi::DatagramWriter w;
  w.add(ig).add(e);
  return w.bytes();
}

// The hostile CIGI datagrams: size bytes 0, 1 and past the end (first and
// second packet), a NaN latitude, an IG's datagram.
std::vector<std::vector<std::uint8_t>> hostileCigi(std::uint32_t frame) {
  std::vector<std::vector<std::uint8_t>> out;
  for (const std::size_t at : {std::size_t{1}, std::size_t{25}})
    for (const std::uint8_t size : {0, 1, 255}) {
      auto bytes = cigiDatagram(frame, kOrigin.lat_deg);
      bytes[at] = size;
      out.push_back(bytes);
    }
  out.push_back(cigiDatagram(frame, std::numeric_limits<double>::quiet_NaN()));
  cigi::DatagramWriter sof;
  sof.add(cigi::StartOfFrame{});
  out.push_back(sof.bytes());
  return out;
}

// The exit summary "<what> datagrams accepted A, dropped D (reasons)".
struct DropSummary {
  std::uint64_t accepted = 0, dropped = 0;
  std::string reasons;
};
std::optional<DropSummary> dropSummary(const std::string& log, const std::string& what) {
  const std::string head = what + " datagrams accepted ";
  const auto at = log.find(head);
  if (at == std::string::npos) return std::nullopt;
  DropSummary s;
  std::size_t pos = at + head.size(), used = 0;
  s.accepted = std::stoull(log.substr(pos), &used);
  pos += used;
  const std::string mid = ", dropped ";
  if (log.compare(pos, mid.size(), mid) != 0) return std::nullopt;
  pos += mid.size();
  s.dropped = std::stoull(log.substr(pos), &used);
  pos += used;
  if (log.compare(pos, 2, " (") != 0) return std::nullopt;
  const auto close = log.find(')', pos);
  if (close == std::string::npos) return std::nullopt;
  s.reasons = log.substr(pos + 2, close - pos - 2);
  return s;
}

// "name N" inside the summary's parentheses, 0 when absent.
std::uint64_t countIn(const std::string& summary, const std::string& name) {
  const auto at = summary.find(name + " ");
  return at == std::string::npos ? 0 : std::stoull(summary.substr(at + name.size() + 1));
}

TEST(HostileInput, RendererKeepsDrawingAndAnswersOnlyItsHost) {
  InputChannel channel("hostile_input", "3", {"--no-exr"});
  ASSERT_GT(channel.weatherPort, 0u) << channel.weatherd->log();
  ASSERT_GT(channel.inputPort, 0u) << channel.render->log();
  ASSERT_GT(channel.cigiPort, 0u) << channel.render->log();
  ChildProcess& render = *channel.render;
  ChildProcess& weatherd = *channel.weatherd;
  const unsigned fdmPort = channel.inputPort, cigiPort = channel.cigiPort;
  const std::string d = channel.dir.string();

  // The intruder has its own address: a channel answers its host's address
  // on any port (a restarted host is answered again).
  UdpSender flightgear, host, intruder(INADDR_LOOPBACK + 1);
  std::size_t hostAnswers = 0, intruderAnswers = 0;
  std::uint32_t frame = 0;
  const auto start = std::chrono::steady_clock::now();
  const int ticks = static_cast<int>(kFeed_s * kRate_hz);
  for (int i = 0; i <= ticks; ++i) {
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                              std::chrono::duration<double>(i / kRate_hz)));
    const double t = i / kRate_hz;
    // The host's first datagram comes before anything else on the CIGI port,
    // so it becomes the host; its hostile ones and the intruder's follow.
    host.send(cigiPort, cigiDatagram(++frame, kOrigin.lat_deg));
    for (const auto& bad : hostileCigi(frame)) host.send(cigiPort, bad);
    intruder.send(cigiPort, cigiDatagram(++frame, kOrigin.lat_deg));
    for (const auto& bad : hostileFdm(t)) flightgear.send(fdmPort, bad);
    const auto good = fgfdm::encodeNetFdm(goodFdm(t));
    flightgear.send(fdmPort, good);
    hostAnswers += host.drain();
    intruderAnswers += intruder.drain();
  }
  std::this_thread::sleep_for(200ms);
  hostAnswers += host.drain();
  intruderAnswers += intruder.drain();
  ASSERT_EQ(render.wait(60s), std::optional<int>(0)) << render.log();
  EXPECT_EQ(weatherd.stop(), 0) << weatherd.log();

  EXPECT_EQ(intruderAnswers, 0u) << "a second sender was answered";
  // UDP on loopback may drop under load; most answers arrive.
  EXPECT_GT(hostAnswers, static_cast<std::size_t>(ticks / 2));

  const std::string log = render.log();
  const auto cigi = dropSummary(log, "CIGI");
  ASSERT_TRUE(cigi) << log;
  const std::string& cigiDrops = cigi->reasons;
  EXPECT_GT(cigi->accepted, static_cast<std::uint64_t>(ticks / 2)) << cigiDrops;
  EXPECT_GT(countIn(cigiDrops, "malformed"), 0u) << cigiDrops;
  EXPECT_GT(countIn(cigiDrops, "out of range"), 0u) << cigiDrops;
  EXPECT_GT(countIn(cigiDrops, "not from a host"), 0u) << cigiDrops;
  EXPECT_GT(countIn(cigiDrops, "foreign sender"), 0u) << cigiDrops;
  const auto fdm = dropSummary(log, "FlightGear FDM");
  ASSERT_TRUE(fdm) << log;
  const std::string& fdmDrops = fdm->reasons;
  EXPECT_GT(fdm->accepted, static_cast<std::uint64_t>(ticks / 2)) << fdmDrops;
  EXPECT_GT(countIn(fdmDrops, "out of range"), 0u) << fdmDrops;
  EXPECT_GT(countIn(fdmDrops, "malformed"), 0u) << fdmDrops;
  EXPECT_GT(countIn(fdmDrops, "unsupported version"), 0u) << fdmDrops;
  // Each kind is logged once, not once per datagram.
  std::size_t warnings = 0;
  for (auto at = log.find("dropped a datagram"); at != std::string::npos; at = log.find("dropped a datagram", at + 1))
    ++warnings;
  EXPECT_LT(warnings, 30u) << log;

  // Frames all through the barrage, each camera finite and on the good track.
  std::vector<nlohmann::json> frames;
  std::ifstream jsonl(d + "/frames/frames.jsonl");
  for (std::string line; std::getline(jsonl, line);)
    if (!line.empty()) frames.push_back(nlohmann::json::parse(line));
  ASSERT_GE(frames.size(), 5u) << "too few frames in " << d;
  double firstT = 1e9, lastT = -1, worst_m = 0;
  for (const auto& fr : frames) {
    EXPECT_EQ(fr["source"], "fdm");
    const double t = fr["host_time_s"].get<double>();
    const geo::Geodetic pos{fr["lat_deg"].get<double>(), fr["lon_deg"].get<double>(), fr["alt_m"].get<double>()};
    ASSERT_TRUE(std::isfinite(pos.lat_deg) && std::isfinite(pos.lon_deg) && std::isfinite(pos.alt_m));
    firstT = std::min(firstT, t);
    lastT = std::max(lastT, t);
    // Render time lags by the smoother's delay; after the feed ends the
    // camera extrapolates for at most 2 s and holds.
    const double error_m = geo::length(geo::toEcef(pos) - geo::toEcef(trackAt(std::min(t, kFeed_s))));
    worst_m = std::max(worst_m, error_m);
  }
  EXPECT_LT(worst_m, 30.0 + kSpeed_mps * 2.0);
  EXPECT_LT(firstT, kFeed_s / 2) << "frames started late";
  EXPECT_GT(lastT, kFeed_s * 0.8) << "frames stopped during the barrage";
  std::printf("hostile input: %zu frames over %.1f-%.1f s of feed, worst camera error %.1f m; CIGI drops (%s); "
              "FlightGear drops (%s); host answers %zu, intruder answers %zu\n",
              frames.size(), firstT, lastT, worst_m, cigiDrops.c_str(), fdmDrops.c_str(), hostAnswers,
              intruderAnswers);
}

}  // namespace
}  // namespace sky::test
