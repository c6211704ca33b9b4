// Stability at the limits of the cloud model and the march (issue 7): the
// camera inside a layer of each of the ten cloud types, a layer as dense as
// the model allows (coverage 1, density 1, 9 km of cumulonimbus: optical
// depth in the thousands along a level ray) and a nearly transparent one,
// and the march at 1 and 4096 samples per layer span. Every frame must be
// finite on the GPU and agree with the double-precision CPU reference (the
// same model and the same march settings) within the bounds of
// stability_test.cpp; the step-count extremes must also bracket the truth:
// 4096 samples agree with the `reference` preset's 256, and 1 sample still
// draws a cloud of the right mean transmittance within a stated, much wider
// bound (a single sample per span is a crude Riemann sum, not garbage).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/presets.hpp"

namespace sky::test {
namespace {

// The bounds of stability_test.cpp (displayed RMSE relative to the
// reference's mean displayed value; relative difference of mean luminance).
constexpr double kRelativeRmseTolerance = 0.05;
constexpr double kRelativeMeanTolerance = 0.01;
// Small frames: the CPU reference costs samples x light samples per pixel,
// and inside a layer every ray marches through cloud to its end; smaller
// still for the 4096-sample march. (Measured, sanitized build, loaded
// machine: the ten types 14 s, the step counts 58 s, most of it building
// the renderers' and references' noise and tables.)
constexpr std::uint32_t kW = 32, kH = 18;
constexpr std::uint32_t kStepsW = 16, kStepsH = 9;

double meanTransmittance(const render::Image& im) {
  double t = 0;
  for (std::size_t i = 3; i < im.rgba.size(); i += 4) t += im.rgba[i];
  return t / double(im.rgba.size() / 4);
}

// The CPU reference for a renderer's settings (building its noise and tables
// takes seconds: once per renderer).
render::CpuReference referenceFor(const render::CloudRenderer& r) {
  auto reference = render::CpuReference::create(r.settings());
  EXPECT_TRUE(reference) << describe(reference.error());
  if (!reference) std::abort();
  return std::move(*reference);
}

// GPU and CPU reference agree on one frame; returns the GPU image.
render::Image expectAgreement(render::CloudRenderer& r, const render::CpuReference& reference,
                              const render::FrameInputs& in, const std::string& name) {
  auto gpu = r.render(in);
  EXPECT_TRUE(gpu) << describe(gpu.error());
  auto cpu = reference.render(in);
  EXPECT_TRUE(cpu) << describe(cpu.error());
  if (!gpu || !cpu) return {};
  savePng(*gpu, "limits_" + name);
  EXPECT_EQ(render::computeStats(*gpu).nonFinite, 0u) << name;
  EXPECT_EQ(render::computeStats(*cpu).nonFinite, 0u) << name;
  const Diff d = diff(*gpu, *cpu);
  const double mean = render::computeStats(*cpu).meanLuminance;
  const double meanError = std::abs(render::computeStats(*gpu).meanLuminance - mean) / mean;
  std::printf("[ limit    ] %-26s mean %.4g (gpu %+.3f %%) displayed rmse %.2f %%, T %.4f\n", name.c_str(), mean,
              100 * meanError, 100 * d.displayedRmse / d.displayedMean, meanTransmittance(*gpu));
  EXPECT_GT(mean, 0.0) << name;
  EXPECT_LT(meanError, kRelativeMeanTolerance) << name;
  EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean) << name;
  return std::move(*gpu);
}

struct TypedLayer {
  weather::CloudType type;
  double base_m, thickness_m;
};

// Each type at a height and depth it has in the weather (the cirriform ones
// thin and high, fog on the ground), the camera in the middle of it looking
// slightly up.
TEST(StabilityLimits, InsideALayerOfEveryCloudType) {
  SKY_RENDERER(r, kW, kH);
  const render::CpuReference reference = referenceFor(r);
  using T = weather::CloudType;
  const std::vector<TypedLayer> layers = {
      {T::Cumulus, 1500, 1500},      {T::Stratocumulus, 1200, 600}, {T::Stratus, 500, 400},
      {T::Nimbostratus, 1000, 2500}, {T::Cumulonimbus, 1000, 9000}, {T::Altocumulus, 4000, 800},
      {T::Altostratus, 4500, 1500},  {T::Cirrus, 9000, 400},        {T::Cirrostratus, 9000, 600},
      {T::Cirrocumulus, 8000, 300},  {T::Fog, 0, 200},             {T::Rain, 0, 1500},
      {T::Snow, 0, 1200},
  };
  for (const TypedLayer& t : layers) {
    const std::string name = std::string("inside_") + std::string(weather::toString(t.type));
    SCOPED_TRACE(name);
    weather::CloudLayer l = layer(1, t.base_m, t.thickness_m, 0.7, 1.0);
    l.type = t.type;
    weather::WeatherSnapshot snap;
    snap.layers = {l};
    render::FrameInputs in;
    in.camera = pose(47, 8, t.base_m + 0.5 * t.thickness_m, 30, 10);
    in.weather = &snap;
    in.sunElevation_deg = 35;
    expectAgreement(r, reference, in, name);
  }
}

// Density at both ends: the densest the model allows, looked through from
// inside (transmittance must reach 0 without overflow or NaN in the light
// march), and 1e-9 of it (the energy-conserving step's sigma -> 0 limit).
TEST(StabilityLimits, DensityHugeAndTiny) {
  SKY_RENDERER(r, kW, kH);
  const render::CpuReference reference = referenceFor(r);
  for (const double density : {1.0, 1e-9}) {
    const std::string name = density == 1.0 ? "densest_cumulonimbus" : "density_1e-9";
    SCOPED_TRACE(name);
    weather::CloudLayer l = layer(1, 1000, 9000, 1.0, density);
    l.type = weather::CloudType::Cumulonimbus;
    weather::WeatherSnapshot snap;
    snap.layers = {l};
    render::FrameInputs in;
    in.camera = pose(47, 8, 5000, 0, 0);
    in.weather = &snap;
    in.sunElevation_deg = 50;
    const render::Image im = expectAgreement(r, reference, in, name);
    if (im.rgba.empty()) continue;
    if (density == 1.0)
      EXPECT_LT(meanTransmittance(im), 0.02) << "inside 9 km of solid cloud no background shows";
    else
      EXPECT_GT(meanTransmittance(im), 0.999) << "1e-9 of the density is all but clear";
  }
}

// The march at its step-count limits, on a closed stratus deck seen from
// below (tau about 1-3 along these rays: a step count error shows in the
// transmittance). Bounds on the mean view-ray transmittance against the
// `reference` preset (256 samples): 4096 samples within 0.005 (both are
// converged), 1 sample within 0.15 (one midpoint sample per span: a coarse
// quadrature of a noisy deck; measured below).
TEST(StabilityLimits, StepCountsOneAnd4096) {
  render::FrameInputs in;
  in.camera = pose(47.0, 8.0, 500.0, 0.0, 45.0);
  weather::CloudLayer deck = layer(1, 1500, 1000, 0, 1);
  deck.type = weather::CloudType::Stratus;
  const weather::WeatherSnapshot thin = tiledSnapshot(in.camera.position, deck, 1.0f, 0.05f);
  in.weather = &thin;
  in.sunElevation_deg = 40;
  SKY_RENDERER(shared, kStepsW, kStepsH);  // skips without Vulkan; keeps the driver loaded
  (void)shared;
  auto renderer = [](std::uint32_t steps, std::uint32_t lightSteps) {
    render::RenderSettings s;
    s.width = kStepsW;
    s.height = kStepsH;
    s.march = render::findPreset("reference")->march;
    s.march.primarySteps = steps;
    s.march.lightSteps = lightSteps;
    return render::CloudRenderer::create(s);
  };
  const auto ref = render::findPreset("reference");
  ASSERT_TRUE(ref) << describe(ref.error());
  auto reference = renderer(ref->march.primarySteps, ref->march.lightSteps);
  ASSERT_TRUE(reference) << describe(reference.error());
  auto truth = (*reference)->render(in);
  ASSERT_TRUE(truth) << describe(truth.error());
  const double tRef = meanTransmittance(*truth);
  ASSERT_GT(tRef, 0.05);
  ASSERT_LT(tRef, 0.9);
  struct Case {
    std::uint32_t steps, lightSteps;
    double bound;
  };
  for (const Case c : {Case{1, 1, 0.15}, Case{4096, 2, 0.005}}) {
    const std::string name = "steps_" + std::to_string(c.steps);
    SCOPED_TRACE(name);
    auto r = renderer(c.steps, c.lightSteps);
    ASSERT_TRUE(r) << describe(r.error());
    const render::Image im = expectAgreement(**r, referenceFor(**r), in, name);
    if (im.rgba.empty()) continue;
    std::printf("[ limit    ] %-26s T %.4f, reference (%u samples) %.4f\n", name.c_str(), meanTransmittance(im),
                ref->march.primarySteps, tRef);
    EXPECT_NEAR(meanTransmittance(im), tRef, c.bound);
  }
  // Past the limit is refused, naming the field.
  render::RenderSettings tooMany;
  tooMany.width = kStepsW;
  tooMany.height = kStepsH;
  tooMany.march.primarySteps = 4097;
  auto refused = render::CloudRenderer::create(tooMany);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().detail.find("primarySteps"), std::string::npos) << refused.error().detail;
}

}  // namespace
}  // namespace sky::test
