// CIGI 3.3 codec against the golden hex vectors of the reference
// (../shared/reference/cigi.md §9.2, verified there with tshark), in both byte
// orders, and the malformed datagrams a receiver must reject.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "sky/cigi/codec.hpp"

namespace sky::cigi {
namespace {

std::vector<std::uint8_t> fromHex(const std::string& hex) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
  return out;
}

// Frame 1: IG Control + Entity Control + Weather Control, big-endian.
const std::string kFrame1Be =
    "0118030535008000000004d2004c4b40000004d100000000023000000110ff00"
    "03e900003fc00000c0100000438700004047bb7b4a2339c140211930be0ded29"
    "40934a00000000000c3800000150730c40a00000469c400041c80000427a0000"
    "44bb800044fa000043960000414800003f00000043870000447d50003eb33333";
// Frame 4: the same, little-endian.
const std::string kFrame1Le =
    "0118030535000080d2040000404b4c00d104000000000000023000000110ff00"
    "e90300000000c03f000010c000008743c139234a7bbb474029ed0dbe30192140"
    "00000000004a93400c3800000150730c0000a04000409c460000c84100007a42"
    "0080bb440000fa4400009643000048410000003f0000874300507d443333b33e";
// Frame 2: Start of Frame + Weather Conditions Response + Aerosol Response.
const std::string kFrame2Be =
    "651803050035800000000309004c4ba4000004d2000000006d202a5040a00000"
    "469c4000414800003f00000043870000447d5000000000006e082a013eb33333";

IgControl goldenIgControl() {
  IgControl ig;
  ig.databaseNumber = 5;
  ig.mode = IgMode::Operate;
  ig.timestampValid = true;
  ig.hostFrame = 1234;
  ig.timestamp_10us = 5000000;
  ig.lastIgFrame = 1233;
  return ig;
}

EntityControl goldenEntity() {
  EntityControl e;
  e.entityId = 0;
  e.state = EntityState::Active;
  e.linearExtrapolation = true;
  e.alpha = 255;
  e.entityType = 1001;
  e.roll_deg = 1.5f;
  e.pitch_deg = -2.25f;
  e.yaw_deg = 270.0f;
  e.lat_deg = 47.4647;
  e.lon_deg = 8.5492;
  e.alt_m = 1234.5;
  return e;
}

WeatherControl goldenWeather() {
  WeatherControl w;
  w.layerId = LayerId::CloudLayer1;
  w.humidity_pct = 80;
  w.weatherEnable = true;
  w.scudEnable = true;
  w.cloudType = weather::CloudType::Cumulus;
  w.scope = WeatherScope::Global;
  w.severity = 3;
  w.airTemperature_c = 5;
  w.visibility_m = 20000;
  w.scudFrequency_pct = 25;
  w.coverage_pct = 62.5f;
  w.baseElevation_m = 1500;
  w.thickness_m = 2000;
  w.transitionBand_m = 300;
  w.horizontalWind_mps = 12.5f;
  w.verticalWind_mps = 0.5f;
  w.windDirection_deg = 270;
  w.pressure_hpa = 1013.25f;
  w.aerosol_gpm3 = 0.35f;
  return w;
}

void expectGoldenFrame1(const Datagram& d) {
  ASSERT_EQ(d.packets.size(), 3u);
  EXPECT_TRUE(d.skippedIds.empty());
  EXPECT_EQ(std::get<WeatherControl>(d.packets[2]), goldenWeather());
  const auto& ig = std::get<IgControl>(d.packets[0]);
  EXPECT_EQ(ig.databaseNumber, 5);
  EXPECT_EQ(ig.mode, IgMode::Operate);
  EXPECT_TRUE(ig.timestampValid);
  EXPECT_FALSE(ig.extrapolationEnable);
  EXPECT_EQ(ig.hostFrame, 1234u);
  EXPECT_EQ(ig.timestamp_10us, 5000000u);
  EXPECT_EQ(ig.lastIgFrame, 1233u);
  const auto& e = std::get<EntityControl>(d.packets[1]);
  EXPECT_EQ(e.entityId, 0);
  EXPECT_EQ(e.state, EntityState::Active);
  EXPECT_TRUE(e.linearExtrapolation);
  EXPECT_EQ(e.alpha, 255);
  EXPECT_EQ(e.entityType, 1001);
  EXPECT_EQ(e.roll_deg, 1.5f);
  EXPECT_EQ(e.pitch_deg, -2.25f);
  EXPECT_EQ(e.yaw_deg, 270.0f);
  EXPECT_EQ(e.lat_deg, 47.4647);
  EXPECT_EQ(e.lon_deg, 8.5492);
  EXPECT_EQ(e.alt_m, 1234.5);
}

TEST(Cigi, DecodesGoldenVectorsInBothByteOrders) {
  auto be = decodeDatagram(fromHex(kFrame1Be));
  ASSERT_TRUE(be) << be.error().detail;
  EXPECT_EQ(be->order, ByteOrder::Big);
  expectGoldenFrame1(*be);
  auto le = decodeDatagram(fromHex(kFrame1Le));
  ASSERT_TRUE(le) << le.error().detail;
  EXPECT_EQ(le->order, ByteOrder::Little);
  expectGoldenFrame1(*le);
}

TEST(Cigi, EncodesTheGoldenBytes) {
  for (const auto& [order, hex] :
       {std::pair{ByteOrder::Big, kFrame1Be}, std::pair{ByteOrder::Little, kFrame1Le}}) {
    DatagramWriter w(order);
    w.add(goldenIgControl()).add(goldenEntity()).add(goldenWeather());
    EXPECT_EQ(w.bytes(), fromHex(hex));
  }
}

TEST(Cigi, StartOfFrameGoldenAndRoundTrip) {
  auto d = decodeDatagram(fromHex(kFrame2Be));
  ASSERT_TRUE(d) << d.error().detail;
  ASSERT_EQ(d->packets.size(), 3u);
  EXPECT_EQ(d->direction, Direction::IgToHost);
  const auto& sof = std::get<StartOfFrame>(d->packets[0]);
  EXPECT_EQ(sof.igFrame, 777u);
  EXPECT_EQ(sof.timestamp_10us, 5000100u);
  EXPECT_EQ(sof.lastHostFrame, 1234u);
  EXPECT_EQ(sof.mode, IgMode::Operate);
  EXPECT_TRUE(sof.timestampValid);
  WeatherConditionsResponse wcr;
  wcr.requestId = 42;
  wcr.humidity_pct = 80;
  wcr.airTemperature_c = 5;
  wcr.visibility_m = 20000;
  wcr.horizontalWind_mps = 12.5f;
  wcr.verticalWind_mps = 0.5f;
  wcr.windDirection_deg = 270;
  wcr.pressure_hpa = 1013.25f;
  EXPECT_EQ(std::get<WeatherConditionsResponse>(d->packets[1]), wcr);
  const AerosolConcentrationResponse acr{42, LayerId::CloudLayer1, 0.35f};
  EXPECT_EQ(std::get<AerosolConcentrationResponse>(d->packets[2]), acr);
  DatagramWriter w;
  w.add(sof).add(wcr).add(acr);
  EXPECT_EQ(w.bytes(), fromHex(kFrame2Be));
}

TEST(Cigi, RejectsMalformedDatagramsWithAReason) {
  const auto good = fromHex(kFrame1Be);
  auto expectError = [](std::vector<std::uint8_t> bytes, const std::string& needle) {
    auto r = decodeDatagram(bytes);
    ASSERT_FALSE(r) << "accepted: " << needle;
    EXPECT_NE(r.error().detail.find(needle), std::string::npos) << r.error().detail;
  };
  expectError(std::vector<std::uint8_t>(good.begin(), good.begin() + 10), "shorter");
  auto bad = good;
  bad[0] = 2;  // Entity Control first
  expectError(bad, "must start with IG Control");
  bad = good;
  bad[6] = 0x12;  // byte-swap magic
  expectError(bad, "byte-swap magic");
  bad = good;
  bad[25] = 40;  // Entity Control size byte wrong
  expectError(bad, "size 40, must be 48");
  bad = good;
  bad[4] = 0x33;  // IG mode 3
  expectError(bad, "IG mode 3");
  // A datagram cut inside the Weather Control packet.
  expectError(std::vector<std::uint8_t>(good.begin(), good.end() - 8), "runs past");
  // Entity Control latitude 95 degrees.
  DatagramWriter w;
  EntityControl e = goldenEntity();
  e.lat_deg = 95;
  w.add(goldenIgControl()).add(e);
  expectError(w.bytes(), "latitude");
}

TEST(Cigi, EveryPacketRoundTripsInBothByteOrders) {
  // Frame 3 of the reference, with the values it lists as decoded by tshark.
  CelestialSphereControl cel{14, 30, true, true, true, true, true, 6212025, 50};
  AtmosphereControl atm{true, 45, 15, 30000, 5, 0, 250, 1013.25f};
  EnvironmentalRegionControl reg;
  reg.regionId = 7;
  reg.mergeWeather = true;
  reg.lat_deg = 47;
  reg.lon_deg = 8;
  reg.sizeX_m = 50000;
  reg.sizeY_m = 40000;
  reg.cornerRadius_m = 5000;
  reg.rotation_deg = 30;
  reg.transitionPerimeter_m = 2000;
  ViewDefinition vd;
  vd.nearEnable = vd.farEnable = vd.leftEnable = vd.rightEnable = vd.topEnable = vd.bottomEnable = true;
  vd.near_m = 0.5f;
  vd.far_m = 100000;
  vd.left_deg = -40;
  vd.right_deg = 40;
  vd.top_deg = 25;
  vd.bottom_deg = -25;
  ViewControl vc;
  vc.xEnable = vc.yEnable = vc.zEnable = vc.rollEnable = vc.pitchEnable = vc.yawEnable = true;
  vc.z_m = -1.2f;
  vc.pitch_deg = -5;
  const EnvironmentalConditionsRequest ecr{kRequestWeather | kRequestAerosol, 42, 47.4647, 8.5492, 3000};
  for (ByteOrder order : {ByteOrder::Big, ByteOrder::Little}) {
    DatagramWriter w(order);
    w.add(goldenIgControl()).add(cel).add(atm).add(reg).add(vd).add(vc).add(ecr).add(goldenWeather());
    auto d = decodeDatagram(w.bytes());
    ASSERT_TRUE(d) << d.error().detail;
    ASSERT_EQ(d->packets.size(), 8u);
    EXPECT_EQ(std::get<CelestialSphereControl>(d->packets[1]), cel);
    EXPECT_EQ(std::get<AtmosphereControl>(d->packets[2]), atm);
    EXPECT_EQ(std::get<EnvironmentalRegionControl>(d->packets[3]), reg);
    EXPECT_EQ(std::get<ViewDefinition>(d->packets[4]), vd);
    EXPECT_EQ(std::get<ViewControl>(d->packets[5]), vc);
    EXPECT_EQ(std::get<EnvironmentalConditionsRequest>(d->packets[6]), ecr);
    EXPECT_EQ(std::get<WeatherControl>(d->packets[7]), goldenWeather());
  }
}

TEST(Cigi, RejectsPacketsOfTheOtherDirection) {
  DatagramWriter w;
  w.add(goldenIgControl()).add(AerosolConcentrationResponse{1, LayerId::CloudLayer1, 0.1f});
  auto r = decodeDatagram(w.bytes());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("IG-to-host packet inside a host datagram"), std::string::npos);
}

TEST(Cigi, RejectsOutOfRangeWeather) {
  WeatherControl w = goldenWeather();
  w.coverage_pct = 120;
  DatagramWriter d;
  d.add(goldenIgControl()).add(w);
  auto r = decodeDatagram(d.bytes());
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("packet 1 (Weather Control) at byte 44: coverage 120 outside [0, 100]"),
            std::string::npos)
      << r.error().detail;
}

TEST(Cigi, SkipsUserDefinedPacketsBySize) {
  DatagramWriter w;
  w.add(goldenIgControl());
  auto bytes = w.bytes();
  const std::vector<std::uint8_t> user = {201, 16, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14};
  bytes.insert(bytes.end(), user.begin(), user.end());
  auto r = decodeDatagram(bytes);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->skippedIds.size(), 1u);
  EXPECT_EQ(r->skippedIds[0], 201);
  EXPECT_STREQ(packetIdName(201), "user-defined");
}

// Host packets we do not decode (Component Control 4, 32 bytes; Rate Control
// 8, 32 bytes; Short Articulated Part Control 7, 24 bytes) are skipped by
// their size byte and reported by id, in both byte orders, and the packets
// after them are still decoded.
TEST(Cigi, SkipsUndecodedHostPacketsByIdInBothOrders) {
  for (const ByteOrder order : {ByteOrder::Big, ByteOrder::Little}) {
    auto bytes = DatagramWriter(order).add(IgControl{}).bytes();
    for (const auto& [id, size] : {std::pair<std::uint8_t, std::uint8_t>{4, 32}, {8, 32}, {7, 24}}) {
      std::vector<std::uint8_t> packet(size, 0x5a);
      packet[0] = id;
      packet[1] = size;
      bytes.insert(bytes.end(), packet.begin(), packet.end());
    }
    const auto tail = DatagramWriter(order).add(IgControl{}).add(EntityControl{}).bytes();
    bytes.insert(bytes.end(), tail.begin() + 24, tail.end());
    const auto r = decodeDatagram(bytes);
    ASSERT_TRUE(r) << r.error().detail;
    EXPECT_EQ(r->skippedIds, (std::vector<std::uint8_t>{4, 8, 7}));
    ASSERT_EQ(r->packets.size(), 2u);
    EXPECT_TRUE(std::holds_alternative<EntityControl>(r->packets[1]));
  }
  EXPECT_STREQ(packetIdName(4), "Component Control");
  EXPECT_STREQ(packetIdName(8), "Rate Control");
  EXPECT_STREQ(packetIdName(117), "Image Generator Message");
  EXPECT_EQ(packetId(Packet(AtmosphereControl{})), 10);
}

// Skyshell's camera exposure component (Component Control, class View,
// component id 100): round trip in both byte orders at the offsets CIGI 3.3
// gives Component Control (2 component id, 4 instance id, 6 class, 7 state,
// 8.. data words), every field checked, and other components skipped.
std::vector<std::uint8_t> withExposure(ByteOrder order, const CameraExposureControl& c) {
  return DatagramWriter(order).add(IgControl{}).add(c).bytes();
}

TEST(CigiCameraExposure, RoundTripsAtComponentControlOffsetsInBothOrders) {
  CameraExposureControl c;
  c.viewId = 2;
  c.mode = ExposureMode::Fixed;
  c.ev100 = 14.5f;
  c.compensation_ev = -1.25f;
  for (const ByteOrder order : {ByteOrder::Big, ByteOrder::Little}) {
    const auto bytes = withExposure(order, c);
    ASSERT_EQ(bytes.size(), 24u + 32u);
    const std::uint8_t* p = bytes.data() + 24;
    EXPECT_EQ(p[0], 4);
    EXPECT_EQ(p[1], 32);
    const bool big = order == ByteOrder::Big;
    EXPECT_EQ(big ? (p[2] << 8 | p[3]) : (p[3] << 8 | p[2]), 100) << "component id";
    EXPECT_EQ(big ? (p[4] << 8 | p[5]) : (p[5] << 8 | p[4]), 2) << "instance id: the view";
    EXPECT_EQ(p[6], 1) << "component class View";
    EXPECT_EQ(p[7], 1) << "component state: fixed";
    for (std::size_t i = 16; i < 32; ++i) EXPECT_EQ(p[i], 0) << "reserved data byte " << i;
    const auto r = decodeDatagram(bytes);
    ASSERT_TRUE(r) << r.error().detail;
    ASSERT_EQ(r->packets.size(), 2u);
    ASSERT_TRUE(std::holds_alternative<CameraExposureControl>(r->packets[1]));
    EXPECT_EQ(std::get<CameraExposureControl>(r->packets[1]), c);
    EXPECT_TRUE(r->skippedIds.empty());
  }
  // The EV100 at byte 8 as the big-endian float it is: 14.5 = 0x41680000.
  const auto be = withExposure(ByteOrder::Big, c);
  EXPECT_EQ(std::vector<std::uint8_t>(be.begin() + 32, be.begin() + 36), (std::vector<std::uint8_t>{0x41, 0x68, 0, 0}));
}

TEST(CigiCameraExposure, EveryFieldOutOfItsRangeDropsTheDatagramSayingWhich) {
  const auto rejects = [](std::vector<std::uint8_t> bytes, const std::string& says) {
    const auto r = decodeDatagram(bytes);
    ASSERT_FALSE(r) << says;
    EXPECT_NE(r.error().detail.find(says), std::string::npos) << r.error().detail;
  };
  CameraExposureControl fixed;
  fixed.mode = ExposureMode::Fixed;
  fixed.ev100 = 14;
  const auto good = withExposure(ByteOrder::Big, fixed);
  ASSERT_TRUE(decodeDatagram(good));
  auto b = good;
  b[24 + 7] = 2;
  rejects(b, "packet 1 (Component Control (camera exposure)) at byte 31: camera exposure state 2 is neither 0 (auto) nor 1 (fixed)");
  b = good;
  b[24 + 6] = 0x41;  // class View with a reserved bit
  rejects(b, "at byte 30: reserved bits 6-7");
  for (const float ev : {31.0f, -10.5f, std::nanf(""), INFINITY}) {
    CameraExposureControl bad = fixed;
    bad.ev100 = ev;
    rejects(withExposure(ByteOrder::Little, bad), "at byte 32: EV100");
  }
  CameraExposureControl autoNan;
  autoNan.ev100 = std::nanf("");
  rejects(withExposure(ByteOrder::Big, autoNan), "at byte 32: EV100 is not finite");
  CameraExposureControl autoAny;
  autoAny.ev100 = 99;  // auto: the EV100 is not used, only finite
  EXPECT_TRUE(decodeDatagram(withExposure(ByteOrder::Big, autoAny)));
  for (const float comp : {10.5f, -11.0f, std::nanf("")}) {
    CameraExposureControl bad = fixed;
    bad.compensation_ev = comp;
    rejects(withExposure(ByteOrder::Big, bad), "at byte 36: exposure compensation");
  }
  for (const std::size_t word : {16u, 20u, 24u, 28u}) {
    b = good;
    b[24 + word + 3] = 1;
    rejects(b, "at byte " + std::to_string(24 + word) + ": reserved data word is not 0");
  }
  // Our class and component id in a packet that is not 32 bytes.
  b = good;
  b[24 + 1] = 24;
  b.resize(24 + 24);
  rejects(b, "size 24, must be 32");
}

TEST(CigiCameraExposure, OtherComponentsAreSkippedAndCounted) {
  // Component id 100 of the Entity class, and component 101 of the View
  // class: not ours, skipped by their size whatever their data.
  CameraExposureControl c;
  auto bytes = withExposure(ByteOrder::Big, c);
  bytes[24 + 6] = 0;  // class Entity
  bytes[24 + 7] = 200;
  auto other = withExposure(ByteOrder::Little, c);
  other[24 + 2] = 101;  // little-endian component id 101
  other[24 + 8] = 0xff;
  for (const auto& d : {bytes, other}) {
    const auto r = decodeDatagram(d);
    ASSERT_TRUE(r) << r.error().detail;
    EXPECT_EQ(r->packets.size(), 1u);
    EXPECT_EQ(r->skippedIds, (std::vector<std::uint8_t>{4}));
  }
}

}  // namespace
}  // namespace sky::cigi
