// AreaFrames (issue 27): subscribers of one area share one snapshot build
// and one encoded frame per (held, new) pair while the weather stands still;
// a subscriber of another area, or one holding an older snapshot, gets its
// own; after a change (clear) or kAreaSnapshotReuse nothing kept is served.
// Each frame is checked by the protocol's own decoder and applyDelta: it
// takes what the peer holds to a fresh snapshot's tiles.
#include <algorithm>

#include <gtest/gtest.h>

#include "region_builder.hpp"

#include "sky/server/area_frames.hpp"
#include "sky/stream/framing.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;

constexpr auto layer = test::stackedLayer;

stream::Subscribe around(double lat, double lon, double radius_m) {
  stream::Subscribe s;
  s.area = {lat, lon, radius_m};
  s.tileLevel = 12;
  return s;
}

stream::Message decodeFrame(const Frame& frame) {
  stream::FrameDecoder decoder;
  decoder.append(frame);
  auto payload = decoder.next();
  EXPECT_TRUE(payload && *payload);
  auto message = stream::decodeMessage(**payload);
  EXPECT_TRUE(message);
  return *message;
}

class AreaFramesTest : public ::testing::Test {
 protected:
  // A storm cell of a layer only it has, moving east across both areas'
  // overlap, over one global layer.
  std::vector<weather::CloudLayer> global = {layer(1, weather::CloudType::Stratocumulus, 0.5)};
  std::vector<weather::Region> regions = {
      test::squareRegion(9, 46, 13.0, 20000, 5000, {layer(9, weather::CloudType::Cumulonimbus, 0.9)})};
  const stream::Subscribe areaA = around(46, 13.0, 40000);
  // Its east edge reaches into the storm: part of the storm's tiles.
  const stream::Subscribe areaB = around(46, 13.45, 40000);
  TileCache cache;
  AreaFrames frames;
  int builds = 0;
  AreaFrames::Clock::time_point t0 = AreaFrames::Clock::now();

  std::shared_ptr<const AreaSnapshot> snapshotOf(const stream::Subscribe& area, AreaFrames::Clock::time_point at) {
    return frames.snapshot(area, at, [&] {
      ++builds;
      return buildSnapshotWithGenerations(area, global, 0.0, kDefaultMaxCells, regions, &cache);
    });
  }
  // What a peer subscribed to `area` decodes from a fresh Snapshot of the
  // weather now (the wire quantises tiles, so this is what a delta must
  // reach).
  weather::WeatherSnapshot freshOnTheWire(const stream::Subscribe& area) {
    const auto s = buildSnapshot(area, global, 0.0, kDefaultMaxCells, regions);
    return std::get<weather::WeatherSnapshot>(decodeFrame(stream::encodeFrame(stream::encodeMessage(s))));
  }
};

TEST_F(AreaFramesTest, SubscribersOfOneAreaGetOneBuildAndByteIdenticalDeltas) {
  // Two channels of one simulator subscribe the same area.
  const auto held1 = snapshotOf(areaA, t0);
  const auto held2 = snapshotOf(areaA, t0 + 1ms);
  EXPECT_EQ(builds, 1);
  EXPECT_EQ(held1, held2) << "the second subscriber is answered from the first's build";
  const auto first1 = frames.frame(nullptr, held1);
  const auto first2 = frames.frame(nullptr, held2);
  EXPECT_EQ(*first1, *first2);
  const auto heldOnWire = std::get<weather::WeatherSnapshot>(decodeFrame(*first1));
  EXPECT_FALSE(heldOnWire.tiles.empty());

  // The storm moves: a change, so what was kept is not served again.
  regions[0].centerLon_deg += 0.02;
  frames.clear(t0 + 2ms);
  const auto now1 = snapshotOf(areaA, t0 + 3ms);
  const auto now2 = snapshotOf(areaA, t0 + 4ms);
  EXPECT_EQ(builds, 2);
  EXPECT_NE(now1, held1);
  EXPECT_EQ(now1, now2);
  const auto delta1 = frames.frame(held1, now1);
  const auto delta2 = frames.frame(held2, now2);
  EXPECT_EQ(delta1, delta2) << "encoded once";
  EXPECT_EQ(frames.counters().encoded, 2u);
  EXPECT_EQ(frames.counters().shared, 2u);

  // It is a delta of the storm's tiles, and it takes the held snapshot to
  // the new weather.
  const auto message = decodeFrame(*delta1);
  const auto* delta = std::get_if<weather::WeatherDelta>(&message);
  ASSERT_NE(delta, nullptr) << "a delta, not a snapshot";
  ASSERT_FALSE(delta->tiles.empty());
  EXPECT_LT(delta->tiles.size(), heldOnWire.tiles.size() / 2);
  for (const auto& t : delta->tiles) EXPECT_EQ(t.layerId, 9u) << "only the storm's layer changed";
  weather::WeatherSnapshot applied = heldOnWire;
  ASSERT_TRUE(weather::applyDelta(applied, *delta));
  const auto fresh = freshOnTheWire(areaA);
  EXPECT_EQ(applied.tiles, fresh.tiles);
  EXPECT_EQ(applied.layers.size(), fresh.layers.size());
}

TEST_F(AreaFramesTest, AnotherAreaGetsItsOwnSnapshotAndDelta) {
  const auto heldA = snapshotOf(areaA, t0);
  const auto heldB = snapshotOf(areaB, t0);
  EXPECT_EQ(builds, 2);
  EXPECT_NE(heldA, heldB);
  const auto onWireB = std::get<weather::WeatherSnapshot>(decodeFrame(*frames.frame(nullptr, heldB)));

  regions[0].centerLon_deg += 0.02;
  frames.clear(t0 + 1ms);
  const auto nowA = snapshotOf(areaA, t0 + 2ms), nowB = snapshotOf(areaB, t0 + 2ms);
  const auto deltaA = frames.frame(heldA, nowA), deltaB = frames.frame(heldB, nowB);
  EXPECT_NE(*deltaA, *deltaB);
  EXPECT_EQ(frames.counters().shared, 0u);
  // B's delta has the storm's tiles in B's area only, and takes B's
  // snapshot to B's new weather.
  const auto messageA = decodeFrame(*deltaA), message = decodeFrame(*deltaB);
  const auto* delta = std::get_if<weather::WeatherDelta>(&message);
  ASSERT_NE(delta, nullptr);
  ASSERT_TRUE(std::holds_alternative<weather::WeatherDelta>(messageA));
  EXPECT_GT(delta->tiles.size(), 0u);
  EXPECT_LT(delta->tiles.size(), std::get<weather::WeatherDelta>(messageA).tiles.size());
  const auto cellsB = coverArea(areaB.area, areaB.tileLevel, kDefaultMaxCells).cells;
  for (const auto& t : delta->tiles) EXPECT_NE(std::find(cellsB.begin(), cellsB.end(), t.cellId), cellsB.end());
  weather::WeatherSnapshot applied = onWireB;
  ASSERT_TRUE(weather::applyDelta(applied, *delta));
  EXPECT_EQ(applied.tiles, freshOnTheWire(areaB).tiles);
}

TEST_F(AreaFramesTest, APeerHoldingAnOlderSnapshotGetsItsOwnDelta) {
  // One peer was coalesced: it still holds the first weather when the
  // other already holds the second.
  const auto v1 = snapshotOf(areaA, t0);
  regions[0].centerLon_deg += 0.02;
  frames.clear(t0 + 1ms);
  const auto v2 = snapshotOf(areaA, t0 + 1ms);
  regions[0].centerLon_deg += 0.02;
  frames.clear(t0 + 2ms);
  const auto v3 = snapshotOf(areaA, t0 + 2ms);
  const auto fromV2 = frames.frame(v2, v3), fromV1 = frames.frame(v1, v3);
  EXPECT_NE(*fromV1, *fromV2);
  EXPECT_EQ(frames.counters().encoded, 2u);
  // Each takes its own holder to the newest weather.
  const auto fresh = freshOnTheWire(areaA);
  for (const auto& [held, frame] : {std::pair{v1, fromV1}, std::pair{v2, fromV2}}) {
    auto applied = std::get<weather::WeatherSnapshot>(decodeFrame(encodeWeatherFrame(nullptr, *held)));
    const auto message = decodeFrame(*frame);
    ASSERT_TRUE(std::holds_alternative<weather::WeatherDelta>(message));
    ASSERT_TRUE(weather::applyDelta(applied, std::get<weather::WeatherDelta>(message)));
    EXPECT_EQ(applied.tiles, fresh.tiles);
  }
}

TEST_F(AreaFramesTest, NothingKeptOutlivesAChangeOrTheReuseTime) {
  const auto a = snapshotOf(areaA, t0);
  const auto encoded = frames.frame(nullptr, a);
  // Within the reuse time, without a change: the same.
  EXPECT_EQ(snapshotOf(areaA, t0 + kAreaSnapshotReuse / 2), a);
  EXPECT_EQ(frames.frame(nullptr, a), encoded);
  // A change: built and encoded again, from the weather as it is now.
  global[0].coverage = 0.7;
  frames.clear(t0 + kAreaSnapshotReuse / 2);
  const auto b = snapshotOf(areaA, t0 + kAreaSnapshotReuse / 2);
  EXPECT_NE(b, a);
  EXPECT_EQ(builds, 2);
  const auto whole = std::get<weather::WeatherSnapshot>(decodeFrame(*frames.frame(nullptr, b)));
  ASSERT_FALSE(whole.layers.empty());
  EXPECT_NEAR(whole.layers[0].coverage, 0.7, 1e-6);
  // No change, but past the reuse time: built again.
  const auto c = snapshotOf(areaA, t0 + kAreaSnapshotReuse / 2 + kAreaSnapshotReuse);
  EXPECT_NE(c, b);
  EXPECT_EQ(builds, 3);
}

}  // namespace
}  // namespace sky::server
