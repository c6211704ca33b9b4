// The quality presets (sky/render/presets.hpp): the names --preset takes and
// the error for others; `high` is the default march; `reference` is the most
// expensive; each preset's march, run by the shared core in double
// precision, transmits a uniform slab as exp(-sigma L) (a closed form) and
// a cumulus layer close to what `reference` transmits, and the cheaper a
// preset, the fewer shape-noise lookups it makes (counted by the harness).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "core_harness.hpp"
#include "sky/render/presets.hpp"

namespace sky::test {
namespace {

using render::Preset;

Core::MarchParams params(const render::MarchSettings& m) {
  return Core::MarchParams{int(m.primarySteps), int(m.lightSteps), m.minTransmittance, double(m.emptyStride),
                           m.cloudStep_m, m.emptyStep_m, m.stepGrowth};
}

// One layer from base to base + thickness over a camera at 500 m (R = 6371
// km), of a type filling it uniformly with extinction sigma, or Haggstrom's
// cumulus profile (density and shape vary with height).
Core::CoreFrame slabFrame(Core& c, const render::MarchSettings& m, double sigma, bool cumulus) {
  const double R = 6371000, alt = 500, base = 1500, H = 1000;
  Core::CloudType t = uniformType(sigma);
  if (cumulus) {
    t = haggstromCumulus(sigma);
    t.columnFill = 0.0;  // the profile alone
  }
  Core::CoreFrame f = frameOver(R, alt, 1);
  f.march = params(m);
  f.layerCount = 1;
  c.layers[0] = shellLayer(f, alt, base, H, t);
  return f;
}

Core::LayerResult march(Core& c, const Core::CoreFrame& f, double mu) {
  const Core::real3 dir(std::sqrt(1 - mu * mu), 0, mu);
  return c.marchLayer(f, 0, dir, c.layerSpan(f, c.layers[0], mu, 1e12), 0.5, 1.0);
}

TEST(Presets, NamesAndUnknownNameError) {
  const auto& all = render::presets();
  ASSERT_EQ(all.size(), 5u);
  const char* names[] = {"reference", "high", "medium", "low", "realtime"};
  for (std::size_t i = 0; i < all.size(); ++i) EXPECT_EQ(all[i].name, names[i]);
  auto medium = render::findPreset("medium");
  ASSERT_TRUE(medium);
  EXPECT_GT(medium->march.cloudStep_m, 0.0) << "medium marches in metres";
  EXPECT_EQ(medium->temporal.interleave, 4u) << "medium draws 1 pixel of 16 per frame";
  auto bad = render::findPreset("ultra");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(bad.error().detail.find("'ultra'"), std::string::npos) << bad.error().detail;
  for (const char* n : names) EXPECT_NE(bad.error().detail.find(n), std::string::npos) << n;
  EXPECT_FALSE(render::findPreset(""));
  EXPECT_FALSE(render::findPreset("Medium"));
}

TEST(Presets, HighIsTheDefaultAndReferenceTheMostExpensive) {
  const render::MarchSettings def;
  const auto high = render::findPreset("high");
  ASSERT_TRUE(high);
  EXPECT_EQ(high->march.primarySteps, def.primarySteps);
  EXPECT_EQ(high->march.lightSteps, def.lightSteps);
  EXPECT_EQ(high->march.minTransmittance, def.minTransmittance);
  EXPECT_EQ(high->march.emptyStride, def.emptyStride);
  const auto& all = render::presets();
  EXPECT_EQ(all[0].march.minTransmittance, 0.0) << "reference: no early exit";
  EXPECT_EQ(all[0].march.emptyStride, 1u) << "reference: every sample";
  EXPECT_GE(all[0].march.lightSteps, 6u);
  EXPECT_EQ(all[0].march.cloudStep_m, 0.0) << "reference: evenly placed samples";
  EXPECT_FALSE(all[0].march.airTable.enabled) << "reference: the air marched per pixel";
  EXPECT_EQ(all[0].march.airSteps, 64u) << "reference: the air march's most steps";
  for (std::size_t i = 1; i < all.size(); ++i) {
    EXPECT_TRUE(all[i].march.airTable.enabled) << all[i].name << ": the air from the table";
    // Cheaper presets never build a larger table.
    if (i > 1) {
      const render::AirTableSettings &t = all[i].march.airTable, &before = all[i - 1].march.airTable;
      EXPECT_LE(std::uint64_t(t.azimuths) * t.zeniths * t.slices,
                std::uint64_t(before.azimuths) * before.zeniths * before.slices)
          << all[i].name;
    }
  }
  EXPECT_EQ(all[0].temporal.interleave, 1u) << "reference: every pixel of every frame";
  EXPECT_EQ(high->temporal.interleave, 1u) << "high: every pixel of every frame";
  // Cheaper presets never reproject fewer pixels. Between two presets that
  // draw the same share of the pixels (same interleave, same divisor) the
  // later one's march is the cheaper: never more light steps, an exit no
  // later; evenly placed ones fewer samples, those in metres (primarySteps a
  // cap) never shorter steps, never slower growth, never more air steps, and
  // at least one of these strictly cheaper. Across a change of that share
  // (high -> medium draws 1 pixel of 16) the march may cost more per ray;
  // CumulusCloseToReferenceWithFewerLookups checks the cost per frame.
  for (std::size_t i = 1; i < all.size(); ++i) {
    const render::MarchSettings &m = all[i].march, &before = all[i - 1].march;
    EXPECT_LE(m.lightSteps, before.lightSteps) << all[i].name;
    EXPECT_GE(all[i].temporal.interleave, all[i - 1].temporal.interleave) << all[i].name;
    EXPECT_GE(all[i].resolution.divisor, all[i - 1].resolution.divisor) << all[i].name;
    if (all[i].temporal.interleave != all[i - 1].temporal.interleave ||
        all[i].resolution.divisor != all[i - 1].resolution.divisor)
      continue;
    EXPECT_GE(m.minTransmittance, before.minTransmittance) << all[i].name;
    if (m.cloudStep_m == 0) {
      EXPECT_LT(m.primarySteps, before.primarySteps) << all[i].name;
    }
    if (before.cloudStep_m > 0) {
      EXPECT_GE(m.cloudStep_m, before.cloudStep_m) << all[i].name;
      EXPECT_GE(m.emptyStep_m, before.emptyStep_m) << all[i].name;
      EXPECT_GE(m.stepGrowth, before.stepGrowth) << all[i].name;
      EXPECT_LE(m.airSteps, before.airSteps) << all[i].name;
      EXPECT_TRUE(m.lightSteps < before.lightSteps || m.minTransmittance > before.minTransmittance ||
                  m.cloudStep_m > before.cloudStep_m || m.stepGrowth > before.stepGrowth ||
                  m.airSteps < before.airSteps)
          << all[i].name << " is not cheaper than " << all[i - 1].name;
    }
  }
}

// A uniform slab: every preset's step integration is exact for a constant
// extinction (the product of the steps' e^{-sigma dt} is e^{-sigma L}), as
// long as the early exit does not stop it (tau 1 vertical, 2 slant, T > 5 %);
// with tau 8 (slant) reference marches through and the others stop within
// one step of falling under their threshold.
TEST(Presets, UniformSlabTransmitsBeerLambertForEveryPreset) {
  const double sigma = 1e-3, H = 1000;
  for (const Preset& p : render::presets()) {
    Core c;
    const Core::CoreFrame f = slabFrame(c, p.march, sigma, false);
    EXPECT_NEAR(march(c, f, 1.0).transmittance, std::exp(-sigma * H), 1e-4) << p.name;
    const double slant = c.layerSpan(f, c.layers[0], 0.5, 1e12).t1 - c.layerSpan(f, c.layers[0], 0.5, 1e12).t0;
    EXPECT_NEAR(march(c, f, 0.5).transmittance, std::exp(-sigma * slant), 1e-4) << p.name;
    const Core::CoreFrame g = slabFrame(c, p.march, 4 * sigma, false);
    const double tau = 4 * sigma * slant, T = march(c, g, 0.5).transmittance;
    if (p.march.minTransmittance == 0)
      EXPECT_NEAR(T, std::exp(-tau), 1e-6) << p.name;
    else
      EXPECT_LT(T, p.march.minTransmittance * std::exp(tau / p.march.primarySteps)) << p.name;
  }
}

// A cumulus profile: each preset's transmittance and in-scattered light
// within a stated distance of reference's, and its lookups per frame fewer
// than the preset before it's: a ray's lookups times the share of the
// pixels it draws each frame (1 / (interleave divisor)^2).
constexpr double kCumulusSigma = 0.004;  // 1/m at full density: tau about 1-2 vertically

TEST(Presets, CumulusCloseToReferenceWithFewerLookups) {
  const auto& all = render::presets();
  for (double mu : {1.0, 0.5, 0.2}) {
    Core ref;
    const Core::LayerResult want = march(ref, slabFrame(ref, all[0].march, kCumulusSigma, true), mu);
    double previous = double(ref.shapeLookups);
    for (std::size_t i = 1; i < all.size(); ++i) {
      Core c;
      const Core::LayerResult got = march(c, slabFrame(c, all[i].march, kCumulusSigma, true), mu);
      std::printf("mu %.1f %-9s T %.4f (ref %.4f) L %.4f (ref %.4f) lookups %llu (ref %llu)\n", mu,
                  all[i].name.c_str(), got.transmittance, want.transmittance, got.inscatter.x, want.inscatter.x,
                  (unsigned long long)c.shapeLookups, (unsigned long long)ref.shapeLookups);
      // Transmittance: within 0.005, or where the early exit stops the
      // march, within its threshold. Light: within 10 % (measured: realtime
      // 4.6-6.8 %, the others under 2.5 %).
      EXPECT_NEAR(got.transmittance, want.transmittance, std::max(0.005, all[i].march.minTransmittance))
          << all[i].name << " mu " << mu;
      EXPECT_NEAR(got.inscatter.x / want.inscatter.x, 1.0, 0.10) << all[i].name << " mu " << mu;
      const double side = double(all[i].temporal.interleave) * all[i].resolution.divisor;
      const double perFrame = double(c.shapeLookups) / (side * side);
      EXPECT_LT(perFrame, previous) << all[i].name << " mu " << mu;
      previous = perFrame;
    }
  }
}

}  // namespace
}  // namespace sky::test
