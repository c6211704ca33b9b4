// Weather stream: frames split anywhere reassemble; oversize frames and
// corrupted buffers are rejected; every message kind round-trips.
#include <chrono>
#include <cmath>

#include <gtest/gtest.h>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::stream {
namespace {

weather::WeatherSnapshot sampleSnapshot() {
  weather::WeatherSnapshot s;
  s.weatherClock_s = 12.5;
  s.tileLevel = 9;
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1500;
  l.thickness_m = 1200;
  l.coverage = 0.625;
  l.wind = {10, 270, 0.5};
  s.layers.push_back(l);
  s.tiles.push_back({weather::cellAt(46.2, 12.8, 9), 1, 0.6f, 1.0f, weather::CloudType::Cumulonimbus, 0.2f});
  return s;
}

TEST(Framing, ReassemblesFramesSplitAtEveryByte) {
  const std::vector<std::uint8_t> a = encodeMessage(Heartbeat{1.0});
  const std::vector<std::uint8_t> b = encodeMessage(sampleSnapshot());
  std::vector<std::uint8_t> wire = encodeFrame(a);
  const auto fb = encodeFrame(b);
  wire.insert(wire.end(), fb.begin(), fb.end());
  for (std::size_t split = 0; split <= wire.size(); ++split) {
    FrameDecoder d;
    std::vector<std::vector<std::uint8_t>> got;
    d.append(std::span(wire).first(split));
    while (auto f = d.next().value()) got.push_back(*f);
    d.append(std::span(wire).subspan(split));
    while (auto f = d.next().value()) got.push_back(*f);
    ASSERT_EQ(got.size(), 2u) << "split at " << split;
    EXPECT_EQ(got[0], a);
    EXPECT_EQ(got[1], b);
  }
}

TEST(Framing, RejectsOversizedFrame) {
  FrameDecoder d;
  const std::uint8_t header[4] = {0x7f, 0, 0, 0};
  d.append(header);
  auto r = d.next();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::TooLarge);
}

TEST(Messages, RoundTripEveryKind) {
  const Hello h{kProtocolVersion, "weatherd-test", 42.0, 10.0};
  auto m = decodeMessage(encodeMessage(h));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<Hello>(*m).serverId, "weatherd-test");
  EXPECT_EQ(std::get<Hello>(*m).clockRate, 10.0);

  const Subscribe s{kProtocolVersion, {46.2, 12.8, 80000}, 0, 12000, 9};
  m = decodeMessage(encodeMessage(s));
  ASSERT_TRUE(m);
  EXPECT_EQ(std::get<Subscribe>(*m).area.radius_m, 80000);
  EXPECT_EQ(std::get<Subscribe>(*m).tileLevel, 9);

  m = decodeMessage(encodeMessage(sampleSnapshot()));
  ASSERT_TRUE(m);
  const auto& snap = std::get<weather::WeatherSnapshot>(*m);
  ASSERT_EQ(snap.layers.size(), 1u);
  EXPECT_EQ(snap.layers[0].type, weather::CloudType::Cumulus);
  EXPECT_FLOAT_EQ(static_cast<float>(snap.layers[0].coverage), 0.625f);
  EXPECT_FLOAT_EQ(static_cast<float>(snap.layers[0].wind.vertical_mps), 0.5f);
  ASSERT_EQ(snap.tiles.size(), 1u);
  EXPECT_EQ(snap.tiles[0].cellId, weather::cellAt(46.2, 12.8, 9));
  // Tiles travel quantised to 1/255: 0.6 = 153/255 exactly, 0.2 = 51/255.
  EXPECT_EQ(snap.tiles[0].coverage, 153.0f / 255.0f);
  EXPECT_EQ(snap.tiles[0].blend, 51.0f / 255.0f);
  EXPECT_EQ(snap.tiles[0].blendType, weather::CloudType::Cumulonimbus);

  m = decodeMessage(encodeMessage(StreamError{7, "bad subscribe"}));
  ASSERT_TRUE(m);
  EXPECT_EQ(std::get<StreamError>(*m).detail, "bad subscribe");
}

TEST(Messages, RejectsOutOfRangeValues) {
  Subscribe s{kProtocolVersion, {95.0, 0, 1000}, 0, 1000, 9};  // latitude 95
  auto m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("center_lat_deg"), std::string::npos);

  weather::WeatherSnapshot snap = sampleSnapshot();
  snap.layers[0].coverage = 2.0;
  m = decodeMessage(encodeMessage(snap));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("coverage"), std::string::npos);

  Hello h{kProtocolVersion + 1, "x", 0, 1};
  m = decodeMessage(encodeMessage(h));
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::Unsupported);
}

TEST(Messages, QuantisationErrorIsAtMostHalfAStep) {
  for (double v = 0; v <= 1.0; v += 0.001)
    EXPECT_LE(std::abs(weather::dequantizeUnit(weather::quantizeUnit(v)) - v), 0.5 / 255 + 1e-7) << v;
  EXPECT_EQ(weather::quantizeUnit(-1), 0);
  EXPECT_EQ(weather::quantizeUnit(7), 255);
  EXPECT_EQ(weather::quantizeUnit(std::nan("")), 0);
}

TEST(Messages, SnapshotTileChecksNameTheProblem) {
  weather::WeatherSnapshot s = sampleSnapshot();
  s.tiles[0].cellId = weather::cellAt(46.2, 12.8, 10);  // a level-10 cell in a level-9 snapshot
  auto m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("is not an S2 cell of level 9"), std::string::npos) << m.error().detail;
  s = sampleSnapshot();
  s.tiles[0].layerId = 2;  // no such layer
  m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("layer 2, which the Snapshot does not have"), std::string::npos);
  s = sampleSnapshot();
  s.layers.push_back(s.layers[0]);  // duplicate id
  m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("appears twice"), std::string::npos);
}

TEST(Messages, SubscribeOfAnotherVersionIsUnsupported) {
  Subscribe s{kProtocolVersion + 1, {46.2, 12.8, 80000}, 0, 12000, 9};
  auto m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::Unsupported);
  EXPECT_NE(m.error().detail.find("protocol_version " + std::to_string(kProtocolVersion + 1)), std::string::npos);
}

TEST(Messages, DeltaRoundTripsAndApplies) {
  weather::WeatherSnapshot state = sampleSnapshot();
  weather::WeatherDelta d;
  d.weatherClock_s = 20;
  d.tileLevel = 9;
  weather::CloudLayer stratus = state.layers[0];
  stratus.id = 2;
  stratus.type = weather::CloudType::Stratus;
  stratus.base_m = 400;
  stratus.thickness_m = 300;
  d.layers.push_back(stratus);
  const std::uint64_t other = weather::cellAt(46.3, 12.9, 9);
  d.tiles.push_back({weather::cellAt(46.2, 12.8, 9), 1, 0.2f, 1.0f});  // changes the existing tile
  d.tiles.push_back({other, 2, 1.0f, 0.5f});                          // a tile of the new layer
  auto m = decodeMessage(encodeMessage(d));
  ASSERT_TRUE(m) << m.error().detail;
  const auto& got = std::get<weather::WeatherDelta>(*m);
  ASSERT_TRUE(weather::applyDelta(state, got));
  EXPECT_EQ(state.weatherClock_s, 20);
  ASSERT_EQ(state.layers.size(), 2u);
  ASSERT_EQ(state.tiles.size(), 2u);
  EXPECT_EQ(state.tiles[0].coverage, 51.0f / 255.0f);
  EXPECT_EQ(state.tiles[1].layerId, 2u);

  // Removing a layer takes its tiles; a bad delta leaves the state unchanged.
  weather::WeatherDelta remove;
  remove.weatherClock_s = 21;
  remove.removedLayerIds = {2};
  ASSERT_TRUE(weather::applyDelta(state, remove));
  EXPECT_EQ(state.layers.size(), 1u);
  EXPECT_EQ(state.tiles.size(), 1u);
  const weather::WeatherSnapshot before = state;
  weather::WeatherDelta bad;
  bad.weatherClock_s = 22;
  bad.tileLevel = 9;
  bad.tiles.push_back({other, 7, 1.0f, 1.0f});  // layer 7 does not exist
  auto r = weather::applyDelta(state, bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("layer 7"), std::string::npos);
  EXPECT_EQ(state.weatherClock_s, before.weatherClock_s);
  EXPECT_EQ(state.tiles, before.tiles);
}

// Regression: FlatBuffers reads scalars in place, so a payload starting at an
// address not aligned for doubles was undefined behaviour (UBSan: misaligned
// load); decodeMessage now realigns such payloads first.
TEST(Messages, DecodesAPayloadAtAnOddAddress) {
  const auto good = encodeMessage(sampleSnapshot());
  std::vector<std::uint8_t> shifted(good.size() + 1);
  std::copy(good.begin(), good.end(), shifted.begin() + 1);
  auto m = decodeMessage(std::span(shifted).subspan(1));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<weather::WeatherSnapshot>(*m).tiles.size(), 1u);
}

// Regression: the tile-vector alignment check rejected an empty Snapshot,
// whose (empty) tile vector FlatBuffers does not pad.
TEST(Messages, EmptySnapshotAndDeltaDecode) {
  auto m = decodeMessage(encodeMessage(weather::WeatherSnapshot{}));
  ASSERT_TRUE(m) << m.error().detail;
  m = decodeMessage(encodeMessage(weather::WeatherDelta{}));
  ASSERT_TRUE(m) << m.error().detail;
}

TEST(Messages, CorruptedBuffersNeverDecodeOutOfBounds) {
  // Flip every byte of a valid snapshot in turn: each result is either a
  // clean error or a range-checked message (ASan catches any overread).
  const auto good = encodeMessage(sampleSnapshot());
  for (std::size_t i = 0; i < good.size(); ++i) {
    auto bad = good;
    bad[i] ^= 0xA5;
    (void)decodeMessage(bad);
  }
  const std::vector<std::uint8_t> junk = {1, 2, 3};
  EXPECT_FALSE(decodeMessage(junk));
}

// Regression, found by fuzz_stream_frame: a Message whose union type says
// ErrorMessage but whose body table is absent passed the FlatBuffers verifier
// and decodeMessage then read through a null table (SEGV).
TEST(Messages, UnionTypeWithoutBodyIsRejected) {
  const std::string hex =
      "000000340c00000008000c000700000008000000000000050c00000008000c0006000800080000000000"
      "01ffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffffff"
      "ffffffff00040000000300000062616400";
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2)
    bytes.push_back(static_cast<std::uint8_t>(std::stoul(hex.substr(i, 2), nullptr, 16)));
  FrameDecoder d;
  d.append(bytes);
  auto frame = d.next();
  ASSERT_TRUE(frame && *frame);
  auto m = decodeMessage(**frame);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("carries no body"), std::string::npos) << m.error().detail;
}

}  // namespace
}  // namespace sky::stream

namespace sky::stream {
namespace {

CameraReport sampleReport() {
  CameraReport r;
  r.channel = "cockpit-2 centre";
  r.lat_deg = 46.123456789;
  r.lon_deg = -179.5;
  r.alt_m = 1834.25;
  r.heading_deg = 359.5;
  r.pitch_deg = -12.5;
  r.roll_deg = 30.25;
  r.frame = 1234567890123ull;
  r.weatherVersion = 77;
  r.weatherClock_s = 43200.5;
  return r;
}

TEST(CameraReports, RoundTrip) {
  auto m = decodeMessage(encodeMessage(sampleReport()));
  ASSERT_TRUE(m) << m.error().detail;
  const auto& r = std::get<CameraReport>(*m);
  EXPECT_EQ(r.channel, "cockpit-2 centre");
  EXPECT_EQ(r.lat_deg, 46.123456789) << "positions travel as doubles";
  EXPECT_EQ(r.lon_deg, -179.5);
  EXPECT_EQ(r.alt_m, 1834.25);
  // Angles travel as floats: these values are exact in a float.
  EXPECT_EQ(r.heading_deg, 359.5);
  EXPECT_EQ(r.pitch_deg, -12.5);
  EXPECT_EQ(r.roll_deg, 30.25);
  EXPECT_EQ(r.frame, 1234567890123ull);
  EXPECT_EQ(r.weatherVersion, 77u);
  EXPECT_EQ(r.weatherClock_s, 43200.5);
  EXPECT_STREQ(kindName(*m), "CameraReport");
}

TEST(CameraReports, EveryFieldIsRangeChecked) {
  struct Case {
    const char* field;
    void (*spoil)(CameraReport&);
  };
  const Case cases[] = {
      {"lat_deg", [](CameraReport& r) { r.lat_deg = 90.5; }},
      {"lat_deg", [](CameraReport& r) { r.lat_deg = std::nan(""); }},
      {"lon_deg", [](CameraReport& r) { r.lon_deg = 180.5; }},
      {"alt_m", [](CameraReport& r) { r.alt_m = -1001; }},
      {"alt_m", [](CameraReport& r) { r.alt_m = INFINITY; }},
      {"heading_deg", [](CameraReport& r) { r.heading_deg = -1; }},
      {"heading_deg", [](CameraReport& r) { r.heading_deg = 360.5; }},
      {"pitch_deg", [](CameraReport& r) { r.pitch_deg = 90.5; }},
      {"roll_deg", [](CameraReport& r) { r.roll_deg = -181; }},
      {"weather_clock_s", [](CameraReport& r) { r.weatherClock_s = std::nan(""); }},
  };
  for (const Case& c : cases) {
    CameraReport r = sampleReport();
    c.spoil(r);
    auto m = decodeMessage(encodeMessage(r));
    ASSERT_FALSE(m) << c.field;
    EXPECT_NE(m.error().detail.find(std::string("CameraReport.") + c.field), std::string::npos) << m.error().detail;
  }
  // The edges themselves are in range.
  CameraReport edge = sampleReport();
  edge.lat_deg = -90;
  edge.lon_deg = 180;
  edge.heading_deg = 0;
  edge.pitch_deg = 90;
  edge.roll_deg = -180;
  EXPECT_TRUE(decodeMessage(encodeMessage(edge)));
}

TEST(CameraReports, TheChannelIsBoundedPrintableUtf8) {
  auto decodeChannel = [](const std::string& channel) {
    CameraReport r = sampleReport();
    r.channel = channel;
    return decodeMessage(encodeMessage(r));
  };
  EXPECT_TRUE(decodeChannel(""));
  EXPECT_TRUE(decodeChannel(std::string(kMaxChannelBytes, 'x')));
  EXPECT_TRUE(decodeChannel("Kanal S\xc3\xbc" "d \xe2\x9c\x88 \xf0\x9f\x9b\xa9"));  // 2-, 3- and 4-byte UTF-8
  for (const std::string& bad : {std::string(kMaxChannelBytes + 1, 'x'), std::string("tab\there"),
                                 std::string("del\x7f"), std::string("\xff"), std::string("cut \xc3"),
                                 std::string("overlong \xc0\xaf"), std::string("surrogate \xed\xa0\x80"),
                                 std::string("past U+10FFFF \xf4\x90\x80\x80"), std::string("nul\0in", 6)}) {
    auto m = decodeChannel(bad);
    ASSERT_FALSE(m) << bad;
    EXPECT_NE(m.error().detail.find("CameraReport.channel"), std::string::npos) << m.error().detail;
  }
}

// The host clock offset travels as doubles, exactly (channels compare it
// bit for bit); the host is a bounded, non-empty printable name, the offset
// finite and bounded, the rate in (0, 3600].
TEST(HostClocks, RoundTripExactAndEveryFieldIsChecked) {
  const HostClock sent{"192.168.10.4", 4983.000123456789, 2.5};
  auto m = decodeMessage(encodeMessage(sent));
  ASSERT_TRUE(m) << m.error().detail;
  const auto& got = std::get<HostClock>(*m);
  EXPECT_EQ(got.host, sent.host);
  EXPECT_EQ(got.offset_s, sent.offset_s);
  EXPECT_EQ(got.rate, sent.rate);
  EXPECT_STREQ(kindName(*m), "HostClock");
  struct Case {
    const char* field;
    HostClock clock;
  };
  const Case cases[] = {
      {"host", {"", 0, 1}},
      {"host", {std::string(kMaxChannelBytes + 1, 'h'), 0, 1}},
      {"host", {"tab\there", 0, 1}},
      {"host", {"cut \xc3", 0, 1}},
      {"offset_s", {"h", std::nan(""), 1}},
      {"offset_s", {"h", INFINITY, 1}},
      {"offset_s", {"h", 1.5e12, 1}},
      {"rate", {"h", 0, 0}},
      {"rate", {"h", 0, -1}},
      {"rate", {"h", 0, 3600.5}},
      {"rate", {"h", 0, std::nan("")}},
  };
  for (const Case& c : cases) {
    auto bad = decodeMessage(encodeMessage(c.clock));
    ASSERT_FALSE(bad) << c.field;
    EXPECT_NE(bad.error().detail.find(std::string("HostClock.") + c.field), std::string::npos) << bad.error().detail;
  }
  EXPECT_TRUE(decodeMessage(encodeMessage(HostClock{std::string(kMaxChannelBytes, 'h'), -1.0e12, 3600})));
}

// Kinds appended to the schema after a build reach it as UnknownKind, which
// the receiver ignores; only a missing body is malformed.
TEST(Messages, AKindThisBuildDoesNotKnowDecodesAsUnknown) {
  auto m = decodeMessage(encodeMessage(UnknownKind{200}));
  ASSERT_TRUE(m) << m.error().detail;
  ASSERT_TRUE(std::holds_alternative<UnknownKind>(*m));
  EXPECT_EQ(std::get<UnknownKind>(*m).bodyType, 200);
  m = decodeMessage(encodeMessage(UnknownKind{0}));  // body type NONE
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::Malformed);
}

// Hello.features came later: FlatBuffers leaves a field at its default out of
// the buffer, so a Hello without features is byte for byte what a server from
// before the field sends, and reads as 0.
TEST(Messages, HelloFeatures) {
  Hello h{kProtocolVersion, "weatherd-test", 42.0, 10.0};
  const auto without = encodeMessage(h);
  auto m = decodeMessage(without);
  ASSERT_TRUE(m);
  EXPECT_EQ(std::get<Hello>(*m).features, 0u);
  h.features = kFeatureCameraReports;
  const auto with = encodeMessage(h);
  EXPECT_GT(with.size(), without.size());
  m = decodeMessage(with);
  ASSERT_TRUE(m);
  EXPECT_EQ(std::get<Hello>(*m).features, kFeatureCameraReports);
}

}  // namespace
}  // namespace sky::stream

namespace sky::stream {
namespace {

// A connection holds up to kMaxAreas areas: Subscribe, Snapshot and Delta
// carry the area index across the wire; one past the last is refused with
// the field named; a message without the field (an older peer) is area 0.
TEST(Areas, TheIndexRoundTripsAndIsRangeChecked) {
  Subscribe s;
  s.area = {47, 8, 900000};
  s.tileLevel = 9;
  s.areaIndex = 1;
  auto m = decodeMessage(encodeMessage(s));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<Subscribe>(*m).areaIndex, 1);
  EXPECT_EQ(std::get<Subscribe>(*m).area.radius_m, 900000);

  weather::WeatherSnapshot snap = sampleSnapshot();
  snap.areaIndex = 1;
  m = decodeMessage(encodeMessage(snap));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<weather::WeatherSnapshot>(*m).areaIndex, 1);

  weather::WeatherDelta d;
  d.areaIndex = 1;
  m = decodeMessage(encodeMessage(d));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<weather::WeatherDelta>(*m).areaIndex, 1);

  s.areaIndex = kMaxAreas;
  m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("Subscribe.area_index"), std::string::npos) << m.error().detail;
  snap.areaIndex = kMaxAreas;
  m = decodeMessage(encodeMessage(snap));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("Snapshot.area_index"), std::string::npos) << m.error().detail;
  d.areaIndex = kMaxAreas;
  m = decodeMessage(encodeMessage(d));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("Delta.area_index"), std::string::npos) << m.error().detail;

  // The default (0) is what a peer from before the field means.
  Subscribe plain;
  plain.area = {47, 8, 120000};
  m = decodeMessage(encodeMessage(plain));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<Subscribe>(*m).areaIndex, 0);
}

// A delta of one area never applies to another's snapshot, and leaves it as
// it was; snapshots of two areas have no delta between them.
TEST(Areas, ADeltaAppliesOnlyToItsOwnArea) {
  weather::WeatherSnapshot coarse = sampleSnapshot();
  coarse.areaIndex = 1;
  weather::WeatherSnapshot fine = sampleSnapshot();
  weather::WeatherDelta d;
  d.areaIndex = 1;
  d.weatherClock_s = 99;
  d.layers = {coarse.layers[0]};
  d.layers[0].coverage = 0.9;
  const weather::WeatherSnapshot before = fine;
  auto r = weather::applyDelta(fine, d);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("area 1"), std::string::npos) << r.error().detail;
  EXPECT_EQ(fine.weatherClock_s, before.weatherClock_s);
  EXPECT_EQ(fine.layers[0].coverage, before.layers[0].coverage);
  ASSERT_TRUE(weather::applyDelta(coarse, d));
  EXPECT_EQ(coarse.layers[0].coverage, 0.9);
  EXPECT_FALSE(weather::diffSnapshots(fine, coarse));
  const auto same = weather::diffSnapshots(coarse, coarse);
  ASSERT_TRUE(same);
  EXPECT_EQ(same->areaIndex, 1);
}

// Issue 18: the server reads with the subscriber's cap, so a peer announcing
// a snapshot-sized frame is refused from its 4-byte header alone.
TEST(Framing, TheSubscriberCapRefusesFromTheHeader) {
  FrameDecoder atCap(kMaxSubscriberFrameBytes);
  const std::uint8_t fits[4] = {0, 0, 0x10, 0x00};  // 4096 bytes: waits for them
  atCap.append(fits);
  ASSERT_TRUE(atCap.next());
  FrameDecoder over(kMaxSubscriberFrameBytes);
  const std::uint8_t tooMany[4] = {0, 0, 0x10, 0x01};  // 4097 bytes
  over.append(tooMany);
  auto r = over.next();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::TooLarge);
  EXPECT_NE(r.error().detail.find("cap is 4096"), std::string::npos) << r.error().detail;
  EXPECT_LT(kMaxSubscriberFrameBytes, kMaxFrameBytes);
  // Both kinds a subscriber sends fit with room, the longest channel name too.
  CameraReport report;
  report.channel = std::string(kMaxChannelBytes, 'c');
  EXPECT_LT(encodeFrame(encodeMessage(report)).size(), kMaxSubscriberFrameBytes / 4);
  EXPECT_LT(encodeFrame(encodeMessage(Subscribe{})).size(), kMaxSubscriberFrameBytes / 4);
}

weather::WeatherSnapshot snapshotWithLayers(std::size_t n) {
  weather::WeatherSnapshot s = sampleSnapshot();
  s.tiles.clear();
  const weather::CloudLayer base = s.layers[0];
  s.layers.clear();
  for (std::size_t i = 0; i < n; ++i) {
    weather::CloudLayer l = base;
    l.id = static_cast<std::uint32_t>(i + 1);
    s.layers.push_back(l);
  }
  return s;
}

// Issue 18: a snapshot of 60 000 distinct layers took a pairwise duplicate
// check (1.8e9 comparisons) before this cap; now it is refused by its count.
TEST(Messages, LayerCountIsCappedAndCheckedBeforeDecoding) {
  auto m = decodeMessage(encodeMessage(snapshotWithLayers(kMaxMessageLayers)));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<weather::WeatherSnapshot>(*m).layers.size(), kMaxMessageLayers);

  m = decodeMessage(encodeMessage(snapshotWithLayers(kMaxMessageLayers + 1)));
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::TooLarge);
  EXPECT_NE(m.error().detail.find("Snapshot.layers: 257, at most 256"), std::string::npos) << m.error().detail;

  const auto huge = encodeMessage(snapshotWithLayers(60000));
  const auto started = std::chrono::steady_clock::now();
  m = decodeMessage(huge);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::TooLarge);
  // The verifier's linear pass over ~2 MB; the sanitizer build is slow, so
  // the bound is loose (the quadratic check took minutes).
  EXPECT_LT(took_s, 1.0);

  // A duplicate at the far end of a full list is still found (after sorting).
  weather::WeatherSnapshot dup = snapshotWithLayers(kMaxMessageLayers);
  dup.layers.back().id = 1;
  m = decodeMessage(encodeMessage(dup));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("id 1 appears twice"), std::string::npos) << m.error().detail;

  weather::WeatherDelta delta;
  delta.tileLevel = 9;
  delta.removedLayerIds.assign(kMaxMessageLayers + 1, 7);
  m = decodeMessage(encodeMessage(delta));
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().detail.find("Delta.removed_layer_ids: 257, at most 256"), std::string::npos)
      << m.error().detail;
}

TEST(Messages, TileCountIsCappedAtWhatOneFrameHolds) {
  weather::WeatherSnapshot s = sampleSnapshot();
  // Any cell will do: the count is checked before the first tile is looked at.
  s.tiles.assign(kMaxMessageTiles + 1, s.tiles[0]);
  auto m = decodeMessage(encodeMessage(s));
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::TooLarge);
  EXPECT_NE(m.error().detail.find("Snapshot.tiles: 262145, at most 262144"), std::string::npos) << m.error().detail;
  // Every tile of a full snapshot is matched to its layer by binary search.
  s = snapshotWithLayers(kMaxMessageLayers);
  const auto cell = weather::cellAt(46.2, 12.8, 9);
  for (std::uint32_t i = 0; i < 100000; ++i)
    s.tiles.push_back({cell, 1 + i % static_cast<std::uint32_t>(kMaxMessageLayers), 0.5f, 1.0f,
                       weather::CloudType::Cumulus, 0.0f});
  m = decodeMessage(encodeMessage(s));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<weather::WeatherSnapshot>(*m).tiles.size(), 100000u);
}

}  // namespace
}  // namespace sky::stream
