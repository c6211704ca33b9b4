// When the sun map's cascades are rebuilt (renderer/core/src/sun_map_plan.hpp):
// each cascade when the camera moved a quarter of its extent from it, so in
// a flight the fine cascade is rebuilt often and the coarse ones 4x less
// often per cascade; every cascade when the clouds drift, the sun turns or
// the tiles change; the whole map at once on a jump. A rebuild is spread over buildFrames frames into
// the other slot of the cascades it rebuilds, and the frames read each
// cascade around the camera where it was built.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "frame_setup.hpp"
#include "sun_map_plan.hpp"

namespace sky::test {
namespace {

using render::FrameSetup;
using render::SunMapPlan;
using render::SunMapPlanner;

constexpr double kExtent_m = 4000;   // cascade 0's half extent
constexpr std::uint32_t kSize = 128;  // half a texel of cascade 0: 31.25 m
constexpr double kWind_mps = 10;

// A camera 2 km under a cumulus layer at (0, 0, 0) of an ECEF frame whose
// local axes are ECEF's (the planner only takes differences), the sun 30
// degrees up in the east, a 4-cascade deep map built over 4 frames.
FrameSetup setupAt(const glm::dvec3& camera_m) {
  FrameSetup s;
  s.cameraEcef_m = camera_m;
  s.localToEcef = glm::dmat3(1.0);
  s.hGround_m = 500;
  s.sunDir = glm::normalize(glm::dvec3(std::cos(0.5236), 0, std::sin(0.5236)));
  s.march.sunShadow = {render::SunShadow::Deep, kSize, 4, kExtent_m, 16, 4};
  render::LayerSetup l;
  l.hBase_m = -1500;
  l.hTop_m = -2500;
  l.windEnu_mps = glm::dvec3(kWind_mps, 0, 0);
  l.windAtCamera_mps = l.windEnu_mps;
  s.layers.push_back(l);
  return s;
}

struct Planner {
  SunMapPlanner planner;
  double clock_s = 0;
  std::uint64_t uploads = 1;
  SunMapPlan plan(const FrameSetup& s, bool jumped = false) { return planner.plan(s, clock_s, uploads, jumped); }
  // Frames until the rebuild under way completes; returns the last plan.
  SunMapPlan finish(const FrameSetup& s) {
    SunMapPlan p;
    for (int k = 0; k < 16; ++k) {
      p = plan(s);
      if (p.completes || !p.builds()) return p;
    }
    return p;
  }
};

// The first frame builds every cascade at once, all around the camera;
// a still frame then builds nothing.
TEST(SunMapPlan, TheFirstFrameBuildsEveryCascadeAtOnce) {
  Planner p;
  const FrameSetup s = setupAt({0, 0, 0});
  const SunMapPlan first = p.plan(s);
  EXPECT_EQ(first.reason, "first frame");
  EXPECT_TRUE(first.completes);
  EXPECT_EQ(first.frame.firstCascade, 0u);
  EXPECT_EQ(first.frame.endCascade, 4u);
  EXPECT_EQ(first.frame.rowEnd, kSize);
  EXPECT_EQ(first.frame.buildSlots, first.frame.readSlots) << "nothing to read: built where it is read";
  const SunMapPlan still = p.plan(s);
  EXPECT_FALSE(still.builds());
  EXPECT_TRUE(still.reason.empty());
}

// The camera 1.5 km on: past a quarter of cascade 0's half extent (1 km),
// within cascade 1's (4 km). Only cascade 0 is rebuilt, over 4 frames into
// its other slot; cascades 1-3 are read around the camera's old place.
TEST(SunMapPlan, ACameraThatMovesRebuildsOnlyTheCascadesItLeft) {
  Planner p;
  p.plan(setupAt({0, 0, 0}));
  const FrameSetup moved = setupAt({1500, 0, 0});
  for (std::uint32_t k = 0; k < 4; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    const SunMapPlan plan = p.plan(moved);
    EXPECT_EQ(plan.reason, "camera moved");
    EXPECT_EQ(plan.frame.firstCascade, 0u);
    EXPECT_EQ(plan.frame.endCascade, 1u);
    EXPECT_EQ(plan.frame.rowBegin, 32 * k);
    EXPECT_EQ(plan.frame.rowEnd, 32 * (k + 1));
    EXPECT_EQ(plan.frame.buildSlots, 1u) << "cascade 0 into its other slot";
    EXPECT_EQ(plan.frame.readSlots, k == 3 ? 1u : 0u) << "read from the new slot once built";
    EXPECT_NEAR(plan.frame.build.origin.x, 0.0, 1e-9) << "built around the camera";
    for (const glm::dvec3& o : plan.frame.readOrigins) EXPECT_NEAR(o.x, -1500.0, 1e-9) << "cascades 1-3 stay";
    EXPECT_EQ(plan.completes, k == 3);
    if (k < 3) EXPECT_NEAR(plan.frame.read.origin.x, -1500.0, 1e-9) << "the old cascade 0 until the new is built";
    else EXPECT_NEAR(plan.frame.read.origin.x, 0.0, 1e-9) << "the new cascade 0 from its last band on";
  }
  const SunMapPlan after = p.plan(moved);
  EXPECT_FALSE(after.builds());
  EXPECT_EQ(after.frame.readSlots, 1u) << "cascade 0 swapped slots, 1-3 did not";
  EXPECT_NEAR(after.frame.read.origin.x, 0.0, 1e-9);
  EXPECT_NEAR(after.frame.readOrigins[0].x, -1500.0, 1e-9);

  // 4.5 km from the start: past a quarter of cascade 1's (4 km); cascade 2's
  // quarter is 16 km. Cascade 0 is 3 km from its anchor (within its jump
  // limit, 4 km): cascades 0 and 1.
  const SunMapPlan further = p.finish(setupAt({4500, 0, 0}));
  EXPECT_EQ(further.frame.firstCascade, 0u);
  EXPECT_EQ(further.frame.endCascade, 2u);
  EXPECT_EQ(further.frame.readSlots, 2u) << "cascades 0 and 1 swapped again and once";
}

// Clouds drifting at 10 m/s: every cascade is rebuilt when they moved half
// of cascade 0's texel (31.25 m, 3.1 s): a coarse cascade kept longer would
// jump by more than a frame's motion when rebuilt.
TEST(SunMapPlan, DriftingCloudsRebuildEveryCascadeAtTheFinesPace) {
  Planner p;
  const FrameSetup s = setupAt({0, 0, 0});
  p.plan(s);
  std::uint32_t builds = 0;
  for (int frame = 1; frame <= 200 * 30; ++frame) {
    p.clock_s = frame / 30.0;
    const SunMapPlan plan = p.plan(s);
    ASSERT_FALSE(plan.frame.rowEnd == kSize && plan.frame.rowBegin == 0) << "a steady drift is never a jump";
    if (!plan.completes) continue;
    ++builds;
    EXPECT_EQ(plan.reason, "clouds drifted");
    EXPECT_EQ(plan.frame.firstCascade, 0u);
    EXPECT_EQ(plan.frame.endCascade, 4u);
  }
  // 2000 m of drift: every 31.25 m (+ the frames a build takes).
  EXPECT_GE(builds, 55u);
  EXPECT_LE(builds, 64u);
}

// The key light turning past 0.05 degrees, or tiles changing, move every
// cascade's shadows: all four are rebuilt, spread; the turn takes the new
// sun's axes. A jump (the sun 2 degrees on) builds the whole map at once.
TEST(SunMapPlan, TheSunTurningOrTilesChangingRebuildEveryCascade) {
  Planner p;
  FrameSetup s = setupAt({0, 0, 0});
  p.plan(s);
  ++p.uploads;
  const SunMapPlan tiles = p.plan(s);
  EXPECT_EQ(tiles.reason, "tiles changed");
  EXPECT_EQ(tiles.frame.firstCascade, 0u);
  EXPECT_EQ(tiles.frame.endCascade, 4u);
  EXPECT_FALSE(tiles.completes);
  EXPECT_TRUE(p.finish(s).completes);
  EXPECT_EQ(p.plan(s).frame.readSlots, 15u) << "every cascade swapped";

  const glm::dvec3 oldV = p.plan(s).frame.read.axisV;  // (U is horizontal: the sun turns up in its plane)
  const double e = 0.5236 + 0.1 * 3.14159265 / 180;
  s.sunDir = glm::normalize(glm::dvec3(std::cos(e), 0, std::sin(e)));
  const SunMapPlan turned = p.plan(s);
  EXPECT_EQ(turned.reason, "sun turned");
  EXPECT_EQ(turned.frame.endCascade - turned.frame.firstCascade, 4u);
  EXPECT_GT(glm::length(turned.frame.build.axisV - oldV), 1e-3) << "the new sun's axes";
  const SunMapPlan done = p.finish(s);
  EXPECT_TRUE(done.completes);
  EXPECT_LT(glm::length(done.frame.read.axisV - done.frame.build.axisV), 1e-12) << "read on the new axes";

  s.sunDir = glm::normalize(glm::dvec3(std::cos(e + 0.035), 0, std::sin(e + 0.035)));
  const SunMapPlan jump = p.plan(s);
  EXPECT_EQ(jump.reason, "sun turned");
  EXPECT_TRUE(jump.completes);
  EXPECT_EQ(jump.frame.rowEnd, kSize);
  EXPECT_EQ(jump.frame.endCascade, 4u);
}

// A coarse cascade due while the fine one was rebuilt lately is rebuilt
// without it: the camera walks 17 km in steps of 900 m, so cascade 0 (due
// past 1 km) is rebuilt every other step and cascade 1 (past 4 km) falls due
// on steps where cascade 0 is not.
TEST(SunMapPlan, ACoarseCascadeDueWhileTheFineIsFreshIsRebuiltWithoutIt) {
  Planner p;
  p.plan(setupAt({0, 0, 0}));
  std::uint32_t rebuilds[4] = {0, 0, 0, 0};
  bool coarseAlone = false;
  for (double x = 900; x <= 17000; x += 900) {
    const SunMapPlan last = p.finish(setupAt({x, 0, 0}));
    if (!last.completes) continue;
    EXPECT_EQ(last.reason, "camera moved");
    coarseAlone = coarseAlone || last.frame.firstCascade > 0;
    for (std::uint32_t c = last.frame.firstCascade; c < last.frame.endCascade; ++c) ++rebuilds[c];
  }
  EXPECT_TRUE(coarseAlone);
  EXPECT_EQ(rebuilds[0], 9u) << "every 1800 m";
  EXPECT_EQ(rebuilds[1], 4u) << "at 4.5, 9 and 13.5 km, and at 16.2 between 0 and 2 (a rebuild is a range)";
  EXPECT_EQ(rebuilds[2], 1u) << "at 16.2 km";
  EXPECT_EQ(rebuilds[3], 0u);
}

// A frame without layers builds nothing and keeps what it reads.
TEST(SunMapPlan, AFrameWithoutLayersBuildsNothing) {
  Planner p;
  FrameSetup s = setupAt({0, 0, 0});
  s.layers.clear();
  const SunMapPlan none = p.plan(s);
  EXPECT_FALSE(none.builds());
  EXPECT_TRUE(none.reason.empty());
}

}  // namespace
}  // namespace sky::test
