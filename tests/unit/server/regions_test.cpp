// Regional weather in the server: a region's layers replace the global layer
// of the same id inside it and blend across its transition perimeter in the
// snapshot tiles; regions grow in and shrink out on ramps; a drifting storm
// moves with its wind, and the tiles a renderer advects from an older
// snapshot agree with a fresh one; a refused region leaves everything as it
// was; regions survive a restart (same state hash); the JSON names bad fields.
#include <algorithm>
#include <filesystem>

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include "region_builder.hpp"

#include "sky/server/api_json.hpp"
#include "sky/server/live_weather.hpp"
#include "sky/server/snapshot_builder.hpp"
#include "sky/server/weather_store.hpp"
#include "sky/weather/query.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::server {
namespace {

using namespace std::chrono_literals;
const WallClock::time_point kT0{std::chrono::hours(1000)};

weather::CloudLayer layer(std::uint32_t id, weather::CloudType type, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = type;
  l.base_m = 1500;
  l.thickness_m = 1000;
  l.coverage = coverage;
  l.density = 1;
  l.wind = {10, 270, 0};
  return l;
}

constexpr auto cell = test::squareRegion;

struct Fixture : test::WeatherFixture {
  Fixture() : WeatherFixture({layer(1, weather::CloudType::Cumulus, 0.8)}) {}
};

// Point `east_m` east and `north_m` north of (lat, lon) along a geodesic.
weather::CellCentre offset(double lat, double lon, double east_m, double north_m) {
  weather::CellCentre p;
  GeographicLib::Geodesic::WGS84().Direct(lat, lon, std::atan2(east_m, north_m) * 180 / M_PI,
                                          std::hypot(east_m, north_m), p.lat_deg, p.lon_deg);
  return p;
}

const weather::CoverageTile* tileAt(const weather::WeatherSnapshot& s, std::uint32_t layerId,
                                    const weather::CellCentre& p) {
  const std::uint64_t id = weather::cellAt(p.lat_deg, p.lon_deg, s.tileLevel);
  for (const auto& t : s.tiles)
    if (t.cellId == id && t.layerId == layerId) return &t;
  return nullptr;
}

stream::Subscribe around(double lat, double lon, double radius_m) {
  stream::Subscribe s;
  s.area = {lat, lon, radius_m};
  s.tileLevel = 13;  // ~1 km cells
  return s;
}

TEST(Regions, AClearingAndAStormInTheTiles) {
  const std::vector<weather::CloudLayer> global = {layer(1, weather::CloudType::Cumulus, 0.8)};
  // A clearing (layer 1 at coverage 0) 20 km square with a 10 km perimeter,
  // and a storm cell of a layer only it has, 30 km east.
  const std::vector<weather::Region> regions = {
      cell(1, 46, 13, 20000, 10000, {layer(1, weather::CloudType::Cumulus, 0.0)}),
      cell(2, 46, 13.39, 8000, 4000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)})};
  const auto s = buildSnapshot(around(46, 13.2, 60000), global, 0.0, kDefaultMaxCells, regions);
  ASSERT_EQ(s.layers.size(), 2u);
  EXPECT_EQ(s.layers[1].id, 6u);
  EXPECT_EQ(s.layers[1].coverage, 0.0) << "outside its regions a region-only layer is absent";
  EXPECT_EQ(s.layers[1].type, weather::CloudType::Cumulonimbus);
  const double tol = 0.03;  // the tile is sampled at its ~1 km cell's centre
  // Clearing: none inside, the global 0.8 beyond the perimeter, half way
  // between at the perimeter's middle (smoothstep 0.5).
  EXPECT_NEAR(tileAt(s, 1, offset(46, 13, 0, 0))->coverage, 0.0, 1e-6);
  EXPECT_NEAR(tileAt(s, 1, offset(46, 13, 0, -25000))->coverage, 0.8, 1e-6);
  EXPECT_NEAR(tileAt(s, 1, offset(46, 13, 0, 15000))->coverage, 0.4, tol);
  EXPECT_NEAR(tileAt(s, 6, offset(46, 13, 0, 0))->coverage, 0.0, 1e-6);
  // Storm: full inside its cell, none well outside, its type on layer 6.
  const auto* inStorm = tileAt(s, 6, offset(46, 13.39, 0, 0));
  ASSERT_NE(inStorm, nullptr);
  EXPECT_NEAR(inStorm->coverage, 1.0, 1e-6);
  EXPECT_EQ(inStorm->blendType, weather::CloudType::None) << "layer 6's own type";
  EXPECT_NEAR(tileAt(s, 6, offset(46, 13.39, 0, 12000))->coverage, 0.0, 1e-6);
  EXPECT_NEAR(tileAt(s, 1, offset(46, 13.39, 0, 0))->coverage, 0.8, 1e-6) << "the storm has no layer 1";
}

// One base and top per layer id in a snapshot's table: a cloud layer only
// regions have takes the geometry of the region weighing most at the
// subscriber's centre; fog takes the lowest base and highest top of every
// region in reach of the subscriber's area, so two stations' fog at 18 m
// (300 m deep) and 125 m (61 m deep) both cover their own ground.
TEST(Regions, FogInTheTableSpansEveryStationsFogInTheArea) {
  auto fog = [](double base, double thickness) {
    weather::CloudLayer l = layer(40, weather::CloudType::Fog, 1.0);
    l.base_m = base;
    l.thickness_m = thickness;
    return l;
  };
  auto cloud = [](double base) {
    weather::CloudLayer l = layer(45, weather::CloudType::Stratus, 1.0);
    l.base_m = base;
    return l;
  };
  const std::vector<weather::Region> regions = {cell(7, 45.65, 12.19, 4000, 20000, {fog(18, 300), cloud(600)}),
                                                cell(8, 46.03, 12.60, 4000, 20000, {fog(125, 61), cloud(700)}),
                                                cell(9, 40.0, 12.0, 4000, 20000, {fog(-50, 1000)})};  // 650 km south
  const weather::CellCentre nearB{46.0, 12.6};
  const auto table = snapshotLayers({}, regions, &nearB, 120000);
  auto find = [&](std::uint32_t id) { return *std::find_if(table.begin(), table.end(), [&](const auto& l) { return l.id == id; }); };
  EXPECT_EQ(find(40).base_m, 18);
  EXPECT_EQ(find(40).base_m + find(40).thickness_m, 318);
  EXPECT_EQ(find(40).coverage, 0);  // outside its regions there is none
  EXPECT_EQ(find(45).base_m, 700);  // a cloud layer: the nearest station's
  // A point query's table (radius 0) at the first station: its own fog.
  const weather::CellCentre atA{45.65, 12.19};
  const auto local = snapshotLayers({}, regions, &atA);
  const auto it = std::find_if(local.begin(), local.end(), [](const auto& l) { return l.id == 40; });
  EXPECT_EQ(it->base_m, 18);
  EXPECT_EQ(it->thickness_m, 300);
}

TEST(Regions, AnotherTypeInARegionBlendsIntoTheLayer) {
  const std::vector<weather::CloudLayer> global = {layer(1, weather::CloudType::Cumulus, 0.5)};
  const std::vector<weather::Region> regions = {
      cell(4, -20, 179.95, 20000, 10000, {layer(1, weather::CloudType::Stratocumulus, 0.9)})};
  const auto s = buildSnapshot(around(-20, 180, 40000), global, 0.0, kDefaultMaxCells, regions);
  const auto* inside = tileAt(s, 1, offset(-20, 179.95, 3000, 0));  // across the antimeridian
  ASSERT_NE(inside, nullptr);
  EXPECT_NEAR(inside->coverage, 0.9, 1e-6);
  EXPECT_EQ(inside->blendType, weather::CloudType::Stratocumulus);
  EXPECT_NEAR(inside->blend, 1.0, 1e-6);
  const auto* edge = tileAt(s, 1, offset(-20, 179.95, 15000, 0));
  ASSERT_NE(edge, nullptr);
  EXPECT_GT(edge->blend, 0.2);
  EXPECT_LT(edge->blend, 0.8);
  EXPECT_NEAR(edge->coverage, 0.5 + edge->blend * 0.4, 1e-5) << "coverage and type blend by the same weight";
}

TEST(Regions, TheTileCacheGivesTheSameSnapshots) {
  const std::vector<weather::CloudLayer> global = {layer(1, weather::CloudType::Cumulus, 0.8)};
  std::vector<weather::Region> regions = {
      cell(1, 46, 13, 20000, 10000, {layer(1, weather::CloudType::Cumulus, 0.0)}),
      cell(2, 46, 13.39, 8000, 4000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)})};
  TileCache cache;
  for (int round = 0; round < 3; ++round) {  // the first fills the cache, the others read it
    regions[1].centerLon_deg = 13.39 + 0.01 * (round == 2);  // the storm moves in the last round
    const auto plain = buildSnapshot(around(46, 13.2, 60000), global, 0.0, kDefaultMaxCells, regions);
    const auto cached = buildSnapshot(around(46, 13.2, 60000), global, 0.0, kDefaultMaxCells, regions, &cache);
    EXPECT_EQ(cached.tileLevel, plain.tileLevel);
    EXPECT_EQ(cached.tiles, plain.tiles) << round;
  }
  EXPECT_EQ(cache.coverings(), 1u);
  // Counted per layer (1 and 6): round 1 changed nothing, round 2 moved only
  // the storm, which has no layer 1.
  EXPECT_EQ(cache.tileHits(), 3u) << "round 1's layers and round 2's layer 1 came back from the memo";
  EXPECT_EQ(cache.tileMisses(), 3u);
  // A storm far from the area moves: the area's tiles come back as they were,
  // and equal what deriving them gives.
  regions.push_back(cell(3, 10, 60, 8000, 4000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)}));
  for (int round = 0; round < 3; ++round) {
    regions[2].centerLon_deg = 60 + 0.5 * round;
    const auto plain = buildSnapshot(around(46, 13.2, 60000), global, 0.0, kDefaultMaxCells, regions);
    const auto cached = buildSnapshot(around(46, 13.2, 60000), global, 0.0, kDefaultMaxCells, regions, &cache);
    EXPECT_EQ(cached.tiles, plain.tiles) << round;
  }
  EXPECT_EQ(cache.tileHits(), 9u) << "adding the far storm and moving it changed nothing here";
  EXPECT_EQ(cache.tileMisses(), 3u);
}

TEST(Regions, OverlappingRegionsAverageByWeight) {
  const std::vector<weather::CloudLayer> global = {layer(1, weather::CloudType::Cumulus, 0.5)};
  const std::vector<weather::Region> regions = {cell(1, 0, 0, 20000, 0, {layer(1, weather::CloudType::Cumulus, 0.2)}),
                                                cell(2, 0, 0, 20000, 0, {layer(1, weather::CloudType::Cumulus, 1.0)})};
  const auto tiles = deriveTiles(std::vector<std::uint64_t>{weather::cellAt(0, 0, 13)}, global, regions);
  ASSERT_EQ(tiles.size(), 1u);
  EXPECT_NEAR(tiles[0].coverage, 0.6, 1e-6);  // (0.2 + 1.0) / 2, total weight capped at 1
}

TEST(Regions, GrowInShrinkOutAndShowInTheView) {
  Fixture f;
  const weather::Region storm = cell(7, 46, 13, 20000, 5000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)});
  auto added = f.submit({SetRegion{storm, Timing{std::nullopt, 300}}});
  ASSERT_TRUE(added) << added.error().detail;
  EXPECT_NE(added->summary.find("region 7 added"), std::string::npos) << added->summary;
  f.now += 150s;  // half way: half the size
  WeatherView v = f.weather.view();
  ASSERT_EQ(v.regions.size(), 1u);
  EXPECT_NEAR(v.regions[0].sizeX_m, 10000, 1e-6);
  EXPECT_NEAR(v.regions[0].transition_m, 2500, 1e-6);
  EXPECT_EQ(v.pending.size(), 1u);
  f.now += 200s;
  v = f.weather.view();
  EXPECT_NEAR(v.regions[0].sizeX_m, 20000, 1e-6);
  EXPECT_TRUE(v.pending.empty());
  EXPECT_FALSE(f.weather.changing(v.clock_s));
  // Removal shrinks it over 100 s, then it is gone.
  ASSERT_TRUE(f.submit({RemoveRegion{7, Timing{std::nullopt, 100}}}));
  f.now += 25s;
  v = f.weather.view();
  ASSERT_EQ(v.regions.size(), 1u);
  EXPECT_NEAR(v.regions[0].sizeX_m, 15000, 1e-6);
  EXPECT_TRUE(f.weather.changing(v.clock_s));
  f.now += 100s;
  EXPECT_TRUE(f.weather.view().regions.empty());
  const auto gone = f.submit({RemoveRegion{7, Timing{}}});
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().detail, "changes[0].id: no region 7");
}

TEST(Regions, ARefusedRegionLeavesEverythingAsItWas) {
  Fixture f;
  const auto hash = f.weather.stateHash();
  weather::Region bad = cell(3, 46, 13, 0, 0, {layer(2, weather::CloudType::Stratus, 0.5)});
  const auto refused = f.submit({SetLayer{layer(1, weather::CloudType::Cumulus, 0.1), Timing{}},
                                 SetRegion{bad, Timing{}}});
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(refused.error().detail.find("changes[1].region: region 3: size_x_m 0 outside (0, 2000000]"),
            std::string::npos)
      << refused.error().detail;
  EXPECT_EQ(f.weather.stateHash(), hash);
  EXPECT_NEAR(f.weather.view().layers[0].coverage, 0.8, 1e-12) << "the first change of the batch is not applied";
  EXPECT_TRUE(f.weather.view().regions.empty());
  // Too many distinct layer ids counting the regions' own.
  std::vector<weather::CloudLayer> many;
  for (std::uint32_t id = 100; id < 100 + weather::kMaxRegionLayers; ++id)
    many.push_back(layer(id, weather::CloudType::Cumulus, 0.5));
  ASSERT_TRUE(f.submit({SetRegion{cell(1, 0, 0, 1000, 0, many), Timing{}}}));
  for (std::uint32_t id = 200; id < 200 + weather::kMaxRegionLayers; ++id) many[id - 200].id = id;
  const auto tooMany = f.submit({SetRegion{cell(2, 0, 0, 1000, 0, many), Timing{}}});
  ASSERT_FALSE(tooMany);
  EXPECT_NE(tooMany.error().detail.find("distinct layer ids"), std::string::npos) << tooMany.error().detail;
}

TEST(Regions, ADriftingStormIsWhereTheRendererAdvectsIt) {
  Fixture f;
  weather::Region storm = cell(9, 46, 13, 8000, 2000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)});
  storm.layers[0].wind = {20, 270, 0};  // blows east at 20 m/s
  storm.driftsWithWind = true;
  ASSERT_TRUE(f.submit({SetRegion{storm, Timing{}}}));
  // 15 minutes later the centre is 18 km east.
  f.now += 900s;
  const auto regions = f.weather.regionsAt(f.weather.clockNow());
  ASSERT_EQ(regions.size(), 1u);
  const weather::CellCentre moved = offset(46, 13, 18000, 0);
  EXPECT_NEAR(regions[0].centerLat_deg, moved.lat_deg, 1e-9);
  EXPECT_NEAR(regions[0].centerLon_deg, moved.lon_deg, 1e-9);
  // A renderer holding the snapshot from when the storm was placed, asked
  // 900 s later, carries its tiles by the layer's wind (weather::advect,
  // snapshotLookup); the server's fresh snapshot agrees where the storm is
  // now and where it was.
  f.now = kT0;
  const double t0 = f.weather.clockNow();
  const auto old = buildSnapshot(around(46, 13.1, 40000), f.weather.layersAt(t0), t0, kDefaultMaxCells,
                                 f.weather.regionsAt(t0));
  const double t1 = t0 + 900;
  const auto fresh = buildSnapshot(around(46, 13.1, 40000), f.weather.layersAt(t1), t1, kDefaultMaxCells,
                                   f.weather.regionsAt(t1));
  const auto rendererView = weather::snapshotLookup(old, t1);
  const auto serverView = weather::snapshotLookup(fresh, t1);
  const weather::CloudLayer& stormLayer = old.layers[1];
  ASSERT_EQ(stormLayer.id, 6u);
  for (const auto& [p, expected] : {std::pair{moved, 1.0}, std::pair{offset(46, 13, 0, 0), 0.0}}) {
    const auto a = rendererView(stormLayer, p.lat_deg, p.lon_deg);
    const auto b = serverView(stormLayer, p.lat_deg, p.lon_deg);
    ASSERT_TRUE(a && b);
    EXPECT_NEAR(a->coverage, expected, 1e-6);
    EXPECT_NEAR(b->coverage, expected, 1e-6);
  }
}

TEST(Regions, SurviveARestartWithTheSameHash) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "skyshell-regions-test";
  fs::create_directories(dir);
  const fs::path file = dir / "regions.db";
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(file.string() + suffix);
  std::uint64_t hash = 0;
  Fixture f;
  {
    auto store = WeatherStore::open(file);
    ASSERT_TRUE(store) << store.error().detail;
    ASSERT_TRUE(store->save(f.weather.toJson(), nullptr));
    f.weather.attachStore(&*store);
    weather::Region storm = cell(9, 46, 13, 8000, 2000, {layer(6, weather::CloudType::Cumulonimbus, 1.0)});
    storm.driftsWithWind = true;
    ASSERT_TRUE(f.submit({SetRegion{cell(1, 46, 12, 20000, 5000, {layer(1, weather::CloudType::Cumulus, 0.0)}),
                                    Timing{}},
                          SetRegion{storm, Timing{std::nullopt, 600}}}));
    f.now += 100s;
    hash = f.weather.stateHash();
  }
  auto store = WeatherStore::open(file);
  ASSERT_TRUE(store);
  auto saved = store->load();
  ASSERT_TRUE(saved && *saved);
  LiveWeather back(Scenario{}, f.now, [&] { return f.now; }, [&] { return f.unixMs; });
  ASSERT_TRUE(back.restore((*saved)->state, (*saved)->events));
  EXPECT_EQ(back.stateHash(), hash);
  const auto before = f.weather.regionsAt(1100), after = back.regionsAt(1100);
  ASSERT_EQ(after.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(server::toJson(after[i]), server::toJson(before[i])) << i;
  }
}

TEST(Regions, ApiJsonReadsRegionsStrictly) {
  auto ok = parseChangeRequest(R"({"changes": [{"op": "set_region", "ramp_s": 60, "region": {
      "id": 4, "center_lat_deg": 46.1, "center_lon_deg": 13.2, "size_x_m": 9000, "size_y_m": 7000,
      "transition_m": 3000, "drifts_with_wind": true, "layers": [{"id": 6, "type": "cumulonimbus",
      "base_m": 900, "thickness_m": 9000, "transition_band_m": 0, "coverage": 0.9, "density": 1,
      "wind": {"speed_mps": 12, "from_deg": 250, "vertical_mps": 0}}]}},
      {"op": "remove_region", "id": 2, "at_s": 5000}]})");
  ASSERT_TRUE(ok) << ok.error().detail;
  const auto& set = std::get<SetRegion>(ok->changes[0]);
  EXPECT_EQ(set.region.id, 4u);
  EXPECT_EQ(set.region.sizeY_m, 7000);
  EXPECT_EQ(set.region.cornerRadius_m, 0) << "optional, default 0";
  EXPECT_TRUE(set.region.driftsWithWind);
  ASSERT_EQ(set.region.layers.size(), 1u);
  EXPECT_EQ(set.region.layers[0].type, weather::CloudType::Cumulonimbus);
  EXPECT_EQ(set.timing.ramp_s, 60);
  EXPECT_EQ(std::get<RemoveRegion>(ok->changes[1]).regionId, 2u);

  const auto missing = parseChangeRequest(
      R"({"changes": [{"op": "set_region", "region": {"id": 4, "center_lat_deg": 46, "center_lon_deg": 13,
          "size_x_m": 9000, "layers": []}}]})");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().detail, "changes[0].region.size_y_m: missing (required)");
  const auto unknown = parseChangeRequest(
      R"({"changes": [{"op": "set_region", "region": {"id": 4, "center_lat_deg": 46, "center_lon_deg": 13,
          "size_x_m": 9000, "size_y_m": 9000, "layers": [], "placed_at_clock_s": 5}}]})");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().detail.find("changes[0].region.placed_at_clock_s: unknown key"), std::string::npos)
      << unknown.error().detail;
  const auto badLayer = parseChangeRequest(
      R"({"changes": [{"op": "set_region", "region": {"id": 4, "center_lat_deg": 46, "center_lon_deg": 13,
          "size_x_m": 9000, "size_y_m": 9000, "layers": [{"id": 1}]}}]})");
  ASSERT_FALSE(badLayer);
  EXPECT_EQ(badLayer.error().detail.rfind("changes[0].region.layers[0].type", 0), 0u) << badLayer.error().detail;
}

}  // namespace
}  // namespace sky::server
