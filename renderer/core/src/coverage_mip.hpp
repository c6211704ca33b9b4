// The weather map's max-coverage mip: per ring and layer slice, a coarse grid
// whose cell holds the largest coverage any bilinear weather lookup of that
// ring inside it can return (the block of texels under it, widened by the
// filter's one texel). A lookup blending the rings returns at most the
// larger of the two, so that is what the mip gives there.
// The march in metres skips a long step whose cell holds 0 with one read
// instead of the weather, cloud-map and shape lookups (cloud_core.glsl,
// sampleMaxCoverage). The GPU reads it from a storage buffer; the CPU
// reference from this grid.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "sky_shared.h"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::render {

// Cells per edge (kCoverageMipSize in sky_shared.h): 256 / 32 = 8 texels,
// ~6 km in the fine ring, ~37 km in the coarse one.
inline constexpr std::uint32_t kCoverageMipCells = gpu::kCoverageMipSize;
// Floats in a mip (the GPU buffer's size).
inline constexpr std::size_t kCoverageMipFloats =
    std::size_t(kWeatherRings) * gpu::kMaxLayers * kCoverageMipCells * kCoverageMipCells;

// kWeatherRings x kMaxLayers x cells x cells maxima in [0, 1]: ring, slice,
// row (north), column (east).
std::vector<float> buildCoverageMip(const WeatherField& field);

// The mip of a field brought up to date after the texels in these
// rectangles changed (WeatherFieldChange::dirty): only the cells whose
// filter reaches into them are recomputed; the result equals buildCoverageMip.
void updateCoverageMip(std::vector<float>& mip, const WeatherField& field, std::span<const TexelRect> changed);

// At gnomonic plane point (x_m, y_m) (m east/north of the anchor) in slice:
// the fine ring's cell inside the ring blend band, the coarse ring's beyond
// it, the larger of both across it; 0 outside the rings (as the weather
// lookup, WeatherField::sample).
double sampleCoverageMip(const std::vector<float>& mip, const WeatherField& field, std::uint32_t slice, double x_m,
                         double y_m);

}  // namespace sky::render
