// More layers than a frame draws: the channel keeps those with the most cloud
// (ties by id), their tiles only, in their order, and names the rest.
#include <gtest/gtest.h>

#include "sky/app/drawable_weather.hpp"

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
