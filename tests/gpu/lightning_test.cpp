// Lightning on the GPU against the CPU reference and against closed forms:
// an in-cloud flash lighting its deck at night and a cloud-to-ground bolt
// under it (the same image from both within the GPU/CPU bounds of
// gpu_vs_cpu_test.cpp), the bolt's light across its line equal to the
// channel's intensity over its distance (a line source), the flash's light
// gone a lifetime later, and an interleaved renderer drawing a flash-lit
// frame whole (no history holds a flash).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "flash_setup.hpp"
#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/cpu_reference.hpp"

namespace sky::test {
namespace {

constexpr double kRelativeRmseTolerance = 0.05;  // as gpu_vs_cpu_test.cpp
constexpr double kRelativeMeanTolerance = 0.005;
constexpr double kDegPerM = 1.0 / 111'195.0;     // of latitude, on the mean sphere

// A night deck (sun 20 degrees below the horizon, no moon) from 1500 to
// 2500 m over a camera at 600 m looking up along heading 0.
struct NightDeck {
  geo::GeodeticPose camera = pose(47, 8, 600, 0, 20);
  weather::WeatherSnapshot snapshot;
  NightDeck() { snapshot.layers.push_back(layer(1, 1500, 1000, 0.8, 1.0)); }
  render::FrameInputs inputs(const std::vector<weather::LightningFlash>& flashes, double clock_s) const {
    render::FrameInputs in;
    in.camera = camera;
    in.weather = &snapshot;
    in.weatherClock_s = clock_s;
    in.sunElevation_deg = -20;
    in.moonElevation_deg = -30;
    in.flashes = flashes;
    return in;
  }
};

weather::LightningFlash flashAhead(double ahead_m, weather::FlashKind kind, double bottom_m, double top_m) {
  weather::LightningFlash f;
  f.seed = 2024;
  f.time_s = 100.0;
  f.lat_deg = 47 + ahead_m * kDegPerM;
  f.lon_deg = 8;
  f.kind = kind;
  f.bottom_m = bottom_m;
  f.top_m = top_m;
  f.energy_j = 1e9;
  return f;
}

void expectAgree(const render::Image& gpu, const render::Image& cpu, const char* name) {
  savePng(gpu, std::string("gpu_lightning_") + name);
  savePng(cpu, std::string("cpu_lightning_") + name);
  const Diff d = diff(gpu, cpu);
  const double mean = render::computeStats(cpu).meanLuminance;
  const double meanError = std::abs(render::computeStats(gpu).meanLuminance - mean) / mean;
  std::printf("[ lightning] %-14s mean %.4g (gpu %+.3f %%) displayed rmse %.2f %%\n", name, mean, 100 * meanError,
              100 * d.displayedRmse / d.displayedMean);
  EXPECT_LT(meanError, kRelativeMeanTolerance) << name;
  EXPECT_EQ(render::computeStats(gpu).nonFinite, 0u) << name;
  EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean) << name;
}

TEST(Lightning, AFlashLightsItsCloudAsTheReferenceDoes) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const NightDeck scene;
  const double clock = 100.0 + 0.02;  // the exposure (1/30 s) holds the first stroke
  const auto dark = reference->render(scene.inputs({}, clock));
  ASSERT_TRUE(dark);
  for (const auto& [name, flash] :
       {std::pair{"in_cloud", flashAhead(3000, weather::FlashKind::InCloud, 1700, 2300)},
        std::pair{"ground", flashAhead(4000, weather::FlashKind::CloudToGround, 0, 1500)}}) {
    const std::vector<weather::LightningFlash> flashes{flash};
    auto gpu = r.render(scene.inputs(flashes, clock));
    ASSERT_TRUE(gpu) << describe(gpu.error());
    auto cpu = reference->render(scene.inputs(flashes, clock));
    ASSERT_TRUE(cpu) << describe(cpu.error());
    expectAgree(*gpu, *cpu, name);
    // At night the flash is most of the light: the deck it lights is far
    // brighter than the deck under the night sky alone.
    EXPECT_GT(render::computeStats(*cpu).meanLuminance, 10 * render::computeStats(*dark).meanLuminance) << name;
    // A lifetime later it gives none: the image is the dark one again.
    auto after = r.render(scene.inputs(flashes, 100.0 + weather::kFlashLifetime_s + 0.1));
    ASSERT_TRUE(after);
    EXPECT_NEAR(render::computeStats(*after).meanLuminance, render::computeStats(*dark).meanLuminance,
                0.01 * render::computeStats(*dark).meanLuminance)
        << name;
  }
}

// The bolt's light over the whole image (the excess over the same frame
// without it, summed over the pixels times their solid angle) is the line
// source's: each segment's intensity per metre over its distance, times its
// length across the view over its distance, seen through the air between.
// The channel's own air is bounded, not computed: the sum is within [0.85,
// 1.05] of the segments' sum without the air (a few kilometres of clear air
// at night take 3-10 %). The deck is high (8 km), so the flash's light
// there (six and a half kilometres of glow above the bolt) adds nothing
// measurable.
TEST(Lightning, TheBoltCarriesTheChannelsLight) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp); skips without a device
  (void)shared;
  render::RenderSettings settings;
  settings.width = 160;
  settings.height = 90;
  auto reference = render::CpuReference::create(settings);
  ASSERT_TRUE(reference) << describe(reference.error());
  NightDeck scene;
  scene.camera = pose(47, 8, 700, 0, 0);
  scene.snapshot.layers = {layer(1, 8000, 500, 0.3, 1.0)};
  const double clock = 100.0 + 0.02;
  const std::vector<weather::LightningFlash> flashes{flashAhead(3000, weather::FlashKind::CloudToGround, 0, 1500)};
  auto lit = reference->render(scene.inputs(flashes, clock));
  ASSERT_TRUE(lit);
  auto dark = reference->render(scene.inputs({}, clock));
  ASSERT_TRUE(dark);
  savePng(*lit, "cpu_lightning_bolt");
  const double pixelAngle = 2 * std::tan(settings.verticalFov_deg * std::numbers::pi / 360.0) / settings.height;
  double sum = 0;
  for (std::size_t i = 0; i < lit->rgba.size(); i += 4)
    sum += (0.2126 * (lit->rgba[i] - dark->rgba[i]) + 0.7152 * (lit->rgba[i + 1] - dark->rgba[i + 1]) +
            0.0722 * (lit->rgba[i + 2] - dark->rgba[i + 2])) *
           pixelAngle * pixelAngle;
  // The channel as the frame draws it, in the camera's frame.
  const render::FlashSetup setup = render::prepareFlashes(flashes, clock, render::kDefaultExposure_s,
                                                          geo::enuFrameAt(scene.camera.position), pixelAngle);
  ASSERT_FALSE(setup.boltStart.empty());
  double expected = 0;
  for (std::size_t k = 0; k < setup.boltStart.size(); ++k) {
    const glm::dvec3 a(setup.boltStart[k]), b = setup.boltEnd[k];
    const double angular = std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0));
    expected += setup.boltStart[k].w * angular / glm::length(0.5 * (a + b));
  }
  expected *= 0.2126 * 0.85 + 0.7152 * 0.9 + 0.0722 * 1.0;  // lightning.glsl's flash colour, as luminance
  std::printf("[ lightning] bolt 3 km ahead: image sum %.4g, the segments' %.4g (ratio %.3f)\n", sum, expected,
              sum / expected);
  EXPECT_GT(sum, 0.85 * expected);
  EXPECT_LT(sum, 1.05 * expected);
}

TEST(Lightning, AnInterleavedRendererDrawsAFlashLitFrameWhole) {
  render::RenderSettings s;
  s.width = 64;
  s.height = 36;
  s.temporal.interleave = 2;
  SKY_RENDERER(shared, 64, 36);
  (void)shared;
  auto created = render::CloudRenderer::create(s);
  ASSERT_TRUE(created) << describe(created.error());
  render::CloudRenderer& r = **created;
  const NightDeck scene;
  const std::vector<weather::LightningFlash> flashes{flashAhead(3000, weather::FlashKind::InCloud, 1700, 2300)};
  ASSERT_TRUE(r.render(scene.inputs(flashes, 99.0)));   // before the flash: nothing lit
  ASSERT_TRUE(r.render(scene.inputs(flashes, 99.05)));
  EXPECT_FALSE(r.lastTemporal().drawnWhole) << r.lastTemporal().reason;
  ASSERT_TRUE(r.render(scene.inputs(flashes, 100.02)));
  EXPECT_TRUE(r.lastTemporal().drawnWhole);
  EXPECT_EQ(r.lastTemporal().reason, "lightning");
}

}  // namespace
}  // namespace sky::test
