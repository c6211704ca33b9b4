// OpenEXR output of a rendered frame (tinyexr): the linear radiance, the
// view-ray transmittance through the clouds and the cloud depth, as float
// channels of one scanline image, for compositing and for tests that need
// every value.
#pragma once

#include <string>

#include "sky/core/result.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::render {

// Channel names in the file (EXR keeps channels sorted by name; these sort as
// listed): R, G, B linear radiance (no exposure, no tonemap; the PNG's input);
// cloud.depth, m (0 where no cloud); cloud.transmittance, in [0, 1].
inline constexpr const char* kExrRed = "R";
inline constexpr const char* kExrGreen = "G";
inline constexpr const char* kExrBlue = "B";
inline constexpr const char* kExrCloudDepth = "cloud.depth";
inline constexpr const char* kExrCloudTransmittance = "cloud.transmittance";

// Writes a ZIP-compressed 32-bit float EXR, top row first. An image without
// cloud depth (not a render) gets a depth channel of 0. Errors:
// InvalidArgument for an empty or inconsistent image, Io when tinyexr cannot
// write the file (its message included).
Result<void> writeExr(const Image& image, const std::string& path);

}  // namespace sky::render
