// Cumulonimbus anvils in the shared density model (cloud_density.glsl, the
// CPU reference's double-precision build of it) with the type table's own
// numbers: over a storm cell whose coverage falls from 0.9 at its core to
// 0.15 at its rim, the cloud's horizontal extent at the top of the layer is
// the whole cell while at mid-height it is the tower, both against Haggstrom's
// eq. 5-7 / 17 evaluated by hand; the top is flat (the same for a low and a
// tall tower); beyond the tower the anvil overhangs clear air; and no other
// type's profile or coverage changes.
#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "cloud_types.hpp"
#include "core_harness.hpp"

namespace sky::test {
namespace {

using weather::CloudType;

Core::CloudType coreType(const render::CloudTypeParams& p) { return render::coreCloudType<Core::CloudType>(p); }

// The storm cell of the GPU suite's cumulonimbus scene (tests/gpu/scenes.cpp):
// coverage 0.9 out to 3 km, falling linearly to 0.15 at 14 km, 0 beyond.
constexpr double kCore_m = 3000, kRim_m = 14000, kCoreCover = 0.9, kRimCover = 0.15;
double cellCoverage(double d_m) {
  if (d_m < kCore_m) return kCoreCover;
  if (d_m <= kRim_m) return kCoreCover + (kRimCover - kCoreCover) * (d_m - kCore_m) / (kRim_m - kCore_m);
  return 0;
}

// Whether any shape noise value in [0, 1] makes cloud at distance d from the
// cell's centre and height fraction ph (noise 1 is the most cloud can get:
// cloudShape grows with the noise), with the cloud map neutral (0.5: coverage
// unmoved) and the peak noise given.
bool cloudPossible(Core& c, const Core::CloudType& t, double d_m, double ph, double peakNoise) {
  const double cover = c.anvilCoverage(t, ph, c.mappedCoverage(cellCoverage(d_m), 0.5));
  const double sa = c.shapeProfile(t, ph, cover, peakNoise);
  return c.cloudShape(t, Core::real2(1.0), cover, sa) > 0;
}

// Largest distance from the centre (10 m steps) at which cloud is possible.
double extent_m(Core& c, const Core::CloudType& t, double ph, double peakNoise) {
  double last = -1;
  for (double d = 0; d <= kRim_m + 2000; d += 10)
    if (cloudPossible(c, t, d, ph, peakNoise)) last = d;
  return last;
}

TEST(Anvil, CumulonimbusTopSpreadsOverTheCellWiderThanTheTower) {
  Core c;
  const render::CloudTypeParams& p = render::cloudTypeParams(CloudType::Cumulonimbus);
  ASSERT_EQ(p.peak, 1.0);
  ASSERT_EQ(p.anvil, 1.0);
  const Core::CloudType cb = coreType(p);
  // Mid-height (ph 0.5, below the anvil zone; peak noise 1: wh = 1): SA =
  // SAT(0.5 / 0.07) SAT((1 - 0.5) / (1 - 0.2)) = 0.625, and cloud forms
  // where noise * SA > 1 - c, so only where c > 0.375: d < 3 km + (0.9 -
  // 0.375) / 0.75 * 11 km = 10.7 km.
  const double towerHand_m = kCore_m + (kCoreCover - 0.375) / (kCoreCover - kRimCover) * (kRim_m - kCore_m);
  EXPECT_NEAR(towerHand_m, 10700.0, 1e-9);
  const double tower_m = extent_m(c, cb, 0.5, 1.0);
  EXPECT_NEAR(tower_m, towerHand_m, 10.0);
  // Top (ph 0.95, end of the anvil zone): coverage c -> 1 wherever c > 0,
  // the top rounding -> 1, so SA = 1 and cloud fills the whole cell out to
  // its 14 km rim, whatever the tower's peak (tall: peak noise 1, low: 0).
  for (double peakNoise : {1.0, 0.0}) {
    SCOPED_TRACE(peakNoise);
    EXPECT_NEAR(c.anvilCoverage(cb, 0.95, 0.15), 1.0, 1e-12);
    EXPECT_NEAR(c.shapeProfile(cb, 0.95, 1.0, peakNoise), 1.0, 1e-12);
    EXPECT_NEAR(extent_m(c, cb, 0.95, peakNoise), kRim_m, 10.0);
  }
  EXPECT_GT(kRim_m, 1.25 * tower_m);
  // Overhang: at 12 km (c = 0.286) the anvil is full cloud for every noise value above the soft edge
  // while nothing can form at mid-height below it.
  EXPECT_FALSE(cloudPossible(c, cb, 12000, 0.5, 1.0));
  const double cTop = c.anvilCoverage(cb, 0.95, cellCoverage(12000));
  EXPECT_NEAR(c.cloudShape(cb, Core::real2(p.coverageEdge), cTop, c.shapeProfile(cb, 0.95, cTop, 1.0)), 1.0, 1e-12);
  // The anvil has density where it spreads: DA(0.93) = 0.93 SAT(0.93 / 0.15)
  // SAT(0.07 / 0.1) (1 + (sqrt(0.93) - 0.4) / 0.55 (0.2 - 1)), eq. 8-9 and 18.
  const double daHand = 0.93 * 1.0 * 0.7 * (1 + (std::sqrt(0.93) - 0.4) / 0.55 * (0.2 - 1));
  EXPECT_GT(daHand, 0.1);
  EXPECT_NEAR(c.densityProfile(cb, 0.93), daHand, 1e-12);
}

TEST(Anvil, OtherTypesKeepHaggstromsProfileAndCoverage) {
  Core c;
  for (CloudType type : {CloudType::Cumulus, CloudType::Stratocumulus, CloudType::Stratus, CloudType::Nimbostratus,
                         CloudType::Altocumulus, CloudType::Altostratus, CloudType::Cirrus, CloudType::Cirrostratus,
                         CloudType::Cirrocumulus}) {
    SCOPED_TRACE(std::string(weather::toString(type)));
    const render::CloudTypeParams& p = render::cloudTypeParams(type);
    ASSERT_EQ(p.anvil, 0.0);
    const Core::CloudType t = coreType(p);
    for (double ph : {0.05, 0.5, 0.7, 0.8, 0.95})
      for (double peakNoise : {0.0, 1.0}) {
        // Eq. 5-6 by hand: SAT(ph / baseRound) SAT((wh - ph) / (wh (1 - topRoundStart))).
        const double wh = p.peak * (1 - p.peakVariation * (1 - peakNoise));
        const double hand = std::clamp(ph / p.baseRound, 0.0, 1.0) *
                            std::clamp((wh - ph) / (wh * (1 - p.topRoundStart)), 0.0, 1.0);
        EXPECT_NEAR(c.shapeProfile(t, ph, 0.6, peakNoise), hand, 1e-12) << "ph " << ph;
        EXPECT_EQ(c.anvilCoverage(t, ph, 0.3), 0.3);
      }
  }
  // A cumulus top narrows instead: at ph 0.95 SA = 0.05 / 0.8, so cloud
  // needs c > 1 - 0.0625 and the storm cell's 0.9 core has none.
  const Core::CloudType cu = coreType(render::cloudTypeParams(CloudType::Cumulus));
  EXPECT_LT(extent_m(c, cu, 0.95, 1.0), 0.0);
}

}  // namespace
}  // namespace sky::test
