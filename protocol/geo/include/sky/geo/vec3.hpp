// A minimal double-precision 3-vector for the geodetic math in protocol/.
// (The renderer uses GLM; protocol/ keeps to its own small type so that the
// math both processes share has no GPU-side dependency.)
#pragma once

#include <cmath>

namespace sky::geo {

struct Vec3d {
  double x = 0, y = 0, z = 0;

  friend constexpr Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3d operator*(Vec3d a, double s) { return {a.x * s, a.y * s, a.z * s}; }
  friend constexpr Vec3d operator*(double s, Vec3d a) { return a * s; }
  friend constexpr Vec3d operator-(Vec3d a) { return {-a.x, -a.y, -a.z}; }
};

constexpr double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(Vec3d a) { return std::sqrt(dot(a, a)); }
inline Vec3d normalize(Vec3d a) { return a * (1.0 / length(a)); }

}  // namespace sky::geo
