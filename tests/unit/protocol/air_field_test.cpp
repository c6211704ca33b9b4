// The air's temperature and humidity as a field: between air tiles (the
// wind field's kernel: exact for a uniform field, no step at cell edges),
// between air levels (linear in height) and past them (the standard
// atmosphere's lapse, within kAirBeyondLevels_m), missing humidity, and air
// tiles on the stream (round trip, range and level checks, deltas of the
// changed tiles only, other levels: no delta).
#include <cmath>

#include <gtest/gtest.h>

#include "sky/stream/messages.hpp"
#include "sky/weather/air_field.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::weather {
namespace {

// A snapshot with air levels at `levels` and a tile per cell of a cap and
// level, its values from f(lat, lon, level index).
template <class F>
WeatherSnapshot airSnapshot(std::vector<float> levels, const SphericalCap& cap, int cellLevel, F f) {
  WeatherSnapshot s;
  s.airLevels_m = std::move(levels);
  s.airTileLevel = cellLevel;
  for (std::uint32_t k = 0; k < s.airLevels_m.size(); ++k)
    for (std::uint64_t cell : coverCap(cap, cellLevel, 100000)) {
      const CellCentre c = cellCentre(cell);
      const AirValues v = f(c.lat_deg, c.lon_deg, k);
      s.airTiles.push_back(quantizedAir({cell, k, float(v.temperature_c), float(v.humidity_pct)}));
    }
  return s;
}

TEST(AirFieldTest, NoTilesNoAir) {
  EXPECT_FALSE(AirField(WeatherSnapshot{}).at(46, 14, 1000));
}

TEST(AirFieldTest, UniformLevelsAreExactAndLinearInHeightBetweenThem) {
  const WeatherSnapshot s = airSnapshot({0, 1500, 5500}, {46, 14, 200000}, 8, [](double, double, std::uint32_t k) {
    const double t[] = {15.0, 5.0, -20.0}, h[] = {80.0, 60.0, 30.0};
    return AirValues{t[k], h[k]};
  });
  const AirField f(s);
  for (auto [alt, t, h] : {std::tuple{0.0, 15.0, 80.0}, {1500.0, 5.0, 60.0}, {750.0, 10.0, 70.0},
                           {3500.0, -7.5, 45.0}, {5500.0, -20.0, 30.0}}) {
    SCOPED_TRACE(alt);
    const auto a = f.at(46.3, 14.2, alt);
    ASSERT_TRUE(a);
    EXPECT_NEAR(a->temperature_c, t, 1e-4);
    EXPECT_NEAR(a->humidity_pct, h, 1e-4);
  }
}

TEST(AirFieldTest, PastTheLevelsTheStandardLapseForAWhileThenNothing) {
  const WeatherSnapshot s = airSnapshot({2, 1500}, {46, 14, 200000}, 8, [](double, double, std::uint32_t k) {
    return AirValues{k == 0 ? 20.0 : 10.0, 50.0};
  });
  const AirField f(s);
  // 1000 m above the top level: 6.5 K colder than it; 1000 m below the
  // lowest (a valley below sea level is rare; the lapse holds either way).
  const auto above = f.at(46, 14, 2500);
  ASSERT_TRUE(above);
  EXPECT_NEAR(above->temperature_c, 10.0 - 6.5, 1e-3);
  EXPECT_NEAR(above->humidity_pct, 50.0, 1e-4);
  const auto below = f.at(46, 14, -400);
  ASSERT_TRUE(below);
  EXPECT_NEAR(below->temperature_c, 20.0 + 0.402 * 6.5, 1e-3);
  EXPECT_FALSE(f.at(46, 14, 1500 + kAirBeyondLevels_m + 1));
  // Outside the tiles' reach: nothing either.
  EXPECT_FALSE(f.at(-30, 100, 1000));
}

TEST(AirFieldTest, NoStepAtCellEdgesAndAPlaneFollowedClosely) {
  // Temperature falling 1 K per 0.1 degree of longitude eastwards.
  const WeatherSnapshot s = airSnapshot({1000}, {46, 14, 150000}, 9, [](double, double lon, std::uint32_t) {
    return AirValues{20.0 - 10.0 * (lon - 14.0), 50.0};
  });
  const AirField f(s);
  double worst = 0, worstStep = 0;
  for (int i = 0; i < 400; ++i) {
    const double lon = 13.5 + i * 0.0025;
    const auto a = f.at(46.05, lon, 1000), b = f.at(46.05, lon + 1e-4, 1000);
    ASSERT_TRUE(a && b);
    worst = std::max(worst, std::abs(a->temperature_c - (20.0 - 10.0 * (lon - 14.0))));
    worstStep = std::max(worstStep, std::abs(b->temperature_c - a->temperature_c));
  }
  std::printf("[ air ] plane: worst %.3f K off, worst change over 1e-4 deg %.4f K\n", worst, worstStep);
  EXPECT_LT(worst, 0.5);      // cells of level 9 are ~0.2 degree: the kernel's smoothing of a plane
  EXPECT_LT(worstStep, 0.01);  // the plane itself changes 0.001 K over that step
}

TEST(AirFieldTest, AMissingHumidityIsNotZero) {
  WeatherSnapshot s = airSnapshot({0, 3000}, {46, 14, 100000}, 8, [](double, double, std::uint32_t k) {
    return AirValues{10.0, k == 0 ? 90.0 : double(kNoHumidity)};
  });
  const AirField f(s);
  // Within reach of the level that has one: its humidity, not 0; the
  // temperature from both levels as ever.
  const auto low = f.at(46, 14, 1000);
  ASSERT_TRUE(low);
  EXPECT_NEAR(low->humidity_pct, 90.0, 1e-4);
  EXPECT_NEAR(low->temperature_c, 10.0, 1e-4);
  // Past its reach: none (not the 90 % of 3 km below).
  const auto top = f.at(46, 14, 3000);
  ASSERT_TRUE(top);
  EXPECT_LT(top->humidity_pct, 0);
  for (AirTile& t : s.airTiles) t.humidity_pct = kNoHumidity;
  const auto none = AirField(s).at(46, 14, 1000);
  ASSERT_TRUE(none);
  EXPECT_LT(none->humidity_pct, 0);
}

TEST(AirTiles, RoundTripOnTheStreamToATenthOfADegree) {
  WeatherSnapshot s;
  s.airLevels_m = {2, 111, 5574};
  s.airTileLevel = 8;
  s.airTiles = {{cellAt(38, -97, 8), 0, 21.349f, 64.3f},
                {cellAt(38, -97, 8), 2, -99.99f, kNoHumidity},
                {cellAt(-89.9, 179.9, 8), 1, 59.96f, 100.0f}};
  const auto m = stream::decodeMessage(stream::encodeMessage(s));
  ASSERT_TRUE(m) << describe(m.error());
  const auto& back = std::get<WeatherSnapshot>(*m);
  EXPECT_EQ(back.airLevels_m, s.airLevels_m);
  EXPECT_EQ(back.airTileLevel, 8);
  ASSERT_EQ(back.airTiles.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(back.airTiles[k], quantizedAir(s.airTiles[k]));
    EXPECT_NEAR(back.airTiles[k].temperature_c, s.airTiles[k].temperature_c, 0.05 + 1e-4);
  }
  EXPECT_EQ(back.airTiles[0].humidity_pct, 64.5f);
  EXPECT_EQ(back.airTiles[1].humidity_pct, kNoHumidity);
  // Out of range: the encoder clamps (the decoder's checks are reached by
  // the fuzz corpus).
  s.airTiles = {{cellAt(38, -97, 8), 0, 85, 140}};
  const auto c = stream::decodeMessage(stream::encodeMessage(s));
  ASSERT_TRUE(c);
  EXPECT_EQ(std::get<WeatherSnapshot>(*c).airTiles[0].temperature_c, 60.0f);
  EXPECT_EQ(std::get<WeatherSnapshot>(*c).airTiles[0].humidity_pct, 100.0f);
}

TEST(AirTiles, BadTilesAndLevelsAreRefusedWithWhereAndWhat) {
  auto refused = [](const WeatherSnapshot& s, const std::string& what) {
    const auto m = stream::decodeMessage(stream::encodeMessage(s));
    ASSERT_FALSE(m) << what;
    EXPECT_NE(describe(m.error()).find(what), std::string::npos) << describe(m.error());
  };
  WeatherSnapshot s;
  s.airLevels_m = {0, 1000};
  s.airTileLevel = 8;
  s.airTiles = {{cellAt(38, -97, 9), 0, 10, 50}};
  refused(s, "Snapshot.air_tiles[0].cell_id");
  s.airTiles = {{cellAt(38, -97, 8), 2, 10, 50}};
  refused(s, "Snapshot.air_tiles[0].level 2 past the 2 air levels");
  s.airTiles.clear();
  s.airLevels_m = {0, 1000, 1000};
  refused(s, "Snapshot.air_levels_m[2]");
  s.airLevels_m = {0, std::nanf("")};
  refused(s, "Snapshot.air_levels_m[1]");
  s.airLevels_m.assign(kMaxAirLevels + 1, 0);
  for (std::size_t k = 0; k < s.airLevels_m.size(); ++k) s.airLevels_m[k] = float(k * 100);
  refused(s, "air_levels_m");
}

TEST(AirTiles, ADeltaCarriesOnlyTheChangedAirTilesAndOtherLevelsMakeASnapshot) {
  WeatherSnapshot before = airSnapshot({0, 1500}, {46, 14, 60000}, 9, [](double, double, std::uint32_t k) {
    return AirValues{k == 0 ? 12.0 : 3.0, 70.0};
  });
  ASSERT_GT(before.airTiles.size(), 4u);
  WeatherSnapshot after = before;
  after.airTiles[3].temperature_c = 13.5f;
  auto d = diffSnapshots(before, after);
  ASSERT_TRUE(d);
  ASSERT_EQ(d->airTiles.size(), 1u);
  EXPECT_EQ(d->airTiles[0], after.airTiles[3]);
  const auto m = stream::decodeMessage(stream::encodeMessage(*d));
  ASSERT_TRUE(m) << describe(m.error());
  WeatherSnapshot applied = before;
  ASSERT_TRUE(applyDelta(applied, std::get<WeatherDelta>(*m)));
  EXPECT_EQ(applied.airTiles, after.airTiles);
  // The same tiles at other heights, or a tile gone: a snapshot.
  WeatherSnapshot moved = before;
  moved.airLevels_m[1] = 1600;
  EXPECT_FALSE(diffSnapshots(before, moved));
  WeatherSnapshot fewer = before;
  fewer.airTiles.pop_back();
  EXPECT_FALSE(diffSnapshots(before, fewer));
  // A delta's air tile past the snapshot's levels is refused, the snapshot kept.
  WeatherDelta wrong;
  wrong.airTileLevel = 9;
  wrong.airTiles = {{before.airTiles[0].cellId, 5, 1, 1}};
  WeatherSnapshot kept = before;
  const auto r = applyDelta(kept, wrong);
  ASSERT_FALSE(r);
  EXPECT_NE(describe(r.error()).find("air level 5"), std::string::npos) << describe(r.error());
  EXPECT_EQ(kept.airTiles, before.airTiles);
}

// Deltas of new cells cannot grow a receiver's snapshot past what one frame
// carries: the delta that would is refused and the snapshot kept.
TEST(AirTiles, DeltasCannotGrowASnapshotWithoutEnd) {
  WeatherSnapshot s;
  s.airLevels_m = {0};
  s.airTileLevel = 20;
  // (applyDelta keys tiles by their cell id; it does not decode them)
  std::uint64_t cell = cellAt(46, 14, 20);
  for (std::size_t k = 0; k + 1 < kMaxSnapshotTiles; ++k, cell += 2) s.airTiles.push_back({cell, 0, 1, 2});
  WeatherDelta d;
  d.airTileLevel = 20;
  d.airTiles = {{cell, 0, 1, 2}};
  ASSERT_TRUE(applyDelta(s, d));  // the last tile that fits
  d.airTiles = {{cell + 2, 0, 1, 2}};
  const auto r = applyDelta(s, d);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::TooLarge);
  EXPECT_NE(describe(r.error()).find("more than 262144"), std::string::npos) << describe(r.error());
  EXPECT_EQ(s.airTiles.size(), kMaxSnapshotTiles);
}

}  // namespace
}  // namespace sky::weather
