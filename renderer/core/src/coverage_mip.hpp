// The weather map's max-coverage mip: per layer slice, a coarse grid whose
// cell holds the largest coverage any bilinear weather lookup inside it can
// return (the block of texels under it, widened by the filter's one texel).
// The march in metres skips a long step whose cell holds 0 with one read
// instead of the weather, cloud-map and shape lookups (cloud_core.glsl,
// sampleMaxCoverage). The GPU reads it from a storage buffer; the CPU
// reference from this grid.
#pragma once

#include <cstdint>
#include <vector>

#include "sky_shared.h"
#include "weather_field.hpp"

namespace sky::render {

// Cells per edge (kCoverageMipSize in sky_shared.h): 256 / 32 = 8 texels, ~6 km.
inline constexpr std::uint32_t kCoverageMipCells = gpu::kCoverageMipSize;

// kMaxLayers x cells x cells maxima in [0, 1]: slice, row (north), column (east).
std::vector<float> buildCoverageMip(const WeatherField& field);

// The cell of gnomonic plane point (x_m, y_m) (m east/north of the anchor)
// in slice: its value, or 0 outside the map (as the weather lookup).
double sampleCoverageMip(const std::vector<float>& mip, const WeatherField& field, std::uint32_t slice, double x_m,
                         double y_m);

}  // namespace sky::render
