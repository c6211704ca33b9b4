// The renderer's CIGI and FlightGear inputs under hostile datagrams (issue 18:
// no input can stop a channel): size bytes of 0, 1 and past the end, NaN and
// absurd fields, datagrams from a second sender. Each is dropped and counted
// by reason, never answered, and the channel keeps its last good pose. The
// listeners are driven through handleDatagram; they bind a loopback port but
// nothing is sent on it.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "sky/app/cigi_listener.hpp"
#include "sky/app/fdm_listener.hpp"
#include "sky/fgfdm/net_fdm.hpp"

namespace sky::app {
namespace {

namespace asio = boost::asio;
using Endpoint = asio::ip::udp::endpoint;

const Endpoint kHostA(asio::ip::make_address("127.0.0.1"), 40001);
const Endpoint kHostB(asio::ip::make_address("127.0.0.2"), 40002);
const Endpoint kHostAOtherPort(asio::ip::make_address("127.0.0.1"), 40009);

std::vector<std::uint8_t> hostDatagram(double lat_deg, std::uint32_t frame = 1) {
  cigi::IgControl ig;
  ig.hostFrame = frame;
  cigi::EntityControl e;
  e.lat_deg = lat_deg;
  e.lon_deg = 12.8;
  e.alt_m = 900;
  cigi::DatagramWriter w;
  w.add(ig).add(e);
  return w.bytes();
}

struct CigiFixture : ::testing::Test {
  asio::io_context io;
  SharedState state;

  double poseLat() const {
    const auto p = state.pose();
    return p ? p->pose.position.lat_deg : std::nan("");
  }
};

// The size byte of the first packet (IG Control, byte 1) and of the second
// (Entity Control at byte 24, size at 25): 0, 1 (below the 2-byte header: a
// walker that trusted it would loop forever or read out of bounds) and past
// the end of the datagram.
TEST_F(CigiFixture, SizeBytesZeroOneAndPastTheEndAreDroppedAndCounted) {
  CigiListener cigi(io, state, "127.0.0.1", 0);
  ASSERT_FALSE(cigi.handleDatagram(hostDatagram(46.0), kHostA).empty());
  ASSERT_EQ(poseLat(), 46.0);
  int spoiled = 0;
  for (const std::size_t at : {std::size_t{1}, std::size_t{25}})
    for (const int size : {0, 1, 255, 73}) {  // 73: one byte past the 72-byte datagram at byte 24
      auto bytes = hostDatagram(47.0, 2);
      bytes[at] = static_cast<std::uint8_t>(size);
      EXPECT_TRUE(cigi.handleDatagram(bytes, kHostA).empty()) << "size byte " << size << " at " << at;
      ++spoiled;
    }
  // An unknown packet id (user-defined 201) whose size byte is 0: skipped by
  // size, it must not be taken as 0 bytes long.
  auto unknown = hostDatagram(47.0, 3);
  unknown.insert(unknown.end(), {201, 0, 0, 0});
  EXPECT_TRUE(cigi.handleDatagram(unknown, kHostA).empty());
  ++spoiled;
  // A datagram cut short inside its second packet.
  auto cut = hostDatagram(47.0, 4);
  cut.resize(40);
  EXPECT_TRUE(cigi.handleDatagram(cut, kHostA).empty());
  ++spoiled;
  EXPECT_EQ(cigi.drops().of(DropReason::Malformed), static_cast<std::uint64_t>(spoiled));
  EXPECT_EQ(cigi.datagramsDropped(), static_cast<std::uint64_t>(spoiled));
  EXPECT_EQ(cigi.datagramsAccepted(), 1u);
  EXPECT_EQ(poseLat(), 46.0) << "the last good pose is kept";
  // And the channel goes on with the next good datagram.
  EXPECT_FALSE(cigi.handleDatagram(hostDatagram(46.5, 5), kHostA).empty());
  EXPECT_EQ(poseLat(), 46.5);
}

TEST_F(CigiFixture, OutOfRangeAndIgDatagramsAreDroppedByReason) {
  CigiListener cigi(io, state, "127.0.0.1", 0);
  ASSERT_FALSE(cigi.handleDatagram(hostDatagram(46.0), kHostA).empty());
  EXPECT_TRUE(cigi.handleDatagram(hostDatagram(std::nan("")), kHostA).empty());
  EXPECT_TRUE(cigi.handleDatagram(hostDatagram(1e30), kHostA).empty());
  cigi::DatagramWriter ig;
  ig.add(cigi::StartOfFrame{});
  EXPECT_TRUE(cigi.handleDatagram(ig.bytes(), kHostA).empty());
  EXPECT_EQ(cigi.drops().of(DropReason::OutOfRange), 2u);
  EXPECT_EQ(cigi.drops().of(DropReason::NotFromHost), 1u);
  EXPECT_EQ(poseLat(), 46.0);
  EXPECT_EQ(cigi.drops().summary(), "out of range 2, not from a host 1");
}

// Without --cigi-host the first sender of a valid datagram is the host: a
// second sender is dropped, counted and never answered (no reflector). The
// host's address on another port is the host restarted, and is answered.
// View packets (issue 19): a View Definition with a NaN or out-of-range
// half-angle fails the decoder, and its whole datagram is dropped as out of
// range; one whose half-angles are each fine but give no frustum (left
// right of right) is dropped alone, counted as out of range, and the pose
// in its datagram still taken; packets for other views are ignored and
// counted; this view's are applied.
TEST_F(CigiFixture, BadViewPacketsAreDroppedAndCounted) {
  ChannelView initial;
  initial.viewId = 1;
  initial.frustum = {-30, 30, 20, -20};
  state.setView(initial);
  CigiListener cigi(io, state, "127.0.0.1", 0);
  auto withView = [](double lat, auto... packets) {
    cigi::IgControl ig;
    cigi::EntityControl e;
    e.lat_deg = lat;
    e.alt_m = 900;
    cigi::DatagramWriter w;
    w.add(ig).add(e);
    (w.add(packets), ...);
    return w.bytes();
  };
  cigi::ViewDefinition vd;
  vd.viewId = 1;
  vd.leftEnable = vd.rightEnable = true;
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 95.0f}) {
    vd.left_deg = bad;
    EXPECT_TRUE(cigi.handleDatagram(withView(46.0, vd), kHostA).empty());
  }
  EXPECT_EQ(cigi.drops().of(DropReason::OutOfRange), 3u);
  EXPECT_TRUE(std::isnan(poseLat()));
  vd.left_deg = 40;  // right of right (30)
  vd.right_deg = 30;
  EXPECT_FALSE(cigi.handleDatagram(withView(46.5, vd), kHostA).empty());
  EXPECT_EQ(poseLat(), 46.5);
  EXPECT_EQ(cigi.drops().of(DropReason::OutOfRange), 4u);
  EXPECT_EQ(state.view().frustum, initial.frustum);
  cigi::ViewControl vc;
  vc.viewId = 2;
  vc.yawEnable = true;
  vc.yaw_deg = 60;
  vd.viewId = 2;
  EXPECT_FALSE(cigi.handleDatagram(withView(46.6, vd, vc), kHostA).empty());
  EXPECT_EQ(cigi.otherViewPackets(), 2u);
  vc.viewId = 1;
  vd.viewId = 1;
  vd.left_deg = -10;
  vd.right_deg = 50;
  EXPECT_FALSE(cigi.handleDatagram(withView(46.7, vd, vc), kHostA).empty());
  EXPECT_EQ(state.view().frustum, (render::ViewFrustum{-10, 50, 20, -20}));
  EXPECT_EQ(state.view().eyepoint.yaw_deg, 60);
  EXPECT_EQ(cigi.drops().of(DropReason::OutOfRange), 4u);
}

TEST_F(CigiFixture, TheFirstValidSenderIsTheOnlyHostAnswered) {
  CigiListener cigi(io, state, "127.0.0.1", 0);
  EXPECT_FALSE(cigi.host());
  // A broken datagram does not make its sender the host.
  auto broken = hostDatagram(46.0);
  broken[1] = 0;
  EXPECT_TRUE(cigi.handleDatagram(broken, kHostB).empty());
  EXPECT_FALSE(cigi.host());
  ASSERT_FALSE(cigi.handleDatagram(hostDatagram(46.0), kHostA).empty());
  ASSERT_TRUE(cigi.host());
  EXPECT_TRUE(cigi.host()->matches(kHostA));
  EXPECT_TRUE(cigi.handleDatagram(hostDatagram(10.0), kHostB).empty());
  EXPECT_EQ(cigi.drops().of(DropReason::ForeignSender), 1u);
  EXPECT_EQ(poseLat(), 46.0);
  EXPECT_FALSE(cigi.handleDatagram(hostDatagram(46.1), kHostA).empty());
  EXPECT_EQ(poseLat(), 46.1);
  EXPECT_FALSE(cigi.handleDatagram(hostDatagram(46.2), kHostAOtherPort).empty());
  EXPECT_EQ(poseLat(), 46.2);
  EXPECT_TRUE(cigi.handleDatagram(hostDatagram(10.0), kHostB).empty());
  EXPECT_EQ(cigi.drops().of(DropReason::ForeignSender), 2u);
  EXPECT_EQ(cigi.datagramsAccepted(), 3u);
}

// --cigi-host: only that sender is answered, from the first datagram on.
TEST_F(CigiFixture, AGivenHostIsHonoured) {
  auto host = parseCigiHost("127.0.0.2:40002");
  ASSERT_TRUE(host) << host.error().detail;
  CigiListener cigi(io, state, "127.0.0.1", 0, *host);
  EXPECT_TRUE(cigi.handleDatagram(hostDatagram(10.0), kHostA).empty());
  EXPECT_FALSE(state.pose());
  EXPECT_FALSE(cigi.handleDatagram(hostDatagram(46.0), kHostB).empty());
  EXPECT_EQ(poseLat(), 46.0);
  EXPECT_EQ(cigi.drops().of(DropReason::ForeignSender), 1u);

  // Without a port: any port of that address.
  SharedState other;
  CigiListener anyPort(io, other, "127.0.0.1", 0, *parseCigiHost("127.0.0.1"));
  EXPECT_FALSE(anyPort.handleDatagram(hostDatagram(46.0), kHostA).empty());
  EXPECT_FALSE(anyPort.handleDatagram(hostDatagram(46.0), kHostAOtherPort).empty());
  EXPECT_TRUE(anyPort.handleDatagram(hostDatagram(46.0), kHostB).empty());
}

TEST(CigiHostOption, ParsesAddressesAndPorts) {
  auto v4 = parseCigiHost("10.1.2.3:8005");
  ASSERT_TRUE(v4);
  EXPECT_EQ(v4->address.to_string(), "10.1.2.3");
  EXPECT_EQ(v4->port, std::optional<unsigned short>(8005));
  auto bare = parseCigiHost("10.1.2.3");
  ASSERT_TRUE(bare);
  EXPECT_FALSE(bare->port);
  auto v6 = parseCigiHost("[::1]:8005");
  ASSERT_TRUE(v6);
  EXPECT_TRUE(v6->address.is_v6());
  EXPECT_EQ(v6->port, std::optional<unsigned short>(8005));
  auto v6bare = parseCigiHost("fe80::1");
  ASSERT_TRUE(v6bare);
  EXPECT_FALSE(v6bare->port);
  for (const char* bad : {"", "host.example:8005", "10.1.2.3:", "10.1.2.3:0", "10.1.2.3:65536", "10.1.2.3:80x",
                          "[::1", "[::1]x", "[::1]:", "\xff\xfe:1"}) {
    auto r = parseCigiHost(bad);
    EXPECT_FALSE(r) << bad;
    if (!r && bad[0] != '\0') {
      EXPECT_EQ(r.error().detail.find(bad), std::string::npos) << "the text is not echoed";
    }
  }
}

// A drop is logged once per kind: the values in a detail do not make a new
// kind, so a sender varying them cannot flood the log; the field does.
TEST(DropKind, ValuesDoNotMakeANewKind) {
  const auto kind = [](const std::string& d) { return dropKind(DropReason::OutOfRange, d); };
  const std::string lat = "packet 1 (Entity Control) at byte 48: latitude ";
  EXPECT_EQ(kind(lat + "nan outside [-90, 90]"), kind(lat + "1e+30 outside [-90, 90]"));
  EXPECT_EQ(kind(lat + "nan outside [-90, 90]"), kind(lat + "-inf outside [-90, 90]"));
  EXPECT_EQ(kind(lat + "95.5 outside [-90, 90]"), kind(lat + "-1.5e-07 outside [-90, 90]"));
  EXPECT_NE(kind(lat + "nan outside [-90, 90]"),
            kind("packet 1 (Entity Control) at byte 56: longitude nan outside [-180, 180]"));
  EXPECT_NE(dropKind(DropReason::Malformed, "x"), dropKind(DropReason::OutOfRange, "x"));
  EXPECT_EQ(kind("FGNetFDM: field 'v_north' nan ft/s outside [-39370.1, 39370.1]"),
            kind("FGNetFDM: field 'v_north' 1e+30 ft/s outside [-39370.1, 39370.1]"));
}

// FlightGear datagrams with NaN, infinite or absurd values: dropped by the
// decoder (out of range), counted; the smoothed camera stays on the good feed.
TEST(FdmListenerHostile, NonFiniteAndAbsurdPacketsAreDroppedAndTheCameraHolds) {
  asio::io_context io;
  FdmListener fdm(io, "127.0.0.1", 0);
  const auto t0 = std::chrono::steady_clock::now();
  auto at = [&](double t_s) {
    return t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(t_s));
  };
  fgfdm::NetFdm good;
  good.lat_rad = 0.36;
  good.lon_rad = -2.76;
  good.alt_m = 900;
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<void (*)(fgfdm::NetFdm&, double, double)> spoilers = {
      [](fgfdm::NetFdm& f, double n, double) { f.vNorth_fps = static_cast<float>(n); },
      [](fgfdm::NetFdm& f, double, double i) { f.vDown_fps = static_cast<float>(i); },
      [](fgfdm::NetFdm& f, double, double) { f.vEast_fps = 1e30f; },
      [](fgfdm::NetFdm& f, double n, double) { f.lat_rad = n; },
      [](fgfdm::NetFdm& f, double, double) { f.lat_rad = 1e30; },
      [](fgfdm::NetFdm& f, double, double i) { f.alt_m = -i; },
      [](fgfdm::NetFdm& f, double n, double) { f.psi_rad = static_cast<float>(n); },
      [](fgfdm::NetFdm& f, double, double) { f.visibility_m = -1; },
  };
  int t = 0;
  for (int i = 0; i < 5; ++i) fdm.handleDatagram(fgfdm::encodeNetFdm(good), at(0.1 * t++));
  for (const auto& spoil : spoilers) {
    fgfdm::NetFdm bad = good;
    spoil(bad, nan, inf);
    fdm.handleDatagram(fgfdm::encodeNetFdm(bad), at(0.1 * t++));
  }
  auto wrongSize = fgfdm::encodeNetFdm(good);
  fdm.handleDatagram(std::span(wrongSize).first(100), at(0.1 * t++));
  EXPECT_EQ(fdm.datagramsAccepted(), 5u);
  EXPECT_EQ(fdm.drops().of(DropReason::OutOfRange), spoilers.size());
  EXPECT_EQ(fdm.drops().of(DropReason::Malformed), 1u);
  const auto pose = fdm.poseAt(at(0.1 * t + 1));
  ASSERT_TRUE(pose);
  EXPECT_NEAR(pose->pose.position.lat_deg, 0.36 * 180 / 3.14159265358979323846, 1e-9);
  EXPECT_NEAR(pose->pose.position.alt_m, 900, 1e-6);
}

}  // namespace
}  // namespace sky::app
