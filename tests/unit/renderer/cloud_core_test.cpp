// The shared cloud model (shaders/include/cloud_core.glsl) compiled as C++ in
// double precision, checked against closed forms: every phase function
// integrates to 1 over the sphere; the Jendersie-d'Eon fit reproduces the
// parameters published for 10 um droplets; Wrenninge's octave sum with a <= b
// never exceeds the sum of its weights; a uniform slab transmits exp(-sigma_t
// L) along vertical and slant rays; the step integration conserves energy
// (a conservative slab in a uniform radiance field leaves it uniform) and
// has its sigma -> 0 limit; Haggstrom's height functions and anvils at
// hand-computed points; the diffuse light's two-stream depth; a transition
// band's linear fade and its column above a height; ray-shell
// distances for vertical, horizontal and grazing rays; cloud shadows on the
// ground, in the air and on lower layers by the layers' two-stream depth.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <gtest/gtest.h>

#include "core_harness.hpp"

namespace sky::test {
namespace {

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


// Frame of a camera at altitude alt under a sphere of radius R, with one
// layer of the given type; no sun, no sky light.
Core::CoreFrame frameAt(Core& c, double R, double alt, double base, double thickness, const Core::CloudType& type) {
  Core::CoreFrame f = frameOver(R, alt, 0);
  f.layerCount = 1;
  c.layers[0] = shellLayer(f, alt, base, thickness, type);
  return f;
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
  Core::CloudType ice = uniformType(1e-3);
  ice.dropletDiameter_um = 0.0;
  for (double scale : {1.0, 0.125})
    EXPECT_NEAR(sphereIntegral([&](double mu) { return c.phaseCloud(mu, ice, scale); }), 1.0, 1e-3) << "ice";
  EXPECT_NEAR(sphereIntegral([&](double mu) { return c.phaseRayleigh(mu); }), 1.0, 1e-6);
  for (double g : {0.0, 0.8})
    EXPECT_NEAR(sphereIntegral([&](double mu) { return c.phaseCornetteShanks(mu, g); }), 1.0, 1e-3) << "CS g=" << g;
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
  // Ice (HG, g = 0.75) is less forward-peaked than droplets.
  Core::CloudType ice = uniformType(1e-3);
  ice.dropletDiameter_um = 0.0;
  EXPECT_LT(c.phaseCloud(1.0, ice, 1.0), c.phaseMie(1.0, m, 1.0));
}

TEST(CloudCore, OctaveSumIsBoundedByItsWeights) {
  Core c;
  const Core::real4 phases(1.0);
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
  // Octave 3 alone at tau = 8: b^3 exp(-a^3 8) = 0.125 e^-1.
  EXPECT_NEAR(c.octaveSum(Core::real4(0, 0, 0, 1), 8.0), 0.125 * std::exp(-1.0), 1e-12);
  EXPECT_LE(Core::kOctaveExtinction, Core::kOctaveContribution);
}

TEST(CloudCore, UniformSlabTransmitsBeerLambert) {
  Core c;
  const double R = 6371000, base = 1500, H = 1000, alt = 500;
  // Optical depths up to 4 (vertical) and 8 (slant); the march stops once
  // under kMinTransmittance is left, so that case is checked on its own.
  for (double sigma : {2e-4, 2e-3, 4e-3}) {
    Core::CoreFrame f = frameAt(c, R, alt, base, H, uniformType(sigma));
    // Vertical: the span is the layer, H long.
    const Core::Span up = c.layerSpan(f, c.layers[0], 1.0, 1e12);
    EXPECT_NEAR(up.t0, base - alt, 1e-6);
    EXPECT_NEAR(up.t1, base + H - alt, 1e-6);
    const auto r = c.marchLayer(f, 0, Core::real3(0, 0, 1), up, 0.5, 1.0);
    EXPECT_NEAR(r.transmittance, std::exp(-sigma * H), 1e-4) << "vertical, sigma " << sigma;
    // Slant, 30 degrees up: the path between the spheres of radius R + base
    // and R + base + H, by hand: sqrt(rs^2 - r^2 (1 - mu^2)) - r mu.
    const double mu = 0.5, rc = R + alt;
    auto dist = [&](double rs) { return std::sqrt(rs * rs - rc * rc * (1 - mu * mu)) - rc * mu; };
    const double path = dist(R + base + H) - dist(R + base);
    const Core::real3 dir(std::sqrt(1 - mu * mu), 0, mu);
    const Core::Span slant = c.layerSpan(f, c.layers[0], mu, 1e12);
    EXPECT_NEAR(slant.t1 - slant.t0, path, 1e-3);
    const double slantT = c.marchLayer(f, 0, dir, slant, 0.5, 1.0).transmittance;
    if (std::exp(-sigma * path) > Core::kMinTransmittance)
      EXPECT_NEAR(slantT, std::exp(-sigma * path), 1e-4) << "slant, sigma " << sigma;
    else  // early exit: stopped within one step of falling under the threshold
      EXPECT_LT(slantT, Core::kMinTransmittance * std::exp(sigma * (slant.t1 - slant.t0) / Core::kPrimarySteps));
  }
  // sigma_t -> 0: nothing absorbed, nothing scattered, no division by zero.
  Core::CoreFrame f = frameAt(c, R, alt, base, H, uniformType(1e-30));
  f.air.sunIrradiance = Core::real3(1);
  c.layers[0].skyTop = Core::real3(1);
  const auto r = c.marchLayer(f, 0, Core::real3(0, 0, 1), c.layerSpan(f, c.layers[0], 1.0, 1e12), 0.5, 1.0);
  EXPECT_EQ(r.transmittance, 1.0);
  EXPECT_TRUE(std::isfinite(r.inscatter.x));
  EXPECT_LT(r.inscatter.x, 1e-20);
}

// A transition band b below and above the slab's cloud (CIGI Weather
// Control's Transition Band): the cloud fades linearly to nothing across
// each band, so a vertical ray through the shell sees the optical depth of
// H + b (half of each band); rays that start inside a band see the part
// above them. The shell is the layer's heights with the band
// (frame_setup.cpp); layerPresence is what the point query fades by too.
TEST(CloudCore, TransitionBandFadesTheSlabLinearly) {
  Core c;
  const double R = 6371000, base = 1500, H = 1000, b = 250, sigma = 1e-3;
  for (double alt : {500.0, 1375.0}) {  // below the shell; half-way up the lower band
    SCOPED_TRACE("camera at " + std::to_string(alt) + " m");
    Core::CoreFrame f = frameAt(c, R, alt, base - b, H + 2 * b, uniformType(sigma));
    c.layers[0].band = b / (H + 2 * b);
    const Core::Span up = c.layerSpan(f, c.layers[0], 1.0, 1e12);
    EXPECT_NEAR(up.t1, base + H + b - alt, 1e-6);
    const double t = c.marchLayer(f, 0, Core::real3(0, 0, 1), up, 0.5, 1.0).transmittance;
    // The part of the lower band above the camera: b/2 less the part below it,
    // (alt - (base - b))^2 / (2 b).
    const double under = std::max(alt - (base - b), 0.0);
    const double lower = 0.5 * b - 0.5 * under * under / b;
    EXPECT_NEAR(-std::log(t), sigma * (lower + H + 0.5 * b), 2e-3 * sigma * (H + b));
  }
  // No band: the layer as before, however the shell is given.
  Core::CoreFrame f = frameAt(c, R, 500, base, H, uniformType(sigma));
  EXPECT_EQ(c.layers[0].band, 0.0);
  EXPECT_NEAR(c.marchLayer(f, 0, Core::real3(0, 0, 1), c.layerSpan(f, c.layers[0], 1.0, 1e12), 0.5, 1.0).transmittance,
              std::exp(-sigma * H), 1e-4);
}

// The column of cloud above a height in the shell (cloudShadow's and the
// diffuse light's depth above) is the presence's integral, by quadrature.
TEST(CloudCore, PresenceAboveIsThePresencesIntegral) {
  Core c;
  for (double band : {0.0, 0.05, 0.25, 0.49})
    for (double ph = -0.1; ph <= 1.1; ph += 0.02) {
      constexpr int kN = 20000;
      double sum = 0;
      const double from = std::clamp(ph, 0.0, 1.0);
      for (int i = 0; i < kN; ++i) sum += c.layerPresence(from + (i + 0.5) * (1 - from) / kN, band);
      EXPECT_NEAR(c.layerPresenceAbove(ph, band), sum * (1 - from) / kN, 1e-6) << "band " << band << " ph " << ph;
    }
}

// Hillaire's step integral conserves energy exactly: in a uniform, isotropic
// radiance field L a slab of albedo a returns L (T + a (1 - T)) whatever its
// optical depth or step count (a conservative slab, a = 1, leaves L as it
// is); Ford's eq. 4.4 (sigma dropped from the exponent) breaks this.
TEST(CloudCore, StepIntegrationConservesEnergy) {
  Core c;
  const double L = 0.7;
  for (double sigma : {1e-4, 0.01, 0.06, 1.0}) {
    Core::CoreFrame f = frameAt(c, 6371000, 500, 1500, 1000, uniformType(sigma));
    c.layers[0].skyTop = Core::real3(L);
    const auto r = c.marchLayer(f, 0, Core::real3(0, 0, 1), c.layerSpan(f, c.layers[0], 1.0, 1e12), 0.5, 1.0);
    const double T = r.transmittance;
    EXPECT_NEAR(r.inscatter.x, L * Core::kAlbedo * (1 - T), 1e-12 * L) << sigma;
    EXPECT_LE(L * T + r.inscatter.x, L * (1 + 1e-12)) << sigma;
  }
  // With sunlight the in-scattered light is at most what the slab removes
  // times the largest source: the sun through the octave sum at tau = 0 plus
  // the diffuse light.
  Core::CoreFrame f = frameAt(c, 6371000, 500, 1500, 1000, haggstromCumulus());
  f.air.sunIrradiance = Core::real3(20);
  f.air.sunDir = normalize(Core::real3(0.3, 0.2, 0.9));
  c.layers[0].skyTop = Core::real3(0.3);
  c.layers[0].sunDiffuseTop = Core::real3(5);
  c.coverage = 0.8;
  c.noise = 0.9;
  const Core::real3 dir = normalize(Core::real3(0.1, 0.2, 1.0));
  const auto r = c.marchLayer(f, 0, dir, c.layerSpan(f, c.layers[0], dir.z, 1e12), 0.5, 1.0);
  const double maxSource = 20 * c.octaveSum(c.octavePhases(dot(dir, f.air.sunDir), c.layers[0].primary), 0.0) + 5.3;
  EXPECT_LT(r.transmittance, 0.9);
  EXPECT_LE(r.inscatter.x, Core::kAlbedo * (1 - r.transmittance) * maxSource);
}

TEST(CloudCore, HeightFunctionsAtHandComputedPoints) {
  Core c;
  const Core::CloudType cu = haggstromCumulus();
  // SA = SAT(ph / 0.07) * SAT((wh - ph) / (0.8 wh)), wh = 1 (peak noise 1).
  EXPECT_NEAR(c.shapeProfile(cu, 0.035, 0.5, 1.0), 0.5, 1e-12);  // top factor saturates at 1
  EXPECT_NEAR(c.shapeProfile(cu, 0.6, 0.5, 1.0), (1 - 0.6) / 0.8, 1e-12);
  EXPECT_EQ(c.shapeProfile(cu, 0.0, 0.5, 1.0), 0.0);
  EXPECT_EQ(c.shapeProfile(cu, 1.0, 0.5, 1.0), 0.0);
  // A low top (peak noise 0, peak variation 0.5: wh = 0.5) ends the cloud at 0.5.
  Core::CloudType varied = cu;
  varied.peakVariation = 0.5;
  EXPECT_EQ(c.shapeProfile(varied, 0.55, 0.5, 0.0), 0.0);
  EXPECT_NEAR(c.shapeProfile(varied, 0.3, 0.5, 0.0), (0.5 - 0.3) / (0.8 * 0.5), 1e-12);
  // DA = ph * SAT(ph / 0.15) * SAT((1 - ph) / 0.1).
  EXPECT_NEAR(c.densityProfile(cu, 0.5), 0.5, 1e-12);
  EXPECT_NEAR(c.densityProfile(cu, 0.1), 0.1 * 0.1 / 0.15, 1e-12);
  EXPECT_NEAR(c.densityProfile(cu, 0.95), 0.95 * 0.5, 1e-12);
  // Anvil (eq. 17-18) at coverage 1: at ph = 0.8, half way through the anvil
  // zone, the top rounding (1 - 0.8) / 0.8 is lifted half way to 1, the shape
  // exponent is 1 - 0.5 = 0.5 and the density is cut by SAT(R(sqrt(0.8),
  // 0.4, 0.95, 1, 0.2)).
  Core::CloudType cb = cu;
  cb.anvil = 1.0;
  const double sa = 0.5 * (1 - 0.8) / 0.8 + 0.5;
  EXPECT_NEAR(c.shapeProfile(cb, 0.8, 1.0, 1.0), std::sqrt(sa), 1e-12);
  const double cut = 1 + (std::sqrt(0.8) - 0.4) / (0.95 - 0.4) * (0.2 - 1);
  EXPECT_NEAR(c.densityProfile(cb, 0.8), 0.8 * cut, 1e-12);
  // The anvil spreads coverage over the cell at the top, not below 0.65.
  EXPECT_NEAR(c.anvilCoverage(cb, 0.95, 0.2), 1.0, 1e-12);
  EXPECT_NEAR(c.anvilCoverage(cb, 0.5, 0.2), 0.2, 1e-12);
  EXPECT_EQ(c.anvilCoverage(cb, 0.95, 0.0), 0.0);
}

TEST(CloudCore, CoverageIsAnAreaFractionAndZeroIsEmpty) {
  Core c;
  const Core::CloudType cu = haggstromCumulus();
  // Coverage 0: nothing for any noise.
  for (double n : {0.0, 0.5, 1.0}) EXPECT_EQ(c.cloudShape(cu, Core::real2(n), 0.0, 1.0), 0.0);
  // With SA = 1, cloud starts at noise 1 - c and is full kCoverageEdge later.
  EXPECT_EQ(c.cloudShape(cu, Core::real2(0.59), 0.4, 1.0), 0.0);
  EXPECT_NEAR(c.cloudShape(cu, Core::real2(0.6 + 0.125), 0.4, 1.0), 0.5, 1e-12);
  EXPECT_EQ(c.cloudShape(cu, Core::real2(0.9), 0.4, 1.0), 1.0);
  // The cloud map moves partial coverage only: 0 and 1 are fixed points.
  for (double m : {0.0, 0.5, 1.0}) {
    EXPECT_EQ(c.mappedCoverage(0.0, m), 0.0);
    EXPECT_EQ(c.mappedCoverage(1.0, m), 1.0);
  }
  EXPECT_NEAR(c.mappedCoverage(0.5, 0.5), 0.5, 1e-12);
  // Erosion leaves full shape full and carves edges (eq. 16).
  EXPECT_NEAR(c.erodeShape(cu, 1.0, 0.3, 0.5, 0.5), 1.0, 1e-12);
  EXPECT_LT(c.erodeShape(cu, 0.3, 0.9, 0.5, 0.5), 0.3);
  // Fibrous types read the second noise channel.
  Core::CloudType ci = cu;
  ci.fibrous = 1.0;
  EXPECT_EQ(c.cloudShape(ci, Core::real2(1.0, 0.0), 0.5, 1.0), 0.0);
  EXPECT_EQ(c.cloudShape(cu, Core::real2(1.0, 0.0), 0.5, 1.0), 1.0);
}

// The diffuse light: at the layer top the sky's radiance as it is; below,
// the sky plus the sunlight scattered out of the beam, through the depth
// above by the two-stream t = 1 / (1 + 3/4 (1 - g) tau).
TEST(CloudCore, DiffuseLightFollowsTheTwoStreamDepth) {
  Core c;
  Core::CoreLayer L{};
  L.thickness = 1000;
  L.skyTop = Core::real3(0.3);
  L.sunDiffuseTop = Core::real3(4.0);
  L.sunCosine = 0.5;
  const Core::CloudType cu = haggstromCumulus();
  EXPECT_NEAR(c.diffuseLight(L, cu, 1.0, 1.0, 1.0).x, 0.3, 1e-12);
  const double tau = 0.06 * 1.0 * 1.0 * 0.5 * 1000;  // extinction, density, coverage, fill, depth
  const double expected = (0.3 + 4.0 * (1 - std::exp(-tau / 0.5))) / (1 + 0.75 * (1 - 0.85) * tau);
  EXPECT_NEAR(c.diffuseLight(L, cu, 0.0, 1.0, 1.0).x, expected, 1e-12);
  // Less cover above lets more through.
  EXPECT_GT(c.diffuseLight(L, cu, 0.0, 0.3, 1.0).x / (0.3 + 4.0), c.diffuseLight(L, cu, 0.0, 1.0, 1.0).x / (0.3 + 4.0));
}

// Cloud shadows on the ground: each layer's cloud column depth where the sun
// ray crosses it, tau = extinction x density x column fill x thickness; of
// the beam e^(-tau / mu) and the diffuse part 1 / (1 + 0.75 (1 - g) tau)
// the mean over a field of coverage c, 1 - c (1 - T), multiplied over the
// layers; no cloud, no shadow; and the ground's radiance from them by hand.
TEST(CloudCore, GroundShadowIsTheTwoStreamDepthOfTheLayersAbove) {
  Core c;
  const double R = 6371000, alt = 500;
  Core::CloudType st = uniformType(0.01);
  st.columnFill = 0.8;
  Core::CoreFrame f = frameAt(c, R, alt, 1500, 1000, st);
  const double mu = 0.5;
  f.air.sunDir = Core::real3(std::sqrt(1 - mu * mu), 0, mu);
  const Core::real3 ground(0, 0, -alt);  // the ground point under the camera
  c.coverage = 0.9;
  c.density = 0.7;
  const double tau = 0.01 * 0.7 * 0.8 * 1000;
  const double beam = 1 - 0.9 * (1 - std::exp(-tau / mu)), spread = 1 - 0.9 * (1 - 1 / (1 + 0.75 * (1 - 0.85) * tau));
  Core::real2 s = c.cloudShadow(f.air, f.layerCount, -1, ground, 0.0, mu);
  EXPECT_NEAR(s.x, beam, 1e-12);
  EXPECT_NEAR(s.y, spread, 1e-12);
  // A second, thinner layer higher up: the factors multiply.
  Core::CloudType ci = uniformType(5e-4);
  ci.columnFill = 0.3;
  c.layers[1] = c.layers[0];
  const double hB = alt - 8000, hT = alt - 9000;
  c.layers[1].hBase = hB;
  c.layers[1].hTop = hT;
  c.layers[1].cBase = hB * (2 * f.air.r - hB);
  c.layers[1].cTop = hT * (2 * f.air.r - hT);
  c.layers[1].primary = c.layers[1].secondary = ci;
  f.layerCount = 2;
  const double tau2 = 5e-4 * 0.7 * 0.3 * 1000;
  const double beam2 = 1 - 0.9 * (1 - std::exp(-tau2 / mu)), spread2 = 1 - 0.9 * (1 - 1 / (1 + 0.75 * (1 - 0.85) * tau2));
  s = c.cloudShadow(f.air, f.layerCount, -1, ground, 0.0, mu);
  EXPECT_NEAR(s.x, beam * beam2, 1e-12);
  EXPECT_NEAR(s.y, spread * spread2, 1e-12);
  // The ground's radiance: albedo / pi x (sun mu T (beam + (1 - beam)
  // spread) + sky spread), clear air (no table: T = 1).
  f.air.sunIrradiance = Core::real3(2.0);
  f.groundIrradiance = Core::real3(0.4);
  const double b2 = beam * beam2, s2 = spread * spread2;
  const double expected = 0.1 / kPi * (2.0 * mu * (b2 + (1 - b2) * s2) + 0.4 * s2);
  EXPECT_NEAR(c.groundRadiance(f, Core::real3(0, 0, -1), alt).x, expected, 1e-9);
  // No cloud: the sun and the sky reach the ground whole.
  c.coverage = 0.0;
  s = c.cloudShadow(f.air, f.layerCount, -1, ground, 0.0, mu);
  EXPECT_EQ(s.x, 1.0);
  EXPECT_EQ(s.y, 1.0);
  EXPECT_NEAR(c.groundRadiance(f, Core::real3(0, 0, -1), alt).x, 0.1 / kPi * (2.0 * mu + 0.4), 1e-9);
}

// The sky's light under a storm a few kilometres across with the sun low:
// the diffuse factor is the cover straight above (closed: dimmed by the
// column's two-stream transmittance), while the direct beam comes in under
// the storm's edge from the open sky (the sun ray meets the layer 57 km
// away at 3 degrees). Beside the storm both are clear.
TEST(CloudCore, TheSkysLightUnderAStormIsTheStormsNotTheSkyAlongTheSun) {
  Core c;
  const double R = 6371000, alt = 300, base = 1500, H = 3000;
  Core::CloudType cb = uniformType(0.02);
  cb.columnFill = 0.8;
  Core::CoreFrame f = frameAt(c, R, alt, base, H, cb);
  const double mu = std::sin(3 * kPi / 180);
  f.air.sunDir = Core::real3(std::sqrt(1 - mu * mu), 0, mu);
  c.density = 1.0;
  // The storm: closed within 4 km of the camera's vertical.
  c.coverageAt = [](Core::real3 p) { return std::hypot(p.x, p.y) < 4000 ? 1.0 : 0.0; };
  const double tau = 0.02 * 1.0 * 0.8 * H;
  const Core::real2 under = c.cloudShadow(f.air, 1, -1, Core::real3(0, 0, 0), alt, mu);
  EXPECT_NEAR(under.y, 1 / (1 + 0.75 * (1 - 0.85) * tau), 1e-9) << "the storm overhead hides the sky";
  EXPECT_EQ(under.x, 1.0) << "the low sun shines in under its edge";
  const Core::real2 beside = c.cloudShadow(f.air, 1, -1, Core::real3(0, 9000, 0), alt, mu);
  EXPECT_EQ(beside.x, 1.0);
  EXPECT_EQ(beside.y, 1.0) << "beside the storm the sky is open";
}

// The clouds' shadow in the air (cloudShadow at a point of the air, and the
// air march through it): under a layer the whole column's depth, inside it
// the part above the point, over it none; and the air's in-scattering under
// a uniform overcast, with clear air and no multiple scattering, is the
// unshadowed one times the beam e^(-tau / mu) exactly (the shadow is the
// same at every step); with the shadow off, or without layers, it is the
// unshadowed one.
TEST(CloudCore, TheAirIsInTheCloudsShadow) {
  Core c;
  const double R = 6371000, alt = 500, base = 1500, H = 1000;
  Core::CloudType st = uniformType(0.01);
  st.columnFill = 0.8;
  Core::CoreFrame f = frameAt(c, R, alt, base, H, st);
  const double mu = 0.6;
  f.air.sunDir = Core::real3(std::sqrt(1 - mu * mu), 0, mu);
  f.air.sunIrradiance = Core::real3(1.0);
  c.coverage = 1.0;  // an overcast
  c.density = 0.7;
  const double tau = 0.01 * 0.7 * 0.8 * H;
  const auto spread = [](double t) { return 1 / (1 + 0.75 * (1 - 0.85) * t); };
  const auto at = [&](double h) { return c.cloudShadow(f.air, 1, -1, Core::real3(0, 0, h - alt), h, mu); };
  EXPECT_NEAR(at(1000).x, std::exp(-tau / mu), 1e-12) << "under the base: the whole column";
  EXPECT_NEAR(at(1000).y, spread(tau), 1e-12);
  // At a quarter of the way up, three quarters of the column are above (the
  // sun cosine at the point, not at the ground: the same here to 1e-4).
  EXPECT_NEAR(at(base + 0.25 * H).x, std::exp(-0.75 * tau / mu), 1e-9) << "inside";
  EXPECT_NEAR(at(base + 0.25 * H).y, spread(0.75 * tau), 1e-12);
  EXPECT_EQ(at(base + H + 10).x, 1.0) << "over the top";
  EXPECT_EQ(at(base + H + 10).y, 1.0);
  c.coverage = 0.4;  // broken: 60 % of the sun rays pass clear
  EXPECT_NEAR(at(1000).x, 0.6 + 0.4 * std::exp(-tau / mu), 1e-12);
  EXPECT_NEAR(at(1000).y, 0.6 + 0.4 * spread(tau), 1e-12);
  c.coverage = 1.0;

  // Looking down at 30 degrees from the camera under the layer: every step
  // of the air march is in the same shade.
  const Core::real3 dir(std::cos(30 * kPi / 180), 0, -std::sin(30 * kPi / 180));
  const double tEnd = alt / std::sin(30 * kPi / 180);
  Core::real q[Core::kAirQueries] = {tEnd};
  f.air.shadowLayers = 0;
  const Core::AirPath lit = c.marchAir(f.air, dir, tEnd, q, 1);
  f.air.shadowLayers = 1;
  const Core::AirPath shaded = c.marchAir(f.air, dir, tEnd, q, 1);
  ASSERT_GT(lit.inscatter[0].x, 0.0);
  // The sun's cosine varies by ~1e-4 over the 1 km of ground the ray spans.
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(shaded.inscatter[0][k] / lit.inscatter[0][k], std::exp(-tau / mu), 1e-3 * std::exp(-tau / mu)) << k;
  EXPECT_EQ(shaded.transmittance[0], lit.transmittance[0]) << "the shadow dims the light, not the air";
  c.coverage = 0.0;
  EXPECT_EQ(c.marchAir(f.air, dir, tEnd, q, 1).inscatter[0], lit.inscatter[0]) << "no cloud, no shade";
}

// A layer in the shadow of the layer above (cirrus over cumulus, a deck
// over a layer): with no sky light its in-scattered sunlight is the
// unshadowed one times the upper layer's mean beam transmittance, 1 - c (1 -
// e^(-tau / mu)); its transmittance is its own; the upper layer is not
// shadowed by the lower one, nor any layer by itself.
TEST(CloudCore, ALayerIsInTheShadowOfTheLayersAboveIt) {
  Core c;
  const double R = 6371000, alt = 500;
  Core::CoreFrame f = frameAt(c, R, alt, 1500, 1000, uniformType(2e-3));
  Core::CloudType deck = uniformType(4e-3);
  deck.columnFill = 0.9;
  c.layers[1] = shellLayer(f, alt, 5000, 400, deck);
  f.layerCount = 2;
  const double mu = 0.8;
  f.air.sunDir = Core::real3(std::sqrt(1 - mu * mu), 0, mu);
  f.air.sunIrradiance = Core::real3(1.0);
  c.coverage = 0.6;
  const Core::real3 up(0, 0, 1);
  const Core::Span lower = c.layerSpan(f, c.layers[0], 1.0, 1e12), upper = c.layerSpan(f, c.layers[1], 1.0, 1e12);
  f.air.shadowLayers = f.layerShadows = 0;
  const auto lit = c.marchLayer(f, 0, up, lower, 0.5, 1.0), litUpper = c.marchLayer(f, 1, up, upper, 0.5, 1.0);
  f.air.shadowLayers = f.layerShadows = 2;
  const auto shaded = c.marchLayer(f, 0, up, lower, 0.5, 1.0), shadedUpper = c.marchLayer(f, 1, up, upper, 0.5, 1.0);
  const double tau = 4e-3 * 0.9 * 400;
  ASSERT_GT(lit.inscatter.x, 0.0);
  // The sun's cosine along the 1 km span and the deck's height above it
  // vary by ~1e-4 (the Earth's curvature): the beam to that.
  EXPECT_NEAR(shaded.inscatter.x / lit.inscatter.x, 1 - 0.6 * (1 - std::exp(-tau / mu)), 1e-3);
  EXPECT_EQ(shaded.transmittance, lit.transmittance);
  EXPECT_EQ(shadedUpper.inscatter, litUpper.inscatter) << "nothing above the deck";
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

// The upscale's ground test without roots (rayMeetsSphere) is
// intersectSphere's "hit with the far root ahead" for rays of any length,
// from the ground up to orbit and below the ground, all round the horizon:
// 20 000 directions per height, skipping only those within 1e-9 of the
// horizon's cosine, where both are rounding.
TEST(CloudCore, TheRootlessGroundTestIsTheSpheresHitAhead) {
  Core c;
  const double Rs = 6371000;
  std::uint32_t seed = 12345u, met = 0, missed = 0;
  auto uniform = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return double(seed >> 8) / double(1u << 24);
  };
  for (const double h : {-50.0, 0.0, 1.0, 800.0, 12000.0, 400000.0}) {
    const double r = Rs + std::max(h, 0.0), cc = h * (2 * r - h);
    const double horizonMu = cc > 0 ? -std::sqrt(cc) / r : 0.0;
    for (int k = 0; k < 20000; ++k) {
      // Cosines crowded round the horizon's, half of them within 0.01 of it.
      const double mu = k % 2 == 0 ? 2 * uniform() - 1 : std::clamp(horizonMu + 0.02 * (uniform() - 0.5), -1.0, 1.0);
      if (std::abs(mu - horizonMu) < 1e-9) continue;
      const double phi = 6.283185307179586 * uniform(), s = std::sqrt(1 - mu * mu), length = 0.1 + 10 * uniform();
      const dvec3 v(length * s * std::cos(phi), length * s * std::sin(phi), length * mu);
      const auto roots = c.intersectSphere(r, cc, mu);
      const bool expected = roots.hit && roots.t1 > 0.0;
      ASSERT_EQ(c.rayMeetsSphere(v, r, cc), expected) << "h " << h << " mu " << mu;
      (expected ? met : missed) += 1;
    }
  }
  EXPECT_GT(met, 30000u);
  EXPECT_GT(missed, 30000u);
}

// The same test from another point than the camera (rayFromMeetsSphere: the
// previous frame's camera, for the reprojection's ground/sky sides) against
// the quadratic |o + (0, 0, r) + t v|^2 = R^2 solved in double from the
// sphere's centre: the far root ahead. Origins up to 2 km away in every
// direction (a frame's motion is metres), from below the ground to 400 km,
// directions crowded round the origin's own horizon; and from o = 0 it is
// rayMeetsSphere exactly.
TEST(CloudCore, TheGroundTestFromAnotherPointIsTheSpheresHitAhead) {
  Core c;
  const double Rs = 6371000;
  std::uint32_t seed = 777u, met = 0, missed = 0;
  auto uniform = [&seed] {
    seed = seed * 1664525u + 1013904223u;
    return double(seed >> 8) / double(1u << 24);
  };
  for (const double h : {-50.0, 0.0, 1.0, 800.0, 12000.0, 400000.0}) {
    const double r = Rs + std::max(h, 0.0), cc = h * (2 * r - h), R = r - h;
    for (int k = 0; k < 20000; ++k) {
      const dvec3 o = k % 4 == 0 ? dvec3(0) : dvec3(4000 * uniform() - 2000, 4000 * uniform() - 2000, 200 * uniform() - 100);
      const dvec3 m = o + dvec3(0, 0, r);
      const double mLength = glm::length(m);
      const double horizonMu = mLength > R ? -std::sqrt(mLength * mLength - R * R) / mLength : 0.0;
      // Directions about the origin's own up, half within 0.01 of its horizon.
      const dvec3 up = m / mLength;
      const dvec3 east = glm::normalize(glm::cross(dvec3(0, 1, 0), up)), north = glm::cross(up, east);
      const double mu = k % 2 == 0 ? 2 * uniform() - 1 : std::clamp(horizonMu + 0.02 * (uniform() - 0.5), -1.0, 1.0);
      if (std::abs(mu - horizonMu) < 1e-9) continue;
      const double phi = 6.283185307179586 * uniform(), s = std::sqrt(1 - mu * mu), length = 0.1 + 10 * uniform();
      const dvec3 v = length * (s * std::cos(phi) * east + s * std::sin(phi) * north + mu * up);
      // t^2 |v|^2 + 2 t (m.v) + |m|^2 - R^2 = 0: a hit ahead when the larger root is positive.
      const double a = glm::dot(v, v), b = glm::dot(m, v), q = glm::dot(m, m) - R * R;
      const double disc = b * b - a * q;
      const bool expected = disc >= 0 && (-b + std::sqrt(disc)) / a > 0;
      ASSERT_EQ(c.rayFromMeetsSphere(o, v, r, cc), expected) << "h " << h << " o " << o.x << "," << o.y << "," << o.z
                                                              << " mu " << mu;
      if (o == dvec3(0)) {
        ASSERT_EQ(c.rayFromMeetsSphere(o, v, r, cc), c.rayMeetsSphere(v, r, cc));
      }
      (expected ? met : missed) += 1;
    }
  }
  EXPECT_GT(met, 30000u);
  EXPECT_GT(missed, 30000u);
}

// The weather map's projection (anchorPlane, shared by the GPU passes and
// the CPU reference): the gnomonic projection of the anchor sphere onto its
// tangent plane at the anchor, x = R tan(angle east), whichever way the
// camera's frame is turned; points past 90 degrees are flagged.
TEST(CloudCore, AnchorPlaneIsTheGnomonicProjectionOfTheAnchorSphere) {
  Core c;
  const double R = 6371000.0, h = 1500;
  const dvec3 camera(0, 0, R + h);  // above the anchor
  for (const double yaw_deg : {0.0, 30.0, -135.0}) {
    // camToAnchor: the camera's axes turned by yaw about the local vertical.
    const double a = glm::radians(yaw_deg);
    const dmat3 camToAnchor(dvec3(std::cos(a), std::sin(a), 0), dvec3(-std::sin(a), std::cos(a), 0), dvec3(0, 0, 1));
    for (const double angle_deg : {0.0, 0.5, 10.0, 60.0}) {
      const double t = glm::radians(angle_deg);
      // A point on the sphere `angle` east and one `angle` north of the anchor,
      // written camera-local (the inverse rotation of their anchor offsets).
      const dvec3 east(R * std::sin(t), 0, R * std::cos(t)), north(0, R * std::sin(t), R * std::cos(t));
      const dvec3 pe = glm::transpose(camToAnchor) * (east - camera);
      const dvec3 pn = glm::transpose(camToAnchor) * (north - camera);
      const dvec3 e = c.anchorPlane(camToAnchor, camera, R, pe), n = c.anchorPlane(camToAnchor, camera, R, pn);
      EXPECT_NEAR(e.x, R * std::tan(t), 1e-6 * R * std::tan(t) + 1e-6) << yaw_deg << " " << angle_deg;
      EXPECT_NEAR(e.y, 0, 1e-6);
      EXPECT_NEAR(n.y, R * std::tan(t), 1e-6 * R * std::tan(t) + 1e-6);
      EXPECT_NEAR(n.x, 0, 1e-6);
      EXPECT_GT(e.z, 0);
    }
    // Past a quarter turn the point is behind the anchor's horizon: q.z < 0.
    const dvec3 far(R * std::sin(2.0), 0, R * std::cos(2.0));
    EXPECT_LT(c.anchorPlane(camToAnchor, camera, R, glm::transpose(camToAnchor) * (far - camera)).z, 0);
  }
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// lightning.glsl against closed forms: a flash's light at a point is its
// intensity over the squared distance (softened within the core radius),
// carried by the glow's exponential, times the isotropic phase; two flashes
// add. A straight channel cut into segments draws as the uncut channel
// (no light added where they meet), and across it the light integrates to
// the intensity per metre over the distance.
TEST(Lightning, AFlashsLightFallsAsAPointSourcesInItsGlow) {
  Core c;
  c.flashes = {Core::real4(0.0, 0.0, 2000.0, 5.0e6)};
  for (double d : {0.0, 300.0, 1500.0, 6000.0}) {
    const Core::real3 p(0.0, d, 2000.0);
    const double expected = 5.0e6 * std::exp(-d / 1500.0) / (d * d + 150.0 * 150.0) / (4 * kPi);
    EXPECT_NEAR(c.flashInscatter(1, p).z, expected * 1.0, 1e-12 * expected) << d;
    EXPECT_NEAR(c.flashInscatter(1, p).x, expected * 0.85, 1e-12 * expected) << "the channel's bluish white";
  }
  c.flashes.push_back(Core::real4(0.0, 3000.0, 2000.0, 5.0e6));
  const Core::real3 mid(0.0, 1500.0, 2000.0);
  EXPECT_NEAR(c.flashInscatter(2, mid).z, 2 * c.flashInscatter(1, mid).z, 1e-9);
  EXPECT_EQ(c.flashInscatter(0, mid).z, 0.0) << "no flash, no light";
}

TEST(Lightning, ASegmentedChannelDrawsAsOneLine) {
  // A vertical channel 2 km ahead, from 500 m below the camera to 500 m
  // above, of 10 (linear units x m) per metre: whole, and in 7 pieces.
  const double pixel = 1e-3;
  Core whole, cut;
  whole.boltStarts = {Core::real4(0.0, 2000.0, -500.0, 10.0)};
  whole.boltEnds = {Core::real3(0.0, 2000.0, 500.0)};
  for (int k = 0; k < 7; ++k) {
    cut.boltStarts.push_back(Core::real4(0.0, 2000.0, -500.0 + 1000.0 * k / 7, 10.0));
    cut.boltEnds.push_back(Core::real3(0.0, 2000.0, -500.0 + 1000.0 * (k + 1) / 7));
  }
  double across = 0;
  for (int i = -400; i <= 400; ++i) {
    // Rays across the channel at two heights: one through a joint.
    const double ax = i * pixel / 100;
    for (double el : {0.0, std::atan((-500.0 + 1000.0 * 3 / 7) / 2000.0)}) {
      const Core::real3 dir = glm::normalize(Core::real3(std::sin(ax), std::cos(ax), std::tan(el)));
      const double w = whole.boltRadiance(1, pixel, dir).x, s = cut.boltRadiance(7, pixel, dir).x;
      EXPECT_NEAR(s, w, 0.02 * w + 1e-12) << "at a joint the pieces' light is the whole channel's";
      if (el == 0.0) across += w * (pixel / 100);
    }
  }
  // Across the line: the intensity per metre over the distance, 10 / 2000.
  EXPECT_NEAR(across, 10.0 / 2000.0, 0.01 * 10.0 / 2000.0);
  // The distance it is seen at.
  EXPECT_NEAR(whole.boltRadiance(1, pixel, Core::real3(0, 1, 0)).y, 2000.0, 1e-6);
  // Behind the camera it is not seen.
  EXPECT_EQ(whole.boltRadiance(1, pixel, Core::real3(0, -1, 0)).x, 0.0);
}

}  // namespace
}  // namespace sky::test
