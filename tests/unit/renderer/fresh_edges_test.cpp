// The fresh edges' numbering (shaders/include/fresh_edges.glsl, compiled
// here as C++): the bands' pixels and their numbers map one to one onto
// 0 .. count - 1, a pixel outside every band has none, and the bands are
// where their widths put them, for every combination of sides (zero widths
// included, where the shader divides by max(width, 1)).
#include <vector>

#include <gtest/gtest.h>

#include "fresh_edges.hpp"

namespace sky::render {
namespace {

std::uint32_t freshEdgeCount(glm::uvec4 e, glm::uvec2 size) { return FreshEdges{}.freshEdgeCount(e, size); }
int freshEdgeIndex(glm::ivec2 p, glm::uvec4 e, glm::uvec2 size) { return FreshEdges{}.freshEdgeIndex(p, e, size); }
glm::ivec2 freshEdgePixel(int k, glm::uvec4 e, glm::uvec2 size) { return FreshEdges{}.freshEdgePixel(k, e, size); }

void expectOneToOne(glm::uvec4 e, glm::uvec2 size) {
  const std::uint32_t count = freshEdgeCount(e, size);
  std::vector<int> seen(count, 0);
  std::uint32_t inBands = 0;
  for (int y = 0; y < int(size.y); ++y)
    for (int x = 0; x < int(size.x); ++x) {
      const bool band = x < int(e.x) || x >= int(size.x - e.y) || y < int(e.z) || y >= int(size.y - e.w);
      const int k = freshEdgeIndex(glm::ivec2(x, y), e, size);
      ASSERT_EQ(k >= 0, band) << x << "," << y << " edges " << e.x << " " << e.y << " " << e.z << " " << e.w;
      if (!band) continue;
      ++inBands;
      ASSERT_LT(std::uint32_t(k), count);
      ++seen[std::size_t(k)];
      EXPECT_EQ(freshEdgePixel(k, e, size), glm::ivec2(x, y)) << k;
    }
  EXPECT_EQ(inBands, count);
  for (std::uint32_t k = 0; k < count; ++k) EXPECT_EQ(seen[k], 1) << "number " << k;
}

TEST(FreshEdges, BandsAndNumbersMapOneToOne) {
  const glm::uvec2 size(23, 13);
  for (std::uint32_t l : {0u, 1u, 3u})
    for (std::uint32_t r : {0u, 2u})
      for (std::uint32_t t : {0u, 1u, 4u})
        for (std::uint32_t b : {0u, 3u}) expectOneToOne(glm::uvec4(l, r, t, b), size);
}

TEST(FreshEdges, NoBandsNoPixels) {
  const glm::uvec2 size(160, 90);
  EXPECT_EQ(freshEdgeCount(glm::uvec4(0), size), 0u);
  EXPECT_EQ(freshEdgeIndex(glm::ivec2(0, 0), glm::uvec4(0), size), -1);
  EXPECT_EQ(freshEdgeIndex(glm::ivec2(159, 89), glm::uvec4(0), size), -1);
}

TEST(FreshEdges, ARightTurnsBandIsTheRightColumns) {
  const glm::uvec2 size(160, 90);
  const glm::uvec4 e(0, 5, 0, 0);
  EXPECT_EQ(freshEdgeCount(e, size), 5u * 90u);
  EXPECT_EQ(freshEdgePixel(0, e, size), glm::ivec2(155, 0));
  EXPECT_EQ(freshEdgePixel(5 * 90 - 1, e, size), glm::ivec2(159, 89));
  EXPECT_EQ(freshEdgeIndex(glm::ivec2(154, 40), e, size), -1);
}

}  // namespace
}  // namespace sky::render
