// Image statistics, the display transform (the camera's exposure, ACES
// filmic tonemap, Narkowicz 2015 fit, sRGB transfer, 8 bits) shared by the
// PNG and the window, and PNG output through stb_image_write.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "image_output.hpp"
#include "sky/core/assert.hpp"
#include "sky/render/cloud_renderer.hpp"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO_FOPEN_S
#include <stb_image_write.h>

namespace sky::render {

namespace {

// Narkowicz 2015, "ACES Filmic Tone Mapping Curve": a rational fit of the
// ACES reference rendering and sRGB output transforms' tone scale, per
// channel, f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to
// [0, 1]. f(0) = 0; toe below x ~ 0.05; f(0.104) = 0.133, where a metered
// mean lands (1 / 9.6: exposure.hpp), encoded 102 of 255; f(1) = 0.80, the
// exposure's L_max; the white point, f(x) = 1, is x = 7.24 (the root of
// 0.08 x^2 - 0.56 x - 0.14): 2.86 EV above L_max, 6.1 EV above the metered
// mean. Brighter values clip to white. (Narkowicz scales his input by 0.6
// first; we do not: our exposure is the camera's, documented in exposure.hpp.)
double acesFilmic(double x) {
  constexpr double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

// IEC 61966-2-1 sRGB encoding of a linear value in [0, 1].
double srgbEncode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

bool consistent(const Image& image) {
  return image.width > 0 && image.height > 0 && image.rgba.size() == std::size_t(image.width) * image.height * 4;
}

}  // namespace

ImageStats computeStats(const Image& image) {
  ImageStats stats;
  double sum = 0;
  std::size_t finite = 0;
  for (std::size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
    const float* p = &image.rgba[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) || !std::isfinite(p[3])) {
      ++stats.nonFinite;
      continue;
    }
    sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];  // Rec. 709 luminance
    ++finite;
  }
  stats.meanLuminance = finite ? sum / double(finite) : 0.0;
  return stats;
}

std::vector<std::uint8_t> tonemapToSrgb8(const Image& image, double exposure) {
  SKY_ASSERT(consistent(image));
  std::vector<std::uint8_t> rgb(std::size_t(image.width) * image.height * 3);
  for (std::size_t px = 0; px < std::size_t(image.width) * image.height; ++px)
    for (int c = 0; c < 3; ++c) {
      const double v = image.rgba[px * 4 + std::size_t(c)];
      const double mapped = std::isfinite(v) ? srgbEncode(acesFilmic(std::max(0.0, v * exposure))) : 0.0;
      rgb[px * 3 + std::size_t(c)] = static_cast<std::uint8_t>(std::lround(mapped * 255.0));
    }
  return rgb;
}

Result<void> writePng(const Image& image, const std::string& path, double exposure) {
  if (!consistent(image))
    return fail(ErrorCode::InvalidArgument, "writePng " + path + ": image size does not match its pixels");
  const std::vector<std::uint8_t> rgb = tonemapToSrgb8(image, exposure);
  const int ok = stbi_write_png(path.c_str(), int(image.width), int(image.height), 3, rgb.data(), int(image.width) * 3);
  if (ok == 0) return fail(ErrorCode::Io, "writePng " + path + ": cannot write file");
  return {};
}

Result<void> writeRgbPng(const std::vector<std::uint8_t>& rgb, std::uint32_t width, std::uint32_t height,
                         const std::string& path) {
  if (width == 0 || height == 0 || rgb.size() != std::size_t(width) * height * 3)
    return fail(ErrorCode::InvalidArgument, "writeRgbPng " + path + ": size does not match the pixels");
  if (stbi_write_png(path.c_str(), int(width), int(height), 3, rgb.data(), int(width) * 3) == 0)
    return fail(ErrorCode::Io, "writeRgbPng " + path + ": cannot write file");
  return {};
}

}  // namespace sky::render
