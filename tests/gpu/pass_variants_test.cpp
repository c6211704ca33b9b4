// The cloud pass's shader variants: built at the first frame that needs
// one, each costs that frame a pipeline compile; a live channel builds them
// all at start (CloudRenderer::buildAllVariants), and then no frame builds
// one, whatever it draws: the flow's crossfade, a flash, one layer or two,
// a clear sky, rain at the camera (the near-precipitation pass). Counted, not timed (the machine is shared); the times are
// printed.
#include <chrono>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "scenes.hpp"
#include "sky/render/cloud_renderer.hpp"

namespace sky::test {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

// Cumulus in a 10 m/s westerly (uniform: no wind field), and a second layer
// above it when `two`.
weather::WeatherSnapshot windy(bool two) {
  weather::WeatherSnapshot s;
  weather::CloudLayer low = layer(1, 1200, 1500, 0.5, 1.0);
  low.wind = {10.0, 270.0, 0.0};
  s.layers.push_back(low);
  if (two) {
    weather::CloudLayer high = layer(2, 4000, 1000, 0.4, 1.0);
    high.type = weather::CloudType::Altocumulus;
    s.layers.push_back(high);
  }
  return s;
}

render::FrameInputs frameAt(const weather::WeatherSnapshot* s, double clock_s) {
  render::FrameInputs in;
  in.camera = pose(46, 13, 800, 0, 10);
  in.weather = s;
  in.weatherClock_s = clock_s;
  in.sunElevation_deg = 40;
  return in;
}

std::unique_ptr<render::CloudRenderer> fresh() {
  render::RenderSettings settings;
  settings.width = 96;
  settings.height = 54;
  auto created = render::CloudRenderer::create(settings);
  if (!created) {
    ADD_FAILURE() << describe(created.error());
    return nullptr;
  }
  return std::move(*created);
}

TEST(PassVariants, AfterBuildingThemAllNoFrameBuildsOne) {
  const weather::WeatherSnapshot one = windy(false), two = windy(true), clear;
  weather::WeatherSnapshot rainy = windy(false);
  weather::CloudLayer rain = layer(3, 0, 1500, 1.0, 0.1);
  rain.type = weather::CloudType::Rain;
  rainy.layers.push_back(rain);
  // Built as needed: the flow's first crossfade (clock 150 s of its 600 s
  // period) builds the wind variant at that frame.
  auto lazy = fresh();
  if (!lazy) return;
  ASSERT_TRUE(lazy->render(frameAt(&one, 0)));
  const std::size_t before = lazy->variantsBuilt();
  auto t = Clock::now();
  ASSERT_TRUE(lazy->render(frameAt(&one, 150)));
  const double crossfadeFirst_ms = msSince(t);
  EXPECT_GT(lazy->variantsBuilt(), before) << "the crossfade needs the wind variant";
  t = Clock::now();
  ASSERT_TRUE(lazy->render(frameAt(&one, 151)));
  std::printf("[ variants ] built as needed: the first crossfade frame %.0f ms, the next %.0f ms\n", crossfadeFirst_ms,
              msSince(t));

  auto eager = fresh();
  if (!eager) return;
  const std::size_t atCreate = eager->variantsBuilt();  // the first, built by create()
  t = Clock::now();
  auto built = eager->buildAllVariants();
  ASSERT_TRUE(built) << describe(built.error());
  std::printf("[ variants ] the other %zu built at start in %.0f ms\n", *built, msSince(t));
  const std::size_t all = atCreate + *built;
  EXPECT_EQ(eager->variantsBuilt(), all);
  EXPECT_GE(*built, 12u) << "the clouds' 12 at least (wind, layers 0/1/2, lightning)";
  weather::LightningFlash flash;
  flash.seed = 7;
  flash.time_s = 300;
  flash.lat_deg = 46.03;
  flash.lon_deg = 13;
  flash.kind = weather::FlashKind::CloudToGround;
  flash.bottom_m = 0;
  flash.top_m = 1500;
  flash.energy_j = 1e9;
  struct Case {
    const char* name;
    render::FrameInputs in;
  };
  std::vector<Case> cases = {{"still phase", frameAt(&one, 0)},       {"crossfade", frameAt(&one, 150)},
                             {"two layers crossfading", frameAt(&two, 450)}, {"clear sky", frameAt(&clear, 10)},
                             {"flash", frameAt(&one, 300.01)},         {"flash in a crossfade", frameAt(&two, 150.01)},
                             {"rain at the camera", frameAt(&rainy, 20)}};
  weather::LightningFlash inCrossfade = flash;
  inCrossfade.time_s = 150;
  const std::vector<weather::LightningFlash> flashAt300{flash}, flashAt150{inCrossfade};
  cases[4].in.flashes = flashAt300;  // FrameInputs holds a span
  cases[5].in.flashes = flashAt150;
  for (const Case& c : cases) {
    t = Clock::now();
    auto im = eager->render(c.in);
    ASSERT_TRUE(im) << c.name << ": " << describe(im.error());
    std::printf("[ variants ] %-24s %.0f ms\n", c.name, msSince(t));
    EXPECT_EQ(eager->variantsBuilt(), all) << c.name << " built a variant";
  }
  EXPECT_GT(eager->lastNearPrecip().streaks, 0u) << "the rain case drew its drops";
  // Building them again builds none.
  auto again = eager->buildAllVariants();
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, 0u);
}

}  // namespace
}  // namespace sky::test
