// A wind that varies over the map (wind tiles): a shear moves the clouds on
// each side by their own wind, on the GPU, and the GPU agrees with the CPU
// reference while the noise's two flow phases crossfade.
#include <algorithm>
#include <chrono>
#include <vector>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/presets.hpp"
#include "sky/weather/tiling.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::test {
namespace {

constexpr double kLat = 46, kLon = 14;
constexpr float kWind_mps = 15;

// One layer of uniform cover 0.5 whose wind tiles (level 12, ~2 km) blow
// northwards west of kLon and southwards east of it (shear), or northwards
// everywhere (control); the layer's own wind is calm.
weather::WeatherSnapshot windSnapshot(bool shear, double coverage = 0.5, double density = 1.0) {
  weather::WeatherSnapshot s;
  weather::CloudLayer l = layer(1, 1500, 1000, coverage, density);
  s.layers.push_back(l);
  s.windTileLevel = 12;
  for (std::uint64_t cell : weather::coverCap({kLat, kLon, 60000}, 12, 100000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    const float north = !shear || c.lon_deg < kLon ? kWind_mps : -kWind_mps;
    s.windTiles.push_back({cell, 1, 0.0f, north, 0.0f});
  }
  return s;
}

std::vector<double> luminance(const render::Image& im) {
  std::vector<double> out(std::size_t(im.width) * im.height);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = 0.2126 * im.rgba[4 * i] + 0.7152 * im.rgba[4 * i + 1] + 0.0722 * im.rgba[4 * i + 2];
  return out;
}

// The row shift k (features moved k rows up, i.e. north) that best matches
// `later` to `before` over columns [c0, c1).
int bestRowShift(const render::Image& before, const render::Image& later, std::uint32_t c0, std::uint32_t c1) {
  const auto a = luminance(before), b = luminance(later);
  const int w = int(before.width), h = int(before.height);
  int best = 0;
  double bestErr = 1e300;
  for (int k = -35; k <= 35; ++k) {
    double err = 0;
    int n = 0;
    for (int r = 0; r < h; ++r) {
      const int r0 = r + k;
      if (r0 < 0 || r0 >= h) continue;
      for (int c = int(c0); c < int(c1); ++c) {
        const double d = b[std::size_t(r) * w + c] - a[std::size_t(r0) * w + c];
        err += d * d;
        ++n;
      }
    }
    if (n > 0 && err / n < bestErr) {
      bestErr = err / n;
      best = k;
    }
  }
  return best;
}

// Looking straight down from 12 km on a deck 10 km below (~12 km of it
// across the image): 60 s of 15 m/s is 900 m, ~12 rows.
TEST(WindField, AShearMovesEachSideByItsOwnWind) {
  SKY_RENDERER(r, 160, 90);
  const geo::GeodeticPose camera = pose(kLat, kLon, 12000, 0, -90);
  // Both frames in phase A's plateau (ages 200 and 260 s of its 600): the
  // noise moves with the wind alone, no crossfade.
  auto frame = [&](const weather::WeatherSnapshot& s, double clock_s) {
    render::FrameInputs in;
    in.camera = camera;
    in.weather = &s;
    in.weatherClock_s = clock_s;
    in.sunElevation_deg = 60;
    auto im = r.render(in);
    EXPECT_TRUE(im) << (im ? "" : describe(im.error()));
    return im ? *im : render::Image{};
  };
  const weather::WeatherSnapshot control = windSnapshot(false), shear = windSnapshot(true);
  const render::Image c0 = frame(control, 200), c1 = frame(control, 260);
  const render::Image s0 = frame(shear, 200), s1 = frame(shear, 260);
  ASSERT_EQ(c0.width, 160u);
  savePng(s0, "wind_shear_t200");
  savePng(s1, "wind_shear_t260");
  // West and east thirds, clear of the ~2 km the field blends across.
  const int controlWest = bestRowShift(c0, c1, 0, 53), controlEast = bestRowShift(c0, c1, 107, 160);
  const int shearWest = bestRowShift(s0, s1, 0, 53), shearEast = bestRowShift(s0, s1, 107, 160);
  std::printf("rows moved in 60 s: uniform wind west %d east %d; shear west %d east %d\n", controlWest, controlEast,
              shearWest, shearEast);
  EXPECT_GE(controlWest, 6);  // north is up in the image
  EXPECT_NEAR(controlEast, controlWest, 1);
  EXPECT_NEAR(shearWest, controlWest, 1);   // west of the line: northwards, as the uniform wind
  EXPECT_NEAR(shearEast, -controlWest, 1);  // east of it: as far southwards
}

// The CPU reference at the middle of a crossfade (both flow phases read,
// weighted half and half) and on a plateau: the same model on both.
TEST(WindField, GpuMatchesTheCpuReferenceAcrossTheFlowCrossfade) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const weather::WeatherSnapshot shear = windSnapshot(true);
  for (double clock_s : {150.0, 230.0}) {
    SCOPED_TRACE(clock_s);
    render::FrameInputs in;
    in.camera = pose(kLat, kLon - 0.02, 800, 80, 25);
    in.weather = &shear;
    in.weatherClock_s = clock_s;
    in.sunElevation_deg = 40;
    auto gpu = r.render(in);
    ASSERT_TRUE(gpu) << describe(gpu.error());
    auto cpu = reference->render(in);
    ASSERT_TRUE(cpu) << describe(cpu.error());
    const Diff d = diff(*gpu, *cpu);
    const double mean = render::computeStats(*cpu).meanLuminance;
    const double meanError = std::abs(render::computeStats(*gpu).meanLuminance - mean) / mean;
    std::printf("[ gpu/cpu  ] wind shear at %.0f s: mean %.4f (gpu %+.3f %%) displayed rmse %.2f %%\n", clock_s, mean,
                100 * meanError, 100 * d.displayedRmse / d.displayedMean);
    // The tolerances of gpu_vs_cpu_test.cpp.
    EXPECT_LT(meanError, 0.005);
    EXPECT_LT(d.displayedRmse, 0.05 * d.displayedMean);
  }
}

// A wind field as tiles that all carry the layer's own wind draws what the
// layer's own wind draws, also with `reference`'s march (256 samples, the
// sun's column in 64 steps per layer): the pipeline with the flow's code
// stays within llvmpipe's 65535 loop iterations per invocation
// (docs/light-transport.md). A loop per noise read spent them there and
// left the image too bright (mean transmittance 0.40 for 0.32 here).
TEST(WindField, AUniformFieldDrawsAsTheLayersOwnWindUnderReferencesMarch) {
  SKY_RENDERER(shared, 64, 36);  // skips without Vulkan; keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  render::RenderSettings settings;
  settings.width = 64;
  settings.height = 36;
  settings.march = render::findPreset("reference")->march;
  auto created = render::CloudRenderer::create(settings);
  ASSERT_TRUE(created) << describe(created.error());
  render::CloudRenderer& r = **created;
  // A thin overcast stratus (density 0.05): every sample of the view ray is
  // in cloud and marches its column, the most loop iterations a pixel takes.
  weather::WeatherSnapshot field = windSnapshot(false, 1.0, 0.05);
  field.layers[0].type = weather::CloudType::Stratus;
  weather::WeatherSnapshot own = field;
  own.windTiles.clear();
  own.windTileLevel = 0;
  own.layers[0].wind = {kWind_mps, 180, 0};  // from the south: northwards, as the tiles
  auto frame = [&](const weather::WeatherSnapshot& s) {
    render::FrameInputs in;
    in.camera = pose(kLat, kLon, 500, 0, 45);
    in.weather = &s;
    in.weatherClock_s = 230;  // phase A's plateau
    in.sunElevation_deg = 40;
    auto im = r.render(in);
    EXPECT_TRUE(im) << (im ? "" : describe(im.error()));
    return im ? *im : render::Image{};
  };
  const render::Image a = frame(own), b = frame(field);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  ASSERT_FALSE(a.rgba.empty());
  double ta = 0, tb = 0;
  for (std::size_t i = 3; i < a.rgba.size(); i += 4) {
    ta += a.rgba[i];
    tb += b.rgba[i];
  }
  ta /= double(a.rgba.size() / 4);
  tb /= double(b.rgba.size() / 4);
  const Diff d = diff(b, a);
  std::printf("[ wind ref ] own wind T %.4f, uniform field T %.4f, displayed rmse %.2f %%\n", ta, tb,
              100 * d.displayedRmse / d.displayedMean);
  ASSERT_GT(ta, 0.05);  // the view sees the deck and through it
  ASSERT_LT(ta, 0.95);
  EXPECT_NEAR(tb, ta, 0.01);
  EXPECT_LT(d.displayedRmse, 0.05 * d.displayedMean);
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// What a wind field costs a frame (printed, not asserted: timings belong to
// benchmarks; this machine is shared): the same view of a 0.5-cover deck
// with the layer's own wind, with a wind field on a plateau of the flow, and
// in its crossfade (both phases' noise read), medians of 5 frames each.
TEST(WindField, CostOfTheFieldIsPrinted) {
  SKY_RENDERER(r, 160, 90);
  const weather::WeatherSnapshot field = windSnapshot(true);
  weather::WeatherSnapshot own = field;
  own.windTiles.clear();
  own.windTileLevel = 0;
  own.layers[0].wind = {kWind_mps, 180, 0};
  auto medianMs = [&](const weather::WeatherSnapshot& s, double clock_s) {
    std::vector<double> ms;
    for (int k = 0; k < 6; ++k) {
      render::FrameInputs in;
      in.camera = pose(kLat, kLon - 0.02, 800, 80, 25);
      in.weather = &s;
      in.weatherClock_s = clock_s;
      in.sunElevation_deg = 40;
      const auto t0 = std::chrono::steady_clock::now();
      auto im = r.render(in);
      const auto t1 = std::chrono::steady_clock::now();
      EXPECT_TRUE(im);
      if (k > 0) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    return ms[ms.size() / 2];
  };
  const double base = medianMs(own, 230), plateau = medianMs(field, 230), crossfade = medianMs(field, 150);
  std::printf("[ wind cost ] 160x90: own wind %.1f ms, wind field on a plateau %.1f ms (%.2fx), in the crossfade "
              "%.1f ms (%.2fx)\n",
              base, plateau, plateau / base, crossfade, crossfade / base);
}

}  // namespace
}  // namespace sky::test
