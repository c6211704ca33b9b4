// The frame budget's ladder and controller (renderer/core/src/frame_budget.cpp)
// against frame times made up from its own model: k ms per unit of cost,
// the machine's speed, which changes when the scene does.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "sky/render/frame_budget.hpp"

namespace sky::test {
namespace {

render::Preset preset(const char* name) {
  auto p = render::findPreset(name);
  EXPECT_TRUE(p) << name;
  return *p;
}

// Every preset but reference has a ladder (high five levels, medium, low and
// realtime two), its own march first, each cheaper than the one
// before (fewer samples or longer steps, never more light steps, an exit no
// later) and measured to cost less.
TEST(FrameBudget, LaddersGoFromThePresetDown) {
  const std::pair<const char*, std::size_t> expected[] = {{"high", 5}, {"medium", 2}, {"low", 2}, {"realtime", 2}};
  for (const auto& [name, levels] : expected) {
    const render::Preset p = preset(name);
    auto ladder = render::budgetLadder(p);
    ASSERT_TRUE(ladder) << name;
    ASSERT_EQ(ladder->size(), levels) << name;
    EXPECT_EQ((*ladder)[0].name, name);
    EXPECT_EQ((*ladder)[0].march.primarySteps, p.march.primarySteps);
    EXPECT_EQ((*ladder)[0].march.cloudStep_m, p.march.cloudStep_m);
    EXPECT_EQ((*ladder)[0].relativeCost, 1.0);
    for (std::size_t i = 1; i < ladder->size(); ++i) {
      const render::MarchSettings &m = (*ladder)[i].march, &before = (*ladder)[i - 1].march;
      SCOPED_TRACE(std::string(name) + " level " + std::to_string(i));
      EXPECT_TRUE(m.primarySteps < before.primarySteps || m.cloudStep_m > before.cloudStep_m);
      EXPECT_LE(m.lightSteps, before.lightSteps);
      EXPECT_GE(m.minTransmittance, before.minTransmittance);
      EXPECT_LT((*ladder)[i].relativeCost, (*ladder)[i - 1].relativeCost);
      EXPECT_GT((*ladder)[i].expectedPsnr_db, 0.0);
      EXPECT_EQ(m.airTable.azimuths, p.march.airTable.azimuths) << "the renderer's air table stays";
    }
  }
  auto reference = render::budgetLadder(preset("reference"));
  ASSERT_FALSE(reference);
  EXPECT_EQ(reference.error().code, ErrorCode::InvalidArgument);
}

// Frames at k ms per unit of cost, +-4 % of noise: the controller settles
// on the most accurate level whose cost fits (the budget halfway between
// levels 2 and 3), goes cheaper as soon as the scene gets dearer, and dearer
// again when it gets cheaper, once that level fits with 5 % to spare.
TEST(FrameBudget, SettlesOnTheMostAccurateLevelThatFits) {
  auto ladder = render::budgetLadder(preset("high"));
  ASSERT_TRUE(ladder);
  const auto fitting = [&](double k, double target) {
    for (std::size_t i = 0; i < ladder->size(); ++i)
      if (k * (*ladder)[i].relativeCost <= target) return i;
    return ladder->size() - 1;
  };
  const double k0 = 100;
  const double target = k0 * 0.5 * ((*ladder)[2].relativeCost + (*ladder)[3].relativeCost);
  render::FrameBudget budget(target, *ladder);
  double k = k0;
  std::size_t changes = 0, last = budget.level();
  for (int frame = 0; frame < 60; ++frame) {
    if (frame == 20) k = 1.3 * k0;  // a dearer scene
    if (frame == 40) k = k0;        // and back
    const double noise = frame % 2 ? 1.04 : 0.96;
    const std::size_t next = budget.update(k * budget.current().relativeCost * noise);
    if (next != last) ++changes;
    last = next;
    SCOPED_TRACE("frame " + std::to_string(frame));
    if (frame == 19) {
      EXPECT_EQ(budget.level(), 3u);
    }
    if (frame == 39) {
      EXPECT_EQ(budget.level(), fitting(k, target));
    }
    if (frame == 59) {
      EXPECT_GE(budget.level(), fitting(k, target));
      EXPECT_LE(budget.level(), fitting(k, 0.95 * target));
    }
    if (frame >= 5 && frame % 20 >= 5) {
      EXPECT_NEAR(budget.predicted_ms(budget.level()), k * budget.current().relativeCost,
                  0.1 * k * budget.current().relativeCost);
      if (k * (*ladder).back().relativeCost <= target) {
        EXPECT_LE(k * budget.current().relativeCost, target);
      }
    }
  }
  // Settling takes a step or two each time; the noise makes no more.
  EXPECT_LE(changes, 6u);
}

// A frame time that is not a time (0, negative, NaN) teaches nothing.
TEST(FrameBudget, IgnoresFrameTimesThatAreNotTimes) {
  auto ladder = render::budgetLadder(preset("high"));
  ASSERT_TRUE(ladder);
  render::FrameBudget budget(30, *ladder);
  for (double ms : {0.0, -5.0, std::nan(""), double(INFINITY)}) EXPECT_EQ(budget.update(ms), 0u);
  EXPECT_EQ(budget.predicted_ms(0), 0.0);
}

}  // namespace
}  // namespace sky::test
