// What the bench compares in 8 bits: the renderer's linear radiance through
// the same display transform its PNG output applies, and the resampling a
// configuration rendered below the reference resolution is compared through.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sky/bench/metrics.hpp"
#include "sky/core/result.hpp"

namespace sky::bench {

// Exposure before the tonemap. Must equal renderer/core's PNG exposure
// (kPngExposure in image_output.cpp): tests/unit/bench checks toSrgb8 against
// the bytes sky::render::writePng writes, so a change there shows up here.
inline constexpr double kDisplayExposure = 1.0;

// Linear radiance -> 8-bit sRGB: exposure, ACES filmic tonemap (Narkowicz
// 2015 fit), IEC 61966-2-1 sRGB encoding, rounding to nearest; non-finite
// values become 0, as in the renderer's PNGs. The view must be consistent
// (4 values per pixel).
Srgb8Image toSrgb8(const RgbaView& image, double exposure = kDisplayExposure);

// Bilinear resampling of linear radiance to width x height (pixel centres
// aligned, edges clamped): how an image rendered at a lower resolution is
// brought to the reference's size before it is compared (the renderer has no
// upscale of its own yet).
std::vector<float> resizeBilinear(const RgbaView& image, std::uint32_t width, std::uint32_t height);

// Writes an 8-bit RGB PNG. Errors: InvalidArgument for an inconsistent image,
// Io when the file cannot be written.
Result<void> writePng(const Srgb8Image& image, const std::string& path);

}  // namespace sky::bench
