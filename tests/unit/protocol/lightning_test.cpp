// Lightning: the flash process's statistics and determinism, a flash's
// light against its energy, the bolt's shape, storm cells from a snapshot,
// and the stream message.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "sky/stream/messages.hpp"
#include "sky/weather/lightning.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::weather {
namespace {

constexpr int kLevel = 10;

StormCell cellAtPoint(double lat, double lon, double perSecond) {
  return {cellAt(lat, lon, kLevel), perSecond, 1200, 11200};
}

TEST(Lightning, FlashesDoNotDependOnHowTheClockIsCut) {
  const StormCell cells[] = {cellAtPoint(46.0, 13.0, 0.3), cellAtPoint(-33.9, 151.2, 0.2)};
  const auto whole = drawFlashes(7, cells, 100.0, 400.0, 10000);
  std::vector<LightningFlash> pieces;
  for (double t = 100.0; t < 400.0; t += 0.37) {
    const auto part = drawFlashes(7, cells, t, std::min(400.0, t + 0.37), 10000);
    pieces.insert(pieces.end(), part.begin(), part.end());
  }
  ASSERT_GT(whole.size(), 50u);
  EXPECT_EQ(pieces, whole) << "a server's heartbeat ticks cut the clock differently on every run";
  EXPECT_EQ(drawFlashes(7, cells, 100.0, 400.0, 10000), whole) << "seeded: the same flashes again";
  EXPECT_NE(drawFlashes(8, cells, 100.0, 400.0, 10000), whole) << "another seed, other flashes";
  for (const auto& f : whole) {
    EXPECT_GT(f.time_s, 100.0);
    EXPECT_LE(f.time_s, 400.0);
    EXPECT_TRUE(validate(f)) << validate(f).error().detail;
  }
}

TEST(Lightning, ThePoissonProcessKeepsItsRateAndShares) {
  // 1.5 flashes a second over 600 s: 900 expected, standard deviation 30;
  // a quarter to the ground (sd 13). Bounds at about 3.5 sd.
  const StormCell cells[] = {cellAtPoint(10.0, -60.0, 1.5)};
  const auto flashes = drawFlashes(99, cells, 0.0, 600.0, 10000);
  EXPECT_NEAR(static_cast<double>(flashes.size()), 900.0, 105.0);
  const auto ground = std::count_if(flashes.begin(), flashes.end(),
                                    [](const auto& f) { return f.kind == FlashKind::CloudToGround; });
  EXPECT_NEAR(static_cast<double>(ground), 0.25 * static_cast<double>(flashes.size()), 50.0);
  // Energies: log-normal round 1 GJ (ground) and half that (in cloud): the
  // median of the ground flashes within 20 %.
  std::vector<double> e;
  for (const auto& f : flashes)
    if (f.kind == FlashKind::CloudToGround) e.push_back(f.energy_j);
  std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2), e.end());
  EXPECT_NEAR(e[e.size() / 2], kTypicalFlashEnergy_j, 0.2 * kTypicalFlashEnergy_j);
  for (const auto& f : flashes) {
    EXPECT_EQ(cellAt(f.lat_deg, f.lon_deg, kLevel), cells[0].cellId) << "a flash falls in its own cell";
    if (f.kind == FlashKind::CloudToGround) {
      EXPECT_EQ(f.bottom_m, 0.0);
      EXPECT_EQ(f.top_m, 1200.0) << "a bolt leaves its cloud's base";
    } else {
      EXPECT_GT(f.bottom_m, 1200.0);
      EXPECT_LT(f.top_m, 11200.0) << "an in-cloud flash stays inside the cloud";
    }
  }
}

TEST(Lightning, AClockThatJumpsDrawsABoundedNumber) {
  const StormCell cells[] = {cellAtPoint(0.0, 0.0, 20.0)};
  std::size_t dropped = 0;
  const auto flashes = drawFlashes(1, cells, 0.0, 1.0e7, 500, &dropped);
  EXPECT_EQ(flashes.size(), 500u);
  EXPECT_GT(dropped, 0u) << "what the cap leaves out is counted";
  EXPECT_TRUE(drawFlashes(1, cells, 5.0, 5.0, 500).empty());
  EXPECT_TRUE(drawFlashes(1, cells, std::nan(""), 5.0, 500).empty());
}

TEST(Lightning, AFlashRadiatesItsOpticalEnergy) {
  LightningFlash f;
  f.seed = 1234;
  f.time_s = 50.0;
  f.kind = FlashKind::CloudToGround;
  f.energy_j = 2.0e9;
  // Over its whole life the mean power times the time is the optical energy
  // (1 % of 2 GJ = 20 MJ), to the tail past ten decays (e^-10).
  const double whole = flashPower_w(f, 49.0, 49.0 + 1.0 + kFlashLifetime_s) * (1.0 + kFlashLifetime_s);
  EXPECT_NEAR(whole, 2.0e7, 2.0e7 * 1e-4);
  EXPECT_EQ(flashPower_w(f, 40.0, 49.99), 0.0) << "no light before the first stroke";
  EXPECT_EQ(flashPower_w(f, 50.0 + kFlashLifetime_s + 0.01, 60.0), 0.0);
  // Energies add over adjacent intervals.
  const double a = flashPower_w(f, 49.9, 50.02) * 0.12, b = flashPower_w(f, 50.02, 50.4) * 0.38;
  EXPECT_NEAR(a + b, flashPower_w(f, 49.9, 50.4) * 0.5, 1e-6 * (a + b));
  // The first stroke is at the flash's time: a 1/60 s frame just after it
  // sees most of the light a stroke of its weight gives.
  EXPECT_GT(flashPower_w(f, 50.0, 50.0 + 1.0 / 60.0), 5.0e7);
}

TEST(Lightning, ABoltRunsFromItsCloudToTheGround) {
  LightningFlash f;
  f.seed = 42;
  f.kind = FlashKind::CloudToGround;
  f.bottom_m = 0;
  f.top_m = 1500;
  f.energy_j = 1e9;
  const auto bolt = boltSegments(f);
  ASSERT_FALSE(bolt.empty());
  ASSERT_LE(bolt.size(), kMaxBoltSegments);
  EXPECT_EQ(boltSegments(f).size(), bolt.size());
  EXPECT_EQ(boltSegments(f)[7].b[0], bolt[7].b[0]) << "a function of the flash alone";
  // The main channel: a connected line from the cloud base to the ground point.
  std::size_t main = 0;
  while (main < bolt.size() && bolt[main].weight == 1.0) ++main;
  ASSERT_GE(main, 16u);
  EXPECT_EQ(bolt[0].a[2], 1500.0);
  EXPECT_LE(std::hypot(bolt[0].a[0], bolt[0].a[1]), 0.4 * 1500.0) << "leaves the cloud at most 0.4 of its drop aside";
  EXPECT_EQ(bolt[main - 1].b[0], 0.0);
  EXPECT_EQ(bolt[main - 1].b[1], 0.0);
  EXPECT_EQ(bolt[main - 1].b[2], 0.0);
  for (std::size_t i = 1; i < main; ++i) EXPECT_EQ(bolt[i].a[2], bolt[i - 1].b[2]);
  double length = 0;
  for (std::size_t i = 0; i < main; ++i)
    length += std::hypot(bolt[i].b[0] - bolt[i].a[0], bolt[i].b[1] - bolt[i].a[1], bolt[i].b[2] - bolt[i].a[2]);
  EXPECT_GT(length, 1500.0 * 1.1) << "tortuous: longer than the straight drop";
  for (std::size_t i = main; i < bolt.size(); ++i) {
    EXPECT_LT(bolt[i].weight, 1.0);
    EXPECT_GE(bolt[i].b[2], 0.0) << "branches stop at the ground";
  }
  f.seed = 43;
  EXPECT_NE(boltSegments(f)[3].b[0], bolt[3].b[0]);
  f.kind = FlashKind::InCloud;
  EXPECT_TRUE(boltSegments(f).empty());
}

TEST(Lightning, StormCellsAreWhereTheCumulonimbusIs) {
  WeatherSnapshot s;
  s.tileLevel = kLevel;
  CloudLayer cb;
  cb.id = 1;
  cb.type = CloudType::Cumulonimbus;
  cb.base_m = 900;
  cb.thickness_m = 9000;
  CloudLayer cu = cb;
  cu.id = 2;
  cu.type = CloudType::Cumulus;
  cu.base_m = 1500;
  cu.thickness_m = 2000;
  s.layers = {cb, cu};
  const std::uint64_t a = cellAt(45.0, 9.0, kLevel), b = cellAt(45.2, 9.3, kLevel), c = cellAt(45.4, 9.6, kLevel);
  s.tiles = {{a, 1, 0.5f, 1.0f, CloudType::None, 0.0f},
             {b, 2, 0.8f, 0.5f, CloudType::Cumulonimbus, 0.5f},
             {c, 2, 1.0f, 1.0f, CloudType::None, 0.0f}};
  const std::uint64_t area[] = {a, b, c};
  const auto cells = stormCells(s, area, 2.0);
  ASSERT_EQ(cells.size(), 2u) << "plain cumulus does not flash";
  for (const StormCell& sc : cells) {
    const double km2 = cellArea_m2(sc.cellId) / 1e6;
    if (sc.cellId == a) {
      EXPECT_NEAR(sc.flashesPerSecond, 0.5 * km2 / 100.0 * 2.0 / 60.0, 1e-12);
      EXPECT_EQ(sc.base_m, 900.0);
      EXPECT_EQ(sc.top_m, 9900.0);
    } else {
      EXPECT_EQ(sc.cellId, b);
      // Cumulus blended half into cumulonimbus, 0.8 cover at density 0.5.
      EXPECT_NEAR(sc.flashesPerSecond, 0.8 * 0.5 * 0.5 * km2 / 100.0 * 2.0 / 60.0, 1e-9) << "the tile holds 0.8 as a float";
    }
  }
  EXPECT_TRUE(stormCells(s, area, 0.0).empty()) << "a rate of 0 turns lightning off";
  // A layer without tiles is the same over the whole area (the stream sends
  // none for it): every cell of the area flashes at its coverage.
  s.tiles.clear();
  s.layers[0].coverage = 0.25;
  const auto uniform = stormCells(s, area, 2.0);
  ASSERT_EQ(uniform.size(), 3u);
  for (const StormCell& sc : uniform)
    EXPECT_NEAR(sc.flashesPerSecond, 0.25 * cellArea_m2(sc.cellId) / 1e8 * 2.0 / 60.0, 1e-12);
}

TEST(Lightning, AnAskedForFlashSitsUnderItsCloud) {
  CloudLayer cb;
  cb.type = CloudType::Cumulonimbus;
  cb.base_m = 800;
  cb.thickness_m = 8000;
  CloudLayer ci = cb;
  ci.type = CloudType::Cirrus;
  ci.base_m = 300;  // lower, but not the storm
  const CloudLayer layers[] = {ci, cb};
  const LightningFlash g = triggeredFlash(1, 10.0, 45.0, 7.0, FlashKind::CloudToGround, layers);
  EXPECT_EQ(g.bottom_m, 0.0);
  EXPECT_EQ(g.top_m, 800.0);
  const LightningFlash ic = triggeredFlash(2, 10.0, 45.0, 7.0, FlashKind::InCloud, layers);
  EXPECT_NEAR(ic.bottom_m, 800 + 0.35 * 8000, 1e-9);
  EXPECT_NEAR(ic.top_m, 800 + 0.85 * 8000, 1e-9);
  EXPECT_NE(g.seed, ic.seed);
  EXPECT_TRUE(validate(g));
  EXPECT_EQ(flashKindFromString(toString(FlashKind::InCloud)), FlashKind::InCloud);
  EXPECT_EQ(flashKindFromString("sheet"), std::nullopt);
}

}  // namespace
}  // namespace sky::weather

namespace sky::stream {
namespace {

weather::LightningFlash sampleFlash() {
  weather::LightningFlash f;
  f.seed = 0xfeedfacecafebeefull;
  f.time_s = 43200.125;
  f.lat_deg = -45.5;
  f.lon_deg = 179.75;
  f.bottom_m = 0;
  f.top_m = 1250;
  f.kind = weather::FlashKind::CloudToGround;
  f.energy_j = 1.5e9;
  return f;
}

TEST(LightningMessages, RoundTrip) {
  Lightning l{43200.5, {sampleFlash(), sampleFlash()}, std::nullopt};
  l.flashes[1].kind = weather::FlashKind::InCloud;
  l.flashes[1].bottom_m = 3000;
  l.flashes[1].top_m = 7000.5;
  auto m = decodeMessage(encodeMessage(l));
  ASSERT_TRUE(m) << m.error().detail;
  const auto& got = std::get<Lightning>(*m);
  EXPECT_EQ(got.weatherClock_s, 43200.5);
  EXPECT_EQ(got.flashes, l.flashes) << "every field travels exactly (heights are floats that hold these values)";
  EXPECT_STREQ(kindName(*m), "Lightning");
  EXPECT_FALSE(got.answersTo_s) << "flashes of the running clock answer no request";
  // An answer carries the end of the interval asked for.
  l.answersTo_s = 3630.25;
  auto answer = decodeMessage(encodeMessage(l));
  ASSERT_TRUE(answer) << answer.error().detail;
  EXPECT_EQ(std::get<Lightning>(*answer).answersTo_s, 3630.25);
}

// A renderer's request for an interval's flashes: exact both ways; an
// interval that is empty, runs backwards, is longer than 600 s or is not
// finite is refused, naming the field.
TEST(LightningMessages, ARequestForAnIntervalIsChecked) {
  auto m = decodeMessage(encodeMessage(LightningRequest{3600.5, 3630.25}));
  ASSERT_TRUE(m) << m.error().detail;
  EXPECT_EQ(std::get<LightningRequest>(*m).from_s, 3600.5);
  EXPECT_EQ(std::get<LightningRequest>(*m).to_s, 3630.25);
  EXPECT_STREQ(kindName(*m), "LightningRequest");
  const std::pair<LightningRequest, const char*> bad[] = {
      {{10, 10}, "to_s"},           {{10, 5}, "to_s"},      {{0, 600.5}, "to_s"},
      {{std::nan(""), 1}, "from_s"}, {{0, INFINITY}, "to_s"}, {{-2e12, 0}, "from_s"}};
  for (const auto& [r, field] : bad) {
    auto e = decodeMessage(encodeMessage(r));
    ASSERT_FALSE(e) << r.from_s << " " << r.to_s;
    EXPECT_NE(e.error().detail.find(std::string("LightningRequest.") + field), std::string::npos) << e.error().detail;
  }
  EXPECT_TRUE(decodeMessage(encodeMessage(LightningRequest{0, 600})));
}

TEST(LightningMessages, EveryFieldIsRangeChecked) {
  struct Case {
    const char* field;
    void (*spoil)(weather::LightningFlash&);
  };
  const Case cases[] = {
      {"time_s", [](weather::LightningFlash& f) { f.time_s = INFINITY; }},
      {"lat_deg", [](weather::LightningFlash& f) { f.lat_deg = 91; }},
      {"lon_deg", [](weather::LightningFlash& f) { f.lon_deg = std::nan(""); }},
      {"bottom_m", [](weather::LightningFlash& f) { f.bottom_m = -600; }},
      {"top_m", [](weather::LightningFlash& f) { f.top_m = -1; }},
      {"energy_j", [](weather::LightningFlash& f) { f.energy_j = 0; }},
      {"energy_j", [](weather::LightningFlash& f) { f.energy_j = 1e12; }},
      {"kind", [](weather::LightningFlash& f) { f.kind = static_cast<weather::FlashKind>(2); }},
  };
  for (const Case& c : cases) {
    Lightning l{1.0, {sampleFlash(), sampleFlash()}, std::nullopt};
    c.spoil(l.flashes[1]);
    auto m = decodeMessage(encodeMessage(l));
    ASSERT_FALSE(m) << c.field;
    EXPECT_NE(m.error().detail.find("flashes[1]"), std::string::npos) << m.error().detail;
    EXPECT_NE(m.error().detail.find(c.field), std::string::npos) << m.error().detail;
  }
  Lightning many{1.0, std::vector<weather::LightningFlash>(kMaxMessageFlashes + 1, sampleFlash()), std::nullopt};
  auto m = decodeMessage(encodeMessage(many));
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error().code, ErrorCode::TooLarge);
}

}  // namespace
}  // namespace sky::stream
