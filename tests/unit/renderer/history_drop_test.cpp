// Where a change of the weather's tiles shows (history_drop.hpp), and what
// the temporal planner does with it (temporal_plan.hpp):
//  * every pixel whose ray, within the layer, crosses a texel of the
//    weather map that changed is in a marked cell (the mask is
//    conservative), and a change on the left of the view leaves the right
//    edge unmarked;
//  * a change behind the camera marks nothing; one round the camera marks
//    every cell;
//  * the planner keeps the history for a ramp of tiles and marks the
//    cells for one interleave cycle, and redraws whole for a step, for a
//    change it cannot see in tiles, and with regionDrop off.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "atmosphere_tables.hpp"
#include "frame_setup.hpp"
#include "history_drop.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/weather/tiling.hpp"
#include "temporal_plan.hpp"
#include "weather_field_update.hpp"

namespace sky::render {
namespace {

constexpr std::uint32_t kW = 80, kH = 45;
constexpr double kLat = 46.0, kLon = 13.0;

// A cumulus layer (base 1200 m, 1800 m thick, 8 m/s from the west) tiled
// at S2 level 12 for 60 km round the camera, at coverage 0.5 but within
// `radius_m` of (lat, lon), where it is `inside`.
weather::WeatherSnapshot tiled(double lat, double lon, double radius_m, float inside) {
  weather::WeatherSnapshot s;
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1200;
  l.thickness_m = 1800;
  l.coverage = 0.5;
  l.density = 1;
  l.wind.speed_mps = 8;
  l.wind.fromDirection_deg = 270;
  s.layers = {l};
  s.tileLevel = 12;
  for (std::uint64_t cell : weather::coverCap({kLat, kLon, 60000.0}, 12, 100000)) {
    const weather::CellCentre c = weather::cellCentre(cell);
    const bool in = geo::geodesicDistance_m(c.lat_deg, c.lon_deg, lat, lon) <= radius_m;
    s.tiles.push_back({cell, 1, in ? inside : 0.5f, 1.0f});
  }
  return s;
}

struct Scene {
  FrameInputs in;
  RenderSettings settings;
  WeatherFieldUpdater updater;
  WeatherField before;
  WeatherFieldChange change;
  FrameSetup setup;
};

// The camera at 800 m looking north, 8 degrees up; the weather changes from
// `from` to `to` between two frames (`to` read at clock 30 s: drifted 240 m east).
void prepare(Scene& s, const weather::WeatherSnapshot& from, const weather::WeatherSnapshot& to) {
  s.settings.width = kW;
  s.settings.height = kH;
  s.in.camera.position = {kLat, kLon, 800.0};
  s.in.camera.yaw_deg = 0;
  s.in.camera.pitch_deg = 8;
  s.in.sunAzimuth_deg = 150;
  s.in.sunElevation_deg = 45;
  s.in.weatherClock_s = 30;
  const geo::Geodetic anchor = weatherAnchorFor(s.in.camera.position);
  s.updater.update(&from, nullptr, anchor);
  s.before = s.updater.field();
  s.change = s.updater.update(&to, nullptr, anchor);
  s.in.weather = &to;
  s.setup = prepareFrame(s.settings, s.in, s.updater.field(), sharedAtmosphereTables());
}

// Whether pixel (x, y)'s ray, between the layer's base and top within 80 km,
// passes a point where the two maps differ (as the march would read them).
bool rayMeetsChange(const Scene& s, std::uint32_t x, std::uint32_t y) {
  const FrameSetup& f = s.setup;
  const LayerSetup& l = f.layers[0];
  const glm::dvec2 sc((double(x) + 0.5) / f.rasterWidth, (double(y) + 0.5) / f.rasterHeight);
  const glm::dvec2 st(f.frustum.x + sc.x * (f.frustum.y - f.frustum.x), f.frustum.z - sc.y * (f.frustum.z - f.frustum.w));
  const glm::dvec3 dir = glm::normalize(f.camForward + f.camRight * st.x - f.camDown * st.y);
  const double groundRadius = f.r_m - f.hGround_m;
  for (double t = 50; t < 80000; t += 100) {
    const glm::dvec3 p = dir * t;
    const double alt = glm::length(p + glm::dvec3(0, 0, f.r_m)) - groundRadius;
    if (alt < f.hGround_m - l.hBase_m || alt > f.hGround_m - l.hTop_m) continue;
    const glm::dvec3 q = f.camToAnchor * p + f.camInAnchor_m;
    const glm::dvec2 plane = glm::dvec2(q.x, q.y) * (f.anchorRadius_m / q.z) - l.coverageShift_m;
    const glm::dvec3 a = s.before.sample(0, plane.x, plane.y), b = s.updater.field().sample(0, plane.x, plane.y);
    if (std::abs(a.x - b.x) > 0.5 / 255) return true;
  }
  return false;
}

bool marked(const HistoryDrop& d, std::uint32_t x, std::uint32_t y) {
  return d.cells[(y >> kHistoryDropCellShift) * d.cellsX + (x >> kHistoryDropCellShift)] != 0;
}

TEST(HistoryDrop, EveryPixelWhoseRayMeetsTheChangeIsMarked) {
  // A cell of 6 km, 25 km ahead on the left, growing to 0.95.
  Scene s;
  prepare(s, tiled(46.2, 12.85, 6000, 0.5f), tiled(46.2, 12.85, 6000, 0.95f));
  ASSERT_EQ(s.change.kind, WeatherFieldChange::Kind::Tiles);
  ASSERT_FALSE(s.change.dirty.empty());
  EXPECT_EQ(s.change.largestStep, 114u);  // 0.5 -> 0.95: 128 -> 242 of 255
  const HistoryDrop d = historyDrop(s.setup, s.updater.field(), s.change.dirty);
  EXPECT_FALSE(d.everywhere);
  EXPECT_EQ(d.cellsX, (kW + 7) / 8);
  EXPECT_EQ(d.cellsY, (kH + 7) / 8);
  int met = 0;
  for (std::uint32_t y = 0; y < kH; ++y)
    for (std::uint32_t x = 0; x < kW; ++x)
      if (rayMeetsChange(s, x, y)) {
        ++met;
        EXPECT_TRUE(marked(d, x, y)) << "pixel " << x << ", " << y;
      }
  EXPECT_GT(met, 20) << "the change is in view";
  EXPECT_GT(d.marked, 0u);
  EXPECT_LT(d.fraction(), 0.5);
  // The disc lies left of the view's centre line: the right edge's cells stay.
  for (std::uint32_t cy = 0; cy < d.cellsY; ++cy) EXPECT_EQ(d.cells[cy * d.cellsX + d.cellsX - 1], 0u) << cy;
}

TEST(HistoryDrop, BehindTheCameraNothingAndRoundItEverything) {
  Scene behind;
  prepare(behind, tiled(45.8, 13.0, 6000, 0.5f), tiled(45.8, 13.0, 6000, 0.95f));
  ASSERT_EQ(behind.change.kind, WeatherFieldChange::Kind::Tiles);
  const HistoryDrop none = historyDrop(behind.setup, behind.updater.field(), behind.change.dirty);
  EXPECT_EQ(none.marked, 0u);
  EXPECT_FALSE(none.everywhere);

  Scene round;
  prepare(round, tiled(kLat, kLon, 5000, 0.5f), tiled(kLat, kLon, 5000, 0.6f));
  const HistoryDrop all = historyDrop(round.setup, round.updater.field(), round.change.dirty);
  EXPECT_TRUE(all.everywhere);
  EXPECT_EQ(all.marked, all.cells.size());
}

TEST(TemporalPlanner, AChangeOfTilesKeepsTheHistoryWhereItDoesNotShow) {
  TemporalSettings t;
  t.interleave = 4;
  const weather::WeatherSnapshot base = tiled(46.2, 12.85, 6000, 0.5f);
  const weather::WeatherSnapshot ramp = tiled(46.2, 12.85, 6000, 0.52f);  // 5 steps: a ramp
  const weather::WeatherSnapshot step = tiled(46.2, 12.85, 6000, 0.95f);
  const weather::WeatherSnapshot round = tiled(kLat, kLon, 5000, 0.52f);
  auto planAfter = [&](const weather::WeatherSnapshot& to, TemporalSettings settings, bool withEdit) {
    Scene s;
    prepare(s, base, to);
    TemporalPlanner planner(settings);
    FrameInputs first = s.in;
    first.weather = &base;
    planner.plan(s.setup, first);
    planner.plan(s.setup, first);  // a history
    WeatherEdit edit;
    edit.field = &s.updater.field();
    if (withEdit) edit.rects = s.change.dirty;
    edit.largestStep = s.change.largestStep;
    return planner.plan(s.setup, s.in, edit);
  };
  const TemporalPlan a = planAfter(ramp, t, true);
  EXPECT_FALSE(a.drawWhole) << a.reason;
  EXPECT_GT(a.drop.marked, 0u);
  EXPECT_EQ(a.params.drop, gpu::uvec4(a.drop.cellsX, a.drop.cellsY, kHistoryDropCellShift, 1u));
  const TemporalPlan b = planAfter(step, t, true);  // a step, on a few cells of the view
  EXPECT_TRUE(b.drawWhole);
  EXPECT_EQ(b.reason, "weather changed");
  EXPECT_TRUE(b.drop.cells.empty());
  EXPECT_EQ(b.params.drop.w, 0u);
  const TemporalPlan c = planAfter(round, t, true);  // a ramp round the camera: every cell
  EXPECT_FALSE(c.drawWhole) << c.reason;
  EXPECT_EQ(c.drop.marked, c.drop.cells.size());
  const TemporalPlan d = planAfter(ramp, t, false);  // the map's change is not known
  EXPECT_TRUE(d.drawWhole);
  EXPECT_EQ(d.reason, "weather changed");
  TemporalSettings off = t;
  off.regionDrop = false;
  EXPECT_EQ(planAfter(ramp, off, true).reason, "weather changed");
  // The marks stay for a cycle of n^2 frames (each pixel is redrawn once a
  // cycle: until then its history shows the old weather), then go.
  {
    Scene r;
    prepare(r, base, ramp);
    TemporalPlanner planner(t);
    FrameInputs first = r.in;
    first.weather = &base;
    WeatherEdit none;
    none.field = &r.updater.field();
    none.rects.emplace();
    planner.plan(r.setup, first, none);
    planner.plan(r.setup, first, none);
    WeatherEdit edit = none;
    edit.rects = r.change.dirty;
    edit.largestStep = r.change.largestStep;
    const std::uint32_t marked = planner.plan(r.setup, r.in, edit).drop.marked;
    EXPECT_GT(marked, 0u);
    for (int f = 1; f < 16; ++f) EXPECT_EQ(planner.plan(r.setup, r.in, none).drop.marked, marked) << "frame " << f;
    EXPECT_TRUE(planner.plan(r.setup, r.in, none).drop.cells.empty()) << "a cycle on";
  }
  // The same weather again: nothing marked.
  Scene s;
  prepare(s, base, base);
  TemporalPlanner planner(t);
  planner.plan(s.setup, s.in);
  WeatherEdit unchanged;
  unchanged.field = &s.updater.field();
  unchanged.rects.emplace();
  const TemporalPlan e = planner.plan(s.setup, s.in, unchanged);
  EXPECT_FALSE(e.drawWhole);
  EXPECT_TRUE(e.drop.cells.empty());
}

}  // namespace
}  // namespace sky::render
