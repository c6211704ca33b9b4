// OpenEXR output of a rendered frame (tinyexr): the linear radiance, the
// view-ray transmittance through the clouds and the cloud depth, as float
// channels of one scanline image, for compositing and for tests that need
// every value.
#pragma once

#include <span>
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

// A channel of a frame's own besides the image's (a path-traced frame's
// per-pixel standard error): its name (not one of the above, at most 255
// bytes) and width * height values, top row first.
struct ExrChannel {
  std::string name;
  std::span<const float> values;
};

// Writes a ZIP-compressed 32-bit float EXR, top row first, with `extra`
// channels after the image's (the file sorts them all by name). An image
// without cloud depth (not a render) gets a depth channel of 0. Errors:
// InvalidArgument for an empty or inconsistent image or an extra channel of
// another size or a taken or unusable name, Io when tinyexr cannot write
// the file (its message included).
Result<void> writeExr(const Image& image, const std::string& path, std::span<const ExrChannel> extra = {});

}  // namespace sky::render
