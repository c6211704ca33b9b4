// The interleave order (temporal_plan.hpp): any n^2 consecutive frames draw
// every pixel of a block exactly once, and the order is dispersed (a still
// view fills in evenly, not in a sweep).
#include <cstdlib>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "temporal_plan.hpp"

namespace sky::render {
namespace {

TEST(InterleavePhase, EveryPixelOncePerCycleFromAnyStart) {
  for (std::uint32_t n : {1u, 2u, 4u})
    for (std::uint32_t start = 0; start < n * n; ++start) {
      std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
      for (std::uint32_t k = start; k < start + n * n; ++k) {
        const glm::uvec2 p = interleavePhase(n, k);
        ASSERT_LT(p.x, n);
        ASSERT_LT(p.y, n);
        seen.insert({p.x, p.y});
      }
      EXPECT_EQ(seen.size(), std::size_t(n) * n) << "n " << n << " start " << start;
    }
}

TEST(InterleavePhase, EachFourFramesOfSixteenCoverEveryQuadrant) {
  // Ordered dispersed: frames 4m .. 4m+3 of the 4x4 cycle draw one pixel in
  // each 2x2 quadrant of the block, so the image fills in evenly.
  for (std::uint32_t m = 0; m < 4; ++m) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> quadrants;
    for (std::uint32_t k = 4 * m; k < 4 * m + 4; ++k) {
      const glm::uvec2 p = interleavePhase(4, k);
      quadrants.insert({p.x / 2, p.y / 2});
    }
    EXPECT_EQ(quadrants.size(), 4u) << "frames " << 4 * m << ".." << 4 * m + 3;
  }
  // And consecutive frames never draw the same or a side-by-side pixel of a block.
  for (std::uint32_t k = 0; k + 1 < 16; ++k) {
    const glm::uvec2 a = interleavePhase(4, k), b = interleavePhase(4, k + 1);
    EXPECT_GE(std::abs(int(a.x) - int(b.x)) + std::abs(int(a.y) - int(b.y)), 2) << k;
  }
}

}  // namespace
}  // namespace sky::render
