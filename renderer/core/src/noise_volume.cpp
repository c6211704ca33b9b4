// Shape-noise generation (see noise_volume.hpp): periodic Worley and value
// noise on integer lattices that divide the texture, so the result tiles.
#include "noise_volume.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <glm/glm.hpp>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// Worley cells per period for the first octave; later octaves double it.
// 4 cells over the 5 km period gives ~1.2 km cumulus cells.
constexpr int kWorleyBaseCells = 4;
constexpr int kWorleyOctaves = 3;
// Value-noise lattice for the first fBm octave; octaves double it.
constexpr int kValueBaseCells = 4;
constexpr int kValueOctaves = 3;
// Blend of the billowy Worley part and the irregular value part: mostly Worley,
// as in Schneider's Perlin-Worley shape noise.
constexpr double kWorleyWeight = 0.65;

std::uint32_t hashPcg(std::uint32_t x) {
  const std::uint32_t state = x * 747796405u + 2891336453u;
  const std::uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

std::uint32_t hashCell(int x, int y, int z, std::uint32_t salt) {
  std::uint32_t h = hashPcg(salt);
  h = hashPcg(h ^ static_cast<std::uint32_t>(x));
  h = hashPcg(h ^ static_cast<std::uint32_t>(y));
  h = hashPcg(h ^ static_cast<std::uint32_t>(z));
  return h;
}

double toUnit(std::uint32_t h) { return static_cast<double>(h >> 8) / 16777216.0; }

int wrap(int i, int n) { return ((i % n) + n) % n; }

// 1 - distance to the nearest feature point, in cell units, of a periodic
// Worley pattern with `cells` cells per period; p in cells.
double worleyInverted(const glm::dvec3& p, int cells, std::uint32_t salt) {
  const int cx = static_cast<int>(std::floor(p.x));
  const int cy = static_cast<int>(std::floor(p.y));
  const int cz = static_cast<int>(std::floor(p.z));
  double best2 = 3.0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = cx + dx, y = cy + dy, z = cz + dz;
        const std::uint32_t h = hashCell(wrap(x, cells), wrap(y, cells), wrap(z, cells), salt);
        const glm::dvec3 feature(x + toUnit(hashPcg(h)), y + toUnit(hashPcg(h + 1)),
                                 z + toUnit(hashPcg(h + 2)));
        const glm::dvec3 d = feature - p;
        best2 = std::min(best2, d.x * d.x + d.y * d.y + d.z * d.z);
      }
  return 1.0 - std::min(std::sqrt(best2), 1.0);
}

double smooth(double t) { return t * t * (3.0 - 2.0 * t); }

// Periodic value noise with `cells` lattice cells per period; p in cells.
double valueNoise(const glm::dvec3& p, int cells, std::uint32_t salt) {
  const glm::dvec3 f = glm::floor(p);
  const int x0 = static_cast<int>(f.x), y0 = static_cast<int>(f.y), z0 = static_cast<int>(f.z);
  const double tx = smooth(p.x - f.x), ty = smooth(p.y - f.y), tz = smooth(p.z - f.z);
  auto v = [&](int dx, int dy, int dz) {
    return toUnit(hashCell(wrap(x0 + dx, cells), wrap(y0 + dy, cells), wrap(z0 + dz, cells), salt));
  };
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double x00 = lerp(v(0, 0, 0), v(1, 0, 0), tx), x10 = lerp(v(0, 1, 0), v(1, 1, 0), tx);
  const double x01 = lerp(v(0, 0, 1), v(1, 0, 1), tx), x11 = lerp(v(0, 1, 1), v(1, 1, 1), tx);
  return lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz);
}

}  // namespace

double NoiseVolume::sample(const glm::dvec3& uvw) const {
  SKY_ASSERT(size > 0 && texels.size() == std::size_t(size) * size * size);
  const int n = static_cast<int>(size);
  const glm::dvec3 x = uvw * static_cast<double>(size) - 0.5;
  const glm::dvec3 f = glm::floor(x);
  const glm::dvec3 t = x - f;
  const int i0 = static_cast<int>(f.x), j0 = static_cast<int>(f.y), k0 = static_cast<int>(f.z);
  auto at = [&](int i, int j, int k) {
    const std::size_t idx = (std::size_t(wrap(k, n)) * size + std::size_t(wrap(j, n))) * size +
                            std::size_t(wrap(i, n));
    return texels[idx] / 255.0;
  };
  double result = 0;
  for (int dk = 0; dk <= 1; ++dk)
    for (int dj = 0; dj <= 1; ++dj)
      for (int di = 0; di <= 1; ++di) {
        const double w = (di ? t.x : 1 - t.x) * (dj ? t.y : 1 - t.y) * (dk ? t.z : 1 - t.z);
        result += w * at(i0 + di, j0 + dj, k0 + dk);
      }
  return result;
}

NoiseVolume makeShapeNoise(std::uint32_t size, std::uint32_t seed) {
  SKY_ASSERT(size > 0 && size % (kWorleyBaseCells << (kWorleyOctaves - 1)) == 0);
  const std::size_t count = std::size_t(size) * size * size;
  std::vector<double> raw(count);
  for (std::uint32_t k = 0; k < size; ++k)
    for (std::uint32_t j = 0; j < size; ++j)
      for (std::uint32_t i = 0; i < size; ++i) {
        const glm::dvec3 u = (glm::dvec3(i, j, k) + 0.5) / static_cast<double>(size);
        double worley = 0, worleyNorm = 0, amp = 1;
        for (int o = 0; o < kWorleyOctaves; ++o, amp *= 0.5) {
          const int cells = kWorleyBaseCells << o;
          worley += amp * worleyInverted(u * double(cells), cells, seed * 7919u + std::uint32_t(o));
          worleyNorm += amp;
        }
        double value = 0, valueNorm = 0;
        amp = 1;
        for (int o = 0; o < kValueOctaves; ++o, amp *= 0.5) {
          const int cells = kValueBaseCells << o;
          value += amp * valueNoise(u * double(cells), cells, seed * 104729u + 101u + std::uint32_t(o));
          valueNorm += amp;
        }
        raw[(std::size_t(k) * size + j) * size + i] =
            kWorleyWeight * worley / worleyNorm + (1 - kWorleyWeight) * value / valueNorm;
      }
  // Histogram equalisation: rank / (count - 1), ties broken by index so the
  // result is deterministic.
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return raw[a] < raw[b] || (raw[a] == raw[b] && a < b);
  });
  NoiseVolume volume;
  volume.size = size;
  volume.texels.resize(count);
  for (std::size_t rank = 0; rank < count; ++rank)
    volume.texels[order[rank]] =
        static_cast<std::uint8_t>(std::lround(255.0 * double(rank) / double(count - 1)));
  return volume;
}

}  // namespace sky::render
