// The transport-delay histogram: percentiles of known samples to within its
// 0.5 ms bins, as an upper bound; nothing lost beyond 10 s; a fixed size.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "sky/app/latency_histogram.hpp"

namespace sky::app {
namespace {

TEST(LatencyHistogram, PercentilesOfKnownSamplesToWithinABin) {
  LatencyHistogram h;
  EXPECT_EQ(h.percentile_ms(99), 0.0);
  // 1, 2, ..., 100 ms: p50 is 50 ms, p99 is 99 ms.
  for (int i = 1; i <= 100; ++i) h.add(i);
  EXPECT_EQ(h.count(), 100u);
  EXPECT_GE(h.percentile_ms(50), 50.0);
  EXPECT_LE(h.percentile_ms(50), 50.0 + LatencyHistogram::kBin_ms);
  EXPECT_GE(h.percentile_ms(99), 99.0);
  EXPECT_LE(h.percentile_ms(99), 99.0 + LatencyHistogram::kBin_ms);
  EXPECT_EQ(h.percentile_ms(100), 100.0);
  EXPECT_EQ(h.max_ms(), 100.0);
}

TEST(LatencyHistogram, ALongStallIsCountedAndNaNIsNot) {
  LatencyHistogram h;
  for (int i = 0; i < 98; ++i) h.add(20.25);
  h.add(25000);  // past the last bin: counted there, the max exact
  h.add(std::numeric_limits<double>::quiet_NaN());
  h.add(30);
  EXPECT_EQ(h.count(), 100u);
  EXPECT_NEAR(h.percentile_ms(50), 20.5, 1e-12);
  EXPECT_EQ(h.max_ms(), 25000.0);
  EXPECT_GT(h.percentile_ms(100), 9999.0);
  static_assert(sizeof(LatencyHistogram) < 200 * 1024, "a fixed size, whatever the frame count");
}

}  // namespace
}  // namespace sky::app
