// The display transform of a linear image, shared by the PNG writer and the
// window, so a window shows exactly the bytes the PNG holds.
#pragma once

#include <cstdint>
#include <vector>

#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

// 8-bit sRGB rgb per pixel (row-major, top row first) of a consistent image:
// exposure, ACES filmic tonemap, sRGB transfer; non-finite values become 0.
std::vector<std::uint8_t> tonemapToSrgb8(const Image& image);

}  // namespace sky::render
