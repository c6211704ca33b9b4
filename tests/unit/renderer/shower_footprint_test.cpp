// Showers fall under the cells that drop them: a precipitation layer whose
// top is inside a cloud layer (METAR's showers under cumulus, a rain layer
// under a storm) is drawn only below that layer's cells, in the shared
// density model compiled as C++ (cloud_core.glsl's carrierFootprint and
// layerSample). The carrier is chosen per snapshot (frame_setup.cpp's
// precipitationCarriers).
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

#include "cloud_types.hpp"
#include "core_harness.hpp"
#include "frame_setup.hpp"

namespace sky::test {
namespace {

using weather::CloudType;

constexpr double kR = 6371000;
constexpr double kEye_m = 300;
constexpr double kCarrierBase_m = 1500, kCarrierThickness_m = 1200;
constexpr double kRainTop_m = 1900;
constexpr double kRainHeight_m = 400;  // where the rain is sampled

// Cells of cumulus 4 km apart for the carrier (layer 0), and an unrelated
// pattern for the rain's own noise (layer 1): both constant with height, so
// the cells seen from below are the cells at the footprint's height.
Core::real2 cellNoise(Core::LayerSampling s, Core::real3 p) {
  const double k = 2 * std::numbers::pi;
  const double n = s.coverageShift.z < 0.5 ? 0.5 + 0.5 * std::sin(k * p.x / 4000) * std::sin(k * p.y / 4000)
                                           : 0.5 + 0.5 * std::sin(k * (p.x + 1234) / 5000) * std::cos(k * p.y / 3000);
  return Core::real2(n, n);
}

struct Showers {
  Core c;
  Core::CoreFrame f = frameOver(kR, kEye_m, 1000);
  Core::CoreLayer& carrier = c.layers[0];
  Core::CoreLayer& rain = c.layers[1];
  explicit Showers(double coverage) {
    c.coverage = coverage;
    c.cloudMap = Core::real2(0.5, 1.0);  // mappedCoverage(c, 0.5) = c
    c.shapeAt = cellNoise;
    f.layerCount = 2;
    carrier = shellLayer(f, kEye_m, kCarrierBase_m, kCarrierThickness_m,
                         render::coreCloudType<Core::CloudType>(render::cloudTypeParams(CloudType::Cumulus)));
    rain = shellLayer(f, kEye_m, 0.0, kRainTop_m,
                      render::coreCloudType<Core::CloudType>(render::cloudTypeParams(CloudType::Rain)));
    carrier.sampling.coverageShift.z = 0;
    rain.sampling.coverageShift.z = 1;
  }
  // The rain's density at a point kRainHeight_m above the ground, x east
  // and y north of the camera (m).
  double rainAt(double x, double y, bool cheap = false) {
    const Core::real3 p(x, y, kRainHeight_m - kEye_m);
    const double h = c.heightAboveCameraSphere(p, f.air.r);
    const double ph = (h + rain.hBase) / rain.thickness;
    return c.layerSample(rain, p, h, ph, cheap, f.air.r).rho;
  }
  // Whether the carrier's cloud is over the point: the body of its cloud
  // (before the detail noise erodes its edges) where its shape is full
  // height (ph 0.1: above the base's rounding, below the top's).
  bool cloudAbove(double x, double y) {
    const double z = kCarrierBase_m + 0.1 * kCarrierThickness_m - kEye_m;
    const Core::real3 p(x, y, z + (x * x + y * y) / (2 * f.air.r));  // on that shell, near enough
    const double h = c.heightAboveCameraSphere(p, f.air.r);
    return c.cloudSample(carrier, p, (h + carrier.hBase) / carrier.thickness, true, 1.0).rho > 0;
  }
};

struct Counts {
  int points = 0, wet = 0, wetUnderCloud = 0, cloud = 0;
};

Counts countOver(Showers& s) {
  Counts n;
  for (int i = 0; i < 80; ++i)
    for (int j = 0; j < 80; ++j) {
      const double x = -10000 + 250.0 * i + 37, y = -10000 + 250.0 * j + 91;
      const bool wet = s.rainAt(x, y) > 0, cloud = s.cloudAbove(x, y);
      ++n.points;
      n.wet += wet;
      n.cloud += cloud;
      n.wetUnderCloud += wet && cloud;
    }
  return n;
}

TEST(ShowerFootprint, RainFallsUnderTheCellsThatDropIt) {
  Showers coupled(0.4);
  coupled.rain.carrier = 0;
  const Counts a = countOver(coupled);
  Showers alone(0.4);
  alone.rain.carrier = -1;
  const Counts b = countOver(alone);
  std::printf("[ showers ] cloud over %d of %d points; rain under its cells: %d wet, %d under cloud; rain of its "
              "own noise: %d wet, %d under cloud\n",
              a.cloud, a.points, a.wet, a.wetUnderCloud, b.wet, b.wetUnderCloud);
  ASSERT_GT(a.cloud, a.points / 10);
  ASSERT_LT(a.cloud, a.points / 2);
  // No rain from the clear sky, and every cell rains (the rain's coverage,
  // the carrier's, is a share of 1 of the cells) but where the rain's own
  // noise is 0.
  EXPECT_EQ(a.wetUnderCloud, a.wet);
  EXPECT_GE(a.wet, 0.95 * a.cloud);
  // Its own noise alone, the rain falls from the clear sky as often as not.
  EXPECT_LT(b.wetUnderCloud, 0.6 * b.wet);
}

// Rain of half the carrier's coverage falls from about half its cells: the
// rain's own noise picks which (its coverage there 0.2 / 0.4).
TEST(ShowerFootprint, LessRainThanCloudFallsFromSomeOfTheCells) {
  Showers s(0.4);
  s.rain.carrier = 0;
  s.c.coverageAt = [](Core::real3 p) { return p.z < 800 - kEye_m ? 0.2 : 0.4; };  // rain below, cloud above
  const Counts n = countOver(s);
  std::printf("[ showers ] 0.2 of rain under 0.4 of cloud: %d wet of %d under cloud\n", n.wet, n.cloud);
  EXPECT_EQ(n.wetUnderCloud, n.wet);
  EXPECT_GT(n.wet, 0.3 * n.cloud);
  EXPECT_LT(n.wet, 0.7 * n.cloud);
}

// The long steps' cheap sample (no erosion) is never below the full one,
// under the footprint as without: a step over a shaft's edge is marched
// again in short steps, never skipped.
TEST(ShowerFootprint, TheCheapSampleIsNeverBelowTheFullOne) {
  Showers s(0.4);
  s.rain.carrier = 0;
  int full = 0;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) {
      const double x = -7000 + 233.0 * i, y = -7000 + 241.0 * j;
      const double f = s.rainAt(x, y), cheap = s.rainAt(x, y, true);
      full += f > 0;
      EXPECT_GE(cheap, f) << x << ", " << y;
    }
  EXPECT_GT(full, 100);
}

// A closed carrier covers everything: the rain is its own noise's, the
// same as with no carrier.
TEST(ShowerFootprint, UnderAClosedDeckTheRainIsItsOwn) {
  Showers coupled(1.0), alone(1.0);
  coupled.rain.carrier = 0;
  alone.rain.carrier = -1;
  for (int i = 0; i < 40; ++i) {
    const double x = -5000 + 250.0 * i + 13, y = 3000 - 170.0 * i;
    EXPECT_EQ(coupled.rainAt(x, y), alone.rainAt(x, y)) << x << ", " << y;
  }
}

// The carrier is the cloud layer holding the precipitation's top, the
// lowest of several; fog, other precipitation and a layer above the top
// are not; a precipitation layer's top in clear air has none.
TEST(ShowerFootprint, TheCarrierHoldsThePrecipitationsTop) {
  auto at = [](std::uint32_t id, CloudType type, double base_m, double thickness_m) {
    weather::CloudLayer l;
    l.id = id;
    l.type = type;
    l.base_m = base_m;
    l.thickness_m = thickness_m;
    l.coverage = 0.5;
    l.density = 1;
    return l;
  };
  const std::vector<weather::CloudLayer> layers = {
      at(1, CloudType::Cumulus, 1500, 1200),        // 0: holds 1900
      at(2, CloudType::Cumulonimbus, 1200, 8000),   // 1: holds 1900 too, lower base
      at(3, CloudType::Rain, 0, 1900),              // 2: -> 1
      at(4, CloudType::Fog, 0, 3000),               // 3: fog is no carrier
      at(5, CloudType::Snow, 200, 600),             // 4: top at 800, in fog only -> -1
      at(6, CloudType::Altostratus, 4000, 1000),    // 5
      at(7, CloudType::Sleet, 2000, 2500),          // 6: top at 4500 -> 1 (the storm) not 5
      at(8, CloudType::Hail, 0, 4000),              // 7: top at 4000: the altostratus's base, not in it -> 1
  };
  const std::vector<int> carriers = render::precipitationCarriers(layers);
  const std::vector<int> expected = {-1, -1, 1, -1, -1, -1, 1, 1};
  EXPECT_EQ(carriers, expected);
}

}  // namespace
}  // namespace sky::test
