// The shared cloud model (shaders/include/cloud_core.glsl) compiled as C++ in
// double precision, checked against closed forms: every phase function
// integrates to 1 over the sphere; the Jendersie-d'Eon fit reproduces the
// parameters published for 10 um droplets; Wrenninge's octave sum with a <= b
// never exceeds the sum of its weights; the march through a slab transmits
// exp(-sigma_t * integral of the density) (the layer's trapezoid profile,
// integrated by hand); ray-shell distances equal hand-computed ones for
// vertical, horizontal and grazing rays.
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "sky_shared.h"

namespace sky::render {
namespace {

using namespace glm;
using gpu::kMaxLayers;

// The core inside a class whose texture hooks return what a test sets: a
// uniform field.
class Core {
 public:
  using real = double;
  using real2 = glm::dvec2;
  using real3 = glm::dvec3;
  using uint = std::uint32_t;

  real coverage = 1.0, density = 1.0, noise = 1.0;
  real2 sampleWeather(int, real3) const { return real2(coverage, density); }
  real sampleNoise(int, real3) const { return noise; }
  real sampleCloudMap(int, real3) const { return 0.5; }

#define SKY_CORE_CONST static constexpr
#include "cloud_core.glsl"
#undef SKY_CORE_CONST
};

constexpr double kPi = 3.14159265358979323846;

// Integral over the sphere of an axially symmetric p(cos theta): 2 pi times
// the integral over theta of p sin(theta), midpoint rule on a grid fine
// enough for the 0.988-eccentric lobe (width ~0.01 rad).
template <class F>
double sphereIntegral(F p) {
  constexpr int kN = 400000;
  double sum = 0;
  for (int i = 0; i < kN; ++i) {
    const double th = (i + 0.5) * kPi / kN;
    sum += p(std::cos(th)) * std::sin(th);
  }
  return 2 * kPi * sum * kPi / kN;
}

TEST(CloudCore, PhaseFunctionsIntegrateToOne) {
  Core c;
  for (double g : {0.0, 0.3, 0.6, 0.9, 0.99, -0.5})
    EXPECT_NEAR(sphereIntegral([&](double mu) { return c.phaseHG(mu, g); }), 1.0, 1e-3) << "HG g=" << g;
  for (double alpha : {0.0, 1.0, 22.0})
    EXPECT_NEAR(sphereIntegral([&](double mu) { return c.phaseDraine(mu, 0.556, alpha); }), 1.0, 1e-3)
        << "Draine alpha=" << alpha;
  for (double d : {5.0, 10.0, 20.0, 50.0}) {
    const auto m = c.mieFit(d);
    for (double scale : {1.0, 0.5, 0.125})
      EXPECT_NEAR(sphereIntegral([&](double mu) { return c.phaseMie(mu, m, scale); }), 1.0, 1e-3)
          << "Mie d=" << d << " scale=" << scale;
  }
}

TEST(CloudCore, MieFitMatchesThePublishedParametersAt10um) {
  Core c;
  const auto m = c.mieFit(10.0);
  // formulas.md (Jendersie & d'Eon 2023) at d = 10 um.
  EXPECT_NEAR(m.gHG, 0.9882, 5e-4);
  EXPECT_NEAR(m.gD, 0.556, 5e-4);
  EXPECT_NEAR(m.alpha, 21.99, 1e-2);  // (formulas.md rounds: 21.9955)
  EXPECT_NEAR(m.w, 0.4824, 5e-4);
  // Forward peaked: far more light straight through than sideways or back.
  EXPECT_GT(c.phaseMie(1.0, m, 1.0), 100 * c.phaseMie(0.0, m, 1.0));
}

TEST(CloudCore, OctaveSumIsBoundedByItsWeights) {
  Core c;
  double phases[Core::kScatterOctaves];
  for (auto& p : phases) p = 1.0;
  // tau = 0: sum of b^i; tau > 0 only loses light; a <= b keeps each octave's
  // share b^i exp(-a^i tau) <= b^i.
  double weights = 0, b = 1;
  for (int i = 0; i < Core::kScatterOctaves; ++i, b *= Core::kOctaveContribution) weights += b;
  EXPECT_NEAR(c.octaveSum(phases, 0.0), weights, 1e-12);
  double last = weights;
  for (double tau : {0.1, 1.0, 5.0, 50.0}) {
    const double s = c.octaveSum(phases, tau);
    EXPECT_LT(s, last) << tau;
    EXPECT_GT(s, 0.0);
    last = s;
  }
  EXPECT_LE(Core::kOctaveExtinction, Core::kOctaveContribution);
}

// Frame of a camera at altitude alt below/inside/above one layer, Earth radius R.
Core::CoreFrame frameAt(Core& c, double R, double alt, double base, double thickness) {
  Core::CoreFrame f{};
  f.r = R + alt;
  f.cGround = alt * (2 * f.r - alt);
  f.sunDir = Core::real3(0, 0, 1);
  f.sunRadiance = Core::real3(0);
  f.ambient = Core::real3(0);
  f.layerCount = 1;
  const double hBase = alt - base, hTop = alt - (base + thickness);
  f.layers[0] = Core::CoreLayer(hBase, hTop, hBase * (2 * f.r - hBase), hTop * (2 * f.r - hTop), thickness);
  for (unsigned i = 1; i < kMaxLayers; ++i) f.layers[i] = Core::CoreLayer(0, 0, 0, 0, 1);
  (void)c;
  return f;
}

TEST(CloudCore, SlabTransmittanceIsBeerLambert) {
  Core c;
  const double R = 6371000, base = 1500, H = 1000;
  // The layer's vertical profile is a trapezoid (ramps over the bottom 10 %
  // and the top 20 %): its integral over the thickness is H (1 - 0.05 - 0.1).
  const double profileIntegral = H * (1 - Core::kProfileBottomFade / 2 - Core::kProfileTopFade / 2);
  for (double density : {0.002, 0.02}) {
    c.density = density;
    Core::CoreFrame f = frameAt(c, R, 500, base, H);
    const Core::real3 up(0, 0, 1);
    const Core::Span span = c.layerSpan(f, f.layers[0], 1.0, 1e12);
    EXPECT_NEAR(span.t0, base - 500, 1e-6);
    EXPECT_NEAR(span.t1, base + H - 500, 1e-6);
    Core::MarchState st{Core::real3(0), 1.0, 0.0, 0.0};
    st = c.marchLayer(f, 0, up, span, 0.5, st);
    const double tau = Core::kExtinctionPerDensity_perm * density * profileIntegral;
    // Midpoint steps of dt = H/48 are exact on the profile's linear pieces;
    // each of its two kinks costs at most sigma dt^2/8 times the slope jump
    // (1/(0.1 H) and 1/(0.2 H)): 8.1e-5 in tau at density 0.002, so T is
    // within 1e-4 of exp(-tau); at 0.02 the bound is 8.1e-4 in tau.
    const double dt = H / Core::kPrimarySteps;
    const double tauBound = Core::kExtinctionPerDensity_perm * density * dt * dt / 8 *
                            (1 / (Core::kProfileBottomFade * H) + 1 / (Core::kProfileTopFade * H));
    EXPECT_NEAR(-std::log(st.transmittance), tau, tauBound) << "density " << density;
    if (density < 0.01) {
      EXPECT_NEAR(st.transmittance, std::exp(-tau), 1e-4);
    }
  }
  // sigma_t -> 0: nothing absorbed, nothing scattered, no division by zero.
  c.density = 1e-30;
  Core::CoreFrame f = frameAt(c, R, 500, base, H);
  f.sunRadiance = Core::real3(1);
  Core::MarchState st{Core::real3(0), 1.0, 0.0, 0.0};
  st = c.marchLayer(f, 0, Core::real3(0, 0, 1), c.layerSpan(f, f.layers[0], 1.0, 1e12), 0.5, st);
  EXPECT_EQ(st.transmittance, 1.0);
  EXPECT_TRUE(std::isfinite(st.inscatter.x));
  EXPECT_LT(st.inscatter.x, 1e-20);
}

TEST(CloudCore, RayShellDistancesMatchHandComputedOnes) {
  Core c;
  // A sphere of radius Rs = 6 371 000 m, camera at height h = 1000 m above it
  // (r = Rs + h), c = h (2r - h) = r^2 - Rs^2.
  const double Rs = 6371000, h = 1000, r = Rs + h;
  const double cc = h * (2 * r - h);
  // Straight down (mu = -1): the near root is h.
  auto down = c.intersectSphere(r, cc, -1.0);
  ASSERT_TRUE(down.hit);
  EXPECT_NEAR(down.t0, h, 1e-6);
  EXPECT_NEAR(down.t1, 2 * r - h, 1e-3);
  // Horizontal (mu = 0): the ray stays above the sphere below it (the
  // horizon is below the horizontal): no hit.
  EXPECT_FALSE(c.intersectSphere(r, cc, 0.0).hit);
  // Grazing: the horizon ray, mu = -sqrt(c) / r, touches at distance sqrt(c)
  // = sqrt(2 Rs h + h^2) = sqrt(12 743 000 000) = 112 884.9 m.
  const double horizon = std::sqrt(2 * Rs * h + h * h);
  auto graze = c.intersectSphere(r, cc, -horizon / r * (1 + 1e-12));
  ASSERT_TRUE(graze.hit);
  EXPECT_NEAR(graze.t0, 112884.9, 0.5);
  EXPECT_NEAR(graze.t1, 112884.9, 0.5);
  // A shell 2000 m above the camera, seen straight up and horizontally: up it
  // is 2000 m away; horizontally sqrt((Rs+3000)^2 - r^2) = sqrt(2000 x
  // 12 746 000) = 159 662.1 m.
  const double hs = -2000, cs = hs * (2 * r - hs);
  auto up = c.intersectSphere(r, cs, 1.0);
  ASSERT_TRUE(up.hit);
  EXPECT_NEAR(up.t1, 2000, 1e-6);
  auto level = c.intersectSphere(r, cs, 0.0);
  ASSERT_TRUE(level.hit);
  EXPECT_NEAR(level.t1, std::sqrt((Rs + 3000) * (Rs + 3000) - r * r), 1e-3);
  EXPECT_NEAR(level.t1, 159662.1, 0.5);
  // At a pole the local radius of curvature is larger (6 399 594 m): the same
  // formulas with that radius, as the renderer uses the radius under the camera.
  const double Rp = 6399594.0, rp = Rp + h, cp = h * (2 * rp - h);
  EXPECT_NEAR(c.intersectSphere(rp, cp, -1.0).t0, h, 1e-6);
}

}  // namespace
}  // namespace sky::render
