// The weather map's coarse ring on the GPU: from cruise altitude (10 km), a
// patch of cumulus the server placed 250 km away, beyond the fine ring's
// 100 km, is drawn where the CPU reference draws it (the same rings, sampled
// in double) and makes cloud in the pixels looking at it; before the rings
// the map ended at 100 km and spans starting past 150 km were not marched,
// so it was empty. With the patch only in a second, coarser snapshot
// (FrameInputs::coarseWeather, level 10) and nothing there in the fine one,
// the GPU draws it where the CPU reference does, and without the coarse
// snapshot neither draws anything; a changed coarse tile then updates the
// map in place (a few texels, a small upload), an anchor move rebuilds it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/presets.hpp"
#include "sky/weather/tiling.hpp"

namespace sky::test {
namespace {

// Displayed RMSE (relative to the mean displayed value) and mean luminance
// tolerances as gpu_vs_cpu_test.cpp's (measured there 0-0.7 % and below
// 0.1 %); cloud transmittance RMSE as the scene suite's.
constexpr double kRelativeRmseTolerance = 0.05;
constexpr double kRelativeMeanTolerance = 0.005;
constexpr double kAlphaRmseTolerance = 0.04;

// 320x180 at 60 degrees: 1/3 degree per pixel; the patch is ~13 degrees
// wide, and seen edge-on, a degree or so tall.
constexpr std::uint32_t kW = 320, kH = 180;

const double kPatchLat = 47.0 + 250000.0 / 111195.0;

weather::CloudLayer cumulus() {
  weather::CloudLayer cu = layer(1, 1000.0, 1500.0, 0.0, 1.0);
  cu.type = weather::CloudType::Cumulus;
  return cu;
}

// Looking north, 3 degrees down: that ray enters the layer's top ~205 km
// out and is ~1.75 km up at 250 km (the Earth's curvature: d^2 / 2R =
// 4.9 km), so it crosses the patch inside its 60 km span.
render::FrameInputs farView(const weather::WeatherSnapshot* snap, const weather::WeatherSnapshot* coarse) {
  render::FrameInputs in;
  in.camera = pose(47.0, 8.0, 10000.0, 0.0, -3.0);
  in.weather = snap;
  in.coarseWeather = coarse;
  in.sunAzimuth_deg = 135.0;
  in.sunElevation_deg = 45.0;
  return in;
}

void expectFarCloud(render::CloudRenderer& r, const std::string& preset, const weather::WeatherSnapshot& snap,
                    const weather::WeatherSnapshot* coarse = nullptr) {
  SCOPED_TRACE(preset);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const render::FrameInputs in = farView(&snap, coarse);
  auto gpu = r.render(in);
  ASSERT_TRUE(gpu) << describe(gpu.error());
  savePng(*gpu, "gpu_far_cloud_" + preset);
  EXPECT_EQ(render::computeStats(*gpu).nonFinite, 0u);
  // The CPU reference on a window around the patch (rows 80-103, columns
  // 120-199) and the GPU on the same pixels.
  std::vector<render::PixelCoord> pixels;
  for (std::uint32_t y = 80; y < 104; ++y)
    for (std::uint32_t x = 120; x < 200; ++x) pixels.push_back({x, y});
  auto cpu = reference->renderPixels(in, pixels);
  ASSERT_TRUE(cpu) << describe(cpu.error());
  float minGpu = 1, minCpu = 1;
  std::size_t cloudyGpu = 0, nonFinite = 0;
  double alpha2 = 0, sum2 = 0, meanGpu = 0, meanCpu = 0, meanCompressed = 0;
  auto compressed = [](float v) { return double(v) / (1.0 + double(v)); };
  auto luminance = [](const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; };
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const float* g = &gpu->rgba[(std::size_t(pixels[i].y) * kW + pixels[i].x) * 4];
    const float* c = (*cpu)[i].data();
    for (int k = 0; k < 4; ++k)
      if (!std::isfinite(c[k])) ++nonFinite;
    for (int k = 0; k < 3; ++k) {
      sum2 += (compressed(g[k]) - compressed(c[k])) * (compressed(g[k]) - compressed(c[k]));
      meanCompressed += compressed(c[k]);
    }
    minGpu = std::min(minGpu, g[3]);
    minCpu = std::min(minCpu, c[3]);
    if (g[3] < 0.9f) ++cloudyGpu;
    alpha2 += double(g[3] - c[3]) * double(g[3] - c[3]);
    meanGpu += luminance(g);
    meanCpu += luminance(c);
  }
  const double n = double(pixels.size());
  const double alphaRmse = std::sqrt(alpha2 / n), rmse = std::sqrt(sum2 / (3 * n));
  meanCompressed /= 3 * n;
  const double meanError = std::abs(meanGpu - meanCpu) / meanCpu;
  std::printf("[ rings    ] %s far cloud: min transmittance gpu %.3f cpu %.3f, %zu pixels below 0.9; "
              "mean %.4f (gpu %+.3f %%) displayed rmse %.2f %% alpha rmse %.4f\n",
              preset.c_str(), minGpu, minCpu, cloudyGpu, meanCpu / n, 100 * (meanGpu - meanCpu) / meanCpu,
              100 * rmse / meanCompressed, alphaRmse);
  EXPECT_EQ(nonFinite, 0u);
  EXPECT_LT(minCpu, 0.2f) << "the CPU reference must see the patch through the coarse ring";
  EXPECT_LT(minGpu, 0.2f) << "the GPU must see the patch through the coarse ring";
  EXPECT_GT(cloudyGpu, std::size_t(20));
  EXPECT_LT(meanError, kRelativeMeanTolerance);
  EXPECT_LT(rmse, kRelativeRmseTolerance * meanCompressed);
  EXPECT_LT(alphaRmse, kAlphaRmseTolerance);
}

// The default march, and the march in metres (realtime), whose long steps
// skip on the max-coverage mip and whose layers are left out when the map
// has no coverage for them: both must take the coarse ring into account.
TEST(WeatherRings, FarCloudFromCruiseAltitude) {
  SKY_RENDERER(r, kW, kH);
  const weather::WeatherSnapshot snap = stormCell(cumulus(), kPatchLat, 8.0, 20000.0, 30000.0, 0.9f, 0.6f);
  expectFarCloud(r, "high", snap);
  const auto realtime = render::findPreset("realtime");
  ASSERT_TRUE(realtime) << describe(realtime.error());
  render::RenderSettings s = r.settings();
  s.march = realtime->march;
  auto fast = render::CloudRenderer::create(s);
  ASSERT_TRUE(fast) << describe(fast.error());
  expectFarCloud(**fast, "realtime", snap);
}

// The smallest transmittance in the window around the patch.
float minTransmittance(const render::Image& image) {
  float least = 1;
  for (std::uint32_t y = 80; y < 104; ++y)
    for (std::uint32_t x = 120; x < 200; ++x) least = std::min(least, image.rgba[(std::size_t(y) * kW + x) * 4 + 3]);
  return least;
}

TEST(WeatherRings, FarCloudFromTheCoarseSnapshot) {
  SKY_RENDERER(r, kW, kH);
  // The fine snapshot (level 11, 120 km around the camera) tiles the layer
  // with nothing; the coarse one (level 10, ~10 km cells) has the patch.
  weather::WeatherSnapshot fine;
  fine.tileLevel = 11;
  fine.layers = {cumulus()};
  for (std::uint64_t cell : weather::coverCap({47.0, 8.0, 120000.0}, 11, 8000))
    fine.tiles.push_back({cell, 1, 0.0f, 1.0f});
  weather::WeatherSnapshot coarse;
  coarse.tileLevel = 10;
  coarse.layers = fine.layers;
  for (std::uint64_t cell : weather::coverCap({kPatchLat, 8.0, 30000.0}, 10, 8000))
    coarse.tiles.push_back({cell, 1, 0.9f, 0.6f});
  ASSERT_GT(coarse.tiles.size(), 20u);
  expectFarCloud(r, "high, coarse snapshot", fine, &coarse);
  EXPECT_TRUE(r.lastWeatherMap().rebuilt);

  // Without the coarse snapshot ring 1 holds the fine snapshot's tiles,
  // which end at 120 km: clear air on the GPU and on the CPU.
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const render::FrameInputs without = farView(&fine, nullptr);
  auto gpu = r.render(without);
  ASSERT_TRUE(gpu) << describe(gpu.error());
  EXPECT_EQ(r.lastWeatherMap().reason, "coarse weather appeared or went away");
  EXPECT_GT(minTransmittance(*gpu), 0.999f);
  const std::vector<render::PixelCoord> probes = {{160, 90}, {150, 95}, {170, 100}};
  auto cpu = reference->renderPixels(without, probes);
  ASSERT_TRUE(cpu) << describe(cpu.error());
  for (const auto& p : *cpu) EXPECT_GT(p[3], 0.999f);

  // The coarse snapshot back, then one of its tiles changed: the map is
  // updated in place (its texels, a small rectangle) and still drawn as
  // the CPU reference draws it.
  auto before = r.render(farView(&fine, &coarse));
  ASSERT_TRUE(before) << describe(before.error());
  const std::uint64_t centre = weather::cellAt(kPatchLat, 8.0, 10);
  const auto it =
      std::find_if(coarse.tiles.begin(), coarse.tiles.end(), [&](const auto& t) { return t.cellId == centre; });
  ASSERT_NE(it, coarse.tiles.end());
  it->coverage = 0.0f;  // a hole in the middle of the patch
  expectFarCloud(r, "high, one coarse tile changed", fine, &coarse);
  const render::WeatherMapReport& report = r.lastWeatherMap();
  std::printf("[ rings    ] one coarse tile changed: rebuilt %d, %llu texels rewritten, %llu bytes uploaded\n",
              int(report.rebuilt), static_cast<unsigned long long>(report.texelsRewritten),
              static_cast<unsigned long long>(report.bytesUploaded));
  EXPECT_FALSE(report.rebuilt);
  EXPECT_GT(report.texelsRewritten, 0u);
  EXPECT_LT(report.texelsRewritten, 40u) << "a ~10 km cell holds a few ~4.7 km coarse texels";
  EXPECT_LT(report.bytesUploaded, 1024u);
  ASSERT_TRUE(r.render(farView(&fine, &coarse)));
  EXPECT_EQ(r.lastWeatherMap().texelsRewritten, 0u) << "the same weather again: nothing to do";
  // Seen edge-on the patch stays opaque through one hole; with its eastern
  // half cleared (tiles changed, still no rebuild) the GPU shows it gone
  // and still agrees with the CPU reference.
  for (auto& tile : coarse.tiles)
    if (weather::cellCentre(tile.cellId).lon_deg > 8.0) tile.coverage = 0.0f;
  expectFarCloud(r, "high, eastern half cleared", fine, &coarse);
  EXPECT_FALSE(r.lastWeatherMap().rebuilt);
  auto after = r.render(farView(&fine, &coarse));
  ASSERT_TRUE(after) << describe(after.error());
  std::size_t clearer = 0;
  for (std::size_t i = 3; i < after->rgba.size(); i += 4) clearer += after->rgba[i] > before->rgba[i] + 0.05f;
  EXPECT_GT(clearer, 10u) << "pixels that now see through where the eastern half was";
}

}  // namespace
}  // namespace sky::test
