// The max-coverage mip (see coverage_mip.hpp).
#include "coverage_mip.hpp"

#include <algorithm>
#include <cmath>

#include "sky/core/assert.hpp"

namespace sky::render {

std::vector<float> buildCoverageMip(const WeatherField& field) {
  const std::uint32_t cells = kCoverageMipCells;
  std::vector<float> mip(std::size_t(gpu::kMaxLayers) * cells * cells, 0.0f);
  const int n = int(field.size);
  if (field.texels.size() < std::size_t(field.sliceCount) * n * n * 4 || n == 0) return mip;
  SKY_ASSERT(n % int(cells) == 0);
  const int block = n / int(cells);
  for (std::uint32_t slice = 0; slice < std::min<std::uint32_t>(field.sliceCount, gpu::kMaxLayers); ++slice)
    for (int cy = 0; cy < int(cells); ++cy)
      for (int cx = 0; cx < int(cells); ++cx) {
        // A lookup at texel coordinate tx in [block c - 1/2, block (c+1) - 1/2)
        // filters texels floor(tx) and floor(tx) + 1.
        std::uint8_t most = 0;
        for (int j = std::max(0, cy * block - 1); j <= std::min(n - 1, (cy + 1) * block); ++j)
          for (int i = std::max(0, cx * block - 1); i <= std::min(n - 1, (cx + 1) * block); ++i)
            most = std::max(most, field.texels[((std::size_t(slice) * n + j) * n + i) * 4]);
        mip[(std::size_t(slice) * cells + cy) * cells + cx] = float(most) / 255.0f;
      }
  return mip;
}

double sampleCoverageMip(const std::vector<float>& mip, const WeatherField& field, std::uint32_t slice, double x_m,
                         double y_m) {
  const double u = x_m / (2 * field.halfExtent_m) + 0.5;
  const double v = y_m / (2 * field.halfExtent_m) + 0.5;
  if (!(u >= 0.0 && u < 1.0 && v >= 0.0 && v < 1.0) || slice >= gpu::kMaxLayers) return 0.0;
  const std::size_t cx = std::size_t(u * kCoverageMipCells), cy = std::size_t(v * kCoverageMipCells);
  return mip[(std::size_t(slice) * kCoverageMipCells + cy) * kCoverageMipCells + cx];
}

}  // namespace sky::render
