// The display transform of a linear image, shared by the PNG writer and the
// window, so a window shows exactly the bytes the PNG holds.
#pragma once

#include <cstdint>
#include <vector>

#include "sky/render/cloud_renderer.hpp"
#include "sky/render/exposure.hpp"

namespace sky::render {

// 8-bit sRGB rgb per pixel (row-major, top row first) of a consistent image:
// each channel times `exposure` (the multiplier of the renderer's radiance
// units: displayExposure of an EV100, exposure.hpp; > 0), ACES filmic
// tonemap (its curve and white point: image_output.cpp), sRGB transfer;
// non-finite values become 0.
std::vector<std::uint8_t> tonemapToSrgb8(const Image& image, double exposure = kFixedDisplayExposure);

}  // namespace sky::render
