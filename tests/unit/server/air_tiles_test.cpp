// A forecast's air on the server: temperature and relative humidity read at
// named NAM grid points against grib_get_data (500 and 850 hPa, 2 m), the
// air tiles of a NAM snapshot within the size budget and through the tile
// cache, the point query's temperature between the levels, and GFS's sample
// (no temperature) giving none.
#include <gtest/gtest.h>

#include <cmath>

#include "forecast_samples.hpp"
#include "grib_tools.hpp"
#include "sky/server/air_tiles.hpp"
#include "sky/server/forecast.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/air_field.hpp"
#include "sky/weather/query.hpp"

namespace sky::server {
namespace {

std::size_t levelAt(const ForecastAir& air, double alt_m) {
  for (std::size_t k = 0; k < air.levels_m().size(); ++k)
    if (std::abs(air.levels_m()[k] - alt_m) < 1e-6) return k;
  ADD_FAILURE() << "no air level at " << alt_m << " m";
  return 0;
}

TEST(ForecastAirTest, NamTemperatureAndHumidityAtNamedGridPoints) {
  const auto fc = loadSample(kNam);
  const ForecastAir& air = fc->air();
  ASSERT_FALSE(air.empty());
  EXPECT_EQ(air.levels_m().size(), 20u);  // 19 pressure levels, 100 to 1000 hPa, and 2 m
  EXPECT_EQ(air.levels_m().front(), 2.0);
  const double valid = static_cast<double>(fc->firstValid_unix());
  // Message numbers of the sample (grib_ls -p count,shortName,level): t and
  // r at 500 hPa 106, 107; at 850 hPa 141, 142; 2 m temperature 10, 2 m
  // relative humidity 11.
  struct Level {
    const char* what;
    double alt_m;
    std::size_t t, r;
  };
  for (const Level& l : {Level{"500 hPa", weather::isaAltitude_m(500), 106, 107},
                         Level{"850 hPa", weather::isaAltitude_m(850), 141, 142}, Level{"2 m", 2, 10, 11}}) {
    SCOPED_TRACE(l.what);
    const auto t = gribGetData(kNam, l.t), r = gribGetData(kNam, l.r);
    ASSERT_EQ(t.size(), r.size());
    ASSERT_GT(t.size(), 6000u);
    const std::size_t level = levelAt(air, l.alt_m);
    for (std::size_t k : {100u, 1234u, 2500u, 3777u, 5000u, 6000u}) {
      SCOPED_TRACE(k);
      const auto a = air.at(level, t[k].lat, t[k].lon, valid);
      ASSERT_TRUE(a);
      EXPECT_NEAR(a->temperature_c, t[k].value - 273.15, 0.01);
      EXPECT_NEAR(a->humidity_pct, std::clamp(r[k].value, 0.0, 100.0), 0.01);
    }
  }
}

TEST(ForecastAirTest, GfsSampleHasNoTemperatureSoNoAirTiles) {
  const auto fc = loadSample(kGfs);
  EXPECT_TRUE(fc->air().empty());
  const ForecastField field(fc, 1, static_cast<double>(fc->firstValid_unix()));
  EXPECT_TRUE(deriveAirTiles({46.2, 12.8, 100000}, &field).tiles.empty());
}

TEST(AirTilesOnTheServer, ANamSnapshotCarriesTheForecastsAirWithinTheBudget) {
  const auto fc = loadSample(kNam);
  const double valid = static_cast<double>(fc->firstValid_unix());
  const ForecastField field(fc, 1, valid);
  std::vector<weather::CloudLayer> table;
  for (const auto& l : fc->layers()) table.push_back(l.layer);
  stream::Subscribe request;
  request.area = {38.0, -97.0, 300000};
  request.tileLevel = 13;
  const weather::WeatherSnapshot s = buildSnapshot(request, table, 0, kDefaultMaxCells, {}, nullptr, &field);
  const auto bytes = stream::encodeMessage(s);
  std::printf("300 km NAM snapshot: %zu cover tiles at level %d, %zu wind tiles at level %d, %zu air tiles at level "
              "%d on %zu heights, %zu bytes\n",
              s.tiles.size(), s.tileLevel, s.windTiles.size(), s.windTileLevel, s.airTiles.size(), s.airTileLevel,
              s.airLevels_m.size(), bytes.size());
  EXPECT_LE(bytes.size(), 1u << 20);
  ASSERT_EQ(s.airLevels_m.size(), 20u);
  ASSERT_FALSE(s.airTiles.empty());
  // Each tile is the forecast's air at its cell's centre, to the wire's
  // 0.1 C and 0.5 %.
  for (std::size_t k = 0; k < s.airTiles.size(); k += 53) {
    const auto& t = s.airTiles[k];
    const weather::CellCentre c = weather::cellCentre(t.cellId);
    const auto a = fc->air().at(t.level, c.lat_deg, c.lon_deg, field.valid_unix());
    ASSERT_TRUE(a);
    EXPECT_NEAR(t.temperature_c, a->temperature_c, 0.05 + 1e-4);
    EXPECT_NEAR(t.humidity_pct, a->humidity_pct, 0.25 + 1e-4);
  }
  // Through the tile cache: the same tiles, first derived, then kept; a
  // later forecast time (another field key) derives them again.
  TileCache cache;
  EXPECT_EQ(buildSnapshot(request, table, 0, kDefaultMaxCells, {}, &cache, &field).airTiles, s.airTiles);
  EXPECT_EQ(buildSnapshot(request, table, 0, kDefaultMaxCells, {}, &cache, &field).airTiles, s.airTiles);
  const ForecastField later(fc, 1, valid + 3 * 3600);
  EXPECT_EQ(buildSnapshot(request, table, 0, kDefaultMaxCells, {}, &cache, &later).airTiles,
            buildSnapshot(request, table, 0, kDefaultMaxCells, {}, nullptr, &later).airTiles);
  // The point query between two levels: within the kernel's smoothing of
  // the forecast's own value at each of them, linear between.
  const weather::AirField f(s);
  const double a700 = weather::isaAltitude_m(700), a750 = weather::isaAltitude_m(750);
  const auto t700 = fc->air().at(levelAt(fc->air(), a700), 38.0, -97.0, field.valid_unix());
  const auto t750 = fc->air().at(levelAt(fc->air(), a750), 38.0, -97.0, field.valid_unix());
  ASSERT_TRUE(t700 && t750);
  const auto mid = f.at(38.0, -97.0, (a700 + a750) / 2);
  ASSERT_TRUE(mid);
  std::printf("38 N 97 W between 750 and 700 hPa: forecast %.2f C and %.2f C, field %.2f C\n", t750->temperature_c,
              t700->temperature_c, mid->temperature_c);
  EXPECT_NEAR(mid->temperature_c, (t700->temperature_c + t750->temperature_c) / 2, 0.5);
  // The air varies over the area: 2 m temperatures span more than 3 K.
  double lo = 1e9, hi = -1e9;
  for (const auto& t : s.airTiles)
    if (t.level == 0) {
      lo = std::min<double>(lo, t.temperature_c);
      hi = std::max<double>(hi, t.temperature_c);
    }
  EXPECT_GT(hi - lo, 3.0);
}

// Three hours of forecast time later the air has moved on: the delta the
// server sends a subscriber carries the air tiles that changed on the wire,
// and applied to the old snapshot gives the new one's air exactly.
TEST(AirTilesOnTheServer, ADeltaCarriesTheAirThatChanged) {
  const auto fc = loadSample(kNam);
  const double valid = static_cast<double>(fc->firstValid_unix());
  std::vector<weather::CloudLayer> table;
  for (const auto& l : fc->layers()) table.push_back(l.layer);
  stream::Subscribe request;
  request.area = {38.0, -97.0, 100000};
  request.tileLevel = 12;
  TileCache cache;
  // NAM's sample is one step, so its air is the same at every valid time:
  // the same snapshot with one level 2 K warmer stands for the next step.
  const ForecastField now(fc, 1, valid);
  const BuiltSnapshot before = buildSnapshotWithGenerations(request, table, 0, kDefaultMaxCells, {}, &cache, &now);
  ASSERT_FALSE(before.snapshot.airTiles.empty());
  BuiltSnapshot after = before;
  std::size_t warmed = 0;
  for (auto& t : after.snapshot.airTiles)
    if (t.level == 5) {
      t = weather::quantizedAir({t.cellId, t.level, t.temperature_c + 2.0f, t.humidity_pct});
      ++warmed;
    }
  ASSERT_GT(warmed, 0u);
  const auto d = diffBuilt(before, after);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->airTiles.size(), warmed);
  EXPECT_TRUE(d->tiles.empty());
  const auto m = stream::decodeMessage(stream::encodeMessage(*d));
  ASSERT_TRUE(m) << describe(m.error());
  weather::WeatherSnapshot applied = wholeSnapshot(before);
  ASSERT_TRUE(weather::applyDelta(applied, std::get<weather::WeatherDelta>(*m)));
  EXPECT_EQ(applied.airTiles, after.snapshot.airTiles);
  // Nothing changed: no air tile in the delta.
  const auto same = diffBuilt(before, before);
  ASSERT_TRUE(same);
  EXPECT_TRUE(same->airTiles.empty());
}

// A field whose levels the wire cannot carry as they are (two heights a
// float apart, one past the decoder's range): those are left out, and the
// snapshot still decodes for every subscriber.
class AwkwardLevels final : public LayerField {
 public:
  bool gives(std::uint32_t) const override { return false; }
  void sample(std::uint32_t, std::span<const weather::CellCentre>, std::span<weather::CoverageTile>) const override {}
  std::uint64_t key() const override { return 7; }
  std::vector<double> airLevels() const override { return {0.0, 1000.0, 1000.00001, 2.0e5}; }
  void sampleAir(std::size_t level, std::span<const weather::CellCentre> at,
                 std::span<weather::AirValues> out) const override {
    for (std::size_t k = 0; k < at.size(); ++k) out[k] = {15.0 - 6.5 * static_cast<double>(level), 50.0};
  }
};

TEST(AirTilesOnTheServer, LevelsTheWireCannotCarryAreLeftOut) {
  const AwkwardLevels field;
  const AirTiles air = deriveAirTiles({38.0, -97.0, 50000}, &field);
  EXPECT_EQ(air.levels_m, (std::vector<float>{0.0f, 1000.0f}));
  weather::WeatherSnapshot s;
  s.airLevels_m = air.levels_m;
  s.airTileLevel = air.level;
  s.airTiles = air.tiles;
  const auto m = stream::decodeMessage(stream::encodeMessage(s));
  ASSERT_TRUE(m) << describe(m.error());
  const auto a = weather::AirField(std::get<weather::WeatherSnapshot>(*m)).at(38.0, -97.0, 500);
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->temperature_c, 15.0 - 3.25, 1e-3);
}

}  // namespace
}  // namespace sky::server
