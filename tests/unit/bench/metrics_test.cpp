// Image metrics of skyshell-bench (renderer/bench/metrics.hpp) against values
// worked out by hand and closed forms: a constant offset's PSNR, SSIM of
// constant images and of a single bright pixel under the Gaussian window, the
// ghosting of a frame blended with its predecessor; plus identity, symmetry
// and monotonicity with added noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sky/bench/metrics.hpp"

namespace sky::bench {
namespace {

Srgb8Image constant8(std::uint32_t w, std::uint32_t h, std::uint8_t value) {
  return {w, h, std::vector<std::uint8_t>(std::size_t(w) * h * 3, value)};
}

// Random image with values in [lo, hi] (fixed seed: the same image every run).
Srgb8Image random8(std::uint32_t w, std::uint32_t h, int lo, int hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> dist(lo, hi);
  Srgb8Image img{w, h, std::vector<std::uint8_t>(std::size_t(w) * h * 3)};
  for (auto& v : img.rgb) v = std::uint8_t(dist(rng));
  return img;
}

GrayImage constantGray(std::uint32_t w, std::uint32_t h, double value) {
  return {w, h, std::vector<double>(std::size_t(w) * h, value)};
}

constexpr double kC1 = (0.01 * 255) * (0.01 * 255);  // Wang et al. 2004, eq. 7 with K1 = 0.01, L = 255
constexpr double kC2 = (0.03 * 255) * (0.03 * 255);  // eq. 9 with K2 = 0.03

TEST(Rmse, HandMadeLinearImages) {
  // 2x1 pixels, 4 floats each; only pixel 1's red differs, by 1.2; alpha differs too but is not compared.
  const std::vector<float> a{0.1f, 0.2f, 0.3f, 1.0f, 0.5f, 0.5f, 0.5f, 1.0f};
  const std::vector<float> b{0.1f, 0.2f, 0.3f, 0.0f, 1.7f, 0.5f, 0.5f, 0.0f};
  auto r = rmseLinear({2, 1, a}, {2, 1, b});
  ASSERT_TRUE(r);
  EXPECT_NEAR(*r, std::sqrt(1.2 * 1.2 / 6.0), 1e-6);
}

TEST(Rmse, ConstantOffsetIsTheOffset) {
  std::vector<float> a(5 * 3 * 4), b(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i] = float(i % 7) * 0.1f;
    b[i] = a[i] + 0.25f;
  }
  EXPECT_NEAR(*rmseLinear({5, 3, a}, {5, 3, b}), 0.25, 1e-6);
  EXPECT_DOUBLE_EQ(*rmseLinear({5, 3, a}, {5, 3, a}), 0.0);
}

TEST(Rmse, RefusesMismatchedImages) {
  const std::vector<float> a(8), b(12);
  EXPECT_FALSE(rmseLinear({2, 1, a}, {3, 1, b}));
  EXPECT_FALSE(rmseLinear({2, 1, a}, {2, 1, b}));  // 2x1 image with 12 values
  EXPECT_FALSE(psnr(constant8(2, 2, 0), constant8(2, 3, 0)));
  EXPECT_FALSE(ssim(constant8(20, 20, 0), constant8(20, 21, 0)));
}

TEST(Psnr, ConstantOffsetClosedForm) {
  // b = a + k on every value: MSE = k^2, so PSNR = 20 log10(255 / k).
  for (int k : {1, 5, 17}) {
    Srgb8Image a = random8(16, 9, 20, 200, 3);
    Srgb8Image b = a;
    for (auto& v : b.rgb) v = std::uint8_t(v + k);
    EXPECT_NEAR(*psnr(a, b), 20 * std::log10(255.0 / k), 1e-9) << k;
    EXPECT_NEAR(*rmse8(a, b), double(k), 1e-12);
  }
}

TEST(Psnr, HandMadeImage) {
  // 2x1 pixels, 6 values; one differs by 10: MSE = 100 / 6.
  Srgb8Image a{2, 1, {10, 20, 30, 40, 50, 60}};
  Srgb8Image b{2, 1, {10, 20, 30, 40, 60, 60}};
  EXPECT_NEAR(*psnr(a, b), 10 * std::log10(255.0 * 255.0 * 6.0 / 100.0), 1e-9);
  EXPECT_TRUE(std::isinf(*psnr(a, a)));
}

TEST(Ssim, ImageWithItselfIsOne) {
  const Srgb8Image a = random8(40, 30, 0, 255, 1);
  EXPECT_NEAR(*ssim(a, a), 1.0, 1e-12);
  const Srgb8Image flat = constant8(11, 11, 77);
  EXPECT_NEAR(*ssim(flat, flat), 1.0, 1e-12);
}

TEST(Ssim, ConstantImagesClosedForm) {
  // No variance anywhere: SSIM = (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1) (eq. 13, contrast-structure term 1).
  const double a = 100, b = 110;
  const double expected = (2 * a * b + kC1) / (a * a + b * b + kC1);
  EXPECT_NEAR(*ssimGray(constantGray(25, 13, a), constantGray(25, 13, b)), expected, 1e-12);
}

TEST(Ssim, OneBrightPixelUnderTheWindowByHand) {
  // An 11x11 image holds exactly one window. a = 100 with its centre 200, b =
  // 100. With w0 the window's centre weight (1 / (sum_i exp(-i^2 / 4.5))^2,
  // i = -5..5): mu_a = 100 + 100 w0, var_a = 100^2 w0 (1 - w0), var_b = cov = 0.
  double sum = 0;
  for (int i = -5; i <= 5; ++i) sum += std::exp(-i * i / (2 * 1.5 * 1.5));
  const double w0 = 1.0 / (sum * sum);
  const double muA = 100 + 100 * w0, muB = 100, varA = 100.0 * 100.0 * w0 * (1 - w0);
  const double expected = (2 * muA * muB + kC1) * kC2 / ((muA * muA + muB * muB + kC1) * (varA + kC2));
  GrayImage a = constantGray(11, 11, 100);
  a.v[5 * 11 + 5] = 200;
  auto map = ssimMap(a, constantGray(11, 11, 100));
  ASSERT_TRUE(map);
  ASSERT_EQ(map->v.size(), 1u);
  EXPECT_NEAR(map->v[0], expected, 1e-12);
  EXPECT_LT(expected, 0.99);  // the pixel matters: the test would notice a window that ignores it
}

TEST(Ssim, MapIsValidRegionOnly) {
  auto map = ssimMap(constantGray(30, 20, 5), constantGray(30, 20, 5));
  ASSERT_TRUE(map);
  EXPECT_EQ(map->width, 20u);
  EXPECT_EQ(map->height, 10u);
  EXPECT_FALSE(ssimMap(constantGray(10, 20, 5), constantGray(10, 20, 5)));  // narrower than the window
}

TEST(Ssim, LumaUsesBt601Weights) {
  const GrayImage y = luma(Srgb8Image{3, 1, {255, 0, 0, 0, 255, 0, 0, 0, 255}});
  EXPECT_NEAR(y.v[0], 0.299 * 255, 1e-9);
  EXPECT_NEAR(y.v[1], 0.587 * 255, 1e-9);
  EXPECT_NEAR(y.v[2], 0.114 * 255, 1e-9);
}

TEST(Metrics, Symmetric) {
  const Srgb8Image a = random8(32, 24, 0, 255, 11), b = random8(32, 24, 0, 255, 12);
  EXPECT_DOUBLE_EQ(*psnr(a, b), *psnr(b, a));
  EXPECT_DOUBLE_EQ(*rmse8(a, b), *rmse8(b, a));
  EXPECT_NEAR(*ssim(a, b), *ssim(b, a), 1e-12);
  std::vector<float> la(32 * 24 * 4), lb(la.size());
  for (std::size_t i = 0; i < la.size(); ++i) la[i] = float(a.rgb[i % a.rgb.size()]) / 255, lb[i] = float(i % 5);
  EXPECT_DOUBLE_EQ(*rmseLinear({32, 24, la}, {32, 24, lb}), *rmseLinear({32, 24, lb}, {32, 24, la}));
}

TEST(Metrics, MonotoneWithAddedNoise) {
  // The same noise pattern at growing amplitude: every metric gets worse.
  const Srgb8Image clean = random8(48, 32, 60, 190, 5);
  std::mt19937 rng(9);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> pattern(clean.rgb.size());
  for (double& v : pattern) v = unit(rng);
  double lastSsim = 1.0, lastPsnr = INFINITY, lastRmse = 0;
  for (double sigma : {1.0, 3.0, 8.0, 20.0, 50.0}) {
    Srgb8Image noisy = clean;
    for (std::size_t i = 0; i < noisy.rgb.size(); ++i)
      noisy.rgb[i] = std::uint8_t(std::clamp(std::lround(clean.rgb[i] + sigma * pattern[i]), 0L, 255L));
    const double s = *ssim(clean, noisy), p = *psnr(clean, noisy), r = *rmse8(clean, noisy);
    EXPECT_LT(s, lastSsim) << sigma;
    EXPECT_LT(p, lastPsnr) << sigma;
    EXPECT_GT(r, lastRmse) << sigma;
    lastSsim = s, lastPsnr = p, lastRmse = r;
  }
}

TEST(Temporal, AlternatingErrorFlickersByTwiceItsSize) {
  // e_t = +k, -k, +k, ...: e_t - e_{t-1} = -/+ 2k everywhere.
  const int k = 6;
  std::vector<Srgb8Image> ref, test;
  for (int t = 0; t < 4; ++t) {
    ref.push_back(random8(12, 12, 20, 230, unsigned(t)));
    test.push_back(ref.back());
    for (auto& v : test.back().rgb) v = std::uint8_t(v + (t % 2 == 0 ? k : -k));
  }
  auto te = temporalError(test, ref);
  ASSERT_TRUE(te);
  ASSERT_EQ(te->flicker.size(), 3u);
  for (double f : te->flicker) EXPECT_NEAR(f, 2.0 * k, 1e-12);
  EXPECT_NEAR(te->meanFlicker, 2.0 * k, 1e-12);
}

TEST(Temporal, ConstantBiasDoesNotFlicker) {
  std::vector<Srgb8Image> ref, test;
  for (int t = 0; t < 3; ++t) {
    ref.push_back(random8(12, 12, 0, 200, unsigned(10 + t)));
    test.push_back(ref.back());
    for (auto& v : test.back().rgb) v = std::uint8_t(v + 40);
  }
  auto te = temporalError(test, ref);
  ASSERT_TRUE(te);
  EXPECT_DOUBLE_EQ(te->maxFlicker, 0.0);
}

TEST(Temporal, GhostingIsTheBlendOfThePreviousFrame) {
  // test_1 = (1 - alpha) ref_1 + alpha ref_0 (rounded to 8 bits): ghosting alpha.
  for (double alpha : {0.0, 0.3, 0.75}) {
    const std::vector<Srgb8Image> ref{random8(40, 30, 0, 255, 21), random8(40, 30, 0, 255, 22)};
    Srgb8Image blended = ref[1];
    for (std::size_t i = 0; i < blended.rgb.size(); ++i)
      blended.rgb[i] = std::uint8_t(std::lround((1 - alpha) * ref[1].rgb[i] + alpha * ref[0].rgb[i]));
    const std::vector<Srgb8Image> test{ref[0], blended};
    auto te = temporalError(test, ref);
    ASSERT_TRUE(te);
    ASSERT_TRUE(te->ghosting[0].has_value());
    EXPECT_NEAR(*te->ghosting[0], alpha, 0.01) << alpha;  // rounding to 8 bits costs under half a level
    EXPECT_NEAR(*te->meanGhosting, alpha, 0.01);
  }
}

TEST(Temporal, GhostingAgainstABaselineIgnoresSpatialError) {
  // The test is its baseline (a blurry, biased rendering far from the
  // reference) blended with the baseline's previous frame: ghosting is the
  // blend, whatever the reference holds; with the test as its own baseline it is 0.
  const double alpha = 0.4;
  const std::vector<Srgb8Image> ref{random8(40, 30, 0, 255, 41), random8(40, 30, 0, 255, 42)};
  const std::vector<Srgb8Image> base{random8(40, 30, 0, 255, 43), random8(40, 30, 0, 255, 44)};
  Srgb8Image blended = base[1];
  for (std::size_t i = 0; i < blended.rgb.size(); ++i)
    blended.rgb[i] = std::uint8_t(std::lround((1 - alpha) * base[1].rgb[i] + alpha * base[0].rgb[i]));
  const std::vector<Srgb8Image> test{base[0], blended};
  auto te = temporalError(test, ref, base);
  ASSERT_TRUE(te);
  EXPECT_NEAR(*te->ghosting[0], alpha, 0.01);
  auto self = temporalError(test, ref, test);
  ASSERT_TRUE(self);
  EXPECT_DOUBLE_EQ(*self->ghosting[0], 0.0);
  const std::vector<Srgb8Image> shortBase{base[0]};
  EXPECT_FALSE(temporalError(test, ref, shortBase));
}

TEST(Temporal, NoGhostingWithoutMotion) {
  const Srgb8Image still = random8(20, 20, 0, 255, 30);
  const std::vector<Srgb8Image> ref{still, still}, test{still, constant8(20, 20, 0)};
  auto te = temporalError(test, ref);
  ASSERT_TRUE(te);
  EXPECT_FALSE(te->ghosting[0].has_value());
  EXPECT_FALSE(te->meanGhosting.has_value());
}

TEST(Temporal, RefusesBadSequences) {
  const std::vector<Srgb8Image> one{constant8(4, 4, 0)}, two{constant8(4, 4, 0), constant8(4, 4, 0)};
  const std::vector<Srgb8Image> mixed{constant8(4, 4, 0), constant8(5, 4, 0)};
  EXPECT_FALSE(temporalError(one, one));
  EXPECT_FALSE(temporalError(two, one));
  EXPECT_FALSE(temporalError(mixed, mixed));
}

TEST(HeatMap, BlackWhereEqualWhiteAtFullScale) {
  const Srgb8Image ref = constant8(3, 2, 100);
  Srgb8Image test = ref;
  test.rgb[0] = test.rgb[1] = test.rgb[2] = 100 + 32;  // pixel 0: 32 levels on every channel = full scale
  test.rgb[3] = 255;                                    // pixel 1: 155 levels on one channel, past full scale
  auto map = errorHeatMap(test, ref);
  ASSERT_TRUE(map);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(map->rgb[std::size_t(c)], 255);      // full scale
    EXPECT_EQ(map->rgb[3 + std::size_t(c)], 255);  // saturates
    EXPECT_EQ(map->rgb[6 + std::size_t(c)], 0);    // equal
  }
}

TEST(HeatMap, BrighterForLargerError) {
  const Srgb8Image ref = constant8(1, 1, 0);
  double last = -1;
  for (int e : {2, 6, 12, 18, 24, 30}) {
    auto map = errorHeatMap(constant8(1, 1, std::uint8_t(e)), ref);
    ASSERT_TRUE(map);
    const double lum = 0.2126 * map->rgb[0] + 0.7152 * map->rgb[1] + 0.0722 * map->rgb[2];
    EXPECT_GT(lum, last) << e;
    last = lum;
  }
}

}  // namespace
}  // namespace sky::bench
