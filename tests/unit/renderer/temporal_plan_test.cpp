// The interleave order (temporal_plan.hpp): any n^2 consecutive frames draw
// every pixel of a block exactly once, and the order is dispersed (a still
// view fills in evenly, not in a sweep).
#include <cstdlib>
#include <cmath>
#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "temporal_plan.hpp"

namespace sky::render {
namespace {

TEST(InterleavePhase, EveryPixelOncePerCycleFromAnyStart) {
  for (std::uint32_t n : {1u, 2u, 4u})
    for (std::uint32_t start = 0; start < n * n; ++start) {
      std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
      for (std::uint32_t k = start; k < start + n * n; ++k) {
        const glm::uvec2 p = interleavePhase(n, k);
        ASSERT_LT(p.x, n);
        ASSERT_LT(p.y, n);
        seen.insert({p.x, p.y});
      }
      EXPECT_EQ(seen.size(), std::size_t(n) * n) << "n " << n << " start " << start;
    }
}

TEST(InterleavePhase, EachFourFramesOfSixteenCoverEveryQuadrant) {
  // Ordered dispersed: frames 4m .. 4m+3 of the 4x4 cycle draw one pixel in
  // each 2x2 quadrant of the block, so the image fills in evenly.
  for (std::uint32_t m = 0; m < 4; ++m) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> quadrants;
    for (std::uint32_t k = 4 * m; k < 4 * m + 4; ++k) {
      const glm::uvec2 p = interleavePhase(4, k);
      quadrants.insert({p.x / 2, p.y / 2});
    }
    EXPECT_EQ(quadrants.size(), 4u) << "frames " << 4 * m << ".." << 4 * m + 3;
  }
  // And consecutive frames never draw the same or a side-by-side pixel of a block.
  for (std::uint32_t k = 0; k + 1 < 16; ++k) {
    const glm::uvec2 a = interleavePhase(4, k), b = interleavePhase(4, k + 1);
    EXPECT_GE(std::abs(int(a.x) - int(b.x)) + std::abs(int(a.y) - int(b.y)), 2) << k;
  }
}

// Channels of one display pass the host frame as the pattern index: two
// planners that have planned different numbers of frames (a channel started
// later) draw the same pixel of each block with the same step-offset shift
// for the same host frame; without it each follows its own count.
TEST(TemporalPlanner, PatternIndexOverridesTheLocalCount) {
  TemporalSettings t;
  t.interleave = 4;
  t.accumulation = 0.5;
  FrameSetup setup;  // a still camera looking north
  setup.camForward = {0, 1, 0};
  setup.camRight = {1, 0, 0};
  setup.camDown = {0, 0, -1};
  FrameInputs in;
  TemporalPlanner early(t), late(t);
  for (int i = 0; i < 5; ++i) early.plan(setup, in);  // five frames ahead
  late.plan(setup, in);
  for (std::uint64_t hostFrame : {37u, 38u, 55u}) {
    in.patternIndex = hostFrame;
    const TemporalPlan a = early.plan(setup, in), b = late.plan(setup, in);
    ASSERT_FALSE(a.drawWhole || b.drawWhole) << a.reason << b.reason;
    EXPECT_EQ(a.phase, b.phase) << hostFrame;
    EXPECT_EQ(a.phase, interleavePhase(4, std::uint32_t(hostFrame % 16)));
    EXPECT_EQ(a.jitterShift, b.jitterShift) << hostFrame;
  }
  in.patternIndex.reset();
  EXPECT_NE(early.plan(setup, in).phase, late.plan(setup, in).phase);  // 9th and 5th frames: 4 apart
}

// The history's scene key follows FrameInputs::weatherVersion: a layer that
// moved under the same version is not looked at (the version promises the
// same weather), a new version compares the weather and drops the history
// only when the scene changed; without versions every frame compares.
TEST(TemporalPlanner, TheWeatherVersionDecidesWhenTheSceneIsCompared) {
  TemporalSettings t;
  t.interleave = 2;
  FrameSetup setup;
  setup.camForward = {0, 1, 0};
  setup.camRight = {1, 0, 0};
  setup.camDown = {0, 0, -1};
  weather::WeatherSnapshot w;
  weather::CloudLayer l;
  l.id = 1;
  l.base_m = 1000;
  l.thickness_m = 500;
  w.layers = {l};
  FrameInputs in;
  in.weather = &w;
  in.weatherVersion = 1;
  TemporalPlanner planner(t);
  EXPECT_TRUE(planner.plan(setup, in).drawWhole);
  w.layers[0].base_m = 1200;
  EXPECT_FALSE(planner.plan(setup, in).drawWhole) << "same version: not compared";
  in.weatherVersion = 2;
  const TemporalPlan changed = planner.plan(setup, in);
  EXPECT_TRUE(changed.drawWhole);
  EXPECT_EQ(changed.reason, "weather changed");
  in.weatherVersion = 3;  // a new version with the same weather keeps the history
  EXPECT_FALSE(planner.plan(setup, in).drawWhole);
  in.weatherVersion.reset();
  w.layers[0].base_m = 1400;
  EXPECT_EQ(planner.plan(setup, in).reason, "weather changed");
}

// A fast turn (TemporalSettings::denseTurn_px): a frame whose view turned
// more than the threshold in pixels at the image's centre (yaw or roll
// alike) is drawn at interleave 2 with a phase of the 2x2 cycle; slower, or
// with the threshold 0, at the settings' 4; the turn is reported in pixels.
TEST(TemporalPlanner, AFastTurnDrawsOnePixelOfFour) {
  TemporalSettings t;
  t.interleave = 4;
  FrameSetup setup;
  setup.width = 160;
  setup.height = 90;
  setup.frustum = {-std::tan(0.5236) * 16 / 9, std::tan(0.5236) * 16 / 9, std::tan(0.5236), -std::tan(0.5236)};
  const double pixel_deg = 60.0 / 90.0;
  auto look = [&](double yaw_deg, double roll_deg) {
    const double y = yaw_deg * std::acos(-1.0) / 180, r = roll_deg * std::acos(-1.0) / 180;
    setup.camForward = {std::sin(y), std::cos(y), 0};
    const glm::dvec3 right0{std::cos(y), -std::sin(y), 0}, down0{0, 0, -1};
    setup.camRight = std::cos(r) * right0 + std::sin(r) * down0;
    setup.camDown = -std::sin(r) * right0 + std::cos(r) * down0;
  };
  FrameInputs in;
  TemporalPlanner planner(t);
  look(0, 0);
  ASSERT_TRUE(planner.plan(setup, in).drawWhole);
  look(1.5 * pixel_deg, 0);  // 1.5 px
  TemporalPlan p = planner.plan(setup, in);
  EXPECT_EQ(p.interleave, 4u);
  EXPECT_NEAR(p.turned_px, 1.5, 1e-4);
  look(1.5 * pixel_deg + 3 * pixel_deg, 0);  // 3 px of yaw
  p = planner.plan(setup, in);
  EXPECT_EQ(p.interleave, 2u);
  EXPECT_LT(p.phase.x, 2u);
  EXPECT_LT(p.phase.y, 2u);
  EXPECT_EQ(p.params.image.z, 2u);  // the reprojection reads the packed image at n = 2
  look(4.5 * pixel_deg, 2.5 * pixel_deg);  // 2.5 px of roll
  p = planner.plan(setup, in);
  EXPECT_EQ(p.interleave, 2u);
  EXPECT_NEAR(p.turned_px, 2.5, 1e-4);
  t.denseTurn_px = 0;
  TemporalPlanner never(t);
  look(0, 0);
  never.plan(setup, in);
  look(20 * pixel_deg, 0);
  EXPECT_EQ(never.plan(setup, in).interleave, 4u);
}

// Fresh edges (TemporalSettings::freshEdges): after a turn the frame draws
// at every pixel the band at the side the view turned towards, about as
// wide as the view moved there (the turn at the centre, stretched by the
// projection towards the edges); nothing when the view held
// still or with the setting off; and never more than the rows the packed
// image leaves free in the cloud pass's output (a 25 deg yaw bends the
// corners' rows far out: the top and bottom bands share the room).
TEST(TemporalPlanner, WhatCameIntoViewIsDrawnAtEveryPixel) {
  TemporalSettings t;
  t.interleave = 4;
  t.denseTurn_px = 0;
  t.freshEdges = true;
  FrameSetup setup;
  setup.width = 160;
  setup.height = 90;
  setup.rasterWidth = 160;
  setup.rasterHeight = 90;
  const double tanHalf = std::tan(30.0 * std::acos(-1.0) / 180);
  setup.frustum = {-tanHalf * 16 / 9, tanHalf * 16 / 9, tanHalf, -tanHalf};
  const double pixel_deg = 60.0 / 90.0, toRad = std::acos(-1.0) / 180;
  auto look = [&](double yaw_deg, double pitch_deg) {
    const double y = yaw_deg * toRad, p = pitch_deg * toRad;
    setup.camForward = {std::sin(y) * std::cos(p), std::cos(y) * std::cos(p), std::sin(p)};
    setup.camRight = {std::cos(y), -std::sin(y), 0};
    setup.camDown = glm::cross(setup.camForward, setup.camRight);
  };
  FrameInputs in;
  TemporalPlanner planner(t);
  look(0, 0);
  ASSERT_TRUE(planner.plan(setup, in).drawWhole);
  TemporalPlan p = planner.plan(setup, in);
  EXPECT_EQ(p.freshEdges, glm::uvec4(0)) << "a still view";
  EXPECT_EQ(p.freshEdgePixels, 0u);

  look(3 * pixel_deg, 0);  // 3 px to the right at the centre
  p = planner.plan(setup, in);
  ASSERT_FALSE(p.drawWhole);
  EXPECT_EQ(p.freshEdges.x, 0u);
  EXPECT_GE(p.freshEdges.y, 3u);
  EXPECT_LE(p.freshEdges.y, 8u);  // the projection stretches the edge by ~2
  EXPECT_LE(p.freshEdges.z + p.freshEdges.w, 6u);  // the corners' rows bend out a little
  EXPECT_EQ(p.freshEdgePixels, p.freshEdges.y * 90 + (160 - p.freshEdges.y) * (p.freshEdges.z + p.freshEdges.w));
  EXPECT_EQ(p.params.freshEdges, glm::uvec4(p.freshEdges));

  look(3 * pixel_deg, 3 * pixel_deg);  // then 3 px up
  p = planner.plan(setup, in);
  EXPECT_GE(p.freshEdges.z, 3u);
  EXPECT_LE(p.freshEdges.z, 6u);
  EXPECT_EQ(p.freshEdges.w, 0u);
  EXPECT_LE(p.freshEdges.x + p.freshEdges.y, 4u);

  look(3 * pixel_deg + 60 * pixel_deg, 3 * pixel_deg);  // 40 deg: the history is dropped
  EXPECT_TRUE(planner.plan(setup, in).drawWhole);
  look(3 * pixel_deg + 100 * pixel_deg, 3 * pixel_deg);  // 40 px: more than the free rows hold
  p = planner.plan(setup, in);
  ASSERT_FALSE(p.drawWhole) << p.reason;
  const std::uint32_t capacity = 40 * (90 - 23);  // the rows the packed image leaves free
  EXPECT_LE(p.freshEdgePixels, capacity);
  EXPECT_GT(p.freshEdgePixels, capacity - 160);  // what one band's pixel less frees
  EXPECT_GT(p.freshEdges.y, 0u);

  t.freshEdges = false;
  TemporalPlanner off(t);
  look(0, 0);
  off.plan(setup, in);
  look(3 * pixel_deg, 0);
  EXPECT_EQ(off.plan(setup, in).freshEdges, glm::uvec4(0));
}

}  // namespace
}  // namespace sky::render
