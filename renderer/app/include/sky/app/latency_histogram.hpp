// Transport delay of a channel's frames (the time from the arrival of the
// host datagram whose pose a frame draws to the frame's completion): the
// figure simulator qualification asks for (FAA 14 CFR Part 60, Appendix A:
// at most 150 ms from the host's input to the picture for Levels C and D).
// Kept as a histogram of 0.5 ms bins up to 10 s, so a channel that runs for
// days holds a fixed 160 kB however many frames it draws.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace sky::app {

class LatencyHistogram {
 public:
  static constexpr double kBin_ms = 0.5;
  static constexpr std::size_t kBins = 20000;  // 10 s; longer delays land in the last bin

  void add(double ms) {
    if (!std::isfinite(ms)) return;
    const double clamped = std::clamp(ms, 0.0, kBin_ms * double(kBins) - kBin_ms);
    ++bins_[static_cast<std::size_t>(clamped / kBin_ms)];
    ++count_;
    max_ms_ = std::max(max_ms_, ms);
  }
  std::uint64_t count() const { return count_; }
  double max_ms() const { return max_ms_; }
  // The p-th percentile (p in [0, 100]), to the bin's upper edge: an upper
  // bound within 0.5 ms. 0 without samples.
  double percentile_ms(double p) const {
    if (count_ == 0) return 0;
    const auto rank = static_cast<std::uint64_t>(std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * double(count_)));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
      seen += bins_[i];
      if (seen >= std::max<std::uint64_t>(rank, 1)) return std::min(kBin_ms * double(i + 1), max_ms_);
    }
    return max_ms_;
  }

 private:
  std::array<std::uint64_t, kBins> bins_{};
  std::uint64_t count_ = 0;
  double max_ms_ = 0;
};

}  // namespace sky::app
