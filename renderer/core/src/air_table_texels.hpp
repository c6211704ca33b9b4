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

  // Refills the table column by column: column(i, j) marches column (i, j)
  // and stores its slices through store() (the builder's hook).
  template <class Column>
  void build(Column&& column) {
    for (current_[1] = 0; current_[1] < zeniths_; ++current_[1])
      for (current_[0] = 0; current_[0] < azimuths_; ++current_[0]) column(current_[0], current_[1]);
  }

  // One slice of the column being built.
  void store(int slice, const glm::dvec4& part0, const glm::dvec4& part1, const glm::dvec4& part2) {
    at(current_[0], current_[1], slice) = part0;
    at(current_[0], current_[1], slices_ + slice) = part1;
    at(current_[0], current_[1], 2 * slices_ + slice) = part2;
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
  std::array<int, 2> current_{0, 0};  // the column build() is at
  std::vector<glm::dvec4> texels_;
};

}  // namespace sky::render
