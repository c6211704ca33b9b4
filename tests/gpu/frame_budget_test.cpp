// The frame budget with the real renderer (renderer/core/src/frame_budget.cpp):
// over a replayed camera path, a budget set between two levels' measured
// times holds the frames near it, at the most accurate level that fits.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/frame_budget.hpp"

namespace sky::test {
namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The replayed path: east at 800 m under half-covered cumulus, turning 3
// degrees a frame, looking 12 degrees up.
render::FrameInputs pathFrame(const weather::WeatherSnapshot& snap, std::uint64_t i) {
  render::FrameInputs in;
  in.camera = pose(46.0, 13.0 + 2e-4 * double(i), 800, 30 + 3.0 * double(i), 12);
  in.weather = &snap;
  in.weatherClock_s = double(i) / 30.0;
  in.frameIndex = i;
  return in;
}

double timedFrame(render::CloudRenderer& r, const render::FrameInputs& in) {
  const auto t0 = std::chrono::steady_clock::now();
  auto image = r.render(in);
  EXPECT_TRUE(image) << describe(image.error());
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// `high` at 320x180: each level's time on the path's first frames, the
// budget three quarters of the way from level 2's time to level 1's (so
// level 2 is the most accurate that fits, with more than the controller's
// 5 % to spare), then 40 frames under the budget. After 10 frames to
// settle, the median frame is within 20 % of the budget, and the level the
// frames are drawn at most is 2.
TEST(FrameBudget, HoldsABudgetBetweenTwoLevelsOverAReplay) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  auto preset = render::findPreset("high");
  ASSERT_TRUE(preset);
  render::RenderSettings settings;
  settings.width = 320;
  settings.height = 180;
  settings.march = preset->march;
  auto r = render::CloudRenderer::create(settings);
  ASSERT_TRUE(r) << describe(r.error());
  auto ladder = render::budgetLadder(*preset);
  ASSERT_TRUE(ladder);
  weather::WeatherSnapshot snap;
  snap.layers.push_back(layer(1, 1500, 1000, 0.5, 1.0));

  std::vector<double> levelMs;
  for (std::size_t level = 0; level < 3; ++level) {
    ASSERT_TRUE((*r)->setMarch((*ladder)[level].march));
    std::vector<double> ms;
    for (std::uint64_t i = 0; i < 5; ++i) ms.push_back(timedFrame(**r, pathFrame(snap, i)));
    ms.erase(ms.begin());  // the first frame after a change of march also builds what it needs
    levelMs.push_back(median(ms));
  }
  const double budgetMs = levelMs[2] + 0.75 * (levelMs[1] - levelMs[2]);
  std::printf("[ budget   ] levels 0-2 %.1f / %.1f / %.1f ms; budget %.1f ms\n", levelMs[0], levelMs[1], levelMs[2],
              budgetMs);
  ASSERT_LT(levelMs[2], levelMs[1]) << "the ladder's levels must differ in time for the test to mean anything";

  render::FrameBudget budget(budgetMs, *ladder);
  std::size_t applied = 99;
  std::vector<double> held;
  std::map<std::size_t, int> levels;
  for (std::uint64_t i = 0; i < 40; ++i) {
    if (budget.level() != applied) {
      ASSERT_TRUE((*r)->setMarch(budget.current().march));
      applied = budget.level();
    }
    const std::size_t drawnAt = budget.level();
    const double ms = timedFrame(**r, pathFrame(snap, i));
    budget.update(ms);
    if (i >= 10) {
      held.push_back(ms);
      ++levels[drawnAt];
    }
  }
  const double heldMs = median(held);
  const auto most = std::max_element(levels.begin(), levels.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  std::printf("[ budget   ] held %.1f ms (budget %.1f); level %zu in %d of %zu frames\n", heldMs, budgetMs, most->first,
              most->second, held.size());
  EXPECT_NEAR(heldMs, budgetMs, 0.2 * budgetMs);
  EXPECT_EQ(most->first, 2u);
}

}  // namespace
}  // namespace sky::test
