// Weather stream: frames split anywhere reassemble; oversize frames and
// corrupted buffers are rejected; every message kind round-trips.
#include <gtest/gtest.h>

#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"

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
  s.tiles.push_back({0x89c2590000000000ull, 1, 0.625f, 1.0f});
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

  const Subscribe s{{46.2, 12.8, 80000}, 0, 12000, 9};
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
  EXPECT_EQ(snap.tiles[0].cellId, 0x89c2590000000000ull);

  m = decodeMessage(encodeMessage(StreamError{7, "bad subscribe"}));
  ASSERT_TRUE(m);
  EXPECT_EQ(std::get<StreamError>(*m).detail, "bad subscribe");
}

TEST(Messages, RejectsOutOfRangeValues) {
  Subscribe s{{95.0, 0, 1000}, 0, 1000, 9};  // latitude 95
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
