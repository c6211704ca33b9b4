// Precipitation near the camera on the GPU (renderer/core/src/
// near_precip_pass.cpp, shaders/near_precip*.comp): a renderer whose camera
// is in rain draws, over the image the same renderer draws without the
// drops, exactly the streaks the CPU lists for that frame (near_precip.cpp),
// composited here with the same coverage (precip_streak.glsl compiled as
// C++) and the drops' radiance (the image's mean times the type's factor);
// with interleaving, the streaks never reach the history; a dry frame runs
// no pass and is unchanged.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "atmosphere_tables.hpp"
#include "frame_setup.hpp"
#include "near_precip.hpp"
#include "precip_streak.hpp"
#include "scenes.hpp"
#include "sky/render/cloud_renderer.hpp"
#include "sky/render/presets.hpp"
#include "sky/weather/precipitation.hpp"
#include "weather_field_update.hpp"

namespace sky::test {
namespace {

using Streak = render::PrecipStreak;

constexpr std::uint32_t kW = 320, kH = 180;
constexpr double kRate_mmph = 8;

// Rain of 8 mm/h from the ground into a stratus deck at 1200-1800 m.
weather::WeatherSnapshot rainUnderADeck() {
  weather::WeatherSnapshot s;
  weather::CloudLayer deck = layer(1, 1200, 600, 1.0, 0.6);
  deck.type = weather::CloudType::Stratus;
  weather::CloudLayer rain = layer(2, 0, 1500, 1.0, weather::precipitationDensityForRate(weather::CloudType::Rain,
                                                                                         kRate_mmph));
  rain.type = weather::CloudType::Rain;
  s.layers = {deck, rain};
  return s;
}

// Frame i of a camera flying north at 30 m/s at 300 m, looking level, with
// a 30 Hz clock.
render::FrameInputs frameAt(const weather::WeatherSnapshot* snap, int i) {
  render::FrameInputs in;
  in.camera = pose(46.0 + 30.0 / 30.0 * i / 111195.0, 13.0, 300, 0, 0);
  in.weather = snap;
  in.weatherVersion = 1;
  in.weatherClock_s = 600 + i / 30.0;
  in.sunElevation_deg = 35;
  in.frameIndex = std::uint64_t(i);
  return in;
}

struct Pair {
  std::unique_ptr<render::CloudRenderer> wet, dry;
  render::RenderSettings settings;
  std::string skip;
};

Pair makePair(const char* preset) {
  Pair p;
  p.settings.width = kW;
  p.settings.height = kH;
  const auto found = render::findPreset(preset);
  EXPECT_TRUE(found);
  p.settings.march = found->march;
  p.settings.temporal = found->temporal;
  p.settings.resolution = found->resolution;
  for (bool near : {true, false}) {
    render::RenderSettings s = p.settings;
    s.march.nearPrecipitation = near;
    auto r = render::CloudRenderer::create(s);
    if (!r) {
      if (r.error().code == ErrorCode::NoDevice) p.skip = describe(r.error());
      else ADD_FAILURE() << describe(r.error());
      return p;
    }
    (near ? p.wet : p.dry) = std::move(*r);
  }
  return p;
}

// The wet frame as this test composes it: the dry image with the CPU's
// streaks for the frame over it, each pixel covered by the streaks of its
// tile, in the drops' radiance (the dry image's mean times the factor).
std::vector<float> composed(const render::Image& dry, const render::NearPrecipFrame& near) {
  double mean[3] = {0, 0, 0};
  const std::size_t n = std::size_t(dry.width) * dry.height;
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) mean[c] += dry.rgba[4 * i + c] / double(n);
  std::vector<float> out = dry.rgba;
  for (std::uint32_t y = 0; y < dry.height; ++y)
    for (std::uint32_t x = 0; x < dry.width; ++x) {
      const glm::uvec2 range =
          near.tiles[(y / gpu::kNearPrecipTile) * near.tilesX + x / gpu::kNearPrecipTile];
      double open = 1;
      for (std::uint32_t e = range.x; e < range.x + range.y; ++e) {
        const gpu::SkyStreak& s = near.streaks[near.entries[e]];
        open *= 1 - Streak{}.streakCoverageAlong(glm::dvec2(x + 0.5, y + 0.5), glm::dvec2(s.path.x, s.path.y),
                                                 glm::dvec2(s.path.z, s.path.w), s.shape.x, s.shape.y);
      }
      const std::size_t o = 4 * (std::size_t(y) * dry.width + x);
      for (int c = 0; c < 3; ++c)
        out[o + c] = float(dry.rgba[o + c] * open + near.population.radianceFactor * mean[c] * (1 - open));
    }
  return out;
}

// What the renderer lists for a frame: the renderer's own source of inputs
// and frame setup, fed the frames the renderer was fed (so it has the same
// camera history).
struct Lister {
  render::RenderSettings settings;
  render::NearPrecipSource source;
  render::WeatherFieldUpdater updater;
  render::NearPrecipFrame next(const render::FrameInputs& in) {
    updater.update(in.weather, nullptr, render::weatherAnchorFor(in.camera.position));
    const render::FrameSetup setup =
        render::prepareFrame(settings, in, updater.field(), render::sharedAtmosphereTables());
    return render::buildNearPrecip(source.inputs(settings, in, setup));
  }
};

void expectComposed(const render::Image& wet, const render::Image& dry, const render::NearPrecipFrame& near,
                    const std::string& what) {
  const std::vector<float> want = composed(dry, near);
  std::size_t changed = 0, off = 0;
  double worst = 0;
  for (std::size_t i = 0; i < want.size(); ++i) {
    if (i % 4 == 3) {
      EXPECT_EQ(wet.rgba[i], dry.rgba[i]) << "the drops leave the clouds' transmittance alone";
      continue;
    }
    // The shader's mean is of a 64 x 64 grid of pixels, this test's of all
    // of them: the drops' radiance differs by that, times their coverage.
    const double err = std::abs(double(wet.rgba[i]) - want[i]);
    const double drawn = std::abs(double(want[i]) - dry.rgba[i]);
    worst = std::max(worst, err);
    off += err > 0.05 * drawn + 1e-5 ? 1 : 0;
    changed += std::abs(double(wet.rgba[i]) - dry.rgba[i]) > 1e-5 ? 1 : 0;
  }
  std::printf("[ near     ] %s: %zu streaks, %zu channel values changed, largest difference from the CPU's %.2e\n",
              what.c_str(), near.streaks.size(), changed, worst);
  EXPECT_EQ(off, 0u) << what;
  EXPECT_GT(changed, 200u) << what << ": the streaks must show";
}

TEST(NearPrecipGpu, DrawsTheStreaksTheCpuListsOverTheDryImage) {
  Pair p = makePair("high");
  if (!p.skip.empty()) GTEST_SKIP() << p.skip;
  ASSERT_TRUE(p.wet && p.dry);
  const weather::WeatherSnapshot snap = rainUnderADeck();
  Lister lister{p.settings, {}, {}};
  for (int i = 0; i < 2; ++i) {
    const render::FrameInputs in = frameAt(&snap, i);
    auto wet = p.wet->render(in);
    auto dry = p.dry->render(in);
    ASSERT_TRUE(wet && dry);
    const render::NearPrecipFrame near = lister.next(in);
    const render::NearPrecipReport& report = p.wet->lastNearPrecip();
    EXPECT_EQ(report.type, weather::CloudType::Rain);
    EXPECT_NEAR(report.rate_mmph, kRate_mmph, 0.15 * kRate_mmph) << "the density is quantised on the stream";
    EXPECT_EQ(report.streaks, near.streaks.size());
    EXPECT_NEAR(report.cameraSpeed_mps, i == 0 ? 0.0 : 30.0, 0.1) << "frame " << i;
    const bool timed = std::any_of(p.wet->lastPassTimes().begin(), p.wet->lastPassTimes().end(),
                                   [](const render::PassTime& t) { return t.pass == "near-precip"; });
    EXPECT_TRUE(timed || p.wet->lastPassTimes().empty());
    expectComposed(*wet, *dry, near, "frame " + std::to_string(i) + (i == 0 ? " (still)" : " (30 m/s north)"));
  }
}

TEST(NearPrecipGpu, TheHistoryNeverHoldsTheDrops) {
  // medium interleaves: each frame draws 1 pixel of 16 and takes the rest
  // from the history. Were the streaks in it, the wet frames would carry
  // the last frames' streaks as well as their own.
  Pair p = makePair("medium");
  if (!p.skip.empty()) GTEST_SKIP() << p.skip;
  ASSERT_TRUE(p.wet && p.dry);
  ASSERT_GT(p.settings.temporal.interleave, 1u);
  const weather::WeatherSnapshot snap = rainUnderADeck();
  Lister lister{p.settings, {}, {}};
  for (int i = 0; i < 4; ++i) {
    const render::FrameInputs in = frameAt(&snap, i);
    auto wet = p.wet->render(in);
    auto dry = p.dry->render(in);
    ASSERT_TRUE(wet && dry);
    const render::NearPrecipFrame near = lister.next(in);
    if (i == 0) continue;
    EXPECT_FALSE(p.wet->lastTemporal().drawnWhole) << "frame " << i << " reuses the history";
    expectComposed(*wet, *dry, near, "interleaved frame " + std::to_string(i));
  }
}

TEST(NearPrecipGpu, ADryFrameRunsNoPassAndIsUnchanged) {
  Pair p = makePair("high");
  if (!p.skip.empty()) GTEST_SKIP() << p.skip;
  ASSERT_TRUE(p.wet && p.dry);
  weather::WeatherSnapshot snap = rainUnderADeck();
  snap.layers.pop_back();
  const render::FrameInputs in = frameAt(&snap, 0);
  auto wet = p.wet->render(in);
  auto dry = p.dry->render(in);
  ASSERT_TRUE(wet && dry);
  EXPECT_EQ(p.wet->lastNearPrecip().type, weather::CloudType::None);
  for (const auto& t : p.wet->lastPassTimes()) EXPECT_NE(t.pass, "near-precip");
  EXPECT_EQ(wet->rgba, dry->rgba);
}

// A frame budget's change of level (CloudRenderer::setLevel) carries the
// last image over as the new level's history, except after a frame that drew
// drops near the camera over it: the history would keep them. Then the next
// frame is drawn whole.
TEST(NearPrecipGpu, AChangeOfLevelAfterDropsDrawsWhole) {
  auto high = render::findPreset("high");
  auto medium = render::findPreset("medium");
  ASSERT_TRUE(high && medium);
  render::RenderSettings settings;
  settings.width = 160;
  settings.height = 90;
  settings.march = high->march;
  auto r = render::CloudRenderer::create(settings);
  if (!r && r.error().code == ErrorCode::NoDevice) GTEST_SKIP() << describe(r.error());
  ASSERT_TRUE(r) << describe(r.error());
  const weather::WeatherSnapshot snap = rainUnderADeck();
  render::MarchSettings mediumMarch = medium->march;
  mediumMarch.sunShadow = high->march.sunShadow;  // the renderer's map
  ASSERT_TRUE((*r)->setLevel(high->march, high->temporal, high->resolution));
  ASSERT_TRUE((*r)->render(frameAt(&snap, 0)));
  ASSERT_GT((*r)->lastNearPrecip().streaks, 0u) << "the frame drew drops near the camera";
  ASSERT_TRUE((*r)->setLevel(mediumMarch, medium->temporal, medium->resolution));
  ASSERT_TRUE((*r)->render(frameAt(&snap, 1)));
  EXPECT_TRUE((*r)->lastTemporal().drawnWhole);
  EXPECT_EQ((*r)->lastTemporal().reason, "drawn another way, after drops near the camera");
  // Within one level the history never holds the drops (the copy is taken
  // before they are drawn): the next frame reuses it.
  ASSERT_TRUE((*r)->render(frameAt(&snap, 2)));
  EXPECT_FALSE((*r)->lastTemporal().drawnWhole) << (*r)->lastTemporal().reason;
}

}  // namespace
}  // namespace sky::test
