// The ForeFlight UDP text format: every line of FlightGear's real XGPS
// capture parses to the numbers written in it; XATT lines as X-Plane writes
// them; the antimeridian written both ways; each way a line can be wrong is
// refused with the field named, and nothing of a refused datagram is kept.
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "pcap.hpp"
#include "sky/foreflight/foreflight.hpp"

namespace sky::foreflight {
namespace {

std::span<const std::uint8_t> bytesOf(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(ForeFlight, EveryLineOfFlightGearsCaptureParses) {
  const auto packets = test::readPcap(SKY_TEST_DATA_DIR "/flightgear/fgfs-c172p-foreflight-xgps-hawaii.pcap");
  ASSERT_EQ(packets.size(), 224u);
  for (const auto& p : packets) {
    auto m = parseDatagram(p.payload);
    ASSERT_TRUE(m) << m.error().detail;
    ASSERT_EQ(m->size(), 1u);
    const auto* pos = std::get_if<Position>(&m->front());
    ASSERT_TRUE(pos);
    EXPECT_EQ(pos->sim, "FlightGear");
    // Off Oahu's west coast, at the altitudes and speeds of a C172.
    EXPECT_NEAR(pos->lat_deg, 20.6, 0.1);
    EXPECT_NEAR(pos->lon_deg, -158.3, 0.1);
    EXPECT_GT(pos->alt_m, 800);
    EXPECT_LT(pos->alt_m, 1100);
    EXPECT_LT(pos->groundSpeed_mps, 70);
  }
  // The first line, value by value, as written: "XGPSFlightGear,-158.300,20.600,911.4,0.000,0.0\n".
  const std::string first(packets[0].payload.begin(), packets[0].payload.end());
  EXPECT_EQ(first, "XGPSFlightGear,-158.300,20.600,911.4,0.000,0.0\n");
  const auto m = parseLine("XGPSFlightGear,-158.301,20.600,917.0,269.533,48.1");
  ASSERT_TRUE(m);
  const auto& p = std::get<Position>(*m);
  EXPECT_EQ(p.lon_deg, -158.301);
  EXPECT_EQ(p.lat_deg, 20.600);
  EXPECT_EQ(p.alt_m, 917.0);
  EXPECT_EQ(p.track_deg, 269.533);
  EXPECT_EQ(p.groundSpeed_mps, 48.1);
}

TEST(ForeFlight, AttitudeLinesAsXPlaneWritesThem) {
  // X-Plane 12 names itself with a space and may append more values.
  auto m = parseDatagram(bytesOf("XATTX-Plane 12,285.3,-1.2,0.4\r\nXGPSX-Plane 12,-122.38,37.62,10.2,285.3,0.1\r\n"));
  ASSERT_TRUE(m) << m.error().detail;
  ASSERT_EQ(m->size(), 2u);
  const auto& a = std::get<Attitude>((*m)[0]);
  EXPECT_EQ(a.sim, "X-Plane 12");
  EXPECT_EQ(a.heading_deg, 285.3);
  EXPECT_EQ(a.pitch_deg, -1.2);
  EXPECT_EQ(a.roll_deg, 0.4);
  EXPECT_EQ(std::get<Position>((*m)[1]).lat_deg, 37.62);
  auto longer = parseLine("XATTMySim,10,2,-3,0.1,0.2,0.3,9.81");
  ASSERT_TRUE(longer) << longer.error().detail;
  EXPECT_EQ(std::get<Attitude>(*longer).roll_deg, -3);
  // A negative heading, as some add-ons send, is the same direction.
  EXPECT_EQ(std::get<Attitude>(*parseLine("XATTSim,-90,0,0")).heading_deg, 270);
  // Traffic and other kinds are well-formed and not used.
  auto traffic = parseLine("XTRAFFICX-Plane,168,33.85,-118.32,3200.0,-1.5,1,68.2,126.0,N12345");
  ASSERT_TRUE(traffic);
  EXPECT_EQ(std::get<Other>(*traffic).kind, "XTRAFFIC");
}

TEST(ForeFlight, TheAntimeridianWrittenBothWaysIsOneMeridian) {
  const auto east = parseLine("XGPSsim,180.000,-17.5,3000,90,200");
  const auto west = parseLine("XGPSsim,-180.000,-17.5,3000,90,200");
  ASSERT_TRUE(east && west);
  EXPECT_EQ(std::get<Position>(*east).lon_deg, 180.0);
  EXPECT_EQ(std::get<Position>(*west).lon_deg, -180.0);
  EXPECT_FALSE(parseLine("XGPSsim,180.001,-17.5,3000,90,200"));
}

TEST(ForeFlight, EachWayALineCanBeWrongIsRefusedNamingTheField) {
  struct Case {
    std::string line;
    ErrorCode code;
    const char* says;
  };
  const Case cases[] = {
      {"XGPSsim,-158.3,20.6,911.4,0.0", ErrorCode::Malformed, "4 values, not 5"},
      {"XGPSsim,-158.3,20.6,911.4,0.0,1,2", ErrorCode::Malformed, "6 values, not 5"},
      {"XGPSsim,-158.3,north,911.4,0.0,1", ErrorCode::Malformed, "'latitude' is not a number"},
      {"XGPSsim,-158.3,91,911.4,0.0,1", ErrorCode::InvalidArgument, "'latitude' 91 outside"},
      {"XGPSsim,nan,20,911.4,0.0,1", ErrorCode::InvalidArgument, "'longitude' is not finite"},
      {"XGPSsim,-158.3,20,inf,0.0,1", ErrorCode::InvalidArgument, "'altitude' is not finite"},
      {"XGPSsim,-158.3,20,40000,0.0,1", ErrorCode::InvalidArgument, "'altitude' 40000 outside"},
      {"XGPSsim,-158.3,20,900,0.0,-1", ErrorCode::InvalidArgument, "'ground speed' -1 outside"},
      {"XGPSsim,-158.3,20,900,0.0,1e9", ErrorCode::InvalidArgument, "'ground speed' 1e+09 outside"},
      {"XATTsim,10,95,0", ErrorCode::InvalidArgument, "'pitch' 95 outside"},
      {"XATTsim,10,5", ErrorCode::Malformed, "2 values, not 3"},
      {"XGPS\xc3\xa9,-158.3,20,900,0,1", ErrorCode::Malformed, "not printable ASCII"},
      {"XGPSsim,-158.3,\t20,900,0,1", ErrorCode::Malformed, "not printable ASCII"},
      {"hello", ErrorCode::Malformed, "message kind"},
      {"XGPS" + std::string(65, 'a') + ",1,2,3,4,5", ErrorCode::Malformed, "longer than 64"},
  };
  for (const auto& c : cases) {
    const auto m = parseLine(c.line);
    ASSERT_FALSE(m) << c.line;
    EXPECT_EQ(m.error().code, c.code) << c.line << ": " << m.error().detail;
    EXPECT_NE(m.error().detail.find(c.says), std::string::npos) << c.line << ": " << m.error().detail;
  }
}

TEST(ForeFlight, ADatagramIsTakenWholeOrNotAtAll) {
  EXPECT_FALSE(parseDatagram({}));
  EXPECT_FALSE(parseDatagram(bytesOf("\n\n")));
  const auto oneBad = parseDatagram(bytesOf("XGPSsim,1,2,3,4,5\nXGPSsim,1,200,3,4,5\n"));
  ASSERT_FALSE(oneBad);
  EXPECT_NE(oneBad.error().detail.find("line 2"), std::string::npos) << oneBad.error().detail;
  std::string many;
  for (int i = 0; i < 9; ++i) many += "XGPSsim,1,2,3,4,5\n";
  ASSERT_FALSE(parseDatagram(bytesOf(many)));
  EXPECT_EQ(parseDatagram(bytesOf(many)).error().code, ErrorCode::TooLarge);
  const std::string huge(kMaxDatagramBytes + 1, 'X');
  EXPECT_EQ(parseDatagram(bytesOf(huge)).error().code, ErrorCode::TooLarge);
  // A NUL inside a line is not text.
  std::string nul = "XGPSsim,1,2,3,4,5";
  nul[5] = '\0';
  EXPECT_FALSE(parseDatagram(bytesOf(nul)));
}

TEST(ForeFlight, WhatIsWrittenParsesBack) {
  Position p{"Skyshell", -179.999999, -17.25, 3048.0, 359.5, 123.4};
  const auto back = parseLine(formatLine(p));
  ASSERT_TRUE(back) << back.error().detail;
  const auto& q = std::get<Position>(*back);
  EXPECT_EQ(q.sim, p.sim);
  EXPECT_NEAR(q.lon_deg, p.lon_deg, 1e-6);
  EXPECT_NEAR(q.lat_deg, p.lat_deg, 1e-6);
  EXPECT_NEAR(q.alt_m, p.alt_m, 0.05);
  EXPECT_NEAR(q.track_deg, p.track_deg, 5e-4);
  EXPECT_NEAR(q.groundSpeed_mps, p.groundSpeed_mps, 0.05);
  Attitude a{"Skyshell", 12.5, -3.25, 45.5};
  const auto ab = std::get<Attitude>(*parseLine(formatLine(a)));
  EXPECT_NEAR(ab.heading_deg, 12.5, 0.005);
  EXPECT_NEAR(ab.pitch_deg, -3.25, 0.005);
  EXPECT_NEAR(ab.roll_deg, 45.5, 0.005);
}

}  // namespace
}  // namespace sky::foreflight
