// The wind field on the server: a forecast's winds checked at named grid
// points against grib_get_data (NAM's turned from its Lambert grid to east
// and north, checked against the projection's own geometry), which layers
// they reach, the wind tiles of a forecast's snapshot within the size budget,
// and a region's own wind blending across its perimeter, with a delta that
// carries only the wind tiles that changed.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "forecast_samples.hpp"
#include "grib_tools.hpp"
#include "sky/server/forecast.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/wind_tiles.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::server {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(ForecastWinds, NamWindsAreTurnedFromItsGridToEastAndNorth) {
  const auto fc = loadSample(kNam);
  ASSERT_FALSE(fc->wind().empty());
  EXPECT_GE(fc->wind().levelCount(), 19u);
  // u and v at 500 hPa, messages 108 and 109, along the grid's axes.
  const auto u = gribGetData(kNam, 108), v = gribGetData(kNam, 109);
  ASSERT_EQ(u.size(), v.size());
  ASSERT_GT(u.size(), 6000u);
  auto file = readGrib(readBytes(kNam), "nam", forecastWants);
  ASSERT_TRUE(file);
  GribGrid grid;
  for (const auto& f : file->fields)
    if (f.meta.shortName == "u") grid = f.meta.grid;
  ASSERT_TRUE(grid.uvRelativeToGrid);
  const double alt = weather::isaAltitude_m(500);
  int checked = 0;
  double turnWest = 0, turnEast = 0;
  for (std::size_t k : {100u, 1234u, 2500u, 3777u, 4321u, 5000u, 6000u}) {
    const Point& p = u[k];
    SCOPED_TRACE(std::to_string(p.lat) + ", " + std::to_string(p.lon));
    // Where north points on the grid, from the projection itself: a step
    // north of the point, located on the grid.
    const auto here = locate(grid, p.lat, p.lon), north = locate(grid, p.lat + 0.01, p.lon);
    ASSERT_TRUE(here && north);
    const double alpha = std::atan2(north->i - here->i, north->j - here->j);  // from +y towards +x
    // The grid's unit vectors in east/north: +y is north turned by -alpha.
    const double east = u[k].value * std::cos(alpha) - v[k].value * std::sin(alpha);
    const double northward = u[k].value * std::sin(alpha) + v[k].value * std::cos(alpha);
    const auto w = fc->wind().at(p.lat, p.lon, alt, static_cast<double>(fc->firstValid_unix()));
    ASSERT_TRUE(w);
    EXPECT_NEAR(w->east_mps, east, 0.02);
    EXPECT_NEAR(w->north_mps, northward, 0.02);
    EXPECT_NEAR(std::hypot(w->east_mps, w->north_mps), std::hypot(u[k].value, v[k].value), 0.02);
    (p.lon < grid.lov_deg ? turnWest : turnEast) = alpha / kDeg;
    ++checked;
  }
  EXPECT_EQ(checked, 7);
  std::printf("north on the NAM grid turns %.1f deg west of LoV and %.1f deg east of it\n", turnWest, turnEast);
  EXPECT_GT(std::abs(turnWest) + std::abs(turnEast), 5.0);  // the turn is not negligible here
}

TEST(ForecastWinds, GfsTenMetreWindReachesOnlyTheLowLayers) {
  const auto fc = loadSample(kGfs);
  ASSERT_FALSE(fc->wind().empty());
  const auto u = gribGetData(kGfs, 7), v = gribGetData(kGfs, 8);
  ASSERT_EQ(u.size(), v.size());
  const double valid = static_cast<double>(fc->firstValid_unix());
  const ForecastLayer& boundary = layerOf(*fc, kForecastBoundarySlot);
  const ForecastLayer& high = layerOf(*fc, kForecastHighSlot);
  for (std::size_t k : {10u, 500u, 3000u, 7000u, 9000u}) {
    SCOPED_TRACE(k);
    const auto w = fc->windAt(boundary, u[k].lat, u[k].lon, valid);
    ASSERT_TRUE(w);
    EXPECT_NEAR(w->east_mps, u[k].value, 1e-3);  // GFS's winds are east and north already
    EXPECT_NEAR(w->north_mps, v[k].value, 1e-3);
    EXPECT_FALSE(fc->windAt(high, u[k].lat, u[k].lon, valid));  // 10 m says nothing of cirrus
  }
}

TEST(WindTilesOnTheServer, ANamSnapshotCarriesItsWindFieldWithinTheBudget) {
  const auto fc = loadSample(kNam);
  const double valid = static_cast<double>(fc->firstValid_unix());
  const ForecastField field(fc, 1, valid);
  std::vector<weather::CloudLayer> table;
  for (const auto& l : fc->layers()) table.push_back(l.layer);
  ASSERT_EQ(table.size(), 3u);  // low, middle, high from humidity
  stream::Subscribe request;
  request.area = {38.0, -97.0, 300000};
  request.tileLevel = 13;
  const weather::WeatherSnapshot s = buildSnapshot(request, table, 0, kDefaultMaxCells, {}, nullptr, &field);
  const auto bytes = stream::encodeMessage(s);
  std::printf("300 km NAM snapshot: %zu cover tiles at level %d, %zu wind tiles at level %d, %zu bytes\n",
              s.tiles.size(), s.tileLevel, s.windTiles.size(), s.windTileLevel, bytes.size());
  EXPECT_LE(bytes.size(), 1u << 20);
  ASSERT_FALSE(s.windTiles.empty());
  std::map<std::uint32_t, std::size_t> perLayer;
  for (const auto& t : s.windTiles) ++perLayer[t.layerId];
  EXPECT_EQ(perLayer.size(), 3u);
  // Each tile is the forecast's wind at its cell's centre, at the middle of
  // its layer, to the wire's centimetre per second.
  for (std::size_t k = 0; k < s.windTiles.size(); k += 97) {
    const auto& t = s.windTiles[k];
    const weather::CellCentre c = weather::cellCentre(t.cellId);
    const auto w = fc->windAt(layerOf(*fc, t.layerId), c.lat_deg, c.lon_deg, field.valid_unix());
    ASSERT_TRUE(w);
    EXPECT_NEAR(t.east_mps, w->east_mps, 0.006);
    EXPECT_NEAR(t.north_mps, w->north_mps, 0.006);
  }
  // Through the tile cache (a layer's wind tiles kept with what they came
  // from): the same tiles, first derived and then reused; a later forecast
  // time (another field key) derives them again.
  TileCache cache;
  EXPECT_EQ(buildSnapshot(request, table, 0, kDefaultMaxCells, {}, &cache, &field).windTiles, s.windTiles);
  EXPECT_EQ(buildSnapshot(request, table, 0, kDefaultMaxCells, {}, &cache, &field).windTiles, s.windTiles);
  const ForecastField later(fc, 1, valid + 3 * 3600);
  EXPECT_EQ(buildSnapshot(request, table, 0, kDefaultMaxCells, {}, &cache, &later).windTiles,
            buildSnapshot(request, table, 0, kDefaultMaxCells, {}, nullptr, &later).windTiles);
  // The wind varies: the high layer's tiles span more than 5 m/s here.
  double lo = 1e9, hi = -1e9;
  for (const auto& t : s.windTiles)
    if (t.layerId == kForecastHighSlot) {
      lo = std::min<double>(lo, t.east_mps);
      hi = std::max<double>(hi, t.east_mps);
    }
  EXPECT_GT(hi - lo, 5.0);
  // The point query answers the forecast's wind (smoothed between tiles).
  const weather::CloudLayer& mid = table[1];
  const auto pw = weather::weatherAt(s.layers, nullptr, 38.0, -97.0, mid.base_m + mid.thickness_m / 2,
                                     weather::snapshotWindLookup(s));
  const auto want = fc->windAt(layerOf(*fc, mid.id), 38.0, -97.0, field.valid_unix());
  ASSERT_TRUE(want);
  EXPECT_NEAR(pw.wind.speed_mps, std::hypot(want->east_mps, want->north_mps), 1.5);
}

TEST(WindTilesOnTheServer, ARegionsOwnWindBlendsAndADeltaCarriesWhatMoved) {
  weather::CloudLayer cu;
  cu.id = 1;
  cu.base_m = 1500;
  cu.thickness_m = 1500;
  cu.coverage = 0.4;
  cu.wind = {10, 270, 0};  // east 10 m/s
  weather::Region r;
  r.id = 5;
  r.centerLat_deg = 46;
  r.centerLon_deg = 14;
  r.sizeX_m = r.sizeY_m = 40000;
  r.transition_m = 30000;
  weather::CloudLayer own = cu;
  own.wind = {20, 0, 0};  // from the north: south 20 m/s
  r.layers = {own};
  stream::Subscribe request;
  request.area = {46, 14, 150000};
  request.tileLevel = 11;
  TileCache cache;
  const auto before = buildSnapshotWithGenerations(request, std::span(&cu, 1), 0, kDefaultMaxCells,
                                                   std::span(&r, 1), &cache);
  const weather::WeatherSnapshot& s = before.snapshot;
  ASSERT_FALSE(s.windTiles.empty());
  const weather::WindField field(s);
  const auto at = [&](double lat, double lon) { return field.at(cu, lat, lon); };
  EXPECT_NEAR(at(46, 14).north_mps, -20, 0.05);  // inside: the region's
  EXPECT_NEAR(at(46, 14).east_mps, 0, 0.05);
  EXPECT_NEAR(at(46, 15.6).east_mps, 10, 0.05);  // ~124 km east, past the perimeter: the layer's
  const double halfway = at(46, 14 + 35000 / (111320 * std::cos(46 * kDeg))).north_mps;  // mid-perimeter
  EXPECT_LT(halfway, -3);
  EXPECT_GT(halfway, -17);
  // The region moves 20 km north: only the wind tiles near it change.
  weather::Region moved = r;
  moved.centerLat_deg += 20000 / 111200.0;
  const auto after = buildSnapshotWithGenerations(request, std::span(&cu, 1), 60, kDefaultMaxCells,
                                                  std::span(&moved, 1), &cache);
  const auto delta = diffBuilt(before, after);
  ASSERT_TRUE(delta);
  std::printf("wind tiles: %zu in the area, %zu in the delta of a 20 km move\n", after.snapshot.windTiles.size(),
              delta->windTiles.size());
  EXPECT_GT(delta->windTiles.size(), 0u);
  EXPECT_LT(delta->windTiles.size(), after.snapshot.windTiles.size() / 2);
  weather::WeatherSnapshot applied = wholeSnapshot(before);
  ASSERT_TRUE(weather::applyDelta(applied, *delta));
  EXPECT_EQ(applied.windTiles, after.snapshot.windTiles);
  // Uniform weather has no wind tiles at all.
  const auto calm = buildSnapshot(request, std::span(&cu, 1), 0, kDefaultMaxCells);
  EXPECT_TRUE(calm.windTiles.empty());
  EXPECT_EQ(calm.windTileLevel, 0);
}

}  // namespace
}  // namespace sky::server
