// The weather image on the GPU after partial uploads (renderer/core/src/
// weather_texture.*, gpu_memory.*): over a seeded sequence of tile changes
// in a fine and a coarse snapshot, each uploading only the rectangles
// around the rewritten texels, the image read back holds exactly the CPU
// field's texels (and those equal a fresh build of the same snapshots);
// a one-tile change uploads a few hundred bytes, an anchor move the whole
// 2 MiB map.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "gpu_context.hpp"
#include "gpu_memory.hpp"
#include "sky/weather/tiling.hpp"
#include "weather_field.hpp"
#include "weather_texture.hpp"

namespace sky::test {
namespace {

using render::WeatherField;

constexpr int kFineLevel = 11, kCoarseLevel = 9;

weather::CloudLayer tiledLayer(std::uint32_t id) {
  weather::CloudLayer l;
  l.id = id;
  l.base_m = 1000.0 * id;
  l.thickness_m = 800;
  return l;
}

void expectImageHoldsField(const render::GpuContext& ctx, const render::WeatherTexture& texture) {
  auto read = render::downloadImage(ctx, texture.image(), render::kWeatherChannels);
  ASSERT_TRUE(read) << describe(read.error());
  const auto& texels = texture.field().texels;
  ASSERT_EQ(read->size(), texels.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < texels.size(); ++i) differ += std::to_integer<std::uint8_t>((*read)[i]) != texels[i];
  EXPECT_EQ(differ, 0u) << "bytes of the GPU image that differ from the CPU field";
}

TEST(WeatherUpload, PartialUploadsKeepTheImageEqualToTheField) {
  auto ctx = render::GpuContext::create();
  if (!ctx) {
    if (ctx.error().code == ErrorCode::NoDevice) GTEST_SKIP() << describe(ctx.error());
    FAIL() << describe(ctx.error());
  }
  auto texture = render::WeatherTexture::create(**ctx);
  ASSERT_TRUE(texture) << describe(texture.error());

  const geo::Geodetic camera{47.0, 8.0, 3000.0};
  const auto fineCells = weather::coverCap({camera.lat_deg, camera.lon_deg, 120000.0}, kFineLevel, 8000);
  const auto coarseCells = weather::coverCap({camera.lat_deg, camera.lon_deg, 650000.0}, kCoarseLevel, 8000);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  weather::WeatherSnapshot fine, coarse;
  fine.tileLevel = kFineLevel;
  coarse.tileLevel = kCoarseLevel;
  fine.layers = coarse.layers = {tiledLayer(1), tiledLayer(2)};
  for (std::uint64_t cell : fineCells)
    if (u(rng) < 0.6f) fine.tiles.push_back({cell, std::uint32_t(1 + rng() % 2), u(rng), u(rng)});
  for (std::uint64_t cell : coarseCells)
    if (u(rng) < 0.6f) coarse.tiles.push_back({cell, std::uint32_t(1 + rng() % 2), u(rng), u(rng)});

  render::FrameInputs in;
  in.camera.position = camera;
  in.weather = &fine;
  in.coarseWeather = &coarse;
  ASSERT_TRUE(texture->update(**ctx, in));
  EXPECT_TRUE(texture->lastUpdate().rebuilt);
  const std::uint64_t wholeMap = texture->field().texels.size();
  EXPECT_EQ(texture->lastUpdate().bytesUploaded, wholeMap);
  expectImageHoldsField(**ctx, *texture);

  // Changes of 1 to 200 tiles in one snapshot or the other, and new tiles.
  int partial = 0;
  for (int step = 0; step < 12; ++step) {
    SCOPED_TRACE("step " + std::to_string(step));
    weather::WeatherSnapshot& s = step % 3 == 2 ? coarse : fine;
    const std::size_t k = std::array<std::size_t, 3>{1, 20, 200}[step % 3];
    for (std::size_t i = 0; i < k; ++i) s.tiles[rng() % s.tiles.size()].coverage = u(rng);
    if (step % 4 == 3) {  // a new tile, on a cell its layer has none on yet
      const auto& cells = &s == &fine ? fineCells : coarseCells;
      std::set<std::pair<std::uint64_t, std::uint32_t>> present;
      for (const auto& t : s.tiles) present.insert({t.cellId, t.layerId});
      for (std::uint64_t cell = cells[rng() % cells.size()];; cell = cells[rng() % cells.size()])
        if (!present.count({cell, 1u})) {
          s.tiles.push_back({cell, 1, u(rng), u(rng)});
          break;
        }
    }
    ASSERT_TRUE(texture->update(**ctx, in));
    const render::WeatherMapReport& report = texture->lastUpdate();
    if (!report.rebuilt) {
      ++partial;
      EXPECT_LT(report.bytesUploaded, wholeMap);
    }
    expectImageHoldsField(**ctx, *texture);
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_EQ(partial, 12) << "changed and new tiles only: no step needs a rebuild";
  // The field the GPU holds is the full build's.
  EXPECT_TRUE(texture->field().texels ==
              render::buildWeatherField(&fine, &coarse, render::weatherAnchorFor(camera)).texels);

  // One fine tile 20 km north of the camera (changed, or new): a rectangle
  // of a few texels each way in the fine ring.
  const std::uint64_t near = weather::cellAt(camera.lat_deg + 20000.0 / 111195.0, camera.lon_deg, kFineLevel);
  const auto it = std::find_if(fine.tiles.begin(), fine.tiles.end(), [&](const auto& t) { return t.cellId == near; });
  if (it != fine.tiles.end())
    it->coverage = it->coverage > 0.5f ? 0.1f : 0.9f;
  else
    fine.tiles.push_back({near, 1, 0.9f, 1.0f});
  ASSERT_TRUE(texture->update(**ctx, in));
  const render::WeatherMapReport one = texture->lastUpdate();
  std::printf("[ upload   ] one level-11 tile: %llu texels rewritten, %llu bytes uploaded (whole map %llu)\n",
              static_cast<unsigned long long>(one.texelsRewritten), static_cast<unsigned long long>(one.bytesUploaded),
              static_cast<unsigned long long>(wholeMap));
  EXPECT_FALSE(one.rebuilt);
  EXPECT_GT(one.texelsRewritten, 10u) << "a ~4.9 km cell covers tens of ~780 m texels";
  EXPECT_LT(one.texelsRewritten, 100u);
  EXPECT_LE(one.bytesUploaded, 16u * 16u * render::kWeatherChannels);
  expectImageHoldsField(**ctx, *texture);

  // The camera 20 km on: a new anchor, the whole map.
  in.camera.position.lat_deg += 20000.0 / 111195.0;
  ASSERT_TRUE(texture->update(**ctx, in));
  EXPECT_TRUE(texture->lastUpdate().rebuilt);
  EXPECT_EQ(texture->lastUpdate().reason, "anchor moved");
  EXPECT_EQ(texture->lastUpdate().bytesUploaded, wholeMap);
  expectImageHoldsField(**ctx, *texture);
}

}  // namespace
}  // namespace sky::test
