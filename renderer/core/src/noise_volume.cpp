// Noise generation (see noise_volume.hpp): periodic Worley and Perlin noise on
// integer lattices that divide the texture, so every channel tiles.
#include "noise_volume.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <glm/glm.hpp>

#include "sky/core/assert.hpp"

namespace sky::render {

namespace {

// Worley cells per period for the shape's first octave; later octaves double
// it. 4 cells over cumulus' 5 km period gives ~1.2 km cells.
constexpr int kShapeWorleyCells = 4;
// Perlin lattice cells per period for the first fBm octave, and octaves.
constexpr int kPerlinCells = 4;
constexpr int kPerlinOctaves = 4;
// The ridged (fibrous) channel starts at a finer lattice: ridges ~1/8 period apart.
constexpr int kRidgedCells = 8;
constexpr int kRidgedOctaves = 3;
// Detail Worley cells per period for its first octave (Haggstrom's 32^3
// detail texture keeps >= 4 texels per cell at the finest of 2, 4, 8).
constexpr int kDetailWorleyCells = 2;
// fBm weights of three Worley octaves (Haggstrom 2018 eq. 11 and 13).
constexpr std::array<double, 3> kWorleyFbmWeights = {0.625, 0.25, 0.125};

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

// A periodic Worley pattern: one feature point per cell of a `cells`^3
// lattice over one period, hashed once from the salt.
class WorleyLattice {
 public:
  WorleyLattice(int cells, std::uint32_t salt) : cells_(cells), features_(std::size_t(cells) * cells * cells) {
    for (int z = 0; z < cells; ++z)
      for (int y = 0; y < cells; ++y)
        for (int x = 0; x < cells; ++x) {
          const std::uint32_t h = hashCell(x, y, z, salt);
          features_[index(x, y, z)] = glm::dvec3(toUnit(hashPcg(h)), toUnit(hashPcg(h + 1)), toUnit(hashPcg(h + 2)));
        }
  }

  // 1 - distance to the nearest feature point, in cell units; u in periods.
  double inverted(const glm::dvec3& u) const {
    const glm::dvec3 p = u * double(cells_);
    const int cx = static_cast<int>(std::floor(p.x));
    const int cy = static_cast<int>(std::floor(p.y));
    const int cz = static_cast<int>(std::floor(p.z));
    double best2 = 3.0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx, y = cy + dy, z = cz + dz;
          const glm::dvec3 d = glm::dvec3(x, y, z) + features_[index(wrap(x, cells_), wrap(y, cells_), wrap(z, cells_))] - p;
          best2 = std::min(best2, glm::dot(d, d));
        }
    return 1.0 - std::min(std::sqrt(best2), 1.0);
  }

 private:
  std::size_t index(int x, int y, int z) const { return (std::size_t(z) * cells_ + std::size_t(y)) * cells_ + std::size_t(x); }
  int cells_;
  std::vector<glm::dvec3> features_;
};

// Three Worley octaves from baseCells, fBm-weighted (Haggstrom eq. 11, 13).
class WorleyFbm {
 public:
  WorleyFbm(int baseCells, std::uint32_t salt) {
    for (std::size_t o = 0; o < kWorleyFbmWeights.size(); ++o)
      octaves_.emplace_back(baseCells << o, salt + std::uint32_t(o));
  }
  double operator()(const glm::dvec3& u) const {
    double sum = 0;
    for (std::size_t o = 0; o < octaves_.size(); ++o) sum += kWorleyFbmWeights[o] * octaves_[o].inverted(u);
    return sum;
  }

 private:
  std::vector<WorleyLattice> octaves_;
};

// Quintic fade (Perlin 2002, "Improving noise").
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// Periodic Perlin gradient noise on a `cells`^3 lattice per period, about
// [-1, 1]; gradients are the 12 cube-edge directions, hashed once per corner.
class PerlinLattice {
 public:
  PerlinLattice(int cells, std::uint32_t salt) : cells_(cells), gradients_(std::size_t(cells) * cells * cells) {
    for (int z = 0; z < cells; ++z)
      for (int y = 0; y < cells; ++y)
        for (int x = 0; x < cells; ++x)
          gradients_[(std::size_t(z) * cells + std::size_t(y)) * cells + std::size_t(x)] =
              static_cast<std::uint8_t>(hashCell(x, y, z, salt) % 12u);
  }

  double operator()(const glm::dvec3& u) const {
    static constexpr std::array<glm::dvec3, 12> kGradients = {
        glm::dvec3(1, 1, 0), glm::dvec3(-1, 1, 0), glm::dvec3(1, -1, 0), glm::dvec3(-1, -1, 0),
        glm::dvec3(1, 0, 1), glm::dvec3(-1, 0, 1), glm::dvec3(1, 0, -1), glm::dvec3(-1, 0, -1),
        glm::dvec3(0, 1, 1), glm::dvec3(0, -1, 1), glm::dvec3(0, 1, -1), glm::dvec3(0, -1, -1)};
    const glm::dvec3 p = u * double(cells_);
    const glm::dvec3 f = glm::floor(p);
    const glm::dvec3 t = p - f;
    const int x0 = static_cast<int>(f.x), y0 = static_cast<int>(f.y), z0 = static_cast<int>(f.z);
    auto corner = [&](int dx, int dy, int dz) {
      const std::size_t i = (std::size_t(wrap(z0 + dz, cells_)) * cells_ + std::size_t(wrap(y0 + dy, cells_))) * cells_ +
                            std::size_t(wrap(x0 + dx, cells_));
      return glm::dot(kGradients[gradients_[i]], t - glm::dvec3(dx, dy, dz));
    };
    const double fx = fade(t.x), fy = fade(t.y), fz = fade(t.z);
    auto lerp = [](double a, double b, double s) { return a + (b - a) * s; };
    const double x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), fx), x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), fx);
    const double x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), fx), x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), fx);
    return lerp(lerp(x00, x10, fy), lerp(x01, x11, fy), fz);
  }

 private:
  int cells_;
  std::vector<std::uint8_t> gradients_;
};

// Octaves of Perlin noise from baseCells, amplitudes halving; `ridged` folds
// each octave into 1 - |n|, squared to sharpen the ridges into threads.
class PerlinFbm {
 public:
  PerlinFbm(int baseCells, int octaves, std::uint32_t salt, bool ridged) : ridged_(ridged) {
    for (int o = 0; o < octaves; ++o) octaves_.emplace_back(baseCells << o, salt + std::uint32_t(o));
  }
  // About [0, 1].
  double operator()(const glm::dvec3& u) const {
    double sum = 0, norm = 0, amp = 1;
    for (const auto& octave : octaves_) {
      const double n = octave(u);
      const double r = 1.0 - std::abs(n);
      sum += amp * (ridged_ ? r * r : 0.5 + 0.5 * n);
      norm += amp;
      amp *= 0.5;
    }
    return sum / norm;
  }

 private:
  bool ridged_;
  std::vector<PerlinLattice> octaves_;
};

double remap(double v, double lo, double hi, double newLo, double newHi) {
  return newLo + (v - lo) * (newHi - newLo) / (hi - lo);
}

// Histogram equalisation of one channel into unorm8: rank / (count - 1), ties
// broken by index so the result is deterministic.
void equalise(const std::vector<double>& raw, std::uint32_t channels, std::uint32_t channel,
              std::vector<std::uint8_t>& texels) {
  const std::size_t count = raw.size();
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return raw[a] < raw[b] || (raw[a] == raw[b] && a < b); });
  for (std::size_t rank = 0; rank < count; ++rank)
    texels[std::size_t(order[rank]) * channels + channel] =
        static_cast<std::uint8_t>(std::lround(255.0 * double(rank) / double(count - 1)));
}

glm::dvec3 texelCentre(std::uint32_t i, std::uint32_t j, std::uint32_t k, std::uint32_t size) {
  return (glm::dvec3(i, j, k) + 0.5) / static_cast<double>(size);
}

}  // namespace

glm::dvec4 NoiseVolume::sample(const glm::dvec3& uvw) const {
  SKY_ASSERT(size > 0 && channels >= 1 && channels <= 4 &&
             texels.size() == std::size_t(size) * size * size * channels);
  const int n = static_cast<int>(size);
  const glm::dvec3 x = uvw * static_cast<double>(size) - 0.5;
  const glm::dvec3 f = glm::floor(x);
  const glm::dvec3 t = x - f;
  const int i0 = static_cast<int>(f.x), j0 = static_cast<int>(f.y), k0 = static_cast<int>(f.z);
  glm::dvec4 result(0.0);
  for (int dk = 0; dk <= 1; ++dk)
    for (int dj = 0; dj <= 1; ++dj)
      for (int di = 0; di <= 1; ++di) {
        const double w = (di ? t.x : 1 - t.x) * (dj ? t.y : 1 - t.y) * (dk ? t.z : 1 - t.z);
        const std::size_t idx = ((std::size_t(wrap(k0 + dk, n)) * size + std::size_t(wrap(j0 + dj, n))) * size +
                                 std::size_t(wrap(i0 + di, n))) * channels;
        for (std::uint32_t c = 0; c < channels; ++c) result[int(c)] += w * (texels[idx + c] / 255.0);
      }
  return result;
}

NoiseVolume makeShapeNoise(std::uint32_t size, std::uint32_t seed) {
  SKY_ASSERT(size > 0 && size % (kShapeWorleyCells << 3) == 0);
  const std::size_t count = std::size_t(size) * size * size;
  std::array<std::vector<double>, 4> raw;
  for (auto& channel : raw) channel.resize(count);
  const std::uint32_t salt = seed * 7919u;
  const WorleyLattice base(kShapeWorleyCells, salt + 11u);
  const PerlinFbm billowPerlin(kPerlinCells, kPerlinOctaves, salt + 21u, false);
  const WorleyFbm fine(kShapeWorleyCells * 2, salt + 31u);
  const PerlinFbm ridged(kRidgedCells, kRidgedOctaves, salt + 41u, true);
  const PerlinFbm smooth(kPerlinCells, kPerlinOctaves, salt + 51u, false);
  const WorleyFbm cells(kShapeWorleyCells, salt + 61u);
  for (std::uint32_t k = 0; k < size; ++k)
    for (std::uint32_t j = 0; j < size; ++j)
      for (std::uint32_t i = 0; i < size; ++i) {
        const glm::dvec3 u = texelCentre(i, j, k, size);
        const std::size_t idx = (std::size_t(k) * size + j) * size + i;
        // Perlin-Worley: the Perlin fBm dilated by a base Worley octave
        // (remapped from [worley - 1, 1]), then carved by three finer Worley
        // octaves as Haggstrom eq. 11.
        const double perlinWorley = remap(billowPerlin(u), base.inverted(u) - 1.0, 1.0, 0.0, 1.0);
        raw[0][idx] = remap(perlinWorley, fine(u) - 1.0, 1.0, 0.0, 1.0);
        raw[1][idx] = ridged(u);
        raw[2][idx] = smooth(u);
        raw[3][idx] = cells(u);
      }
  NoiseVolume volume;
  volume.size = size;
  volume.channels = 4;
  volume.texels.resize(count * 4);
  for (std::uint32_t c = 0; c < 4; ++c) equalise(raw[c], 4, c, volume.texels);
  return volume;
}

NoiseVolume makeDetailNoise(std::uint32_t size, std::uint32_t seed) {
  SKY_ASSERT(size > 0 && size % (kDetailWorleyCells << 2) == 0);
  const std::size_t count = std::size_t(size) * size * size;
  std::vector<double> raw(count);
  const WorleyFbm worley(kDetailWorleyCells, seed * 104729u + 101u);
  for (std::uint32_t k = 0; k < size; ++k)
    for (std::uint32_t j = 0; j < size; ++j)
      for (std::uint32_t i = 0; i < size; ++i)
        raw[(std::size_t(k) * size + j) * size + i] = worley(texelCentre(i, j, k, size));
  NoiseVolume volume;
  volume.size = size;
  volume.channels = 1;
  volume.texels.resize(count);
  equalise(raw, 1, 0, volume.texels);
  return volume;
}

}  // namespace sky::render
