// The cloud depth the shared model returns (shaders/include/cloud_core.glsl,
// compiled as C++ in double precision): the mean distance at which the
// clouds take light out of the view ray. For a vertical ray through a
// uniform slab from d0 to d0 + H with extinction sigma it is, in closed
// form, d0 + 1/sigma - H e^(-sigma H) / (1 - e^(-sigma H)); the thin limit
// is the slab's middle, the thick one 1/sigma past its base; two slabs
// weight each one's depth by the light it removes, (1 - T1) and T1 (1 - T2);
// no cloud gives depth 0.
#include <cmath>

#include <gtest/gtest.h>

#include "core_harness.hpp"

namespace sky::test {
namespace {

constexpr double kEarth_m = 6371000, kAlt_m = 500, kBase_m = 1500, kThickness_m = 1000;

Core::CoreLayer slabLayer(const Core::CoreFrame& f, double base_m, double thickness_m, const Core::CloudType& t) {
  return shellLayer(f, kAlt_m, base_m, thickness_m, t);
}

Core::CoreFrame frame(Core& c, double sigma) {
  Core::CoreFrame f = frameOver(kEarth_m, kAlt_m, 0);
  f.layerCount = 1;
  c.layers[0] = slabLayer(f, kBase_m, kThickness_m, uniformType(sigma));
  return f;
}

// The closed form above for a slab starting d0 along the ray.
double slabDepth(double d0, double H, double sigma) {
  const double e = std::exp(-sigma * H);
  return d0 + 1 / sigma - H * e / (1 - e);
}

const Core::real3 kUp(0, 0, 1);

TEST(CloudDepth, VerticalSlabMatchesTheClosedForm) {
  Core c;
  // Each step's extinction sits at its middle (within half a step of where
  // it is inside the step); the march stops once 1 % of the light is left,
  // dropping at most that 1 % of the weight from the far side.
  const double tolerance = 0.5 * kThickness_m / Core::kPrimarySteps + 0.01 * kThickness_m;
  for (double sigma : {2e-4, 2e-3, 4e-3, 0.02}) {
    const auto r = c.shadePixel(frame(c, sigma), kUp, 0.5);
    const double want = slabDepth(kBase_m - kAlt_m, kThickness_m, sigma);
    EXPECT_NEAR(r.depth, want, tolerance) << "sigma " << sigma;
    EXPECT_GT(r.depth, kBase_m - kAlt_m);
    EXPECT_LT(r.depth, kBase_m + kThickness_m - kAlt_m);
  }
}

TEST(CloudDepth, ThinSlabGivesItsMiddleAndAThickOneOneOverSigmaPastItsBase) {
  Core c;
  EXPECT_NEAR(c.shadePixel(frame(c, 1e-9), kUp, 0.5).depth, kBase_m - kAlt_m + 0.5 * kThickness_m, 0.5);
  const auto thick = c.shadePixel(frame(c, 0.05), kUp, 0.5);
  EXPECT_LT(thick.transmittance, Core::kMinTransmittance);
  EXPECT_NEAR(thick.depth, kBase_m - kAlt_m + 1 / 0.05, 0.5 * kThickness_m / Core::kPrimarySteps);
}

TEST(CloudDepth, TwoSlabsWeighEachByTheLightItRemoves) {
  Core c;
  Core::CoreFrame f = frame(c, 1e-3);
  const double base2 = 6000, thick2 = 500, sigma2 = 2e-3;
  c.layers[1] = slabLayer(f, base2, thick2, uniformType(sigma2));
  f.layerCount = 2;
  const auto r = c.shadePixel(f, kUp, 0.5);
  const double T1 = std::exp(-1e-3 * kThickness_m), T2 = std::exp(-sigma2 * thick2);
  const double d1 = slabDepth(kBase_m - kAlt_m, kThickness_m, 1e-3), d2 = slabDepth(base2 - kAlt_m, thick2, sigma2);
  const double want = ((1 - T1) * d1 + T1 * (1 - T2) * d2) / (1 - T1 * T2);
  EXPECT_NEAR(r.transmittance, T1 * T2, 1e-4);
  EXPECT_NEAR(r.depth, want, 0.5 * kThickness_m / Core::kPrimarySteps);
}

TEST(CloudDepth, NoCloudGivesZero) {
  Core c;
  c.coverage = 0.0;
  const auto r = c.shadePixel(frame(c, 1e-3), kUp, 0.5);
  EXPECT_EQ(r.transmittance, 1.0);
  EXPECT_EQ(r.depth, 0.0);
  // Looking down from under the layer: the ray never enters it.
  c.coverage = 1.0;
  const auto down = c.shadePixel(frame(c, 1e-3), Core::real3(0, 0, -1), 0.5);
  EXPECT_EQ(down.transmittance, 1.0);
  EXPECT_EQ(down.depth, 0.0);
}

}  // namespace
}  // namespace sky::test
