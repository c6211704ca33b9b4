// The frame budget's ladder and controller (renderer/core/src/frame_budget.cpp)
// against frame times made up from its own model: k ms per unit of cost,
// the machine's speed, which changes when the scene does.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "sky/render/frame_budget.hpp"

namespace sky::test {
namespace {

render::Preset preset(const char* name) {
  auto p = render::findPreset(name);
  EXPECT_TRUE(p) << name;
  return *p;
}

// The preset's name a level's name starts with ("medium/1.5" -> "medium").
std::string wayOf(const std::string& level) { return level.substr(0, level.find_first_of("/ ")); }

// Every preset but reference has a ladder: its own way of drawing first,
// then cheaper marches of it, then the cheaper presets' ways (their march,
// interleave and resolution divisor); each level measured to cost less and
// to be less accurate than the one before (so the first that fits is the
// most accurate that fits). Within one way, each march is cheaper than the
// one before (fewer samples or longer steps, never more light steps, an
// exit no later). Every level keeps the preset's air table and sun map
// (the renderer is built with them) and draws no more pixels than it.
TEST(FrameBudget, LaddersGoFromThePresetDown) {
  const std::pair<const char*, std::size_t> expected[] = {{"high", 8}, {"medium", 7}, {"low", 5}, {"realtime", 2}};
  for (const auto& [name, levels] : expected) {
    const render::Preset p = preset(name);
    auto ladder = render::budgetLadder(p);
    ASSERT_TRUE(ladder) << name;
    ASSERT_EQ(ladder->size(), levels) << name;
    const render::BudgetLevel& first = (*ladder)[0];
    EXPECT_EQ(first.name, name);
    EXPECT_EQ(first.march.primarySteps, p.march.primarySteps);
    EXPECT_EQ(first.march.cloudStep_m, p.march.cloudStep_m);
    EXPECT_EQ(first.temporal.interleave, p.temporal.interleave);
    EXPECT_EQ(first.temporal.accumulation, p.temporal.accumulation);
    EXPECT_EQ(first.resolution.divisor, p.resolution.divisor);
    EXPECT_EQ(first.relativeCost, 1.0);
    for (std::size_t i = 1; i < ladder->size(); ++i) {
      const render::BudgetLevel &level = (*ladder)[i], &before = (*ladder)[i - 1];
      const render::MarchSettings &m = level.march, &mb = before.march;
      SCOPED_TRACE(std::string(name) + " level " + std::to_string(i) + " (" + level.name + ")");
      EXPECT_LT(level.relativeCost, before.relativeCost);
      EXPECT_LT(level.expectedPsnr_db, before.expectedPsnr_db);
      EXPECT_GT(level.expectedPsnr_db, 0.0);
      EXPECT_EQ(m.airTable.enabled, p.march.airTable.enabled) << "the renderer has an air table or not";
      EXPECT_EQ(m.sunShadow.method, p.march.sunShadow.method) << "the renderer's sun map stays";
      EXPECT_EQ(m.sunShadow.size, p.march.sunShadow.size);
      EXPECT_EQ(level.resolution.divisor % p.resolution.divisor, 0u) << "no more pixels than the preset's";
      EXPECT_GE(level.resolution.divisor, before.resolution.divisor);
      EXPECT_GE(level.temporal.interleave, before.temporal.interleave);
      auto way = render::findPreset(wayOf(level.name));
      ASSERT_TRUE(way) << "a level is a preset's way of drawing";
      EXPECT_EQ(level.temporal.interleave, way->temporal.interleave);
      EXPECT_EQ(level.temporal.accumulation, way->temporal.accumulation);
      EXPECT_EQ(m.airTable.azimuths, way->march.airTable.azimuths) << "the way's air table";
      EXPECT_EQ(m.airTable.slices, way->march.airTable.slices);
      // A level drawn at another size than its way's says which.
      const std::uint32_t d = level.resolution.divisor;
      if (d != way->resolution.divisor)
        EXPECT_NE(level.name.find(d == 1 ? " at full size" : " at 1/" + std::to_string(d) + " size"), std::string::npos);
      else
        EXPECT_EQ(level.name.find(" at "), std::string::npos);
      if (wayOf(level.name) == wayOf(before.name) && level.resolution.divisor == before.resolution.divisor) {
        EXPECT_TRUE(m.primarySteps < mb.primarySteps || m.cloudStep_m > mb.cloudStep_m);
        EXPECT_LE(m.lightSteps, mb.lightSteps);
        EXPECT_GE(m.minTransmittance, mb.minTransmittance);
      }
    }
  }
  auto reference = render::budgetLadder(preset("reference"));
  ASSERT_FALSE(reference);
  EXPECT_EQ(reference.error().code, ErrorCode::InvalidArgument);
}

// Frames at k ms per unit of cost, +-4 % of noise: the controller settles
// on the most accurate level whose cost fits (the budget halfway between
// levels 1 and 2), goes cheaper as soon as the scene gets dearer, and dearer
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
  const double target = k0 * 0.5 * ((*ladder)[1].relativeCost + (*ladder)[2].relativeCost);
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
      EXPECT_EQ(budget.level(), 2u);
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
  // Nor does a frame that is not its level's cost (timesLevel: an
  // interleaved level's frame drawn whole, several times its cost).
  EXPECT_EQ(budget.update(10), 0u);
  EXPECT_EQ(budget.update(1000, false), 0u);
  EXPECT_DOUBLE_EQ(budget.predicted_ms(0), 10.0);
}

// An interleaved level's frame drawn whole does not time the level; every
// other frame does.
TEST(FrameBudget, AFrameDrawnWholeDoesNotTimeAnInterleavedLevel) {
  auto ladder = render::budgetLadder(preset("high"));
  ASSERT_TRUE(ladder);
  render::TemporalReport whole, interleaved;
  whole.drawnWhole = true;
  for (const render::BudgetLevel& level : *ladder) {
    EXPECT_TRUE(render::timesLevel(level, interleaved)) << level.name;
    EXPECT_EQ(render::timesLevel(level, whole), level.temporal.interleave == 1) << level.name;
  }
}

}  // namespace
}  // namespace sky::test
