// The frame budget with the real renderer over a replayed camera path
// (renderer/core/src/frame_budget.cpp): every frame is drawn at the level
// the controller picked, and the controller is told the time that level
// took on this path as recorded, times the machine's speed of the moment,
// not the frame's wall-clock time, so what it picks does not depend on the
// machine's other load. That the frames then hold within 20 % of the budget
// in real time is a speed claim, measured by tests/bench/frame_budget_bench.cpp
// (sky_frame_budget_bench), never asserted by a test.
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/frame_budget.hpp"

namespace sky::test {
namespace {

// Each level of high's ladder on the path below at 320x180, ms: the medians
// of 8 round-robin frames recorded with
//   LP_NUM_THREADS=1 sky_frame_budget_bench --width 320 --height 180
// (Release, 2-core AMD EPYC VM, lavapipe, 2026-12-06); level 5
// (realtime/1.5 at full size, added since) as 0.93 of low/1.5's, its ratio
// in a run of the same command on 2026-12-07 (158.9 against 170.7 ms, with
// a test suite running beside it). Their shape is this path's, not the
// ladder's (measured on the bench's scenes): the controller learns the
// machine's speed from frames, through the ladder.
constexpr std::array<double, 8> kRecordedLevel_ms = {172.56, 76.70, 66.88, 53.38, 47.40, 44.08, 22.76, 13.16};

// The machine's speed over the replay, a phase of kPhaseFrames frames each:
// as recorded, then 1.3x slower (CI has run at up to 1.46x a calibration's
// times: then no level fits), then faster (the preset's own level fits),
// then as recorded again.
constexpr std::array<double, 4> kSpeeds = {1.0, 1.3, 0.75, 1.0};
constexpr std::size_t kPhaseFrames = 25;
// Frames a phase is given to settle before its frames are checked: the
// controller's mean speed follows a change with weight 1/4 a frame.
constexpr std::size_t kSettleFrames = 10;
// Frame-to-frame noise on the recorded times, alternately up and down: more
// than the controller's 5 % margin for moving to a dearer level would let
// two levels alternate, so 3 %.
constexpr double kNoise = 0.03;

// The path's weather: half-covered cumulus, base 1500 m, 1000 m thick.
weather::WeatherSnapshot halfCumulus() {
  weather::WeatherSnapshot snap;
  snap.layers.push_back(layer(1, 1500, 1000, 0.5, 1.0));
  return snap;
}

// The replayed path: east at 800 m under half-covered cumulus, turning 3
// degrees a frame, looking 12 degrees up (the bench's path).
render::FrameInputs pathFrame(const weather::WeatherSnapshot& snap, std::uint64_t i) {
  render::FrameInputs in;
  in.camera = pose(46.0, 13.0 + 2e-4 * double(i), 800, 30 + 3.0 * double(i), 12);
  in.weather = &snap;
  in.weatherClock_s = double(i) / 30.0;
  in.frameIndex = i;
  return in;
}

// The most accurate level whose recorded time at `speed` fits budgetMs,
// else the cheapest.
std::size_t fitting(double speed, double budgetMs) {
  for (std::size_t level = 0; level < kRecordedLevel_ms.size(); ++level)
    if (speed * kRecordedLevel_ms[level] <= budgetMs) return level;
  return kRecordedLevel_ms.size() - 1;
}

bool allFinite(const render::Image& image) {
  for (float v : image.rgba)
    if (!std::isfinite(v)) return false;
  return true;
}

// The budget halfway between levels 1 and 2's recorded times. In each phase,
// after it settles, every frame is drawn at the most accurate level that
// fits at that phase's speed (a dearer one only when it fits with the
// controller's 5 % to spare), and its time fits the budget unless no level
// does, and stays there (two levels next to the budget do not alternate).
// A slower machine moves it to a cheaper level within two frames, but no
// cheaper than the level that fits with 5 % to spare; a faster
// one back within the phase's settling. Each level's march renders (finite
// pixels), and level 0 and the cheapest draw different images: the march
// the controller picks is the one drawn.
TEST(FrameBudget, HoldsABudgetBetweenTwoLevelsOverAReplay) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  auto preset = render::findPreset("high");
  ASSERT_TRUE(preset);
  auto ladder = render::budgetLadder(*preset);
  ASSERT_TRUE(ladder);
  ASSERT_EQ(ladder->size(), kRecordedLevel_ms.size()) << "record the levels' times again (see kRecordedLevel_ms)";
  // The times are recorded; the images only need to be drawn: 64x36.
  render::RenderSettings settings;
  settings.width = 64;
  settings.height = 36;
  settings.march = preset->march;
  auto r = render::CloudRenderer::create(settings);
  ASSERT_TRUE(r) << describe(r.error());
  const weather::WeatherSnapshot snap = halfCumulus();

  const double budgetMs = 0.5 * (kRecordedLevel_ms[1] + kRecordedLevel_ms[2]);
  const std::size_t cheapest = ladder->size() - 1;
  ASSERT_EQ(fitting(1.0, budgetMs), 2u) << "the recorded times must put level 2 under the budget";
  render::FrameBudget budget(budgetMs, *ladder);
  std::vector<std::size_t> drawnAt;
  for (std::size_t phase = 0; phase < kSpeeds.size(); ++phase) {
    const double speed = kSpeeds[phase];
    const std::size_t best = fitting(speed, budgetMs), bestWithSpare = fitting(speed, 0.95 * budgetMs);
    std::printf("[ budget   ] phase %zu: %.2fx the recorded times, budget %.2f ms, level %zu fits (%zu with 5 %% to "
                "spare):",
                phase, speed, budgetMs, best, bestWithSpare);
    for (std::size_t k = 0; k < kPhaseFrames; ++k) {
      const std::uint64_t i = phase * kPhaseFrames + k;
      const std::size_t level = budget.level();
      drawnAt.push_back(level);
      std::printf(" %zu", level);
      ASSERT_TRUE((*r)->setLevel(budget.current().march, budget.current().temporal, budget.current().resolution)) << (*ladder)[level].name;
      auto image = (*r)->render(pathFrame(snap, i));
      ASSERT_TRUE(image) << describe(image.error());
      EXPECT_TRUE(allFinite(*image)) << "frame " << i << " at " << (*ladder)[level].name;
      const double noise = i % 2 ? 1 + kNoise : 1 - kNoise;
      const std::size_t next = budget.update(kRecordedLevel_ms[level] * speed * noise);
      // Cheaper only as far as it must: at most to the level that fits
      // with 5 % to spare (the ladder's costs are not this path's, so the
      // controller's own prediction may stop it short of that).
      if (next > level) {
        EXPECT_LE(next, bestWithSpare) << "after frame " << i << " it went cheaper than it had to";
      }
      if (k < kSettleFrames) continue;
      SCOPED_TRACE("frame " + std::to_string(i) + ", phase " + std::to_string(phase));
      if (k > kSettleFrames) {
        EXPECT_EQ(level, drawnAt[drawnAt.size() - 2]) << "settled frames stay at one level";
      }
      EXPECT_GE(level, best) << "drawn at a level that does not fit";
      EXPECT_LE(level, bestWithSpare) << "a dearer level fits with 5 % to spare";
      if (speed * kRecordedLevel_ms[cheapest] <= budgetMs) {
        EXPECT_LE(speed * kRecordedLevel_ms[level], budgetMs);
      }
    }
    std::printf("\n");
  }
  // The first frame of the slower phase is 30 % over, but moves the mean
  // speed by a quarter of that (under the 10 % that moves at once): the
  // frame after the second is cheaper.
  EXPECT_GT(drawnAt[kPhaseFrames + 2], drawnAt[kPhaseFrames - 1]);
  // Back at the recorded speed, back at the recorded speed's level.
  EXPECT_EQ(drawnAt.back(), drawnAt[kPhaseFrames - 1]);

  // The same frame at the preset's level and at the cheapest.
  std::vector<std::vector<float>> drawn;
  for (const render::BudgetLevel* level : {&ladder->front(), &ladder->back()}) {
    ASSERT_TRUE((*r)->setLevel(level->march, level->temporal, level->resolution));
    auto image = (*r)->render(pathFrame(snap, 0));
    ASSERT_TRUE(image) << describe(image.error());
    drawn.push_back(image->rgba);
  }
  EXPECT_NE(drawn[0], drawn[1]) << "the cheapest level's march draws the same image as the preset's";
}


render::Preset presetNamed(const char* name) {
  auto p = render::findPreset(name);
  EXPECT_TRUE(p) << name;
  return *p;
}

const render::BudgetLevel& levelNamed(const std::vector<render::BudgetLevel>& ladder, const char* name) {
  for (const render::BudgetLevel& level : ladder)
    if (level.name == name) return level;
  ADD_FAILURE() << "no level " << name;
  return ladder.front();
}

// A renderer of 96x54 built with high's march, every pixel drawn (the
// ladder's levels change the rest); null with the test failed.
std::unique_ptr<render::CloudRenderer> highRenderer(const render::Preset& high) {
  render::RenderSettings settings;
  settings.width = 96;
  settings.height = 54;
  settings.march = high.march;
  auto r = render::CloudRenderer::create(settings);
  if (!r) {
    ADD_FAILURE() << describe(r.error());
    return nullptr;
  }
  return std::move(*r);
}

// From high's way of drawing (every pixel) to medium's (1 pixel of 16, the
// rest reprojected, redraws accumulated) on a still view, against a
// renderer built with medium's interleave from the start that changes only
// its march: the history carries over from the image the last frame drew
// whole, so the interleaved frames are those of a renderer that had its
// own history all along (a history of zeros, or none, would not be).
// Through every pixel and back again the same: each change of level
// carries the last image over.
TEST(FrameBudget, ALevelWithAHistoryCarriesTheLastImageOver) {
  SKY_RENDERER(shared, 64, 36);
  (void)shared;
  const render::Preset high = presetNamed("high");
  auto ladder = render::budgetLadder(high);
  ASSERT_TRUE(ladder);
  const render::BudgetLevel& medium = levelNamed(*ladder, "medium");
  ASSERT_EQ(medium.temporal.interleave, 4u);
  ASSERT_EQ(medium.march.airTable.azimuths, high.march.airTable.azimuths);
  auto r = highRenderer(high);
  ASSERT_TRUE(r);
  render::RenderSettings interleaved = r->settings();
  interleaved.temporal = medium.temporal;
  auto own = render::CloudRenderer::create(interleaved);
  ASSERT_TRUE(own) << describe(own.error());
  const weather::WeatherSnapshot snap = halfCumulus();
  const render::FrameInputs still = pathFrame(snap, 0);

  ASSERT_TRUE(r->setLevel(high.march, high.temporal, high.resolution));
  auto whole = r->render(still);
  auto ownWhole = (*own)->render(still);
  ASSERT_TRUE(whole && ownWhole);
  EXPECT_TRUE((*own)->lastTemporal().drawnWhole);
  Diff d = diff(*whole, *ownWhole);
  EXPECT_LT(d.displayedRmse, 1e-5 * d.displayedMean) << "both drew high's march whole";
  EXPECT_GT(d.displayedMean, 0.01) << "an image with something in it";
  ASSERT_TRUE(r->setLevel(medium.march, medium.temporal, medium.resolution));
  ASSERT_TRUE((*own)->setMarch(medium.march));
  for (int frame = 0; frame < 3; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    auto image = r->render(still);
    auto expected = (*own)->render(still);
    ASSERT_TRUE(image && expected);
    const render::TemporalReport& t = r->lastTemporal();
    EXPECT_FALSE(t.drawnWhole) << t.reason;
    EXPECT_EQ(t.interleave, 4u);
    EXPECT_GT(t.reused, 10 * t.drawn);
    EXPECT_EQ(t.reused, (*own)->lastTemporal().reused);
    d = diff(*image, *expected);
    EXPECT_LT(d.displayedRmse, 1e-5 * d.displayedMean);
  }
  // Every pixel once more, then medium's again: its history is that frame.
  ASSERT_TRUE(r->setLevel(high.march, high.temporal, high.resolution));
  ASSERT_TRUE(r->render(still));
  ASSERT_TRUE(r->setLevel(medium.march, medium.temporal, medium.resolution));
  ASSERT_TRUE(r->render(still));
  EXPECT_FALSE(r->lastTemporal().drawnWhole) << r->lastTemporal().reason;
  EXPECT_GT(r->lastTemporal().reused, 10 * r->lastTemporal().drawn);
}

// A level drawn at another size (realtime's way at half size, from high's
// full): its history is the last full image boxed down, so its first frame
// is not drawn whole and is near the frame a renderer built with that
// level draws first (drawn whole), where a history of zeros would not be.
// Back up to full size the upscaled image carries over as the history.
// The level's air table is realtime's own, smaller than high's: the
// renderer's table takes its size. Levels the renderer cannot draw are
// refused and change nothing: more pixels than it was built for, no air
// table.
TEST(FrameBudget, ALevelAtAnotherSizeTakesTheLastImageResized) {
  SKY_RENDERER(shared, 64, 36);
  (void)shared;
  const render::Preset high = presetNamed("high");
  auto ladder = render::budgetLadder(high);
  ASSERT_TRUE(ladder);
  const render::BudgetLevel& realtime = ladder->back();  // realtime's way at half size
  ASSERT_EQ(realtime.resolution.divisor, 2u);
  ASSERT_LT(realtime.march.airTable.azimuths, high.march.airTable.azimuths);
  auto r = highRenderer(high);
  ASSERT_TRUE(r);
  const weather::WeatherSnapshot snap = halfCumulus();
  const render::FrameInputs still = pathFrame(snap, 0);
  ASSERT_TRUE(r->setLevel(high.march, high.temporal, high.resolution));
  ASSERT_TRUE(r->render(still));
  ASSERT_TRUE(r->setLevel(realtime.march, realtime.temporal, realtime.resolution));
  auto first = r->render(still);
  ASSERT_TRUE(first) << describe(first.error());
  EXPECT_FALSE(r->lastTemporal().drawnWhole) << r->lastTemporal().reason;
  EXPECT_GT(r->lastTemporal().reused, 10 * r->lastTemporal().drawn);
  EXPECT_EQ(first->width, 96u);
  EXPECT_EQ(first->height, 54u);

  render::RenderSettings built = r->settings();
  auto direct = render::CloudRenderer::create(built);
  ASSERT_TRUE(direct) << describe(direct.error());
  auto expected = (*direct)->render(still);
  ASSERT_TRUE(expected) << describe(expected.error());
  EXPECT_TRUE((*direct)->lastTemporal().drawnWhole);
  const Diff down = diff(*first, *expected);
  EXPECT_LT(down.displayedRmse, 0.15 * down.displayedMean);
  std::printf("[ budget   ] down to half size: RMSE %.4g of the mean\n", down.displayedRmse / down.displayedMean);
  auto second = r->render(still);
  ASSERT_TRUE(second) << describe(second.error());
  EXPECT_FALSE(r->lastTemporal().drawnWhole) << r->lastTemporal().reason;

  // Back up to full size (low's way, interleaved): the upscaled image is
  // the history, so the frame is not drawn whole and shows what the last
  // one did, but for low's 1 pixel of 16 drawn into it.
  const render::BudgetLevel& low = levelNamed(*ladder, "low");
  ASSERT_EQ(low.resolution.divisor, 1u);
  ASSERT_TRUE(r->setLevel(low.march, low.temporal, low.resolution));
  auto up = r->render(still);
  ASSERT_TRUE(up) << describe(up.error());
  EXPECT_FALSE(r->lastTemporal().drawnWhole) << r->lastTemporal().reason;
  EXPECT_GT(r->lastTemporal().reused, 10 * r->lastTemporal().drawn);
  const Diff carried = diff(*up, *second);
  EXPECT_LT(carried.displayedRmse, 0.1 * carried.displayedMean);
  std::printf("[ budget   ] up to full size: RMSE %.4g of the mean\n", carried.displayedRmse / carried.displayedMean);
  // And down again: the half-size way boxes this image down in turn (its
  // downsample bound to a new source).
  ASSERT_TRUE(r->setLevel(realtime.march, realtime.temporal, realtime.resolution));
  auto again = r->render(still);
  ASSERT_TRUE(again) << describe(again.error());
  EXPECT_FALSE(r->lastTemporal().drawnWhole) << r->lastTemporal().reason;
  const Diff downAgain = diff(*again, *expected);
  EXPECT_LT(downAgain.displayedRmse, 0.15 * downAgain.displayedMean);

  // Built at half size: a level at full size draws more pixels than its
  // cloud pass holds.
  auto refused = (*direct)->setLevel(high.march, realtime.temporal, high.resolution);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::InvalidArgument);
  EXPECT_NE(refused.error().detail.find("divisor"), std::string::npos) << refused.error().detail;
  EXPECT_EQ((*direct)->settings().resolution.divisor, 2u);
  render::MarchSettings noTable = realtime.march;
  noTable.airTable.enabled = false;
  EXPECT_FALSE((*direct)->setLevel(noTable, realtime.temporal, realtime.resolution));
  EXPECT_TRUE((*direct)->settings().march.airTable.enabled);
  EXPECT_TRUE((*direct)->render(still));
}

}  // namespace
}  // namespace sky::test
