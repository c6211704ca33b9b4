// Variance clipping of the reprojected history (shaders/include/history_clip.glsl,
// compiled here as C++ in double): the space round-trips, a history inside
// the neighbourhood's box is kept bit for bit, one outside is moved onto
// the box toward its centre, and the box never reaches past the samples.
#include <cmath>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "glsl_double.hpp"

namespace sky::test {
namespace {

using namespace glm;

struct Clip : render::GlslDouble {
#include "history_clip.glsl"
};

using real4 = Clip::real4;

Clip::HistoryBox boxOf(Clip& c, std::initializer_list<real4> samples) {
  auto box = c.historyBoxEmpty();
  for (const real4& s : samples) box = c.historyBoxAdd(box, c.historyClipSpace(s));
  return box;
}

TEST(HistoryClip, SpaceRoundTrips) {
  Clip c;
  for (real4 v : {real4(0.0), real4(1.0, 0.5, 0.25, 0.3), real4(20.0, 22.0, 25.0, 0.0), real4(0.01, 0.0, 0.3, 1.0)}) {
    const real4 back = c.historyFromClipSpace(c.historyClipSpace(v));
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(back[i], v[i], 1e-12 * (1 + std::abs(v[i]))) << i;
  }
}

TEST(HistoryClip, HistoryInsideTheBoxIsKeptExactly) {
  Clip c;
  const auto box = boxOf(c, {real4(1, 1, 1, 0.2), real4(2, 2, 2, 0.4), real4(1.5, 1.4, 1.6, 0.3)});
  const real4 h(1.5, 1.5, 1.5, 0.3);
  EXPECT_EQ(c.clipHistory(box, h, 1.25), h);
  // No sample: nothing to clip against.
  EXPECT_EQ(c.clipHistory(c.historyBoxEmpty(), real4(9, 0, 0, 1), 1.25), real4(9, 0, 0, 1));
}

// A ghost: the history holds bright cloud where every pixel drawn around it
// now sees dark sky. The clipped history lies on the box (not inside the
// samples' range any further than gamma sigma allows) and keeps its
// direction from the centre.
TEST(HistoryClip, GhostIsMovedOntoTheBox) {
  Clip c;
  const auto box = boxOf(c, {real4(0.10, 0.15, 0.30, 1.0), real4(0.12, 0.16, 0.32, 1.0), real4(0.11, 0.15, 0.31, 0.98),
                             real4(0.10, 0.14, 0.29, 1.0)});
  const real4 ghost(3.0, 3.0, 3.0, 0.05);
  const real4 clipped = c.clipHistory(box, ghost, 1.25);
  const real4 y = c.historyClipSpace(clipped);
  for (int i = 0; i < 4; ++i) {
    EXPECT_GE(y[i], box.lo[i] - 1e-9) << i;
    EXPECT_LE(y[i], box.hi[i] + 1e-9) << i;
  }
  // Sky-like again: transmittance near the samples', radiance near theirs.
  EXPECT_GT(clipped.w, 0.95);
  EXPECT_LT(clipped.x, 0.2);
  // One axis at least touches the box's face (clipped, not clamped inside).
  const real4 mean = box.sum / box.count;
  const real4 sigma = glm::sqrt(glm::max(box.sum2 / box.count - mean * mean, real4(0.0)));
  bool onFace = false;
  for (int i = 0; i < 4; ++i) {
    const double lo = std::max(box.lo[i], mean[i] - 1.25 * sigma[i]);
    const double hi = std::min(box.hi[i], mean[i] + 1.25 * sigma[i]);
    onFace = onFace || std::abs(y[i] - lo) < 1e-9 || std::abs(y[i] - hi) < 1e-9;
  }
  EXPECT_TRUE(onFace);
}

// Compressed space: a bright sunlit edge beside a dark base spans a box that
// a mid-grey history lies inside (it is between them), where a box in
// linear radiance would hold it too; but a history far brighter than both
// (a stale sun glint) is brought back to the bright sample: within 5 % of
// it in any channel (the box is square in YCoCg, not in red, green and
// blue, so its face may pass a channel of the sample a little).
TEST(HistoryClip, BrightAndDarkEdgesBoundTheHistory) {
  Clip c;
  const auto box = boxOf(c, {real4(8, 8, 8, 0.1), real4(0.2, 0.2, 0.25, 0.1)});
  const real4 mid(1.0, 1.0, 1.05, 0.1);
  EXPECT_EQ(c.clipHistory(box, mid, 1.0), mid);
  const real4 glint = c.clipHistory(box, real4(200, 200, 200, 0.1), 1.0);
  EXPECT_LE(glint.x, 8.0 * 1.05);
  EXPECT_LE(glint.z, 8.0 * 1.05);
  EXPECT_GT(glint.x, 4.0);
}

}  // namespace
}  // namespace sky::test
