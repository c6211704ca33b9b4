// The cloud depth the shared model returns (shaders/include/cloud_core.glsl,
// compiled as C++ in double precision): for a vertical ray through a slab of
// uniform density, the depth is the mean distance at which the slab takes
// light out of the ray, the integral of t sigma(t) exp(-tau(t)) over the
// integral of sigma(t) exp(-tau(t)), computed here by fine quadrature; the
// thin-slab limit is the centroid of the layer's height profile; the thick
// limit lies about 1/sigma past the base; no cloud gives depth 0.
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "sky_shared.h"

namespace sky::render {
namespace {

using namespace glm;
using gpu::kMaxLayers;

// The core with uniform texture hooks: full coverage, noise 1, the density a
// test sets.
class Core {
 public:
  using real = double;
  using real2 = glm::dvec2;
  using real3 = glm::dvec3;
  using uint = std::uint32_t;

  real density = 1.0;
  real2 sampleWeather(int, real3) const { return real2(1.0, density); }
  real sampleNoise(int, real3) const { return 1.0; }
  real sampleCloudMap(int, real3) const { return 0.5; }

#define SKY_CORE_CONST static constexpr
#include "cloud_core.glsl"
#undef SKY_CORE_CONST
};

constexpr double kEarthRadius_m = 6371000, kCameraAlt_m = 500, kBase_m = 1500, kThickness_m = 1000;

Core::CoreFrame slabFrame() {
  Core::CoreFrame f{};
  f.r = kEarthRadius_m + kCameraAlt_m;
  f.cGround = kCameraAlt_m * (2 * f.r - kCameraAlt_m);
  f.sunDir = Core::real3(0, 0, 1);
  f.sunRadiance = Core::real3(1);
  f.ambient = Core::real3(0.1);
  f.layerCount = 1;
  const double hBase = kCameraAlt_m - kBase_m, hTop = kCameraAlt_m - (kBase_m + kThickness_m);
  f.layers[0] = Core::CoreLayer(hBase, hTop, hBase * (2 * f.r - hBase), hTop * (2 * f.r - hTop), kThickness_m);
  for (unsigned i = 1; i < kMaxLayers; ++i) f.layers[i] = Core::CoreLayer(0, 0, 0, 0, 1);
  return f;
}

// The layer's height profile written out by hand (cloud_core.glsl: ramps
// over the bottom 10 % and the top 20 % of the thickness).
double profile(double ph) {
  if (ph <= 0 || ph >= 1) return 0;
  return std::min(1.0, ph / 0.1) * std::min(1.0, (1 - ph) / 0.2);
}

// Extinction-weighted mean distance along the vertical ray, by the midpoint
// rule on 200 000 sub-steps (5 mm), with tau integrated alongside.
double exactDepth(double sigmaPerDensity_perm, double density) {
  constexpr int kN = 200000;
  const double d0 = kBase_m - kCameraAlt_m, dt = kThickness_m / kN;
  double tau = 0, num = 0, den = 0;
  for (int i = 0; i < kN; ++i) {
    const double t = d0 + (i + 0.5) * dt;
    const double sigma = sigmaPerDensity_perm * density * profile((t - d0) / kThickness_m);
    const double w = sigma * std::exp(-(tau + 0.5 * sigma * dt)) * dt;
    num += t * w;
    den += w;
    tau += sigma * dt;
  }
  return num / den;
}

Core::PixelResult shadeUp(Core& c) { return c.shadePixel(slabFrame(), Core::real3(0, 0, 1), 0.5); }

TEST(CloudDepth, VerticalSlabMatchesTheExtinctionWeightedMeanDistance) {
  Core c;
  // The march puts each step's extinction at the step's middle; the true
  // extinction-weighted position inside a step is within half a step of it.
  const double halfStep_m = 0.5 * kThickness_m / Core::kPrimarySteps;
  for (double density : {0.002, 0.05, 0.3}) {
    c.density = density;
    const auto r = shadeUp(c);
    const double want = exactDepth(Core::kExtinctionPerDensity_perm, density);
    EXPECT_NEAR(r.depth, want, halfStep_m) << "density " << density;
    EXPECT_GT(r.depth, kBase_m - kCameraAlt_m);
    EXPECT_LT(r.depth, kBase_m + kThickness_m - kCameraAlt_m);
  }
}

TEST(CloudDepth, ThinSlabGivesTheProfileCentroid) {
  Core c;
  c.density = 1e-9;
  // Centroid of the trapezoid profile, by hand: pieces [0, 0.1] rising,
  // [0.1, 0.8] flat, [0.8, 1] falling (fractions of H): area 0.85 H; first
  // moment 0.1^2/3 + (0.8^2 - 0.1^2)/2 + 0.2 (0.8 + 0.2/3) / 2 = 0.405 H^2;
  // centroid 0.405 / 0.85 = 0.476 H above the base.
  const double m1 = 0.01 / 3 + (0.64 - 0.01) / 2 + 0.2 * (0.8 + 0.2 / 3) / 2;
  const double centroid = kBase_m - kCameraAlt_m + kThickness_m * m1 / 0.85;
  const auto r = shadeUp(c);
  EXPECT_NEAR(r.depth, centroid, 0.5);
  EXPECT_NEAR(r.depth, exactDepth(Core::kExtinctionPerDensity_perm, 1e-9), 0.5);
}

TEST(CloudDepth, ThickSlabStopsTheRayNearItsBase) {
  Core c;
  c.density = 1.0;  // sigma_t = 0.05 /m: the ray is gone within the base ramp
  const auto r = shadeUp(c);
  EXPECT_LT(r.transmittance, Core::kMinTransmittance);
  EXPECT_GT(r.depth, kBase_m - kCameraAlt_m);
  EXPECT_LT(r.depth, kBase_m - kCameraAlt_m + 0.1 * kThickness_m);
  EXPECT_NEAR(r.depth, exactDepth(Core::kExtinctionPerDensity_perm, 1.0),
              0.5 * kThickness_m / Core::kPrimarySteps);
}

TEST(CloudDepth, NoCloudGivesZero) {
  Core c;
  c.density = 0.0;
  const auto r = shadeUp(c);
  EXPECT_EQ(r.transmittance, 1.0);
  EXPECT_EQ(r.depth, 0.0);
  // Looking down from under the layer: the ray never enters it.
  c.density = 1.0;
  const auto down = c.shadePixel(slabFrame(), Core::real3(0, 0, -1), 0.5);
  EXPECT_EQ(down.transmittance, 1.0);
  EXPECT_EQ(down.depth, 0.0);
}

}  // namespace
}  // namespace sky::render
