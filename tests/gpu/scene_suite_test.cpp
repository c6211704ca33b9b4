// Issue 5's scene suite: six scenes (midday cumulus from below, sunset
// backlit, overcast stratus from below, a deck seen from 10 km, a
// cumulonimbus, cirrus over cumulus) rendered on the GPU and compared with
// the double-precision CPU reference on sampled pixels; no NaN or Inf; and a
// contact sheet of the six at 320x180 (output/scenes.png, the picture in
// docs/images/scenes.png).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/app/replay_outputs.hpp"
#include "sky/render/cpu_reference.hpp"

namespace sky::test {
namespace {

// Sampled pixels: one per 10x10 cell of the 160x90 image, jittered within
// the cell by a hash (288 with two per cell): the CPU reference costs ~ms per
// pixel under the sanitizers, the whole image would cost minutes.
constexpr std::uint32_t kW = 160, kH = 90, kCell = 10, kPerCell = 2;
// RMSE over the sampled rgb, of the displayed value x / (1 + x) (the
// compression any tonemap applies: a cloud edge in the sun's forward lobe
// reaches radiance ~100, where a 0.5 % difference of density is a linear
// error of 10 % of the whole image's mean but invisible), relative to the
// same compressed mean. Float against double (and lavapipe's 8-bit filter
// weights) move single samples across a soft cloud edge: measured 0.02-0.7 %
// on these scenes; 3 % flags a broken model, not rounding.
constexpr double kRelativeRmseTolerance = 0.03;
// Difference of the sampled mean luminance (linear), relative: a systematic
// error (a sign, a frame, a missing term) moves the mean; per-pixel noise
// does not. Measured under 0.4 %.
constexpr double kRelativeMeanTolerance = 0.015;
// Cloud transmittance (alpha), absolute RMSE: measured under 0.004.
constexpr double kAlphaRmseTolerance = 0.04;

std::uint32_t hash(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  return x ^ (x >> 16);
}

std::vector<render::PixelCoord> samplePixels() {
  std::vector<render::PixelCoord> out;
  for (std::uint32_t cy = 0; cy < kH / kCell; ++cy)
    for (std::uint32_t cx = 0; cx < kW / kCell; ++cx)
      for (std::uint32_t k = 0; k < kPerCell; ++k) {
        const std::uint32_t h = hash(cx * 7919u + cy * 104729u + k * 15485863u);
        out.push_back({cx * kCell + h % kCell, cy * kCell + (h / kCell) % kCell});
      }
  return out;
}

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }
double compressed(float v) { return double(v) / (1.0 + double(v)); }

TEST(Scenes, GpuMatchesTheCpuReferenceOnSampledPixels) {
  SKY_RENDERER(r, kW, kH);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const auto pixels = samplePixels();
  for (const Scene& scene : issueScenes()) {
    SCOPED_TRACE(scene.name);
    const render::FrameInputs in = scene.inputs();
    auto gpu = r.render(in);
    ASSERT_TRUE(gpu) << describe(gpu.error());
    EXPECT_EQ(render::computeStats(*gpu).nonFinite, 0u);
    savePng(*gpu, "scene_" + scene.name);
    auto cpu = reference->renderPixels(in, pixels);
    ASSERT_TRUE(cpu) << describe(cpu.error());
    double sum2 = 0, alpha2 = 0, meanGpu = 0, meanCpu = 0, meanCompressed = 0;
    std::size_t nonFinite = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const float* g = &gpu->rgba[(std::size_t(pixels[i].y) * kW + pixels[i].x) * 4];
      const float* c = (*cpu)[i].data();
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(c[k])) ++nonFinite;
      for (int k = 0; k < 3; ++k) {
        const double e = compressed(g[k]) - compressed(c[k]);
        sum2 += e * e;
        meanCompressed += compressed(c[k]);
      }
      alpha2 += double(g[3] - c[3]) * double(g[3] - c[3]);
      meanGpu += luminance(g);
      meanCpu += luminance(c);
    }
    const double n = double(pixels.size());
    meanGpu /= n;
    meanCpu /= n;
    meanCompressed /= 3 * n;
    const double rmse = std::sqrt(sum2 / (3 * n)), alphaRmse = std::sqrt(alpha2 / n);
    const double meanError = std::abs(meanGpu - meanCpu) / meanCpu;
    std::printf("[ scene    ] %-24s mean %.4f (gpu %+.3f %%) displayed rmse %.2f %% alpha rmse %.4f (%zu pixels)\n",
                scene.name.c_str(), meanCpu, 100 * (meanGpu - meanCpu) / meanCpu, 100 * rmse / meanCompressed,
                alphaRmse, pixels.size());
    EXPECT_EQ(nonFinite, 0u);
    EXPECT_GT(meanCpu, 0.0);
    EXPECT_LT(meanError, kRelativeMeanTolerance);
    EXPECT_LT(rmse, kRelativeRmseTolerance * meanCompressed);
    EXPECT_LT(alphaRmse, kAlphaRmseTolerance);
  }
}

// The look the scenes are for, in numbers: a blue sky, clouds that hide it,
// a grey overcast, a red sunset, and the six on one contact sheet.
TEST(Scenes, LookAndContactSheet) {
  SKY_RENDERER(r, 320, 180);
  app::ContactSheet sheet(3, 2, 320, 320, 180);
  for (const Scene& scene : issueScenes()) {
    SCOPED_TRACE(scene.name);
    auto image = r.render(scene.inputs());
    ASSERT_TRUE(image) << describe(image.error());
    const auto stats = render::computeStats(*image);
    EXPECT_EQ(stats.nonFinite, 0u);
    // Over all pixels: cloud transmittance, red over blue; over the cloud
    // pixels (alpha < 0.5): chroma relative to luminance.
    double alpha = 0, red = 0, blue = 0, cloudChroma = 0, cloudLuminance = 0;
    for (std::size_t i = 0; i < image->rgba.size(); i += 4) {
      const float* p = &image->rgba[i];
      alpha += p[3];
      red += p[0];
      blue += p[2];
      if (p[3] < 0.5f) {
        cloudChroma += std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
        cloudLuminance += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
      }
    }
    alpha /= double(image->rgba.size() / 4);
    const double relativeChroma = cloudLuminance > 0 ? cloudChroma / cloudLuminance : 0.0;
    std::printf("[ look     ] %-24s mean luminance %.3f, cloud transmittance %.3f, red/blue %.2f, cloud chroma %.3f\n",
                scene.name.c_str(), stats.meanLuminance, alpha, red / blue, relativeChroma);
    if (scene.name == "overcast_stratus_below") {
      // The top two thirds of the view look up at the deck: no sky there.
      double upper = 0;
      for (std::uint32_t y = 0; y < 120; ++y)
        for (std::uint32_t x = 0; x < 320; ++x) upper += image->rgba[(std::size_t(y) * 320 + x) * 4 + 3];
      EXPECT_LT(upper / (120.0 * 320.0), 0.02) << "a closed deck hides the sky";
      // Grey: a clear blue sky has max - min of about its luminance (0.5 -
      // 1.5 here); the deck a small fraction of it.
      EXPECT_LT(relativeChroma, 0.25) << "overcast is grey";
    } else if (scene.name == "sunset_backlit") {
      EXPECT_GT(red / blue, 1.5) << "light at a 4 degree sun is red";
    } else {
      EXPECT_LT(alpha, 0.95) << "there is cloud in view";
      EXPECT_GT(alpha, 0.05) << "and sky or ground between";
    }
    sheet.add(*image);
  }
  savePng(sheet.image(), "scenes");
  std::printf("[ sheet    ] %s/scenes.png\n", SKY_GPU_TEST_OUTPUT_DIR);
}

}  // namespace
}  // namespace sky::test
