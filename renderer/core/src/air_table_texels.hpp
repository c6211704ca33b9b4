// The air table (shaders/include/air_table.glsl) on the CPU: its texels in
// double, filled column by column through the builder's store hook, and
// read as the GPU's sampler reads the RGBA32F image (linear, texel centres
// at (i + 0.5) / size, u repeating, v and w clamped to the edge). The CPU
// reference builds and reads it in place of the table pass.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace sky::render {

class AirTableTexels {
 public:
  AirTableTexels() = default;
  AirTableTexels(int azimuths, int zeniths, int slices)
      : azimuths_(azimuths), zeniths_(zeniths), slices_(slices),
        texels_(std::size_t(3) * std::size_t(azimuths) * std::size_t(zeniths) * std::size_t(slices)) {}

  int azimuths() const { return azimuths_; }
  int zeniths() const { return zeniths_; }
  int slices() const { return slices_; }

  void store(int i, int j, int slice, const glm::dvec4& part0, const glm::dvec4& part1, const glm::dvec4& part2) {
    at(i, j, slice) = part0;
    at(i, j, slices_ + slice) = part1;
    at(i, j, 2 * slices_ + slice) = part2;
  }

  // Part `part`'s trilinear value at uvw (w within the part, as air_table.glsl's sampleAirTable).
  glm::dvec4 sample(int part, const glm::dvec3& uvw) const {
    const double x = uvw.x * azimuths_ - 0.5;
    const double y = uvw.y * zeniths_ - 0.5;
    const double z = (part + uvw.z) / 3.0 * (3 * slices_) - 0.5;
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const double wx = x - fx, wy = y - fy, wz = z - fz;
    const int ix = int(fx), iy = int(fy), iz = int(fz);
    glm::dvec4 sum(0.0);
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const double w = (dx ? wx : 1 - wx) * (dy ? wy : 1 - wy) * (dz ? wz : 1 - wz);
          if (w == 0.0) continue;
          sum += w * at(wrap(ix + dx, azimuths_), clampTo(iy + dy, zeniths_), clampTo(iz + dz, 3 * slices_));
        }
    return sum;
  }

  // Bytes the GPU's image of this shape takes (RGBA32F).
  static std::size_t bytes(int azimuths, int zeniths, int slices) {
    return std::size_t(3) * std::size_t(azimuths) * std::size_t(zeniths) * std::size_t(slices) * 16;
  }

 private:
  static int wrap(int i, int n) { return ((i % n) + n) % n; }
  static int clampTo(int i, int n) { return i < 0 ? 0 : (i >= n ? n - 1 : i); }
  glm::dvec4& at(int i, int j, int z) {
    return texels_[(std::size_t(z) * std::size_t(zeniths_) + std::size_t(j)) * std::size_t(azimuths_) + std::size_t(i)];
  }
  const glm::dvec4& at(int i, int j, int z) const {
    return texels_[(std::size_t(z) * std::size_t(zeniths_) + std::size_t(j)) * std::size_t(azimuths_) + std::size_t(i)];
  }

  int azimuths_ = 0, zeniths_ = 0, slices_ = 0;
  std::vector<glm::dvec4> texels_;
};

}  // namespace sky::render
