// Void-and-cluster blue noise (see blue_noise.hpp).
#include "blue_noise.hpp"

#include <cmath>
#include <map>
#include <mutex>

#include "sky/core/assert.hpp"
#include "sky/core/split_mix.hpp"

namespace sky::render {

namespace {

// Ulichney's energy filter: a Gaussian of sigma 1.5 pixels on the torus.
constexpr double kSigma = 1.5;
// Share of the pixels set in the initial random pattern.
constexpr double kInitialFill = 0.1;

// SplitMix64 step: the seed's stream of random numbers.
std::uint64_t nextRandom(std::uint64_t& state) {
  const std::uint64_t z = splitMix64(state);
  state += kSplitMixIncrement;
  return z;
}

class Pattern {
 public:
  explicit Pattern(std::uint32_t size) : size_(size), n_(size * size), on_(n_, false), energy_(n_, 0.0), kernel_(n_) {
    for (std::uint32_t dy = 0; dy < size; ++dy)
      for (std::uint32_t dx = 0; dx < size; ++dx) {
        const double x = std::min(dx, size - dx), y = std::min(dy, size - dy);
        kernel_[dy * size + dx] = std::exp(-(x * x + y * y) / (2 * kSigma * kSigma));
      }
  }

  bool on(std::uint32_t i) const { return on_[i]; }
  std::uint32_t count() const { return count_; }

  void set(std::uint32_t i, bool value) {
    SKY_ASSERT(on_[i] != value);
    on_[i] = value;
    count_ += value ? 1 : -1;
    const double sign = value ? 1.0 : -1.0;
    const std::uint32_t ix = i % size_, iy = i / size_, mask = size_ - 1;
    for (std::uint32_t y = 0; y < size_; ++y)
      for (std::uint32_t x = 0; x < size_; ++x)
        energy_[y * size_ + x] += sign * kernel_[((y - iy) & mask) * size_ + ((x - ix) & mask)];
  }

  // The set pixel with the most energy around it (the tightest cluster),
  // or the unset one with the least (the largest void); the first on ties.
  std::uint32_t tightestCluster() const { return extreme(true); }
  std::uint32_t largestVoid() const { return extreme(false); }

 private:
  std::uint32_t extreme(bool cluster) const {
    std::uint32_t best = n_;
    for (std::uint32_t i = 0; i < n_; ++i) {
      if (on_[i] != cluster) continue;
      if (best == n_ || (cluster ? energy_[i] > energy_[best] : energy_[i] < energy_[best])) best = i;
    }
    SKY_ASSERT(best < n_);
    return best;
  }

  std::uint32_t size_, n_;
  std::vector<bool> on_;
  std::vector<double> energy_;
  std::vector<double> kernel_;  // by toroidal offset (dy, dx)
  std::uint32_t count_ = 0;
};

}  // namespace

std::vector<float> makeBlueNoise(std::uint32_t size, std::uint32_t seed) {
  SKY_ASSERT(size >= 4 && (size & (size - 1)) == 0);
  const std::uint32_t n = size * size;
  Pattern p(size);
  // A random initial pattern.
  std::uint64_t state = 0x5b1e5eedull ^ (std::uint64_t(seed) << 32);
  const auto initial = std::uint32_t(std::lround(kInitialFill * n));
  while (p.count() < initial) {
    const auto i = std::uint32_t(nextRandom(state) % n);
    if (!p.on(i)) p.set(i, true);
  }
  // Relaxed into the prototype: the tightest cluster's pixel moves to the
  // largest void until it would come straight back.
  for (std::uint32_t guard = 0; guard < 16 * n; ++guard) {
    const std::uint32_t c = p.tightestCluster();
    p.set(c, false);
    const std::uint32_t v = p.largestVoid();
    p.set(v, true);
    if (v == c) break;
  }
  std::vector<std::uint32_t> rank(n, 0);
  // Ranks below the prototype's count: its pixels taken out, tightest
  // cluster first, ranked downwards.
  {
    Pattern q = p;
    for (std::uint32_t r = q.count(); r-- > 0;) {
      const std::uint32_t c = q.tightestCluster();
      q.set(c, false);
      rank[c] = r;
    }
  }
  // Ranks from the prototype's count up: the largest void filled next.
  for (std::uint32_t r = p.count(); r < n; ++r) {
    const std::uint32_t v = p.largestVoid();
    p.set(v, true);
    rank[v] = r;
  }
  std::vector<float> out(n);
  for (std::uint32_t i = 0; i < n; ++i) out[i] = float((rank[i] + 0.5) / n);
  return out;
}

const std::vector<float>& blueNoiseTile(std::uint32_t seed) {
  static std::mutex mutex;
  static std::map<std::uint32_t, std::vector<float>> tiles;
  const std::lock_guard lock(mutex);
  auto it = tiles.find(seed);
  if (it == tiles.end()) it = tiles.emplace(seed, makeBlueNoise(kBlueNoiseSize, seed)).first;
  return it->second;
}

}  // namespace sky::render
