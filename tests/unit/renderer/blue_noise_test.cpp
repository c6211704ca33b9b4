// The blue-noise tile of the march's step offsets (blue_noise.hpp), against
// what makes noise blue and usable: every level once, no low frequencies
// (block means of the tile far steadier than white noise's, also across the
// tile's wrap), neighbours far apart, deterministic from the seed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "blue_noise.hpp"

namespace sky::render {
namespace {

constexpr std::uint32_t kSize = 64;

// Variance of the means of 4x4 blocks, the blocks' corners offset by
// (offset, offset) and wrapping around the tile.
double blockMeanVariance(const std::vector<float>& v, std::uint32_t size, std::uint32_t offset) {
  std::vector<double> means;
  for (std::uint32_t by = 0; by < size; by += 4)
    for (std::uint32_t bx = 0; bx < size; bx += 4) {
      double sum = 0;
      for (std::uint32_t y = 0; y < 4; ++y)
        for (std::uint32_t x = 0; x < 4; ++x)
          sum += v[((by + y + offset) % size) * size + (bx + x + offset) % size];
      means.push_back(sum / 16);
    }
  double mean = 0, var = 0;
  for (double m : means) mean += m / means.size();
  for (double m : means) var += (m - mean) * (m - mean) / means.size();
  return var;
}

TEST(BlueNoise, EveryLevelOnce) {
  std::vector<float> v = makeBlueNoise(kSize, 1);
  ASSERT_EQ(v.size(), kSize * kSize);
  std::sort(v.begin(), v.end());
  for (std::size_t k = 0; k < v.size(); ++k) ASSERT_EQ(v[k], float((k + 0.5) / v.size())) << k;
}

TEST(BlueNoise, HasNoLowFrequencies) {
  const std::vector<float> v = makeBlueNoise(kSize, 1);
  // White noise uniform on [0, 1): variance 1/12, so a mean of 16 has 1/192.
  const double white = 1.0 / 192;
  for (std::uint32_t offset : {0u, 2u}) {  // 2: blocks across the tile's wrap
    const double blue = blockMeanVariance(v, kSize, offset);
    std::printf("offset %u: 4x4 block-mean variance %.3g, white noise's %.3g\n", offset, blue, white);
    EXPECT_LT(blue, 0.35 * white);  // measured: 0.21 and 0.18 of it
  }
  // Horizontal and vertical neighbours: white noise's mean |a - b| is 1/3.
  double dx = 0, dy = 0;
  for (std::uint32_t y = 0; y < kSize; ++y)
    for (std::uint32_t x = 0; x < kSize; ++x) {
      dx += std::abs(v[y * kSize + x] - v[y * kSize + (x + 1) % kSize]);
      dy += std::abs(v[y * kSize + x] - v[((y + 1) % kSize) * kSize + x]);
    }
  dx /= kSize * kSize;
  dy /= kSize * kSize;
  std::printf("mean neighbour difference %.3f (x), %.3f (y); white noise's 0.333\n", dx, dy);
  EXPECT_GT(dx, 0.38);  // measured: 0.406, 0.410
  EXPECT_GT(dy, 0.38);
}

TEST(BlueNoise, DeterministicFromTheSeed) {
  EXPECT_EQ(makeBlueNoise(16, 7), makeBlueNoise(16, 7));
  EXPECT_NE(makeBlueNoise(16, 7), makeBlueNoise(16, 8));
  EXPECT_EQ(blueNoiseTile(1), makeBlueNoise(kBlueNoiseSize, 1));
}

}  // namespace
}  // namespace sky::render
