// FlightGear's native FDM decoder against a real capture: every one of the
// 300 packets of tests/data/flightgear/*.pcap decodes to the values in the
// CSV decoded beside it (an independent decode, written by the data's source).
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>

#include "pcap.hpp"
#include "sky/fgfdm/net_fdm.hpp"

namespace sky::fgfdm {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// UDP payloads of the capture.
std::vector<std::vector<std::uint8_t>> udpPayloads(const std::string& path) {
  std::vector<std::vector<std::uint8_t>> out;
  for (auto& d : test::readPcap(path)) out.push_back(std::move(d.payload));
  return out;
}

TEST(FlightGearFdm, DecodesTheRealCaptureFieldByField) {
  const std::string dir = SKY_TEST_DATA_DIR "/flightgear/";
  const auto packets = udpPayloads(dir + "fgfs-c172p-native-fdm-excerpt.pcap");
  ASSERT_EQ(packets.size(), 300u);
  std::istringstream csv(readFile(dir + "fgfs-c172p-native-fdm-excerpt-decoded.csv"));
  std::string header;
  std::getline(csv, header);
  ASSERT_EQ(header.rfind("t_rel_s,version,lat_deg,lon_deg,alt_m", 0), 0u);
  constexpr double kDeg = 180.0 / std::numbers::pi;
  std::size_t row = 0;
  for (std::string line; std::getline(csv, line); ++row) {
    ASSERT_LT(row, packets.size());
    std::vector<double> v;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) v.push_back(std::stod(cell));
    ASSERT_EQ(v.size(), 24u) << "csv row " << row;
    auto f = decodeNetFdm(packets[row]);
    ASSERT_TRUE(f) << "packet " << row << ": " << f.error().detail;
    // The CSV prints each value rounded; tolerances are half its last digit.
    EXPECT_EQ(f->version, static_cast<std::uint32_t>(v[1]));
    EXPECT_NEAR(f->lat_rad * kDeg, v[2], 5e-8) << row;
    EXPECT_NEAR(f->lon_rad * kDeg, v[3], 5e-8) << row;
    EXPECT_NEAR(f->alt_m, v[4], 5e-3) << row;
    EXPECT_NEAR(f->agl_m, v[5], 5e-3) << row;
    EXPECT_NEAR(f->phi_rad * kDeg, v[6], 5e-3) << row;
    EXPECT_NEAR(f->theta_rad * kDeg, v[7], 5e-3) << row;
    EXPECT_NEAR(std::fmod(f->psi_rad * kDeg + 360.0, 360.0), std::fmod(v[8] + 360.0, 360.0), 5e-3) << row;
    EXPECT_NEAR(f->alpha_rad * kDeg, v[9], 5e-3) << row;
    EXPECT_NEAR(f->vcas_kt, v[10], 5e-3) << row;
    EXPECT_NEAR(f->climbRate_fps, v[11], 5e-4) << row;
    EXPECT_NEAR(f->vNorth_fps, v[12], 5e-4) << row;
    EXPECT_NEAR(f->vEast_fps, v[13], 5e-4) << row;
    EXPECT_NEAR(f->vDown_fps, v[14], 5e-4) << row;
    EXPECT_NEAR(f->rpm[0], v[15], 0.5) << row;
    EXPECT_EQ(f->numEngines, static_cast<std::uint32_t>(v[16])) << row;
    EXPECT_EQ(f->wow[0], static_cast<std::uint32_t>(v[17])) << row;
    EXPECT_EQ(f->curTime_unix, static_cast<std::uint32_t>(v[18])) << row;
    EXPECT_EQ(f->warp_s, static_cast<std::int32_t>(v[19])) << row;
    EXPECT_NEAR(f->visibility_m, v[20], 0.5) << row;
    EXPECT_NEAR(f->elevator, v[21], 5e-4) << row;
    EXPECT_NEAR(f->leftAileron, v[22], 5e-4) << row;
    EXPECT_NEAR(f->rudder, v[23], 5e-4) << row;
  }
  EXPECT_EQ(row, 300u);
}

TEST(FlightGearFdm, RejectsOtherSizesAndVersions) {
  NetFdm f;
  f.lat_rad = 0.36;
  f.lon_rad = -2.76;
  f.alt_m = 900;
  auto bytes = encodeNetFdm(f);
  ASSERT_TRUE(decodeNetFdm(bytes));
  auto r = decodeNetFdm(std::span(bytes).first(400));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("400 bytes"), std::string::npos);
  f.version = 25;
  r = decodeNetFdm(encodeNetFdm(f));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::Unsupported);
  EXPECT_NE(r.error().detail.find("'version' is 25"), std::string::npos);
  f.version = kVersion;
  f.lat_rad = std::nan("");
  r = decodeNetFdm(encodeNetFdm(f));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("latitude"), std::string::npos);
}

TEST(FlightGearFdm, EncodeDecodeRoundTripsEveryField) {
  NetFdm f;
  f.lat_rad = 0.5;
  f.lon_rad = -1.25;
  f.alt_m = 1234.5;
  f.numEngines = 2;
  f.rpm = {2400, 2300, 0, 0};
  f.numWheels = 3;
  f.wow = {1, 0, 1};
  f.curTime_unix = 1795299684;  // simulated time, the warp in it
  f.warp_s = -13200;
  f.spoilers = 0.25f;
  const auto bytes = encodeNetFdm(f);
  EXPECT_EQ(bytes[0], 0);
  EXPECT_EQ(bytes[3], 24);  // big-endian version
  auto d = decodeNetFdm(bytes);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->rpm, f.rpm);
  EXPECT_EQ(d->wow, f.wow);
  EXPECT_EQ(d->warp_s, f.warp_s);
  EXPECT_EQ(d->spoilers, f.spoilers);
  EXPECT_EQ(d->alt_m, f.alt_m);
}

}  // namespace
}  // namespace sky::fgfdm
