// The render-resolution scale (ResolutionSettings) on the GPU:
//  * away from the horizon the full-size image is the bilinear blend of the
//    image the same renderer draws at the small size (an independent
//    implementation here), and the cloud depth the nearest small pixel's;
//  * across the horizon the depth-aware upscale keeps ground and sky apart:
//    on the sky's side, where it differs from plain bilinear, it is the
//    closer of the two to the image drawn at full size, by far;
//  * with interleaving, a still view converges to exactly the image the same
//    divisor gives drawn whole;
//  * divisors other than 1, 2 and 4 are refused with the field named.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "scenes.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/presets.hpp"

namespace sky::test {
namespace {

constexpr std::uint32_t kW = 160, kH = 90;

struct Made {
  std::unique_ptr<render::CloudRenderer> renderer;
  std::string skip;
};

Made make(std::uint32_t width, std::uint32_t height, std::uint32_t divisor, bool depthAware = true,
          std::uint32_t interleave = 1) {
  render::RenderSettings s;
  s.width = width;
  s.height = height;
  s.march = render::findPreset("high")->march;
  // The horizon test needs a bright sky over the dark ground; the clouds'
  // shadow in the air under the layer halves the sky's light there and
  // with it the contrast the depth-aware upscale is tested on.
  s.march.cloudShadows = false;
  s.temporal.interleave = interleave;
  s.resolution.divisor = divisor;
  s.resolution.depthAware = depthAware;
  Made m;
  auto r = render::CloudRenderer::create(s);
  if (r) m.renderer = std::move(*r);
  else if (r.error().code == ErrorCode::NoDevice) m.skip = describe(r.error());
  else ADD_FAILURE() << describe(r.error());
  return m;
}

#define SKY_NEED(m)                                \
  if (!(m).renderer) {                             \
    if (!(m).skip.empty()) GTEST_SKIP() << (m).skip; \
    return;                                        \
  }

render::Image renderOk(render::CloudRenderer& r, const render::FrameInputs& in) {
  auto image = r.render(in);
  EXPECT_TRUE(image) << (image ? "" : describe(image.error()));
  return image ? std::move(*image) : render::Image{};
}

weather::WeatherSnapshot cumulus() {
  weather::WeatherSnapshot s;
  s.layers.push_back(layer(1, 1200.0, 1500.0, 0.45, 1.0));
  return s;
}

render::FrameInputs view(const weather::WeatherSnapshot& snap, double pitch_deg) {
  render::FrameInputs in;
  in.camera = pose(47.0, 8.0, 500.0, 0.0, pitch_deg);
  in.weather = &snap;
  in.sunAzimuth_deg = 135.0;
  in.sunElevation_deg = 35.0;
  return in;
}

float at(const render::Image& im, std::uint32_t x, std::uint32_t y, int c) {
  return im.rgba[(std::size_t(y) * im.width + x) * 4 + c];
}

// Displayed value x / (1 + x) of rgb channel c (scenes.hpp, Diff).
double shown(const render::Image& im, std::uint32_t x, std::uint32_t y, int c) {
  const double v = at(im, x, y, c);
  return v / (1.0 + v);
}

TEST(Upscale, AwayFromTheHorizonIsBilinearOfTheSmallImage) {
  for (std::uint32_t d : {2u, 4u}) {
    SCOPED_TRACE("divisor " + std::to_string(d));
    // 90 is not a multiple of 4: the divisor-4 case is checked at 160x88.
    const std::uint32_t h = kH - kH % d;
    Made big = make(kW, h, d);
    SKY_NEED(big);
    Made small = make(kW / d, h / d, 1);
    SKY_NEED(small);
    // Pitched up 45 deg with a 60 deg field of view: no ground in view.
    const weather::WeatherSnapshot snap = cumulus();
    const render::FrameInputs in = view(snap, 45.0);
    const render::Image s = renderOk(*small.renderer, in);
    const render::Image b = renderOk(*big.renderer, in);
    ASSERT_EQ(b.width, kW);
    ASSERT_EQ(b.height, h);
    double worst = 0;
    std::uint32_t depthMismatches = 0;
    for (std::uint32_t y = 0; y < h; ++y)
      for (std::uint32_t x = 0; x < kW; ++x) {
        const double gx = (x + 0.5) / d - 0.5, gy = (y + 0.5) / d - 0.5;
        const int x0 = int(std::floor(gx)), y0 = int(std::floor(gy));
        const double fx = gx - x0, fy = gy - y0;
        auto cx = [&](int v) { return std::uint32_t(std::clamp(v, 0, int(s.width) - 1)); };
        auto cy = [&](int v) { return std::uint32_t(std::clamp(v, 0, int(s.height) - 1)); };
        for (int c = 0; c < 4; ++c) {
          const double want = (1 - fy) * ((1 - fx) * at(s, cx(x0), cy(y0), c) + fx * at(s, cx(x0 + 1), cy(y0), c)) +
                              fy * ((1 - fx) * at(s, cx(x0), cy(y0 + 1), c) + fx * at(s, cx(x0 + 1), cy(y0 + 1), c));
          worst = std::max(worst, std::abs(at(b, x, y, c) - want) / std::max(std::abs(want), 1e-3));
        }
        const std::uint32_t nx = cx(int(std::floor(gx + 0.5))), ny = cy(int(std::floor(gy + 0.5)));
        if (b.cloudDepth_m[std::size_t(y) * kW + x] != s.cloudDepth_m[std::size_t(ny) * s.width + nx])
          ++depthMismatches;
      }
    // float blending against double: a few ulps.
    EXPECT_LT(worst, 1e-5);
    EXPECT_EQ(depthMismatches, 0u);
    std::printf("divisor %u: largest relative difference from bilinear %.2g\n", d, worst);
  }
}

TEST(Upscale, DepthAwareKeepsTheHorizon) {
  Made full = make(kW, kH, 1);
  SKY_NEED(full);
  Made aware = make(kW, kH, 2, true);
  SKY_NEED(aware);
  Made plain = make(kW, kH, 2, false);
  SKY_NEED(plain);
  // Level flight at 500 m under a cumulus layer, heading north: the horizon
  // crosses the middle of the image, the dark ground below the bright sky.
  const weather::WeatherSnapshot snap = cumulus();
  const render::FrameInputs in = view(snap, 0.0);
  const render::Image truth = renderOk(*full.renderer, in);
  const render::Image a = renderOk(*aware.renderer, in);
  const render::Image p = renderOk(*plain.renderer, in);
  // Which pixels see the sky, from geometry here: the ray's elevation
  // against the horizon's dip acos(R / (R + h)) at h = 500 m (R the Earth's
  // radius near 47 N; pixel rows are 0.67 deg apart and the dip, 0.72 deg,
  // lies 0.3 deg from the nearest row's centre).
  const double tanHalf = std::tan(30.0 * M_PI / 180.0), aspect = double(kW) / kH;
  const double dip = std::acos(6.367e6 / (6.367e6 + 500.0));
  std::uint32_t skyDiffer = 0, skyCloser = 0;
  double skyAware = 0, skyPlain = 0, allAware = 0, allPlain = 0;
  for (std::uint32_t y = 0; y < kH; ++y)
    for (std::uint32_t x = 0; x < kW; ++x) {
      const double sx = ((x + 0.5) / kW * 2 - 1) * tanHalf * aspect, sy = (1 - (y + 0.5) / kH * 2) * tanHalf;
      const double elevation = std::asin(sy / std::sqrt(1 + sx * sx + sy * sy));
      double ea = 0, ep = 0;
      for (int c = 0; c < 3; ++c) {
        ea += std::abs(shown(a, x, y, c) - shown(truth, x, y, c));
        ep += std::abs(shown(p, x, y, c) - shown(truth, x, y, c));
      }
      allAware += ea;
      allPlain += ep;
      if (elevation <= -dip + 0.1 * M_PI / 180 || std::abs(ea - ep) < 1e-6) continue;
      ++skyDiffer;
      skyAware += ea;
      skyPlain += ep;
      if (ea < ep) ++skyCloser;
    }
  std::printf("horizon: %u sky pixels differ from bilinear, %u of them closer to the full-size image; their error "
              "%.3f against bilinear's %.3f; whole image %.3f against %.3f\n",
              skyDiffer, skyCloser, skyAware, skyPlain, allAware, allPlain);
  // The sky's row at the horizon (160 pixels) no longer takes the ground's
  // darkness. Below the horizon the ground's first row is hazy, between the
  // sky's brightness and the ground's further down, so there neither
  // upscale is right; the whole image still comes out closer.
  EXPECT_GE(skyDiffer, kW / 2);
  EXPECT_GE(skyCloser, skyDiffer * 3 / 4);
  EXPECT_LT(skyAware, 0.5 * skyPlain);
  EXPECT_LT(allAware, allPlain);
}

// At 160x90 and divisor 4, which 90 is not a multiple of: the small image
// is 40x23, its last row reaching past the full image's edge.
TEST(Upscale, InterleavedStillViewConvergesToTheDivisorsWholeImage) {
  Made whole = make(kW, kH, 4);
  SKY_NEED(whole);
  Made interleaved = make(kW, kH, 4, true, 4);
  SKY_NEED(interleaved);
  const weather::WeatherSnapshot snap = cumulus();
  const render::FrameInputs in = view(snap, 20.0);
  const render::Image truth = renderOk(*whole.renderer, in);
  std::uint64_t drawn = 0;
  for (int f = 0; f <= 16; ++f) {
    const render::Image image = renderOk(*interleaved.renderer, in);
    if (f > 0) drawn += interleaved.renderer->lastTemporal().drawn;
    if (f == 16) {
      ASSERT_EQ(image.rgba.size(), truth.rgba.size());
      EXPECT_EQ(std::memcmp(image.rgba.data(), truth.rgba.data(), truth.rgba.size() * sizeof(float)), 0);
      EXPECT_EQ(image.cloudDepth_m, truth.cloudDepth_m);
    }
  }
  // 16 frames drew every pixel of the 40x23 image once.
  EXPECT_EQ(drawn, std::uint64_t(40) * 23);
}

TEST(Upscale, DivisorsOtherThanOneTwoAndFourAreRefused) {
  render::RenderSettings s;
  s.width = 160;
  s.height = 90;
  for (std::uint32_t d : {0u, 3u, 8u}) {
    s.resolution.divisor = d;
    auto r = render::CloudRenderer::create(s);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(r.error().detail.find("resolution.divisor " + std::to_string(d)), std::string::npos) << r.error().detail;
  }
}

}  // namespace
}  // namespace sky::test
