// The march in metres (cloud_core.glsl, MarchParams cloudStep / emptyStep /
// stepGrowth) and the empty-space skipping of absent layers, run by the
// shared core in double precision (core_harness.hpp) and by the CPU
// reference: a uniform slab still transmits exp(-sigma L) with steps that
// grow with distance (every step is exact for a constant extinction, and the
// steps tile the span); growth and long steps through clear air cut the
// lookups; a layer with no coverage anywhere makes no lookups and leaves the
// image as it is without it; the weather map's max-coverage mip bounds every
// weather lookup in its cells.
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <gtest/gtest.h>

#include "core_harness.hpp"
#include "coverage_mip.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/weather/model.hpp"

namespace sky::test {
namespace {

// One uniform layer (extinction sigma) from 1500 m to 2500 m over a camera at
// 500 m, R = 6371 km; the march in metres with the given steps.
Core::CoreFrame slab(Core& c, double sigma, double cloudStep, double emptyStep, double growth, int maxSamples = 1024) {
  const double R = 6371000, alt = 500, base = 1500, H = 1000;
  Core::CoreFrame f = frameOver(R, alt, 1);
  f.march = Core::MarchParams{maxSamples, 2, 0.0, 1.0, cloudStep, emptyStep, growth};
  f.layerCount = 1;
  c.layers[0] = shellLayer(f, alt, base, H, uniformType(sigma));
  return f;
}

Core::Span spanAt(Core& c, const Core::CoreFrame& f, double mu) { return c.layerSpan(f, c.layers[0], mu, 1e12); }

Core::LayerResult march(Core& c, const Core::CoreFrame& f, double mu, double jitter = 0.5) {
  const Core::real3 dir(std::sqrt(1 - mu * mu), 0, mu);
  return c.marchLayer(f, 0, dir, spanAt(c, f, mu), jitter, 1.0);
}

// The presets' slab tolerance (presets_test.cpp): 1e-4 on the transmittance.
constexpr double kSlabTolerance = 1e-4;

TEST(MarchSteps, UniformSlabIsBeerLambertWithGrowingSteps) {
  const double sigma = 1e-3;
  struct Steps {
    double cloud, empty, growth;
  };
  for (const Steps s : {Steps{50, 50, 0}, Steps{50, 200, 0.01}, Steps{100, 800, 0.05}, Steps{20, 400, 0.2}})
    for (double mu : {1.0, 0.5, 0.2, 0.05})
      for (double jitter : {0.01, 0.37, 0.99}) {  // pixelJitter is in [0, 1)
        Core c;
        const Core::CoreFrame f = slab(c, sigma, s.cloud, s.empty, s.growth);
        const Core::Span sp = spanAt(c, f, mu);
        EXPECT_NEAR(march(c, f, mu, jitter).transmittance, std::exp(-sigma * (sp.t1 - sp.t0)), kSlabTolerance)
            << "cloud " << s.cloud << " empty " << s.empty << " growth " << s.growth << " mu " << mu;
      }
}

// Growth puts fewer samples on far spans: at mu 0.05 the layer is 10-30 km
// away, where 0.05 m per m adds 500-1500 m to each 50 m step.
TEST(MarchSteps, GrowthCutsTheLookupsOfFarSpans) {
  Core flat, growing;
  march(flat, slab(flat, 1e-3, 50, 50, 0), 0.05);
  march(growing, slab(growing, 1e-3, 50, 50, 0.05), 0.05);
  std::printf("mu 0.05: %llu lookups without growth, %llu with 0.05\n", (unsigned long long)flat.lookups,
              (unsigned long long)growing.lookups);
  EXPECT_LT(growing.lookups * 10, flat.lookups);
}

// Clear air (coverage 0): the long steps alone visit it, one weather lookup
// each (coverage 0 stops the density there), so the lookups are the span over
// the long step; the same with long steps as short ones costs their ratio more.
TEST(MarchSteps, LongStepsCrossClearAir) {
  for (double mu : {1.0, 0.3}) {
    Core shortOnly, longSteps;
    shortOnly.coverage = longSteps.coverage = 0.0;
    const Core::CoreFrame a = slab(shortOnly, 1e-3, 25, 25, 0);
    const Core::CoreFrame b = slab(longSteps, 1e-3, 25, 250, 0);
    EXPECT_DOUBLE_EQ(march(shortOnly, a, mu).transmittance, 1.0);
    EXPECT_DOUBLE_EQ(march(longSteps, b, mu).transmittance, 1.0);
    const Core::Span sp = spanAt(longSteps, b, mu);
    EXPECT_EQ(longSteps.lookups, std::uint64_t(std::ceil((sp.t1 - sp.t0) / 250)));
    EXPECT_EQ(shortOnly.lookups, std::uint64_t(std::ceil((sp.t1 - sp.t0) / 25)));
  }
}

// A cloud met by a long step is marched in short steps from that step's
// start: with cloud everywhere, the long steps find it at once and the short
// steps integrate it (the slab test above); here the sample count stays that
// of the short steps plus the one long probe.
TEST(MarchSteps, CloudMetByALongStepIsMarchedInShortSteps) {
  Core c;
  const Core::CoreFrame f = slab(c, 1e-3, 40, 400, 0);
  march(c, f, 1.0);
  // Per short step with cloud: weather, cloud map, shape (detail only at
  // edges: the shape is full, 1) = 3 lookups, plus 2 light steps of shape.
  const std::uint64_t shortSteps = 1000 / 40 + 1;
  EXPECT_LE(c.lookups, 3 + shortSteps * 5);
  EXPECT_GE(c.lookups, 3 + (shortSteps - 1) * 5);
}

// An absent layer (the CPU reference sets it for a layer with no coverage
// anywhere on the weather map) is not marched: no lookups, transmittance 1.
TEST(MarchSteps, AbsentLayerMakesNoLookups) {
  Core c;
  Core::CoreFrame f = slab(c, 1e-3, 0, 0, 0, 48);
  c.layers[0].absent = true;
  EXPECT_EQ(march(c, f, 0.5).transmittance, 1.0);
  EXPECT_EQ(c.lookups, 0u);
}

// Through the CPU reference (weather snapshot -> frame setup -> core): a
// cumulus layer alone, and with a second layer of coverage 0 (uniform, no
// tiles): the same image bit for bit and the same lookups; the empty layer
// alone makes none.
weather::CloudLayer cloudLayer(std::uint32_t id, double base_m, double coverage) {
  weather::CloudLayer l;
  l.id = id;
  l.type = weather::CloudType::Cumulus;
  l.base_m = base_m;
  l.thickness_m = 1500;
  l.coverage = coverage;
  l.density = 1.0;
  return l;
}

TEST(MarchSteps, LayerWithNoCoverageCostsNothingInTheCpuReference) {
  render::RenderSettings settings;
  settings.width = 24;
  settings.height = 14;
  settings.march.primarySteps = 16;
  settings.march.lightSteps = 2;
  auto ref = render::CpuReference::create(settings);
  ASSERT_TRUE(ref) << describe(ref.error());
  render::FrameInputs in;
  in.camera.position = {47.0, 8.0, 500.0};
  in.camera.pitch_deg = 20;
  weather::WeatherSnapshot one, two, empty;
  one.layers = {cloudLayer(1, 1200, 0.6)};
  two.layers = {cloudLayer(1, 1200, 0.6), cloudLayer(2, 4000, 0.0)};
  empty.layers = {cloudLayer(2, 4000, 0.0)};
  std::uint64_t lookupsOne = 0, lookupsTwo = 0, lookupsEmpty = 1;
  in.weather = &one;
  auto a = ref->render(in, &lookupsOne);
  in.weather = &two;
  auto b = ref->render(in, &lookupsTwo);
  in.weather = &empty;
  auto e = ref->render(in, &lookupsEmpty);
  ASSERT_TRUE(a && b && e);
  EXPECT_GT(lookupsOne, 0u);
  EXPECT_EQ(lookupsTwo, lookupsOne);
  EXPECT_EQ(lookupsEmpty, 0u);
  ASSERT_EQ(a->rgba.size(), b->rgba.size());
  for (std::size_t i = 0; i < a->rgba.size(); ++i) ASSERT_EQ(a->rgba[i], b->rgba[i]) << "value " << i;
  for (std::size_t i = 0; i < a->cloudDepth_m.size(); ++i) ASSERT_EQ(a->cloudDepth_m[i], b->cloudDepth_m[i]);
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// The max-coverage mip is conservative: no bilinear weather lookup inside a
// cell returns more coverage than the cell holds (so a long step skipped on
// a 0 cell would have found no cloud), in either ring and across their blend
// band; and cells away from the cloud hold 0.
TEST(MarchSteps, CoverageMipBoundsEveryWeatherLookup) {
  render::WeatherField field;
  field.sliceCount = gpu::kMaxLayers;
  const std::size_t n = field.size;
  field.texels.assign(std::size_t(render::kWeatherRings) * field.sliceCount * n * n * 4, 0);
  auto texel = [&](std::uint32_t ring, std::uint32_t slice, std::size_t j, std::size_t i) -> std::uint8_t& {
    return field.texels[(((std::size_t(ring) * field.sliceCount + slice) * n + j) * n + i) * 4];
  };
  // Slice 1: a ragged patch of coverage around texel (100, 60) and one lone
  // texel in the fine ring; in the coarse ring (4.7 km texels: the fine
  // ring's blend band, 85-95 km east of the centre, is texels 146-148), a
  // patch across that band and one texel far out.
  std::uint32_t state = 12345;
  auto next = [&] { return state = state * 1664525u + 1013904223u; };
  for (std::uint32_t j = 40; j < 80; ++j)
    for (std::uint32_t i = 90; i < 120; ++i)
      if (next() % 3 == 0) texel(0, 1, j, i) = std::uint8_t(next() % 256);
  texel(0, 1, 200, 17) = 255;
  for (std::uint32_t j = 100; j < 150; ++j)
    for (std::uint32_t i = 140; i < 152; ++i)
      if (next() % 2 == 0) texel(1, 1, j, i) = std::uint8_t(next() % 256);
  texel(1, 1, 30, 230) = 200;
  const std::vector<float> mip = render::buildCoverageMip(field);
  ASSERT_EQ(mip.size(), render::kCoverageMipFloats);
  const std::size_t cells = std::size_t(render::kCoverageMipCells) * render::kCoverageMipCells;
  std::size_t zeroCells = 0;
  for (std::size_t c = cells; c < 2 * cells; ++c) zeroCells += mip[c] == 0.0f;  // fine ring, slice 1
  EXPECT_GT(zeroCells, 900u) << "of 1024 cells, all but those near the patch and the lone texel";
  for (std::uint32_t slice : {0u, 1u})
    for (int k = 0; k < 200000; ++k) {
      // Half the points within the fine ring, half over the coarse one.
      const double extent = 1.02 * field.halfExtent_m[k % 2];
      const double x = (double(next() % 2000001) / 1e6 - 1.0) * extent;
      const double y = (double(next() % 2000001) / 1e6 - 1.0) * extent;
      const double coverage = field.sample(slice, x, y).x;
      ASSERT_GE(render::sampleCoverageMip(mip, field, slice, x, y) + 1e-6, coverage)
          << "slice " << slice << " at " << x << ", " << y;
    }
  // And the coarse ring's far texel is seen (a mip of the fine ring alone
  // would give 0 there).
  const double far_m = (230.5 / n - 0.5) * 2 * field.halfExtent_m[1], farY_m = (30.5 / n - 0.5) * 2 * field.halfExtent_m[1];
  EXPECT_GT(field.sample(1, far_m, farY_m).x, 0.5);
  EXPECT_GT(render::sampleCoverageMip(mip, field, 1, far_m, farY_m), 0.5);
}

}  // namespace
}  // namespace sky::test
