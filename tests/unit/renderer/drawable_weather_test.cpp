// More layers than a frame draws: the channel keeps fog that is there, then
// those with the most cloud (ties by id), their tiles only, in their order,
// and names the rest.
#include <algorithm>

#include <gtest/gtest.h>

#include "sky/app/area_of_interest.hpp"
#include "sky/app/drawable_weather.hpp"
#include "sky/app/shared_state.hpp"

namespace sky::app {
namespace {

TEST(DrawableWeather, KeepsTheLayersWithMostCloud) {
  weather::WeatherSnapshot s;
  s.tileLevel = 9;
  const double cover[] = {0.2, 0.9, 0.5, 0.0, 0.5, 0.7};  // ids 1..6
  for (std::uint32_t i = 0; i < 6; ++i) {
    weather::CloudLayer l;
    l.id = i + 1;
    l.coverage = cover[i];
    l.density = 1;
    s.layers.push_back(l);
    s.tiles.push_back({100 + i, i + 1, static_cast<float>(cover[i]), 1.0f});
  }
  std::vector<std::uint32_t> dropped;
  const auto d = drawableWeather(s, 4, &dropped);
  ASSERT_EQ(d.layers.size(), 4u);
  // 0.9 (2), 0.7 (6), 0.5 (3), 0.5 (5) kept, in their original order.
  EXPECT_EQ(d.layers[0].id, 2u);
  EXPECT_EQ(d.layers[1].id, 3u);
  EXPECT_EQ(d.layers[2].id, 5u);
  EXPECT_EQ(d.layers[3].id, 6u);
  EXPECT_EQ(dropped, (std::vector<std::uint32_t>{1, 4}));
  ASSERT_EQ(d.tiles.size(), 4u);
  for (const auto& t : d.tiles) EXPECT_TRUE(t.layerId == 2 || t.layerId == 3 || t.layerId == 5 || t.layerId == 6);
  EXPECT_EQ(d.tileLevel, 9);
  // All fit: unchanged.
  s.layers.resize(3);
  EXPECT_EQ(drawableWeather(s, 4, &dropped).layers.size(), 3u);
  EXPECT_TRUE(dropped.empty());
}

// A METAR's mist is thin by density (2.5 km visibility: 0.03) but what a
// pilot at the station sees first: fog with any cover is kept before the
// cumulus with the least; fog with none anywhere in the area ranks by its 0.
TEST(DrawableWeather, FogThatIsThereIsKeptFirst) {
  weather::WeatherSnapshot s;
  s.tileLevel = 9;
  auto add = [&](std::uint32_t id, weather::CloudType type, double coverage, double density) {
    weather::CloudLayer l;
    l.id = id;
    l.type = type;
    l.coverage = coverage;
    l.density = density;
    s.layers.push_back(l);
  };
  for (std::uint32_t id = 1; id <= 4; ++id) add(id, weather::CloudType::Cumulus, 0.2 * id, 1.0);
  add(40, weather::CloudType::Fog, 0.0, 0.0);  // only a station's region has it: its tiles say where
  s.tiles.push_back({100, 40, 1.0f, 0.03f});
  add(0, weather::CloudType::Fog, 0.0, 0.5);  // a ground fog with no cover here
  std::vector<std::uint32_t> dropped;
  const auto d = drawableWeather(s, 4, &dropped);
  ASSERT_EQ(d.layers.size(), 4u);
  EXPECT_EQ(dropped, (std::vector<std::uint32_t>{0, 1})) << "the empty fog and the thinnest cumulus";
  EXPECT_TRUE(std::any_of(d.layers.begin(), d.layers.end(), [](const auto& l) { return l.id == 40; }));
  ASSERT_EQ(d.tiles.size(), 1u);
}

// Rain is thin by density too (moderate rain 0.06) and seen along the whole
// sight line under its cloud: kept with the fog before the thin cumulus.
TEST(DrawableWeather, PrecipitationThatIsThereIsKeptFirst) {
  weather::WeatherSnapshot s;
  s.tileLevel = 9;
  auto add = [&](std::uint32_t id, weather::CloudType type, double coverage, double density) {
    weather::CloudLayer l;
    l.id = id;
    l.type = type;
    l.coverage = coverage;
    l.density = density;
    s.layers.push_back(l);
  };
  for (std::uint32_t id = 1; id <= 4; ++id) add(id, weather::CloudType::Cumulus, 0.2 * id, 1.0);
  add(62, weather::CloudType::Rain, 0.8, 0.06);
  add(63, weather::CloudType::Snow, 0.0, 0.0);  // none here
  std::vector<std::uint32_t> dropped;
  const auto d = drawableWeather(s, 4, &dropped);
  ASSERT_EQ(d.layers.size(), 4u);
  EXPECT_EQ(dropped, (std::vector<std::uint32_t>{1, 63})) << "the thinnest cumulus and the snow that is not there";
  EXPECT_TRUE(std::any_of(d.layers.begin(), d.layers.end(), [](const auto& l) { return l.id == 62; }));
}

TEST(DrawableWeather, ALayerOnlyARegionHasRanksByItsTiles) {
  // Layer 9 is a storm cell's: absent globally (coverage 0) but dense in its
  // tiles; it outranks the thin global layers.
  weather::WeatherSnapshot s;
  s.tileLevel = 13;
  for (std::uint32_t id : {1u, 2u, 3u, 4u, 9u}) {
    weather::CloudLayer l;
    l.id = id;
    l.coverage = id == 9 ? 0.0 : 0.1 * id;
    s.layers.push_back(l);
    s.tiles.push_back({500, id, static_cast<float>(l.coverage), 1.0f});
  }
  s.tiles.push_back({501, 9, 1.0f, 1.0f});
  std::vector<std::uint32_t> dropped;
  const auto d = drawableWeather(s, 4, &dropped);
  EXPECT_EQ(dropped, (std::vector<std::uint32_t>{1}));
  EXPECT_EQ(d.layers.back().id, 9u);
}

}  // namespace
}  // namespace sky::app

namespace sky::app {
namespace {

// The coarse area's snapshot is cut to the layers the detailed area's
// drawable keeps, whatever the coarse area's own ranking would be (there a
// dropped layer may have more cloud), so both rings of the map hold one set.
TEST(DrawableWeather, TheCoarseAreaKeepsTheDetailedAreasLayers) {
  weather::WeatherSnapshot fine, coarse;
  coarse.areaIndex = 1;
  coarse.tileLevel = 9;
  for (std::uint32_t id = 1; id <= 5; ++id) {
    weather::CloudLayer l;
    l.id = id;
    l.coverage = 0.1 * id;
    fine.layers.push_back(l);
    l.coverage = 1.0 - 0.1 * id;  // the opposite ranking far away
    coarse.layers.push_back(l);
    coarse.tiles.push_back({1000 + id, id, 0.5f, 1.0f});
  }
  const auto drawable = drawableWeather(fine, 4);
  const auto cut = drawableCoarse(coarse, drawable);
  ASSERT_EQ(cut.layers.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(cut.layers[i].id, drawable.layers[i].id);
  EXPECT_EQ(cut.layers.front().id, 2u) << "layer 1 has least cloud near the camera";
  EXPECT_EQ(cut.tiles.size(), 4u);
  for (const auto& t : cut.tiles) EXPECT_NE(t.layerId, 1u);
  EXPECT_EQ(cut.areaIndex, 1);
  EXPECT_EQ(cut.tileLevel, 9);
}

// Both areas are asked for on the first pose; the detailed one again every
// 30 km, the coarse one every 100 km; the coarse one is area 1 at level 9
// (~18 km cells) over 900 km, the detailed one area 0 at level 11.
TEST(AreaTracker, AsksForEachAreaAgainAtItsOwnDistance) {
  AreaTracker t;
  geo::GeodeticPose pose;
  pose.position = {46.0, 13.0, 3000};
  auto asked = t.update(pose);
  ASSERT_EQ(asked.size(), 2u);
  EXPECT_EQ(asked[0].areaIndex, 0);
  EXPECT_EQ(asked[0].tileLevel, 11);
  EXPECT_EQ(asked[0].area.radius_m, kSubscribeRadius_m);
  EXPECT_EQ(asked[1].areaIndex, 1);
  EXPECT_EQ(asked[1].tileLevel, 9);
  EXPECT_EQ(asked[1].area.radius_m, kCoarseSubscribeRadius_m);
  EXPECT_TRUE(t.update(pose).empty());
  const double kmLat = 1.0 / 111.2;
  pose.position.lat_deg += 40 * kmLat;  // 40 km north
  asked = t.update(pose);
  ASSERT_EQ(asked.size(), 1u);
  EXPECT_EQ(asked[0].areaIndex, 0);
  pose.position.lat_deg += 70 * kmLat;  // 110 km from the first pose
  asked = t.update(pose);
  ASSERT_EQ(asked.size(), 2u) << "70 km from the last detailed area, 110 km from the coarse one";
  EXPECT_EQ(asked[1].areaIndex, 1);
  EXPECT_DOUBLE_EQ(asked[1].area.centerLat_deg, pose.position.lat_deg);
}

}  // namespace
}  // namespace sky::app

namespace sky::app {
namespace {

// The flashes a channel holds (they arrive once, as events): those that can
// still give light at the stream's clock, at most kMaxHeldFlashes, the
// newest kept.
TEST(HeldFlashes, OnlyThoseStillGivingLightAreKept) {
  SharedState state;
  auto flashAt = [](double t_s) {
    weather::LightningFlash f;
    f.time_s = t_s;
    f.energy_j = 1e9;
    return f;
  };
  state.addFlashes({flashAt(10.0), flashAt(11.0)}, 11.0);
  EXPECT_EQ(state.weather().flashes.size(), 2u);
  // Later: the first is past its light and the grace, the second not yet.
  const double later = 10.0 + weather::kFlashLifetime_s + kFlashGrace_s + 0.5;
  state.addFlashes({flashAt(later)}, later);
  ASSERT_EQ(state.weather().flashes.size(), 2u);
  EXPECT_EQ(state.weather().flashes[0].time_s, 11.0);
  // A storm's burst: the newest kMaxHeldFlashes.
  std::vector<weather::LightningFlash> burst;
  for (int i = 0; i < 300; ++i) burst.push_back(flashAt(later + i * 1e-3));
  state.addFlashes(burst, later + 0.3);
  ASSERT_EQ(state.weather().flashes.size(), kMaxHeldFlashes);
  EXPECT_EQ(state.weather().flashes.back().time_s, later + 299 * 1e-3);
}

}  // namespace
}  // namespace sky::app
