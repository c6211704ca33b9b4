// A saved state cut by S2 cell for the relays (state_cells.hpp): joining the
// global part and every cell gives the state back (same JSON, same state
// hash after a restore); a region is in every cell its reach touches, across
// the antimeridian and at the pole; drifting and very large regions stay
// global; and a relay that joins only the cells covering a renderer's area
// builds that area's snapshot tile for tile as the server with the whole
// state does.
#include <algorithm>
#include <set>

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include "region_builder.hpp"

#include "sky/server/api_json.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/state_cells.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;
using test::squareRegion;
using test::stackedLayer;

struct Fixture : test::WeatherFixture {
  Fixture() : WeatherFixture({stackedLayer(1, weather::CloudType::Cumulus, 0.6)}) {}
  void submit(std::vector<WeatherChange> changes) {
    auto r = WeatherFixture::submit(std::move(changes));
    ASSERT_TRUE(r) << r.error().detail;
  }
};

weather::CloudLayer clearing() { return stackedLayer(1, weather::CloudType::Cumulus, 0.0); }
weather::CloudLayer storm() { return stackedLayer(2, weather::CloudType::Cumulonimbus, 1.0); }

// A state with every kind of region: stations in Europe and Australia, one
// on the antimeridian, one at the North Pole, a drifting storm, one larger
// than a cell may hold, a region growing in, one moved across the world on a
// ramp and one moved 90 km, one shrinking out, and several set by one change
// (a METAR batch).
void fillWorld(Fixture& f) {
  f.submit({SetRegion{squareRegion(1, 48.1, 11.6, 20000, 5000, {clearing()}), {}},
            SetRegion{squareRegion(2, 48.4, 12.3, 10000, 2000, {storm()}), {}},
            SetRegion{squareRegion(3, -33.9, 151.2, 30000, 10000, {storm()}), {}},
            SetRegion{squareRegion(4, -17.0, 179.95, 40000, 10000, {clearing()}), {}},
            SetRegion{squareRegion(5, 89.9, 40.0, 30000, 5000, {storm()}), {}}});
  weather::Region drifting = squareRegion(6, 47.0, 8.0, 8000, 2000, {storm()});
  drifting.driftsWithWind = true;
  f.submit({SetRegion{drifting, {}}});
  f.submit({SetRegion{squareRegion(7, 10.0, 20.0, 1'500'000, 100'000, {clearing()}), {}}});
  f.submit({SetRegion{squareRegion(8, 48.2, 11.9, 10000, 3000, {storm()}), Timing{std::nullopt, 600}}});
  f.submit({SetRegion{squareRegion(9, 50.0, 5.0, 10000, 3000, {storm()}), {}}});
  f.submit({SetRegion{squareRegion(9, -30.0, 140.0, 10000, 3000, {storm()}), Timing{std::nullopt, 900}}});
  f.submit({SetRegion{squareRegion(10, 47.5, 12.0, 10000, 3000, {storm()}), {}}});
  f.submit({SetRegion{squareRegion(10, 48.3, 12.2, 12000, 3000, {storm()}), Timing{std::nullopt, 900}}});
  f.submit({RemoveRegion{3, Timing{std::nullopt, 300}}});
  f.now += 60s;
}

nlohmann::json joinAll(const StateCells& split) {
  std::vector<const nlohmann::json*> parts;
  for (const auto& [key, cell] : split.cells) parts.push_back(&cell);
  return joinState(split.global, parts);
}

std::set<std::uint64_t> regionIds(const nlohmann::json& j, const char* member = "regions") {
  std::set<std::uint64_t> ids;
  for (const auto& r : j.at(member)) ids.insert(r.at(member == std::string("regions") ? "id" : "region_id").get<std::uint64_t>());
  return ids;
}

TEST(StateCells, JoiningEveryCellGivesTheStateBack) {
  Fixture f;
  fillWorld(f);
  const nlohmann::json state = f.weather.toJson();
  CellReach reach;
  const StateCells split = splitState(state, reach);
  EXPECT_EQ(joinAll(split), state);
  // Restored from the joined state, the weather hashes as the original.
  Fixture back;
  back.now = f.now;
  ASSERT_TRUE(back.weather.restore(joinAll(split), {}));
  EXPECT_EQ(back.weather.stateHash(), f.weather.stateHash());

  // Drifting (6) and too large (7) stay global; placed ones do not. (Set
  // at once, neither has a ramp.)
  EXPECT_EQ(regionIds(split.global), (std::set<std::uint64_t>{6, 7}));
  // So is the ramp moving 9 across the world (no cell holds its path); the
  // ramps of 8 (growing in), 10 (moved 90 km) and 3's removal are in cells.
  EXPECT_EQ(regionIds(split.global, "region_ramps"), (std::set<std::uint64_t>{9}));
  EXPECT_GT(split.cells.size(), 5u);
  // Cutting the same state again takes the reach from the cache and cuts
  // the same.
  const StateCells again = splitState(state, reach);
  EXPECT_EQ(again.cells, split.cells);
}

// Every point within a region's reach lies in a cell that holds the region;
// across the antimeridian and at the pole as well.
TEST(StateCells, ARegionIsInEveryCellItsReachTouches) {
  Fixture f;
  fillWorld(f);
  CellReach reach;
  const nlohmann::json state = f.weather.toJson();
  const StateCells split = splitState(state, reach);
  const auto& geod = GeographicLib::Geodesic::WGS84();
  for (const auto& r : state.at("regions")) {
    const auto id = r.at("id").get<std::uint64_t>();
    if (id == 6 || id == 7) continue;
    auto region = regionFromJson(r, "region", true);
    ASSERT_TRUE(region);
    const double edge_m = std::hypot(region->sizeX_m, region->sizeY_m) / 2 + region->transition_m;
    std::size_t checked = 0;
    for (double fraction : {0.0, 0.5, 0.99})
      for (int az = 0; az < 360; az += 15) {
        double lat = 0, lon = 0;
        geod.Direct(region->centerLat_deg, region->centerLon_deg, az, fraction * edge_m, lat, lon);
        if (weather::regionWeight(*region, lat, lon) <= 0) continue;
        const std::string key = cellKey(weather::cellAt(lat, lon, kStateCellLevel));
        const auto cell = split.cells.find(key);
        ASSERT_NE(cell, split.cells.end()) << "region " << id << " at " << lat << ", " << lon;
        EXPECT_TRUE(regionIds(cell->second).count(id)) << "region " << id << " missing from " << key;
        ++checked;
      }
    EXPECT_GT(checked, 20u) << id;
  }
  // Region 4 straddles the antimeridian: cells on both sides hold it.
  const auto west = split.cells.find(cellKey(weather::cellAt(-17.0, 179.9, kStateCellLevel)));
  const auto east = split.cells.find(cellKey(weather::cellAt(-17.0, -179.9, kStateCellLevel)));
  ASSERT_NE(west, split.cells.end());
  ASSERT_NE(east, split.cells.end());
  EXPECT_NE(west->first, east->first);
  EXPECT_TRUE(regionIds(west->second).count(4));
  EXPECT_TRUE(regionIds(east->second).count(4));
}

// The contract a relay relies on: the cells covering a renderer's area, with
// the global part, give that area's snapshot as the whole state does (tiles
// of every layer the whole state's table has in the area; a layer only far
// regions have is the one difference: absent in the area either way).
TEST(StateCells, TheAreasCellsGiveTheAreasSnapshot) {
  Fixture f;
  fillWorld(f);
  CellReach reach;
  const StateCells split = splitState(f.weather.toJson(), reach);
  std::size_t total = 0;
  for (const weather::SphericalCap area : {weather::SphericalCap{48.2, 11.8, 120000}, weather::SphericalCap{-17.0, -179.8, 120000},
                                          weather::SphericalCap{-33.0, 145.0, 900000},
                                          weather::SphericalCap{47.9, 12.6, 60000}}) {
    bool tooMany = true;
    const auto keys = cellsForAreas({area}, reach, tooMany);
    ASSERT_FALSE(tooMany);
    ASSERT_FALSE(keys.empty());
    std::vector<const nlohmann::json*> parts;
    for (const auto& k : keys)
      if (auto it = split.cells.find(k); it != split.cells.end()) parts.push_back(&it->second);
    Fixture relay;
    relay.now = f.now;
    ASSERT_TRUE(relay.weather.restore(joinState(split.global, parts), {}));
    EXPECT_LT(relay.weather.toJson().at("regions").size(), f.weather.toJson().at("regions").size());
    stream::Subscribe sub;
    sub.area = area;
    sub.tileLevel = 11;
    // Now, and with the ramps of 8, 9 and 10 half way.
    for (const double clock_s : {1060.0, 1400.0}) {
      const auto whole = buildSnapshot(sub, f.weather.layersAt(clock_s), clock_s, kDefaultMaxCells,
                                       f.weather.regionsAt(clock_s));
      const auto part = buildSnapshot(sub, relay.weather.layersAt(clock_s), clock_s, kDefaultMaxCells,
                                      relay.weather.regionsAt(clock_s));
      ASSERT_EQ(whole.tileLevel, part.tileLevel);
      std::map<std::pair<std::uint64_t, std::uint32_t>, double> wholeTiles;
      for (const auto& t : whole.tiles) wholeTiles[{t.cellId, t.layerId}] = t.coverage;
      std::size_t compared = 0;
      for (const auto& t : part.tiles) {
        const auto it = wholeTiles.find({t.cellId, t.layerId});
        ASSERT_NE(it, wholeTiles.end()) << "layer " << t.layerId;
        EXPECT_EQ(t.coverage, it->second) << "cell " << t.cellId << " layer " << t.layerId;
        ++compared;
      }
      // Every tile of the whole state's snapshot is in the relay's, but
      // those of a layer the relay's table has not, which have no cover
      // anywhere in the area.
      std::size_t expected = 0;
      for (const auto& t : whole.tiles) {
        const bool inPart = std::any_of(part.layers.begin(), part.layers.end(),
                                        [&](const auto& l) { return l.id == t.layerId; });
        if (inPart) {
          ++expected;
        } else {
          EXPECT_EQ(t.coverage, 0.0) << "layer " << t.layerId;
        }
      }
      EXPECT_EQ(compared, expected);
      total += compared;
    }
  }
  EXPECT_GT(total, 5000u) << "tiles compared";
}

TEST(StateCells, AnAreaTooLargeAsksForTheWholeState) {
  bool tooMany = false;
  CellReach cache;
  EXPECT_TRUE(cellsForAreas({weather::SphericalCap{0, 0, 9'000'000}}, cache, tooMany).empty());
  EXPECT_TRUE(tooMany);
  const auto keys =
      cellsForAreas({weather::SphericalCap{48, 11, 120000}, weather::SphericalCap{48, 11, 900000}}, cache, tooMany);
  EXPECT_FALSE(tooMany);
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end()));
  EXPECT_GT(keys.size(), 50u);
  EXPECT_LT(keys.size(), 400u);
}

}  // namespace
}  // namespace sky::server
