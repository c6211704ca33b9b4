// The volumetric path tracer (renderer/core/src/volume_paths.cpp) against
// closed forms on plane-parallel slabs: the Beer-Lambert transmittance of a
// uniform and a linearly varying slab by delta and ratio tracking (with a
// loose majorant); single scattering reflected and transmitted by a uniform
// slab (isotropic and Henyey-Greenstein); the plane albedo of an
// isotropically scattering half-space, 1 - H(mu0) sqrt(1 - omega) with
// Chandrasekhar's H function solved here by quadrature; energy
// conservation with albedo 1 (a slab in a uniform radiance field leaves it
// uniform, path by path for HG; reflected plus transmitted sunlight is all
// of it); the phase functions' normalisation and sampling weights.
// Each Monte Carlo estimate is checked within 4.5 of its own standard
// errors (about one false failure in 150 000 per check), plus a stated
// floor where the closed form itself is approximate.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "volume_paths.hpp"

namespace sky::test {
namespace {

namespace vp = render::volume_paths;
using glm::dvec3;
constexpr double kPi = std::numbers::pi;
constexpr double kSigmas = 4.5;

// A slab between z = 0 and z = thickness, sun from above, no surface; the
// extinction sigma(z) = sigma0 (1 - slope + slope * z / thickness) with
// the majorant `loose` times its largest value.
class Slab : public vp::Scene {
 public:
  double thickness = 1.0;
  double sigma0 = 1.0;
  double slope = 0.0;  // 0: uniform; 1: rises linearly from 0 at the bottom
  double loose = 1.0;
  double albedo = 1.0;
  vp::Phase phase;
  dvec3 sunDir{0.0, 0.0, 1.0};
  double sunE = 1.0;
  double escape = 0.0;  // uniform radiance around the slab

  void majorants(const vp::Ray& ray, double tMax, std::vector<vp::MajorantSegment>& out) const override {
    out.clear();
    double t0 = 0.0, t1 = tMax;
    if (std::abs(ray.dir.z) < 1e-12) {
      if (ray.origin.z < 0.0 || ray.origin.z > thickness) return;
      t1 = std::min(t1, 1e12);
    } else {
      double a = (0.0 - ray.origin.z) / ray.dir.z, b = (thickness - ray.origin.z) / ray.dir.z;
      if (a > b) std::swap(a, b);
      t0 = std::max(a, 0.0);
      t1 = std::min(b, tMax);
    }
    if (t1 > t0) out.push_back({t0, t1, sigma0 * loose});
  }
  vp::MediumPoint medium(const dvec3& p, double) const override {
    const double z = std::clamp(p.z / thickness, 0.0, 1.0);
    return vp::MediumPoint{sigma0 * (1.0 - slope + slope * z), albedo, phase};
  }
  double surfaceDistance(const vp::Ray&) const override { return vp::kInfinity; }
  vp::Surface surfaceAt(const dvec3&) const override { return {}; }
  dvec3 sunDirection() const override { return sunDir; }
  dvec3 sunIrradiance(const dvec3&) const override { return dvec3(sunE); }
  dvec3 escapeRadiance(const vp::Ray&) const override { return dvec3(escape); }
};

dvec3 direction(double mu, double phi) {
  const double s = std::sqrt(1.0 - mu * mu);
  return {s * std::cos(phi), s * std::sin(phi), mu};
}

struct Estimate {
  double mean = 0.0;
  double error = 0.0;  // standard error of the mean
};

template <class F>
Estimate estimate(int n, F sample) {
  double sum = 0.0, sumSq = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = sample(i);
    sum += x;
    sumSq += x * x;
  }
  const double mean = sum / n;
  const double var = std::max(0.0, sumSq / n - mean * mean);
  return {mean, std::sqrt(var / (n - 1))};
}

void expectNear(const Estimate& e, double expected, double floor = 0.0) {
  EXPECT_NEAR(e.mean, expected, kSigmas * e.error + floor) << "standard error " << e.error;
}

TEST(VolumePaths, DeltaTrackingFreeFlightsFollowBeerLambert) {
  for (const double slope : {0.0, 1.0}) {
    Slab slab;
    slab.thickness = 2.0;
    slab.sigma0 = 0.8;
    slab.slope = slope;
    slab.loose = 2.0;
    const double mu = 0.5;
    // Optical depth across: sigma0 thickness, half that for the linear ramp.
    const double tau = slab.sigma0 * slab.thickness * (slope > 0.0 ? 0.5 : 1.0);
    std::vector<vp::MajorantSegment> scratch;
    vp::TraceStats stats;
    const Estimate passed = estimate(40000, [&](int i) {
      vp::Rng rng(7, std::uint64_t(i));
      vp::MediumPoint point;
      const vp::Ray ray{{0.0, 0.0, 3.0}, direction(-mu, 0.3)};
      return vp::freeFlight(slab, ray, vp::kInfinity, rng, point, stats, scratch) == vp::kInfinity ? 1.0 : 0.0;
    });
    expectNear(passed, std::exp(-tau / mu));
    EXPECT_EQ(stats.majorantViolations, 0u);
  }
}

TEST(VolumePaths, RatioTrackingIsAnUnbiasedTransmittance) {
  for (const double slope : {0.0, 1.0}) {
    Slab slab;
    slab.sigma0 = 1.5;
    slab.slope = slope;
    slab.loose = 3.0;
    const double mu = 0.7;
    const double tau = slab.sigma0 * (slope > 0.0 ? 0.5 : 1.0);
    std::vector<vp::MajorantSegment> scratch;
    vp::TraceStats stats;
    const Estimate t = estimate(20000, [&](int i) {
      vp::Rng rng(11, std::uint64_t(i));
      return vp::ratioTransmittance(slab, vp::Ray{{0.0, 0.0, -1.0}, direction(mu, 1.0)}, vp::kInfinity, rng, stats,
                                    scratch);
    });
    expectNear(t, std::exp(-tau / mu));
    // Ratio tracking's variance is far below the 0/1 estimate's.
    EXPECT_LT(t.error, 0.5 * std::sqrt(std::exp(-tau / mu) * (1.0 - std::exp(-tau / mu)) / 20000.0));
  }
}

// Single scattering by a uniform slab of optical depth tau, sun at mu0,
// irradiance E, seen at mu (cos from the vertical of the view's way back):
// reflected  L = omega p E mu0 / (mu0 + mu) (1 - exp(-tau (1/mu0 + 1/mu)))
// transmitted L = omega p E mu0 / (mu0 - mu) (exp(-tau/mu0) - exp(-tau/mu)).
TEST(VolumePaths, SingleScatteringOfAUniformSlabIsTheClosedForm) {
  for (const double g : {0.0, 0.7}) {
    Slab slab;
    slab.sigma0 = 0.6;
    slab.albedo = 0.9;
    slab.phase.gHG = g;
    const double mu0 = 0.8;
    slab.sunDir = direction(mu0, 0.0);
    vp::TraceOptions single;
    single.maxEvents = 1;
    const double tau = slab.sigma0 * slab.thickness;
    // Reflected: the camera above, looking down; light leaves upwards at mu.
    const double muR = 0.6;
    const dvec3 lookDown = -direction(muR, 2.0);
    const Estimate up = estimate(60000, [&](int i) {
      vp::Rng rng(3, std::uint64_t(i));
      vp::TraceStats stats;
      return vp::radiance(slab, vp::Ray{{0.0, 0.0, 5.0}, lookDown}, single, rng, stats).x;
    });
    const double pUp = vp::evalPhase(slab.phase, glm::dot(slab.sunDir, lookDown));
    expectNear(up, slab.albedo * pUp * mu0 / (mu0 + muR) * (1.0 - std::exp(-tau * (1.0 / mu0 + 1.0 / muR))));
    // Transmitted: the camera below, looking up at mu.
    const double muT = 0.5;
    const dvec3 lookUp = direction(muT, 2.5);
    const Estimate down = estimate(60000, [&](int i) {
      vp::Rng rng(5, std::uint64_t(i));
      vp::TraceStats stats;
      return vp::radiance(slab, vp::Ray{{0.0, 0.0, -4.0}, lookUp}, single, rng, stats).x;
    });
    const double pDown = vp::evalPhase(slab.phase, glm::dot(slab.sunDir, lookUp));
    expectNear(down,
               slab.albedo * pDown * mu0 / (mu0 - muT) * (std::exp(-tau / mu0) - std::exp(-tau / muT)));
  }
}

// Chandrasekhar's H function for isotropic scattering with albedo omega,
// from 1/H(mu) = sqrt(1 - omega) + (omega/2) int_0^1 mu' H(mu') / (mu + mu')
// dmu' by fixed-point iteration on Gauss-Legendre nodes (this form
// converges for every omega <= 1; Chandrasekhar 1960, ch. V).
class HFunction {
 public:
  explicit HFunction(double omega) : omega_(omega) {
    legendreNodes();
    h_.assign(nodes_.size(), 1.0);
    for (int it = 0; it < 2000; ++it) {
      std::vector<double> next(nodes_.size());
      double change = 0.0;
      for (std::size_t i = 0; i < nodes_.size(); ++i) {
        next[i] = at(nodes_[i]);
        change = std::max(change, std::abs(next[i] - h_[i]));
      }
      h_ = next;
      if (change < 1e-13) break;
    }
  }
  double at(double mu) const {
    double integral = 0.0;
    for (std::size_t i = 0; i < nodes_.size(); ++i) integral += weights_[i] * nodes_[i] * h_[i] / (mu + nodes_[i]);
    return 1.0 / (std::sqrt(1.0 - omega_) + 0.5 * omega_ * integral);
  }
  double zerothMoment() const {
    double m = 0.0;
    for (std::size_t i = 0; i < nodes_.size(); ++i) m += weights_[i] * h_[i];
    return m;
  }

 private:
  // Gauss-Legendre on [0, 1] by Newton's method on P_n.
  void legendreNodes() {
    constexpr int n = 96;
    for (int k = 1; k <= n; ++k) {
      double x = std::cos(kPi * (k - 0.25) / (n + 0.5));
      double dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = x;
        for (int j = 2; j <= n; ++j) {
          const double p2 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p0) / j;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (x * p1 - p0) / (x * x - 1.0);
        const double dx = p1 / dp;
        x -= dx;
        if (std::abs(dx) < 1e-15) break;
      }
      nodes_.push_back(0.5 * (x + 1.0));
      weights_.push_back(1.0 / ((1.0 - x * x) * dp * dp));  // 2 / (...) on [-1, 1], halved
    }
  }
  double omega_;
  std::vector<double> nodes_, weights_, h_;
};

TEST(VolumePaths, TheHFunctionSolverMeetsItsMomentIdentity) {
  // int_0^1 H dmu = (2 / omega) (1 - sqrt(1 - omega)) (Chandrasekhar 1960, eq. V.29).
  for (const double omega : {0.5, 0.9, 0.99}) {
    const HFunction h(omega);
    EXPECT_NEAR(h.zerothMoment(), 2.0 / omega * (1.0 - std::sqrt(1.0 - omega)), 1e-9) << omega;
  }
}

// Plane albedo of an isotropic half-space lit at mu0: the reflected flux
// over the incident, 1 - H(mu0) sqrt(1 - omega). Measured as pi times the
// mean radiance of cosine-distributed upward views over E mu0. The slab is
// 400 mean free paths deep: a half-space to far below the estimate's error.
TEST(VolumePaths, AnIsotropicHalfSpaceReflectsItsChandrasekharAlbedo) {
  for (const double omega : {0.9, 0.99}) {
    Slab slab;
    slab.sigma0 = 400.0;
    slab.albedo = omega;
    const double mu0 = 0.6;
    slab.sunDir = direction(mu0, 0.0);
    vp::TraceOptions options;
    const Estimate a = estimate(30000, [&](int i) {
      vp::Rng rng(13, std::uint64_t(i));
      const dvec3 up = vp::sampleCosine({0.0, 0.0, 1.0}, rng);
      vp::TraceStats stats;
      return kPi * vp::radiance(slab, vp::Ray{{0.0, 0.0, 2.0}, -up}, options, rng, stats).x / mu0;
    });
    const HFunction h(omega);
    expectNear(a, 1.0 - h.at(mu0) * std::sqrt(1.0 - omega));
  }
}

// A conservative slab in a uniform radiance field leaves the field as it
// is: with an HG phase (weights exactly 1) every path returns the field's
// radiance; with the Mie fit's mixture (weights around 1) their mean does.
TEST(VolumePaths, AConservativeSlabInAUniformFieldLosesNoEnergy) {
  Slab slab;
  slab.sigma0 = 10.0;
  slab.sunE = 0.0;
  slab.escape = 1.0;
  slab.phase.gHG = 0.85;
  vp::TraceOptions options;
  for (int i = 0; i < 2000; ++i) {
    vp::Rng rng(17, std::uint64_t(i));
    vp::TraceStats stats;
    const double mu = 2.0 * rng.uniform() - 1.0;
    const dvec3 l = vp::radiance(slab, vp::Ray{{0.0, 0.0, 0.5}, direction(mu, 1.0)}, options, rng, stats);
    ASSERT_NEAR(l.x, 1.0, 1e-12) << "path " << i;
  }
  // Jendersie & d'Eon's fit for 20 um droplets (cloud_core.glsl's mieFit).
  const double d = 20.0;
  slab.phase = vp::Phase{std::exp(-0.0990567 / (d - 1.67154)), std::exp(-2.20679 / (d + 3.91029) - 0.428934),
                         std::exp(3.62489 - 8.29288 / (d + 5.52825)), std::exp(-0.599085 / (d - 0.641583) - 0.664888)};
  const Estimate mie = estimate(20000, [&](int i) {
    vp::Rng rng(19, std::uint64_t(i));
    vp::TraceStats stats;
    return vp::radiance(slab, vp::Ray{{0.0, 0.0, 0.5}, direction(0.3, 1.0)}, options, rng, stats).x;
  });
  expectNear(mie, 1.0);
}

// Sunlight on a conservative slab leaves it reflected, transmitted
// diffusely, or transmitted straight: R + T_diffuse + exp(-tau/mu0) = 1,
// each flux measured from cosine-distributed views above and below.
TEST(VolumePaths, AConservativeSlabReflectsAndTransmitsAllTheSunlight) {
  Slab slab;
  slab.sigma0 = 3.0;
  const double d = 12.0;
  slab.phase = vp::Phase{std::exp(-0.0990567 / (d - 1.67154)), std::exp(-2.20679 / (d + 3.91029) - 0.428934),
                         std::exp(3.62489 - 8.29288 / (d + 5.52825)), std::exp(-0.599085 / (d - 0.641583) - 0.664888)};
  const double mu0 = 0.7;
  slab.sunDir = direction(mu0, 0.0);
  vp::TraceOptions options;
  const auto flux = [&](double side, std::uint64_t seed) {
    return estimate(30000, [&](int i) {
      vp::Rng rng(seed, std::uint64_t(i));
      const dvec3 n = vp::sampleCosine({0.0, 0.0, side}, rng);
      vp::TraceStats stats;
      return kPi * vp::radiance(slab, vp::Ray{{0.0, 0.0, side > 0 ? 2.0 : -1.0}, -n}, options, rng, stats).x / mu0;
    });
  };
  const Estimate r = flux(1.0, 23), t = flux(-1.0, 29);
  const Estimate total{r.mean + t.mean + std::exp(-slab.sigma0 / mu0), std::hypot(r.error, t.error)};
  expectNear(total, 1.0);
  EXPECT_GT(r.mean, 0.1);
  EXPECT_GT(t.mean, 0.3);
}

TEST(VolumePaths, PhaseFunctionsIntegrateToOneAndTheirSamplingWeightsAverageOne) {
  const double d = 20.0;
  const vp::Phase mie{std::exp(-0.0990567 / (d - 1.67154)), std::exp(-2.20679 / (d + 3.91029) - 0.428934),
                      std::exp(3.62489 - 8.29288 / (d + 5.52825)), std::exp(-0.599085 / (d - 0.641583) - 0.664888)};
  for (const vp::Phase& p : {vp::Phase{}, vp::Phase{0.8, 0, 0, 0}, vp::Phase{-0.3, 0, 0, 0}, mie}) {
    constexpr int kN = 400000;
    double integral = 0.0, meanCos = 0.0;
    for (int i = 0; i < kN; ++i) {
      const double th = (i + 0.5) * kPi / kN;
      const double w = vp::evalPhase(p, std::cos(th)) * std::sin(th) * 2.0 * kPi * kPi / kN;
      integral += w;
      meanCos += w * std::cos(th);
    }
    EXPECT_NEAR(integral, 1.0, 1e-6);
    // The weighted samples' mean cosine is the phase function's.
    const dvec3 axis = glm::normalize(dvec3(0.3, -0.4, 0.5));
    const Estimate c = estimate(100000, [&](int i) {
      vp::Rng rng(31, std::uint64_t(i));
      double weight = 0.0;
      const dvec3 out = vp::samplePhase(p, axis, rng, weight);
      EXPECT_NEAR(glm::length(out), 1.0, 1e-12);
      return weight * glm::dot(out, axis);
    });
    expectNear(c, meanCos);
  }
}

}  // namespace
}  // namespace sky::test
