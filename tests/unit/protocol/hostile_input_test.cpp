// The CIGI and FlightGear decoders against hostile datagrams (issue 18): CIGI
// size bytes of 0, 1 and past the end at every packet position, and FGNetFDM
// fields that are NaN, infinite or absurd. Each is rejected with a reason;
// the bounds themselves are accepted.
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sky/cigi/codec.hpp"
#include "sky/fgfdm/net_fdm.hpp"

namespace sky {
namespace {

// IG Control, Entity Control, a user-defined packet (id 201, 8 bytes, skipped
// by size) and View Definition: 24 + 48 + 8 + 32 bytes.
std::vector<std::uint8_t> hostDatagram() {
  cigi::DatagramWriter w;
  w.add(cigi::IgControl{}).add(cigi::EntityControl{});
  std::vector<std::uint8_t> bytes = w.bytes();
  bytes.insert(bytes.end(), {201, 8, 1, 2, 3, 4, 5, 6});
  cigi::DatagramWriter v;
  v.add(cigi::IgControl{}).add(cigi::ViewDefinition{});
  bytes.insert(bytes.end(), v.bytes().begin() + 24, v.bytes().end());
  return bytes;
}

TEST(CigiHostile, SizeBytesZeroOneAndPastTheEndAreMalformedAtEveryPacket) {
  const auto good = hostDatagram();
  ASSERT_EQ(good.size(), 112u);
  auto decoded = cigi::decodeDatagram(good);
  ASSERT_TRUE(decoded) << decoded.error().detail;
  EXPECT_EQ(decoded->packets.size(), 3u);
  EXPECT_EQ(decoded->skippedIds.size(), 1u);
  for (const std::size_t packetAt : {std::size_t{0}, std::size_t{24}, std::size_t{72}, std::size_t{80}}) {
    const std::size_t pastEnd = good.size() - packetAt + 1;
    for (const std::size_t size : {std::size_t{0}, std::size_t{1}, pastEnd, std::size_t{255}}) {
      auto bytes = good;
      bytes[packetAt + 1] = static_cast<std::uint8_t>(size);
      const auto r = cigi::decodeDatagram(bytes);
      ASSERT_FALSE(r) << "size " << size << " of the packet at byte " << packetAt;
      EXPECT_EQ(r.error().code, ErrorCode::Malformed) << r.error().detail;
    }
  }
  // The last packet cut by one byte, and a lone byte after the last packet.
  auto cut = good;
  cut.pop_back();
  EXPECT_FALSE(cigi::decodeDatagram(cut));
  auto trailing = good;
  trailing.push_back(201);
  const auto r = cigi::decodeDatagram(trailing);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("1 byte left"), std::string::npos) << r.error().detail;
}

fgfdm::NetFdm goodFdm() {
  fgfdm::NetFdm f;
  f.lat_rad = 0.36;
  f.lon_rad = -2.76;
  f.alt_m = 900;
  f.curTime_unix = 1795299684;  // the FlightGear capture's
  f.warp_s = -13200;
  f.visibility_m = 32000;
  return f;
}

struct FdmCase {
  const char* field;
  std::function<void(fgfdm::NetFdm&, double)> set;
  double bound;  // the nominal bound of the field's magnitude
};

// Every checked field: NaN, +-infinity, 1 % past its bound and 1e30 are
// rejected naming the field; 0.1 % inside its bound is accepted.
TEST(FgFdmHostile, NonFiniteAndAbsurdFieldsAreRejectedNamingTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const double halfPi = 3.14159265358979323846 / 2;
  // 12 km/s (net_fdm.cpp: kMaxSpeed_mps) in the wire's units.
  const double maxSpeed_fps = 12000.0 / 0.3048, maxSpeed_kt = 12000.0 / (1852.0 / 3600.0);
  const std::vector<FdmCase> cases = {
      {"latitude", [](fgfdm::NetFdm& f, double v) { f.lat_rad = v; }, halfPi},
      {"longitude", [](fgfdm::NetFdm& f, double v) { f.lon_rad = v; }, 4 * halfPi},
      {"altitude", [](fgfdm::NetFdm& f, double v) { f.alt_m = v; }, 1.0e7},
      {"theta", [](fgfdm::NetFdm& f, double v) { f.theta_rad = static_cast<float>(v); }, halfPi},
      {"psi", [](fgfdm::NetFdm& f, double v) { f.psi_rad = static_cast<float>(v); }, 4 * halfPi},
      {"phidot", [](fgfdm::NetFdm& f, double v) { f.phidot_rps = static_cast<float>(v); }, 100},
      {"vcas", [](fgfdm::NetFdm& f, double v) { f.vcas_kt = static_cast<float>(v); }, maxSpeed_kt},
      {"climb_rate", [](fgfdm::NetFdm& f, double v) { f.climbRate_fps = static_cast<float>(v); }, maxSpeed_fps},
      {"v_north", [](fgfdm::NetFdm& f, double v) { f.vNorth_fps = static_cast<float>(v); }, maxSpeed_fps},
      {"v_east", [](fgfdm::NetFdm& f, double v) { f.vEast_fps = static_cast<float>(v); }, maxSpeed_fps},
      {"v_down", [](fgfdm::NetFdm& f, double v) { f.vDown_fps = static_cast<float>(v); }, maxSpeed_fps},
      {"v_body_u", [](fgfdm::NetFdm& f, double v) { f.vWindBodyNorth_fps = static_cast<float>(v); }, maxSpeed_fps},
      {"A_Z_pilot", [](fgfdm::NetFdm& f, double v) { f.aZPilot_fps2 = static_cast<float>(v); }, 1000},
  };
  for (const auto& c : cases) {
    const bool altitude = std::string(c.field) == "altitude";  // its floor is -12 km, not -1e7
    for (const double v : {nan, inf, -inf, c.bound * 1.01, -c.bound * 1.01, 1e30}) {
      auto f = goodFdm();
      c.set(f, v);
      const auto r = fgfdm::decodeNetFdm(fgfdm::encodeNetFdm(f));
      ASSERT_FALSE(r) << c.field << " = " << v;
      EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
      EXPECT_NE(r.error().detail.find(std::string("'") + c.field + "'"), std::string::npos) << r.error().detail;
    }
    for (const double v : {c.bound * 0.999, -c.bound * 0.999}) {
      if (altitude && v < 0) continue;
      auto f = goodFdm();
      c.set(f, v);
      const auto r = fgfdm::decodeNetFdm(fgfdm::encodeNetFdm(f));
      EXPECT_TRUE(r) << c.field << " = " << v << ": " << (r ? "" : r.error().detail);
    }
  }
}

// cur_time is FlightGear's simulated time with the warp in it (SimGear's
// SGTime::update), so every value of both is taken: a user may warp far;
// a visibility that is not a distance is refused.
TEST(FgFdmHostile, AnyTimeIsTakenAbsurdVisibilityIsNot) {
  auto f = goodFdm();
  for (const auto& [cur, warp] : {std::pair<std::uint32_t, std::int32_t>{100u, -101}, {4294967295u, 1}, {0u, -2000000000}}) {
    f.curTime_unix = cur;
    f.warp_s = warp;
    const auto r = fgfdm::decodeNetFdm(fgfdm::encodeNetFdm(f));
    ASSERT_TRUE(r) << cur << " " << warp << ": " << r.error().detail;
    EXPECT_EQ(r->curTime_unix, cur);
  }
  f = goodFdm();
  f.visibility_m = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(fgfdm::decodeNetFdm(fgfdm::encodeNetFdm(f)));
  f.visibility_m = -1;
  EXPECT_FALSE(fgfdm::decodeNetFdm(fgfdm::encodeNetFdm(f)));
}

}  // namespace
}  // namespace sky
