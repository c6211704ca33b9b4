// Display transform, resampling and PNG writing for the bench (display.hpp).
#include "sky/bench/display.hpp"

#include <algorithm>
#include <cmath>

// Static, so these stb symbols never meet renderer/core's copy at link time.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>

namespace sky::bench {

namespace {

// Narkowicz 2015, "ACES Filmic Tone Mapping Curve".
double acesFilmic(double x) {
  constexpr double a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
  return std::clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

// IEC 61966-2-1 sRGB encoding of a linear value in [0, 1].
double srgbEncode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

}  // namespace

Srgb8Image toSrgb8(const RgbaView& image, double exposure) {
  const std::size_t n = std::size_t(image.width) * image.height;
  Srgb8Image out{image.width, image.height, std::vector<std::uint8_t>(n * 3)};
  for (std::size_t p = 0; p < n && p * 4 + 3 < image.rgba.size(); ++p)
    for (std::size_t c = 0; c < 3; ++c) {
      const double v = image.rgba[p * 4 + c];
      const double mapped = std::isfinite(v) ? srgbEncode(acesFilmic(std::max(0.0, v * exposure))) : 0.0;
      out.rgb[p * 3 + c] = static_cast<std::uint8_t>(std::lround(mapped * 255.0));
    }
  return out;
}

std::vector<float> resizeBilinear(const RgbaView& image, std::uint32_t width, std::uint32_t height) {
  std::vector<float> out(std::size_t(width) * height * 4);
  if (image.width == 0 || image.height == 0) return out;
  const double sx = double(image.width) / width, sy = double(image.height) / height;
  auto at = [&](std::uint32_t x, std::uint32_t y, std::size_t c) {
    return double(image.rgba[(std::size_t(y) * image.width + x) * 4 + c]);
  };
  for (std::uint32_t y = 0; y < height; ++y) {
    const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, double(image.height - 1));
    const auto y0 = std::uint32_t(fy);
    const std::uint32_t y1 = std::min(y0 + 1, image.height - 1);
    const double ty = fy - y0;
    for (std::uint32_t x = 0; x < width; ++x) {
      const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, double(image.width - 1));
      const auto x0 = std::uint32_t(fx);
      const std::uint32_t x1 = std::min(x0 + 1, image.width - 1);
      const double tx = fx - x0;
      for (std::size_t c = 0; c < 4; ++c) {
        const double top = at(x0, y0, c) * (1 - tx) + at(x1, y0, c) * tx;
        const double bottom = at(x0, y1, c) * (1 - tx) + at(x1, y1, c) * tx;
        out[(std::size_t(y) * width + x) * 4 + c] = float(top * (1 - ty) + bottom * ty);
      }
    }
  }
  return out;
}

Result<void> writePng(const Srgb8Image& image, const std::string& path) {
  if (image.width == 0 || image.height == 0 || image.rgb.size() != std::size_t(image.width) * image.height * 3)
    return fail(ErrorCode::InvalidArgument, "writePng " + path + ": image size does not match its pixels");
  if (stbi_write_png(path.c_str(), int(image.width), int(image.height), 3, image.rgb.data(), int(image.width) * 3) == 0)
    return fail(ErrorCode::Io, "writePng " + path + ": cannot write file");
  return {};
}

}  // namespace sky::bench
