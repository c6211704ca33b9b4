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

// Each level's frame time over `rounds` rounds, round-robin (the first
// round also builds what each level needs and is not counted), so the
// machine's drift falls on all levels alike: the median per level, and in
// `fastest` the fastest (the machine's other load only adds time, so the
// fastest frames give the levels' own relative costs best).
std::vector<double> levelTimes(render::CloudRenderer& r, const std::vector<render::BudgetLevel>& ladder,
                               const weather::WeatherSnapshot& snap, std::uint64_t rounds,
                               std::vector<double>* fastest) {
  std::vector<std::vector<double>> ms(ladder.size());
  for (std::uint64_t round = 0; round < rounds; ++round)
    for (std::size_t level = 0; level < ladder.size(); ++level) {
      EXPECT_TRUE(r.setMarch(ladder[level].march));
      const double t = timedFrame(r, pathFrame(snap, round));
      if (round > 0) ms[level].push_back(t);
    }
  std::vector<double> out;
  fastest->clear();
  for (auto& m : ms) {
    out.push_back(median(m));
    fastest->push_back(*std::min_element(m.begin(), m.end()));
  }
  return out;
}

// The most accurate level whose time fits the budget, else the cheapest.
std::size_t bestFitting(const std::vector<double>& levelMs, double budgetMs) {
  for (std::size_t level = 0; level < levelMs.size(); ++level)
    if (levelMs[level] <= budgetMs) return level;
  return levelMs.size() - 1;
}

// `high` at 320x180: every level's time on the path's first frames (8 each,
// again up to three times, until level 3 is faster than level 1, 20 % apart on
// the bench); the budget halfway between levels 1 and 3; then 40 frames
// under the budget. This machine is shared and its speed drifts by a third
// within a minute (CI once measured level 4 at 85 ms where the calibration
// had put level 3 at 66), so the test does not assume the calibration still
// holds while the budget runs: after each budgeted frame it draws a probe
// frame at a fixed level, and the probes' median over the calibrated time of
// that level (fitted from every level's, below) scales every level's time to
// the machine's speed during the run.
// After 10 frames to settle, the level the frames are drawn at most is the
// most accurate one that fits at that speed or a neighbour (two neighbouring
// levels are 5-10 % apart, less than the noise of separate measurement), and
// the median frame fits (5 % over at most), or, when no level fits at that
// speed, is within 5 % of the cheapest level's time.
// The calibration also checks the ladder's relative costs, which the bench
// measured on its scenes, against this renderer on this path (20 %), from
// each level's fastest of 8 frames: a burst of the machine's other load
// during one level's frames can move a median ratio past that.
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
  ASSERT_GE(ladder->size(), 4u);
  weather::WeatherSnapshot snap;
  snap.layers.push_back(layer(1, 1500, 1000, 0.5, 1.0));

  std::vector<double> levelMs, fastestMs;
  for (int attempt = 0; attempt < 3 && !(levelMs.size() > 3 && levelMs[3] < levelMs[1]); ++attempt)
    levelMs = levelTimes(**r, *ladder, snap, 9, &fastestMs);
  const std::size_t cheapest = ladder->size() - 1;
  const double budgetMs = 0.5 * (levelMs[1] + levelMs[3]);
  std::printf("[ budget   ] levels 0-%zu:", cheapest);
  for (double ms : levelMs) std::printf(" %.1f", ms);
  std::printf(" ms; budget %.1f ms, level %zu fits\n", budgetMs, bestFitting(levelMs, budgetMs));
  ASSERT_LT(levelMs[3], levelMs[1]) << "the ladder's levels must differ in time for the test to mean anything";
  for (std::size_t level = 1; level < ladder->size(); ++level)
    EXPECT_NEAR(fastestMs[level] / fastestMs[0], (*ladder)[level].relativeCost, 0.2 * (*ladder)[level].relativeCost)
        << "level " << level << ": the bench's relative cost does not hold on this path";

  constexpr std::size_t kProbe = 2;
  render::FrameBudget budget(budgetMs, *ladder);
  std::vector<double> held, probes;
  std::map<std::size_t, int> levels;
  for (std::uint64_t i = 0; i < 40; ++i) {
    ASSERT_TRUE((*r)->setMarch(budget.current().march));
    const std::size_t drawnAt = budget.level();
    const double ms = timedFrame(**r, pathFrame(snap, i));
    budget.update(ms);
    ASSERT_TRUE((*r)->setMarch((*ladder)[kProbe].march));
    const double probe = timedFrame(**r, pathFrame(snap, i));
    if (i >= 10) {
      held.push_back(ms);
      probes.push_back(probe);
      ++levels[drawnAt];
    }
  }
  // The probe level's calibrated time from every level's, through the
  // ladder's relative costs (checked above to 20 %): one level's reading can
  // be off by a burst of the machine's other load (CI once read level 2
  // slower than level 1, and scaled by it, put the fitting level two off).
  std::vector<double> perUnitCost;
  for (std::size_t level = 0; level < ladder->size(); ++level)
    perUnitCost.push_back(levelMs[level] / (*ladder)[level].relativeCost);
  const double probeCalibratedMs = median(perUnitCost) * (*ladder)[kProbe].relativeCost;
  const double speed = median(probes) / probeCalibratedMs;
  std::vector<double> duringMs;
  for (double ms : levelMs) duringMs.push_back(ms * speed);
  const std::size_t best = bestFitting(duringMs, budgetMs);
  const double heldMs = median(held);
  const auto most = std::max_element(levels.begin(), levels.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
  std::printf("[ budget   ] held %.1f ms (budget %.1f); level %zu in %d of %zu frames; the machine ran at %.2fx the "
              "calibration's times, where level %zu fits\n",
              heldMs, budgetMs, most->first, most->second, held.size(), speed, best);
  EXPECT_GE(most->first + 1, best);
  EXPECT_LE(most->first, best + 1);
  // When even the cheapest level is over the budget at the run's speed (CI
  // once ran at 1.46x the calibration's times), the frames can only be held
  // near that level's time; otherwise they fit the budget.
  EXPECT_LE(heldMs, 1.05 * std::max(budgetMs, duringMs[best]))
      << "the cheapest level takes " << duringMs[cheapest] << " ms at the run's speed";
}

}  // namespace
}  // namespace sky::test
