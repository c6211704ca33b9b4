// Haggstrom 2018's coverage- and density-dependent step lengths (sec.
// 4.2.2-4.2.3, eq. 34 and 36; MarchSettings::coverageStepMin and
// densityStepMin): the factor against hand-evaluated values of the
// equations, a layer's means over the weather map's fine ring, the settings'
// checks, and the factor's effect on the march (the shared core in double
// precision, then the CPU reference end to end).
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <gtest/gtest.h>

#include "core_harness.hpp"
#include "frame_setup.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/weather/model.hpp"

namespace sky::test {
namespace {

using render::stepLengthFactor;

// Eq. 34, max(m, min(1, m + (gc - 0.2) / 0.5 (1 - m))), by hand: m at gc 0.2
// and below, 1 from 0.7 up, linear between.
TEST(StepFactor, CoverageRampIsEquation34) {
  EXPECT_NEAR(stepLengthFactor(0.2, 1.0, 0.4, 1.0), 0.4, 1e-12);
  EXPECT_NEAR(stepLengthFactor(0.45, 1.0, 0.4, 1.0), 0.7, 1e-12);   // 0.4 + 0.5 * 0.6
  EXPECT_NEAR(stepLengthFactor(0.3, 1.0, 0.4, 1.0), 0.52, 1e-12);   // 0.4 + 0.2 * 0.6
  EXPECT_NEAR(stepLengthFactor(0.7, 1.0, 0.4, 1.0), 1.0, 1e-12);
  EXPECT_NEAR(stepLengthFactor(0.95, 1.0, 0.4, 1.0), 1.0, 1e-12);
  EXPECT_NEAR(stepLengthFactor(0.0, 1.0, 0.4, 1.0), 0.4, 1e-12);    // below the ramp: multmin
  EXPECT_NEAR(stepLengthFactor(0.2, 1.0, 0.1, 1.0), 0.1, 1e-12);    // his eq. 35 at gc 0.2
  EXPECT_NEAR(stepLengthFactor(0.45, 1.0, 0.1, 1.0), 0.55, 1e-12);  // 0.1 + 0.5 * 0.9
}

// Eq. 36, 1 / max(gd, d)^0.8: 0.4^-0.8 = e^(0.8 x 0.91629) = 2.08138, 0.5^-0.8 = 2^0.8 = 1.74110,
// 0.1^-0.8 = 10^0.8 = 6.30957 (by hand, logarithms).
TEST(StepFactor, DensityFactorIsEquation36) {
  EXPECT_NEAR(stepLengthFactor(1.0, 0.1, 1.0, 0.4), 2.08138, 1e-5);
  EXPECT_NEAR(stepLengthFactor(1.0, 0.4, 1.0, 0.4), 2.08138, 1e-5);
  EXPECT_NEAR(stepLengthFactor(1.0, 0.5, 1.0, 0.4), 1.74110, 1e-5);
  EXPECT_NEAR(stepLengthFactor(1.0, 0.05, 1.0, 0.1), 6.30957, 1e-5);
  EXPECT_NEAR(stepLengthFactor(1.0, 1.0, 1.0, 0.1), 1.0, 1e-12);
  // Both: the product, 0.7 x 2.08138.
  EXPECT_NEAR(stepLengthFactor(0.45, 0.1, 0.4, 0.4), 1.456966, 1e-5);
}

TEST(StepFactor, OneTurnsEachFactorOff) {
  for (double c : {0.0, 0.1, 0.2, 0.5, 1.0})
    for (double d : {0.0, 0.05, 0.3, 1.0}) {
      EXPECT_EQ(stepLengthFactor(c, d, 1.0, 1.0), 1.0) << c << " " << d;
      EXPECT_NEAR(stepLengthFactor(c, d, 1.0, 0.4), stepLengthFactor(1.0, d, 0.4, 0.4), 1e-12);
    }
}

// A slice of the fine ring with a quarter of its texels at coverage 1 and
// density 0.2, a quarter at coverage 0.2 and density 1, the rest clear: mean
// coverage 0.25 + 0.05 = 0.3; density where covered (0.25 x 0.2 + 0.05 x 1)
// / 0.3 = 1/3. The coarse ring does not count; an empty slice is {0, 1}.
TEST(StepFactor, FineRingMeansWeighTheDensityByCoverage) {
  render::WeatherField field;
  field.sliceCount = gpu::kMaxLayers;
  const std::size_t n = field.size;
  field.texels.assign(std::size_t(render::kWeatherRings) * field.sliceCount * n * n * 4, 0);
  auto texel = [&](std::uint32_t ring, std::uint32_t slice, std::size_t k) {
    return &field.texels[((std::size_t(ring) * field.sliceCount + slice) * n * n + k) * 4];
  };
  for (std::size_t k = 0; k < n * n; ++k) {
    std::uint8_t* t = texel(0, 2, k);
    if (k % 4 == 0) t[0] = 255, t[1] = 51;  // 51 / 255 = 0.2
    if (k % 4 == 1) t[0] = 51, t[1] = 255;
    texel(1, 2, k)[0] = 255;  // the coarse ring, full: ignored
    texel(1, 2, k)[1] = 255;
  }
  const render::LayerMeans m = render::fineRingMeans(field, 2);
  EXPECT_NEAR(m.coverage, 0.3, 1e-12);
  EXPECT_NEAR(m.density, 1.0 / 3.0, 1e-12);
  const render::LayerMeans empty = render::fineRingMeans(field, 1);
  EXPECT_EQ(empty.coverage, 0.0);
  EXPECT_EQ(empty.density, 1.0);
}

TEST(StepFactor, SettingsAreChecked) {
  render::RenderSettings s;
  s.march.cloudStep_m = 40;
  s.march.emptyStep_m = 80;
  s.march.coverageStepMin = 0.4;
  s.march.densityStepMin = 0.4;
  EXPECT_TRUE(render::validateSettings(s));
  for (double bad : {0.0, -0.1, 1.01, std::nan("")}) {
    render::RenderSettings c = s;
    c.march.coverageStepMin = bad;
    auto r = render::validateSettings(c);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().detail.find("march.coverageStepMin"), std::string::npos) << r.error().detail;
    c = s;
    c.march.densityStepMin = bad;
    r = render::validateSettings(c);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().detail.find("march.densityStepMin"), std::string::npos) << r.error().detail;
  }
  // Even placement has no step length to scale: refused unless off.
  render::RenderSettings even;
  EXPECT_TRUE(render::validateSettings(even));
  even.march.densityStepMin = 0.4;
  auto r = render::validateSettings(even);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().detail.find("march.densityStepMin"), std::string::npos) << r.error().detail;
}

// A uniform slab (extinction 1e-3 /m, 1500-2500 m over a camera at 500 m)
// marched in metres with the layer's step factor: the steps still tile the
// span and each is exact for a constant extinction, so the transmittance
// stays exp(-sigma L); the lookups scale as 1 / factor (5 per short step:
// weather, cloud map, shape and 2 light steps; march_steps_test.cpp).
TEST(StepFactor, TheFactorScalesTheStepsOfTheMarch) {
  const double sigma = 1e-3, alt = 500, base = 1500, H = 1000;
  std::uint64_t lookups[3] = {};
  const double factors[3] = {1.0, 2.0, 0.5};
  for (int k = 0; k < 3; ++k) {
    Core c;
    Core::CoreFrame f = frameOver(6371000, alt, 1);
    f.march = Core::MarchParams{4096, 2, 0.0, 1.0, 20, 20, 0.0};
    f.layerCount = 1;
    c.layers[0] = shellLayer(f, alt, base, H, uniformType(sigma));
    c.layers[0].stepFactor = factors[k];
    const Core::Span sp = c.layerSpan(f, c.layers[0], 1.0, 1e12);
    const Core::LayerResult res = c.marchLayer(f, 0, Core::real3(0, 0, 1), sp, 0.5, 1.0);
    EXPECT_NEAR(res.transmittance, std::exp(-sigma * H), 1e-4) << factors[k];
    lookups[k] = c.lookups;
  }
  // 1000 m in steps of 20, 40 and 10 m: 50, 25 and 100 short steps, after
  // the first long step's probe (3 lookups) that finds the cloud.
  const std::uint64_t shortSteps[3] = {50, 25, 100};
  for (int k = 0; k < 3; ++k) {
    EXPECT_GE(lookups[k], 3 + (shortSteps[k] - 1) * 5) << factors[k];
    EXPECT_LE(lookups[k], 3 + (shortSteps[k] + 1) * 5) << factors[k];
  }
}

// End to end through the CPU reference: a thin cumulus layer (density 0.15)
// with medium's steps; divmin 0.2 makes them 0.2^-0.8 = 3.6 times longer.
// The lookups must fall (the frame setup carried the factor to the march)
// and the image must change, but stay near the factor-off image: the longer
// steps are still exact for the extinction at each sample, so only the
// noise's structure below ~150 m moves; a mean luminance within 5 % and a
// mean absolute difference under 10 % of the mean bound that. The air's
// cloud shadows are off: their weather lookups (two per air step, half the
// frame's) do not depend on the march's steps, and the count is the march's.
TEST(StepFactor, DivminLengthensTheStepsOfAThinLayer) {
  render::RenderSettings settings;
  settings.march.cloudShadows = false;
  settings.width = 32;
  settings.height = 18;
  settings.march.primarySteps = 256;
  settings.march.lightSteps = 2;
  settings.march.cloudStep_m = 40;
  settings.march.emptyStep_m = 80;
  settings.march.stepGrowth = 0.01;
  render::RenderSettings thin = settings;
  thin.march.densityStepMin = 0.2;
  auto off = render::CpuReference::create(settings);
  auto on = render::CpuReference::create(thin);
  ASSERT_TRUE(off && on);
  weather::WeatherSnapshot snap;
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1200;
  l.thickness_m = 1500;
  l.coverage = 0.6;
  l.density = 0.15;
  snap.layers = {l};
  render::FrameInputs in;
  in.camera.position = {47.0, 8.0, 500.0};
  in.camera.pitch_deg = 15;
  in.weather = &snap;
  std::uint64_t lookupsOff = 0, lookupsOn = 0;
  auto a = off->render(in, &lookupsOff);
  auto b = on->render(in, &lookupsOn);
  ASSERT_TRUE(a && b);
  const double meanOff = render::computeStats(*a).meanLuminance, meanOn = render::computeStats(*b).meanLuminance;
  double absDiff = 0;
  for (std::size_t i = 0; i < a->rgba.size(); ++i) absDiff += std::abs(double(a->rgba[i]) - double(b->rgba[i]));
  absDiff /= double(a->rgba.size());
  std::printf("divmin 0.2 on density 0.15: lookups %llu -> %llu, mean luminance %.5f -> %.5f, mean |diff| %.5f\n",
              (unsigned long long)lookupsOff, (unsigned long long)lookupsOn, meanOff, meanOn, absDiff);
  EXPECT_LT(double(lookupsOn), 0.7 * double(lookupsOff));
  EXPECT_GT(absDiff, 0.0);
  EXPECT_LT(std::abs(meanOn - meanOff), 0.05 * meanOff);
  EXPECT_LT(absDiff, 0.1 * meanOff);
}

}  // namespace
}  // namespace sky::test
