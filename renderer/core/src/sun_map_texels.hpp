// The sun map (shaders/include/sun_map.glsl) on the CPU: its texels in
// double, filled texel by texel through the builder's store hook, and read
// as the GPU's sampler reads the RGBA32F 2D array image (bilinear, texel
// centres at (i + 0.5) / size, clamped to the edge). The CPU reference builds
// and reads it in place of the map pass.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace sky::render {

class SunMapTexels {
 public:
  SunMapTexels() = default;
  // parts: 1 or 2 image layers a cascade.
  SunMapTexels(int size, int cascades, int parts)
      : size_(size), cascades_(cascades), parts_(parts),
        texels_(std::size_t(size) * std::size_t(size) * std::size_t(cascades) * std::size_t(parts)) {}

  int size() const { return size_; }

  // Refills the map: texel(cascade, i, j) builds texel (i, j) of a cascade
  // and stores it through store() (the builder's hook).
  template <class Texel>
  void build(Texel&& texel) {
    for (current_[2] = 0; current_[2] < cascades_; ++current_[2])
      for (current_[1] = 0; current_[1] < size_; ++current_[1])
        for (current_[0] = 0; current_[0] < size_; ++current_[0]) texel(current_[2], current_[0], current_[1]);
  }

  // The parts of the texel being built.
  void store(const glm::dvec4& part0, const glm::dvec4& part1) {
    at(current_[0], current_[1], current_[2] * parts_) = part0;
    if (parts_ > 1) at(current_[0], current_[1], current_[2] * parts_ + 1) = part1;
  }

  // Layer `layer`'s bilinear value at uv.
  glm::dvec4 sample(int layer, const glm::dvec2& uv) const {
    const double x = uv.x * size_ - 0.5, y = uv.y * size_ - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const double wx = x - fx, wy = y - fy;
    const int ix = int(fx), iy = int(fy);
    glm::dvec4 sum(0.0);
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const double w = (dx ? wx : 1 - wx) * (dy ? wy : 1 - wy);
        if (w == 0.0) continue;
        sum += w * at(clampTo(ix + dx), clampTo(iy + dy), layer);
      }
    return sum;
  }

 private:
  int clampTo(int i) const { return i < 0 ? 0 : (i >= size_ ? size_ - 1 : i); }
  glm::dvec4& at(int i, int j, int layer) {
    return texels_[(std::size_t(layer) * std::size_t(size_) + std::size_t(j)) * std::size_t(size_) + std::size_t(i)];
  }
  const glm::dvec4& at(int i, int j, int layer) const {
    return texels_[(std::size_t(layer) * std::size_t(size_) + std::size_t(j)) * std::size_t(size_) + std::size_t(i)];
  }

  int size_ = 0, cascades_ = 0, parts_ = 0;
  std::array<int, 3> current_{0, 0, 0};  // i, j, cascade of the texel build() is at
  std::vector<glm::dvec4> texels_;
};

}  // namespace sky::render
