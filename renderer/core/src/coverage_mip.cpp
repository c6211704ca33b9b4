// The max-coverage mip (see coverage_mip.hpp).
#include "coverage_mip.hpp"

#include <algorithm>
#include <cmath>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// Whether the field has the texels a mip is built from.
bool mipable(const WeatherField& field) {
  const std::size_t n = field.size;
  return n > 0 && field.texels.size() >= std::size_t(kWeatherRings) * field.sliceCount * n * n * 4;
}

// The largest coverage a bilinear lookup inside mip cell (cx, cy) of this
// array layer of the field can return.
float cellMaximum(const WeatherField& field, std::size_t layer, int cx, int cy) {
  const int n = int(field.size);
  const int block = n / int(kCoverageMipCells);
  // A lookup at texel coordinate tx in [block c - 1/2, block (c+1) - 1/2)
  // filters texels floor(tx) and floor(tx) + 1.
  std::uint8_t most = 0;
  for (int j = std::max(0, cy * block - 1); j <= std::min(n - 1, (cy + 1) * block); ++j)
    for (int i = std::max(0, cx * block - 1); i <= std::min(n - 1, (cx + 1) * block); ++i)
      most = std::max(most, field.texels[((layer * n + j) * n + i) * 4]);
  return float(most) / 255.0f;
}

}  // namespace

std::vector<float> buildCoverageMip(const WeatherField& field) {
  const std::uint32_t cells = kCoverageMipCells;
  std::vector<float> mip(kCoverageMipFloats, 0.0f);
  const std::uint32_t slices = std::min<std::uint32_t>(field.sliceCount, gpu::kMaxLayers);
  if (!mipable(field)) return mip;
  SKY_ASSERT(field.size % cells == 0);
  for (std::uint32_t ring = 0; ring < kWeatherRings; ++ring)
    for (std::uint32_t slice = 0; slice < slices; ++slice) {
      const std::size_t layer = std::size_t(ring) * field.sliceCount + slice;  // texel array layer
      float* out = &mip[(std::size_t(ring) * gpu::kMaxLayers + slice) * cells * cells];
      for (int cy = 0; cy < int(cells); ++cy)
        for (int cx = 0; cx < int(cells); ++cx) out[cy * cells + cx] = cellMaximum(field, layer, cx, cy);
    }
  return mip;
}

void updateCoverageMip(std::vector<float>& mip, const WeatherField& field, std::span<const TexelRect> changed) {
  SKY_ASSERT(mip.size() == kCoverageMipFloats && mipable(field) && field.size % kCoverageMipCells == 0);
  const int cells = int(kCoverageMipCells);
  const int block = int(field.size) / cells;
  for (const TexelRect& r : changed) {
    const std::uint32_t ring = r.layer / field.sliceCount, slice = r.layer % field.sliceCount;
    if (slice >= gpu::kMaxLayers || ring >= kWeatherRings) continue;  // (the wind layers have no mip)
    // Cell c reads texels [c block - 1, (c + 1) block]: the cells whose
    // reach meets the rectangle (the first bound errs low, which only
    // recomputes a cell more).
    auto firstCell = [&](std::uint32_t t) { return std::max(0, (int(t) - block) / block); };
    auto lastCell = [&](std::uint32_t t) { return std::min(cells - 1, (int(t) + 1) / block); };
    float* out = &mip[(std::size_t(ring) * gpu::kMaxLayers + slice) * cells * cells];
    for (int cy = firstCell(r.y); cy <= lastCell(r.y + r.height - 1); ++cy)
      for (int cx = firstCell(r.x); cx <= lastCell(r.x + r.width - 1); ++cx)
        out[cy * cells + cx] = cellMaximum(field, r.layer, cx, cy);
  }
}

namespace {

// One ring's cell at the point, 0 outside the ring.
double ringCell(const std::vector<float>& mip, const WeatherField& field, std::uint32_t ring, std::uint32_t slice,
                double x_m, double y_m) {
  const double u = x_m / (2 * field.halfExtent_m[ring]) + 0.5;
  const double v = y_m / (2 * field.halfExtent_m[ring]) + 0.5;
  if (!(u >= 0.0 && u < 1.0 && v >= 0.0 && v < 1.0)) return 0.0;
  const std::size_t cx = std::size_t(u * kCoverageMipCells), cy = std::size_t(v * kCoverageMipCells);
  return mip[((std::size_t(ring) * gpu::kMaxLayers + slice) * kCoverageMipCells + cy) * kCoverageMipCells + cx];
}

}  // namespace

double sampleCoverageMip(const std::vector<float>& mip, const WeatherField& field, std::uint32_t slice, double x_m,
                         double y_m) {
  if (slice >= gpu::kMaxLayers) return 0.0;
  const double w = ringBlendWeight(x_m, y_m);
  double most = 0;
  if (w < 1.0) most = ringCell(mip, field, 0, slice, x_m, y_m);
  if (w > 0.0) most = std::max(most, ringCell(mip, field, 1, slice, x_m, y_m));
  return most;
}

}  // namespace sky::render
