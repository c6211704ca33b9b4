// Snapshot tiling, checked against S2 directly: every point of the cap lies in
// a tile, every tile touches the cap, the level is lowered only when the cell
// budget demands it, and tiles carry their layer's coverage and density.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

#include <s2/s1angle.h>
#include <s2/s2cap.h>
#include <s2/s2cell.h>
#include <s2/s2cell_id.h>
#include <s2/s2latlng.h>

#include "sky/server/snapshot_builder.hpp"
#include "sky/stream/framing.hpp"
#include "sky/stream/messages.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/region.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {
namespace {

// The sphere tiling.hpp measures caps on (IUGG mean Earth radius).
constexpr double kRadius_m = 6371008.8;

S2Cap s2Cap(const weather::SphericalCap& cap) {
  return S2Cap(S2LatLng::FromDegrees(cap.centerLat_deg, cap.centerLon_deg).Normalized().ToPoint(),
               S1Angle::Radians(cap.radius_m / kRadius_m));
}

// The point `fraction` of the cap's radius from its centre along `bearing_rad`
// (great-circle destination formula, written out here independently of S2).
S2LatLng pointInCap(const weather::SphericalCap& cap, double fraction, double bearing_rad) {
  const double lat1 = cap.centerLat_deg * std::numbers::pi / 180;
  const double lon1 = cap.centerLon_deg * std::numbers::pi / 180;
  const double d = fraction * cap.radius_m / kRadius_m;
  const double lat2 =
      std::asin(std::sin(lat1) * std::cos(d) + std::cos(lat1) * std::sin(d) * std::cos(bearing_rad));
  const double lon2 = lon1 + std::atan2(std::sin(bearing_rad) * std::sin(d) * std::cos(lat1),
                                        std::cos(d) - std::sin(lat1) * std::sin(lat2));
  return S2LatLng::FromRadians(lat2, lon2).Normalized();
}

// Checks that `cells` are valid, distinct, all at `level`, each touching the
// cap, and that sample points across the cap (centre to rim) all fall in one.
void expectCovers(const weather::SphericalCap& cap, int level,
                  const std::vector<std::uint64_t>& cells) {
  ASSERT_FALSE(cells.empty());
  const std::set<std::uint64_t> set(cells.begin(), cells.end());
  EXPECT_EQ(set.size(), cells.size()) << "duplicate cells";
  const S2Cap region = s2Cap(cap);
  for (const std::uint64_t id : cells) {
    const S2CellId cell(id);
    ASSERT_TRUE(cell.is_valid());
    EXPECT_EQ(cell.level(), level);
    EXPECT_TRUE(region.MayIntersect(S2Cell(cell))) << cell.ToString() << " misses the cap";
  }
  constexpr int kBearings = 72;
  for (const double fraction : {0.0, 0.25, 0.5, 0.75, 0.999}) {
    for (int i = 0; i < kBearings; ++i) {
      const S2LatLng p = pointInCap(cap, fraction, 2 * std::numbers::pi * i / kBearings);
      const S2CellId cell = S2CellId(p).parent(level);
      EXPECT_TRUE(set.count(cell.id()))
          << "point " << p.ToStringInDegrees() << " (" << fraction << " of radius) not covered";
    }
  }
}

weather::CloudLayer layer(std::uint32_t id, double coverage, double density) {
  weather::CloudLayer l;
  l.id = id;
  l.base_m = 1500;
  l.thickness_m = 1500;
  l.coverage = coverage;
  l.density = density;
  return l;
}

stream::Subscribe request(double lat_deg, double lon_deg, double radius_m, int level) {
  stream::Subscribe s;
  s.area = {lat_deg, lon_deg, radius_m};
  s.tileLevel = level;
  return s;
}

TEST(CoverArea, MidLatitudeCapAtWantedLevel) {
  const weather::SphericalCap cap{47.4, 8.5, 30'000};
  const Covering c = coverArea(cap, 10, kDefaultMaxCells);
  EXPECT_EQ(c.level, 10);
  expectCovers(cap, c.level, c.cells);
}

TEST(CoverArea, CapAtTheNorthPole) {
  const weather::SphericalCap cap{90.0, 0.0, 100'000};
  const Covering c = coverArea(cap, 9, kDefaultMaxCells);
  EXPECT_EQ(c.level, 9);
  expectCovers(cap, c.level, c.cells);
  // Every longitude meets the pole: cell centres fall in all four quadrants.
  std::set<int> quadrants;
  for (const std::uint64_t id : c.cells)
    quadrants.insert(static_cast<int>(std::floor((S2CellId(id).ToLatLng().lng().degrees() + 180) / 90)));
  EXPECT_EQ(quadrants.size(), 4u);
}

TEST(CoverArea, CapAcrossTheAntimeridian) {
  const weather::SphericalCap cap{-15.0, 179.8, 80'000};
  const Covering c = coverArea(cap, 10, kDefaultMaxCells);
  EXPECT_EQ(c.level, 10);
  expectCovers(cap, c.level, c.cells);
  bool east = false, west = false;
  for (const std::uint64_t id : c.cells) {
    const double lon_deg = S2CellId(id).ToLatLng().lng().degrees();
    east = east || lon_deg > 0;
    west = west || lon_deg < 0;
  }
  EXPECT_TRUE(east && west) << "the covering should straddle +-180";
}

TEST(CoverArea, UnnormalisedLongitudeGivesTheSameCells) {
  const Covering a = coverArea({10.0, -179.9, 20'000}, 11, kDefaultMaxCells);
  const Covering b = coverArea({10.0, 180.1, 20'000}, 11, kDefaultMaxCells);
  EXPECT_EQ(std::set<std::uint64_t>(a.cells.begin(), a.cells.end()),
            std::set<std::uint64_t>(b.cells.begin(), b.cells.end()));
}

TEST(CoverArea, LowersTheLevelWhenTooManyCells) {
  const weather::SphericalCap cap{45.0, 10.0, 2'000'000};
  const Covering c = coverArea(cap, 14, kDefaultMaxCells);
  EXPECT_LT(c.level, 14);
  EXPECT_LE(c.cells.size(), kDefaultMaxCells);
  expectCovers(cap, c.level, c.cells);
  // And it is the finest level that fits: one level finer would not.
  EXPECT_GT(weather::coverCap(cap, c.level + 1, kDefaultMaxCells).size(), kDefaultMaxCells);
}

TEST(CoverArea, WholeEarthAtFineLevelTerminatesWithinBudget) {
  const weather::SphericalCap cap{0.0, 0.0, 2.0e7};
  const Covering c = coverArea(cap, 20, kDefaultMaxCells);
  EXPECT_LE(c.cells.size(), kDefaultMaxCells);
  EXPECT_GE(c.level, 4);  // 6 × 4^5 = 6144 cells fit; 6 × 4^6 do not
}

TEST(CellBudget, KeepsEveryTileInOneFrame) {
  for (std::size_t layers : {0u, 1u, 4u, 32u}) {
    const std::size_t cells = cellBudget(kDefaultMaxCells, layers);
    EXPECT_LE(cells, kDefaultMaxCells);
    EXPECT_LT(cells * std::max<std::size_t>(layers, 1) * kTileWireBytes, stream::kMaxFrameBytes);
  }
  EXPECT_EQ(cellBudget(kDefaultMaxCells, 1), kDefaultMaxCells);
}

TEST(DeriveTiles, UniformLayersGetNoTilesAVaryingOneOnePerCell) {
  const std::vector<std::uint64_t> cells = {S2CellId::FromFace(0).child_begin(2).id(),
                                            S2CellId::FromFace(1).child_begin(2).id()};
  const std::vector<weather::CloudLayer> layers = {layer(1, 0.6, 1.0), layer(5, 0.2, 0.5)};
  EXPECT_TRUE(deriveTiles(cells, layers).empty()) << "uniform weather is its layer table";
  // A region on the first cell's centre changes layer 5 there only.
  const weather::CellCentre c = weather::cellCentre(cells[0]);
  weather::Region r;
  r.id = 1;
  r.centerLat_deg = c.lat_deg;
  r.centerLon_deg = c.lon_deg;
  r.sizeX_m = r.sizeY_m = 100'000;
  r.layers = {layer(5, 0.9, 0.5)};
  const std::vector<weather::Region> regions = {r};
  const auto tiles = deriveTiles(cells, layers, regions);
  ASSERT_EQ(tiles.size(), 2u) << "layer 5 on both cells, layer 1 still none";
  for (const auto& t : tiles) {
    EXPECT_EQ(t.layerId, 5u);
    EXPECT_FLOAT_EQ(t.coverage, t.cellId == cells[0] ? 0.9f : 0.2f);
    EXPECT_FLOAT_EQ(t.density, 0.5f);
  }
}

// A clearing 20 km across at the pole: every cell of the cap gets a tile of
// layer 1, the global 0.6 outside and down to 0.1 inside.
TEST(BuildSnapshot, CarriesLayersClockAndTilesOverTheCap) {
  const std::vector<weather::CloudLayer> layers = {layer(1, 0.6, 1.0)};
  weather::Region clearing;
  clearing.id = 2;
  clearing.centerLat_deg = 90;
  clearing.sizeX_m = clearing.sizeY_m = 20'000;
  clearing.layers = {layer(1, 0.1, 1.0)};
  const std::vector<weather::Region> regions = {clearing};
  const stream::Subscribe req = request(90.0, 0.0, 50'000, 10);
  const weather::WeatherSnapshot s = buildSnapshot(req, layers, 1234.5, kDefaultMaxCells, regions);
  EXPECT_DOUBLE_EQ(s.weatherClock_s, 1234.5);
  ASSERT_EQ(s.layers.size(), 1u);
  EXPECT_EQ(s.layers[0].id, 1u);
  EXPECT_EQ(s.tileLevel, 10);
  std::vector<std::uint64_t> cells;
  std::size_t cleared = 0;
  for (const auto& t : s.tiles) {
    EXPECT_EQ(t.layerId, 1u);
    EXPECT_TRUE(t.coverage == 0.6f || t.coverage == 0.1f) << t.coverage;
    cleared += t.coverage == 0.1f;
    EXPECT_FLOAT_EQ(t.density, 1.0f);
    cells.push_back(t.cellId);
  }
  EXPECT_GT(cleared, 0u);
  EXPECT_LT(cleared, cells.size());
  expectCovers(req.area, s.tileLevel, cells);
}

TEST(BuildSnapshot, NoLayersMeansNoTiles) {
  const weather::WeatherSnapshot s =
      buildSnapshot(request(0, 0, 10'000, 10), {}, 0.0, kDefaultMaxCells);
  EXPECT_TRUE(s.layers.empty());
  EXPECT_TRUE(s.tiles.empty());
}

TEST(BuildSnapshot, ManyLayersOverALargeCapStillFitOneFrame) {
  std::vector<weather::CloudLayer> layers;
  for (std::uint32_t i = 0; i < 32; ++i) layers.push_back(layer(i, 0.5, 0.5));
  // Two regions vary all 32 layers over part of the cap, so every layer has tiles.
  std::vector<weather::Region> regions(2);
  for (std::uint32_t k = 0; k < 2; ++k) {
    regions[k].id = k + 1;
    regions[k].centerLat_deg = 45;
    regions[k].centerLon_deg = 10;
    regions[k].sizeX_m = regions[k].sizeY_m = 100'000;
    for (std::uint32_t i = 16 * k; i < 16 * k + 16; ++i) regions[k].layers.push_back(layer(i, 0.9, 0.5));
  }
  const weather::WeatherSnapshot s =
      buildSnapshot(request(45, 10, 500'000, 12), layers, 0.0, kDefaultMaxCells, regions);
  EXPECT_GT(s.tiles.size(), 32u * 6);
  const auto payload = stream::encodeMessage(s);
  EXPECT_LE(payload.size(), stream::kMaxFrameBytes);
  auto decoded = stream::decodeMessage(payload);
  ASSERT_TRUE(decoded) << decoded.error().detail;
  EXPECT_EQ(std::get<weather::WeatherSnapshot>(*decoded).tiles.size(), s.tiles.size());
}

}  // namespace
}  // namespace sky::server
namespace sky::server {
namespace {

// A region that does not drift holds its cloud where it is, however old the
// renderer's snapshot of it grows (no change, no new snapshot); a drifting
// region's tiles move with its wind to where the server has it. Both read
// as the renderers read them: through the stream's encoding and
// snapshotLookup at later clocks. Before layers carried tilesDrift, every
// tile moved: 10 minutes after the snapshot the still region's centre read
// coverage 0 (it had blown 6 km east).
TEST(BuildSnapshot, AStillRegionHoldsItsTilesAndADriftingOneMovesThem) {
  weather::CloudLayer still = layer(1, 1.0, 1.0), moving = layer(2, 1.0, 1.0);
  still.wind = moving.wind = {10.0, 270.0, 0.0};  // from the west
  weather::CloudLayer globalStill = still, globalMoving = moving;
  globalStill.coverage = globalMoving.coverage = 0;
  const std::vector<weather::CloudLayer> layers = {globalStill, globalMoving};
  weather::Region station;
  station.id = 3;
  station.centerLat_deg = 46;
  station.centerLon_deg = 14;
  station.sizeX_m = station.sizeY_m = 10'000;
  station.layers = {still};
  weather::Region cell = station;
  cell.id = 4;
  cell.centerLat_deg = 46.2;
  cell.driftsWithWind = true;
  cell.layers = {moving};
  const std::vector<weather::Region> regions = {station, cell};
  const weather::WeatherSnapshot built = buildSnapshot(request(46.1, 14.2, 60'000, 11), layers, 0.0, kDefaultMaxCells, regions);
  // What a renderer receives.
  auto decoded = stream::decodeMessage(stream::encodeMessage(built));
  ASSERT_TRUE(decoded) << decoded.error().detail;
  const auto& s = std::get<weather::WeatherSnapshot>(*decoded);
  ASSERT_EQ(s.layers.size(), 2u);
  EXPECT_FALSE(s.layers[0].tilesDrift) << "the still region's layer";
  EXPECT_TRUE(s.layers[1].tilesDrift) << "the drifting region's layer";
  for (double age_s : {0.0, 600.0, 3600.0}) {
    SCOPED_TRACE("snapshot age " + std::to_string(age_s) + " s");
    const weather::CoverageLookup lookup = weather::snapshotLookup(s, age_s);
    const auto atStation = lookup(s.layers[0], station.centerLat_deg, station.centerLon_deg);
    ASSERT_TRUE(atStation);
    EXPECT_FLOAT_EQ(atStation->coverage, 1.0f);
    // The drifting region where the server has it at that clock, and not
    // where it was.
    const weather::Region there = weather::regionAt(cell, age_s);
    const auto atCell = lookup(s.layers[1], there.centerLat_deg, there.centerLon_deg);
    ASSERT_TRUE(atCell);
    EXPECT_FLOAT_EQ(atCell->coverage, 1.0f);
    if (age_s >= 3600) {  // 36 km on: off the 10 km region's old place
      const auto whereItWas = lookup(s.layers[1], cell.centerLat_deg, cell.centerLon_deg);
      ASSERT_TRUE(whereItWas);
      EXPECT_FLOAT_EQ(whereItWas->coverage, 0.0f);
    }
  }
  // A layer both kinds give is held (the server sends it again when it
  // changes); a METAR station holds every layer round it.
  weather::Region sharing = cell;
  sharing.layers = {still};
  weather::Region metar = station;
  metar.centerLat_deg = 46.2;
  metar.centerLon_deg = 14.4;
  metar.replacesAllLayers = true;
  metar.layers = {};
  for (const auto& [name, rs] : {std::pair{"a drifting and a still region on layer 1",
                                           std::vector<weather::Region>{station, sharing}},
                                 std::pair{"a METAR station beside the drifting region",
                                           std::vector<weather::Region>{cell, metar}}}) {
    const weather::WeatherSnapshot both = buildSnapshot(request(46.1, 14.2, 60'000, 11), layers, 0.0, kDefaultMaxCells, rs);
    for (const auto& l : both.layers) EXPECT_FALSE(l.tilesDrift) << name << ": layer " << l.id;
  }
}

}  // namespace
}  // namespace sky::server
