// Fog draws the visibility it stands for: the fog type of the renderer's
// table (cloud_types.cpp), in the shared density model compiled as C++ (the
// CPU reference's core), at the density the weather gives a visibility V
// (weather::fogDensityForVisibility). Koschmieder's law is the physics
// (WMO-No. 8): a black target at the visibility keeps 2 % of its contrast
// against the horizon, i.e. the sight line's transmittance over V is
// exp(-3.912) = 0.020. The answer side (weather::cloudVisibility_m, what
// the CIGI answer and the conditions API give) must return V itself.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "cloud_types.hpp"
#include "core_harness.hpp"
#include "sky/weather/precipitation.hpp"
#include "sky/weather/query.hpp"

namespace sky::test {
namespace {

using weather::CloudType;

// The shape noise is uniform in [0, 1] by construction (cloud_density.glsl's
// cloudShape): over a sight line of many noise cells the optical depth is the
// mean over its values. The harness's noise is one value per march, so the
// march runs once per value of a midpoint grid (shape x detail) and the
// optical depths are averaged.
double sightLineTransmittance(CloudType type, double density, double fogThickness_m, double eyeHeight_m,
                              double distance_m) {
  const double R = 6371000;
  Core c;
  c.coverage = 1.0;
  c.density = density;
  c.cloudMap = Core::real2(0.5, 1.0);
  Core::CoreFrame f = frameOver(R, eyeHeight_m, 0);
  f.layerCount = 1;
  c.layers[0] = shellLayer(f, eyeHeight_m, 0.0, fogThickness_m,
                           render::coreCloudType<Core::CloudType>(render::cloudTypeParams(type)));
  const Core::Span span = c.layerSpan(f, c.layers[0], 0.0, distance_m);  // horizontal, ends at the target
  EXPECT_NEAR(span.t1 - span.t0, distance_m, 1e-6) << "the sight line stays in the fog up to the target";
  constexpr int kShape = 40, kDetail = 8;
  double tau = 0;
  for (int i = 0; i < kShape; ++i)
    for (int j = 0; j < kDetail; ++j) {
      c.noise = (i + 0.5) / kShape;
      c.detail = (j + 0.5) / kDetail;
      const double t = c.marchLayer(f, 0, Core::real3(1, 0, 0), span, 0.5, 1.0).transmittance;
      tau += -std::log(t);
    }
  return std::exp(-tau / (kShape * kDetail));
}

double sightLineTransmittance(double visibility_m, double fogThickness_m, double eyeHeight_m, double distance_m) {
  return sightLineTransmittance(CloudType::Fog, weather::fogDensityForVisibility(visibility_m), fogThickness_m,
                                eyeHeight_m, distance_m);
}

// The fog's soft coverage threshold (0.05 of the noise's range) thins 2.5 %
// of the sheet: T = exp(-3.912 x 0.975) = 0.0219 predicted. Tolerance: the
// contrast within 0.020 +- 0.003 (the visibility within about 5 %).
TEST(Fog, ABlackTargetAtTheVisibilityKeepsTwoPercentContrast) {
  for (double v : {150.0, 400.0, 1000.0, 3000.0}) {
    SCOPED_TRACE("visibility " + std::to_string(v) + " m");
    const double t = sightLineTransmittance(v, 300, 60, v);
    std::printf("[ fog      ] visibility %.0f m: transmittance to a target there %.4f\n", v, t);
    EXPECT_NEAR(t, 0.02, 0.003);
    // Half way the target keeps sqrt of it (Beer-Lambert in a uniform sheet).
    EXPECT_NEAR(sightLineTransmittance(v, 300, 60, 0.5 * v), std::sqrt(t), 0.01);
  }
}

// Rain and snow draw the extinction their rate stands for
// (precipitation.hpp): a target at the Koschmieder visibility of the rate,
// seen at a pilot's eye through the shaft, keeps 2 % of its contrast (the
// same soft threshold as fog's: 0.0219 predicted; tolerance 0.003).
TEST(Precipitation, ABlackTargetAtTheRatesVisibilityKeepsTwoPercentContrast) {
  struct Case {
    CloudType type;
    double rate_mmph;
  };
  for (const Case c : {Case{CloudType::Rain, weather::kModerateRain_mmph}, Case{CloudType::Rain, weather::kHeavyRain_mmph},
                       Case{CloudType::Snow, weather::kModerateSnow_mmph}, Case{CloudType::Sleet, weather::kLightRain_mmph}}) {
    const double v = weather::koschmiederVisibility_m(weather::precipitationExtinction_perm(c.type, c.rate_mmph));
    SCOPED_TRACE(std::string(weather::toString(c.type)) + " " + std::to_string(c.rate_mmph) + " mm/h, visibility " +
                 std::to_string(v) + " m");
    const double t =
        sightLineTransmittance(c.type, weather::precipitationDensityForRate(c.type, c.rate_mmph), 2000, 60, v);
    std::printf("[ precip   ] %s %.1f mm/h: visibility %.0f m, transmittance to a target there %.4f\n",
                std::string(weather::toString(c.type)).c_str(), c.rate_mmph, v, t);
    EXPECT_NEAR(t, 0.02, 0.003);
  }
}

TEST(Fog, TheAnswersVisibilityIsTheReportedOne) {
  for (double v : {100.0, 200.0, 800.0, 5000.0}) {
    const double d = weather::fogDensityForVisibility(v);
    EXPECT_GT(d, 0.0);
    EXPECT_LE(d, 1.0);
    EXPECT_NEAR(weather::cloudVisibility_m(d), v, 1e-9 * v);
  }
  // Shorter than the densest fog the model draws: drawn as that.
  EXPECT_EQ(weather::fogDensityForVisibility(20), 1.0);
  EXPECT_NEAR(weather::cloudVisibility_m(1.0), weather::kMinFogVisibility_m, 1e-9);
  EXPECT_EQ(weather::cloudVisibility_m(0.0), weather::kUnlimitedVisibility_m);
  // One Koschmieder constant for the weather and the renderer's haze.
  EXPECT_EQ(weather::kKoschmiederDepth, Core::kKoschmiederDepth);
  // The fog's extinction per density is the one the answer assumes.
  EXPECT_EQ(render::cloudTypeParams(CloudType::Fog).extinction_perm, weather::kCloudExtinctionPerDensity_perm);
}

}  // namespace
}  // namespace sky::test
