// GPU image against the CPU reference (the same model compiled as C++ in
// double precision with emulated texture filtering) at 64x36, for cameras
// below, inside and above a layer, tiled and uniform coverage, with wind,
// tiles blending the layer's type towards another, the march in metres
// with Haggstrom's coverage and density step factors, and the air read from
// the air table or marched per pixel.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/cpu_reference.hpp"
#include "weather_field.hpp"

namespace sky::test {
namespace {

// RMSE over rgb allowed between GPU and CPU, of the displayed value x / (1 +
// x) relative to the reference's mean displayed value (scenes.hpp: linear
// errors are dominated by the few forward-lobe pixels). Float vs double and
// lavapipe's fixed-point filter weights move single samples across the steep
// coverage threshold, and a sun-facing view amplifies that through
// exp(-tau_sun) times the forward phase lobe: measured 0-0.7 % on these
// scenes, so 5 % flags a broken model, not a rounding.
constexpr double kRelativeRmseTolerance = 0.05;
// Difference of mean luminance allowed, relative: a systematic error (a sign,
// a frame, a missing term) moves the mean; per-pixel noise does not. Measured
// below 0.1 % on these scenes.
constexpr double kRelativeMeanTolerance = 0.005;

struct Case {
  const char* name;
  geo::GeodeticPose camera;
  bool tiled;
  double coverage;
  double windSpeed_mps;
  double clock_s;
  // Every other tile blends the cumulus layer towards this type by 0.7.
  weather::CloudType blendType = weather::CloudType::None;
  double density = 1.0;  // the layer's, or its tiles'
  std::optional<render::ViewFrustum> frustum = std::nullopt;  // unset: the settings' symmetric one
  double sunElevation_deg = 40;  // at azimuth 135
  double upperCoverage = 0;      // > 0: a second layer of this coverage at 5-5.6 km, drawn
  double band_m = 0;             // the layer's transition band below and above
};

// Renders each scene on the GPU and the CPU reference and checks the mean
// and the RMSE. A scene may add a second layer of coverage 0 above (absent:
// not marched).
void compareScenes(render::CloudRenderer& r, const render::CpuReference& reference, const std::vector<Case>& scenes,
                   const std::string& prefix, bool emptyLayerAbove) {
  for (const Case& s : scenes) {
    SCOPED_TRACE(prefix + s.name);
    weather::CloudLayer l = layer(1, 1500, 1000, s.coverage, s.density);
    l.wind = {s.windSpeed_mps, 300.0, 0.0};
    l.transitionBand_m = s.band_m;
    weather::WeatherSnapshot snap;
    if (s.tiled) {
      snap = tiledSnapshot(s.camera.position, l, float(s.coverage), float(s.density));
      for (std::size_t i = 0; i < snap.tiles.size(); i += 2) {
        snap.tiles[i].blendType = s.blendType;
        snap.tiles[i].blend = s.blendType == weather::CloudType::None ? 0.0f : 0.7f;
      }
    } else {
      snap.layers.push_back(l);
    }
    if (emptyLayerAbove) snap.layers.push_back(layer(2, 5000, 1000, 0.0, 1.0));
    if (s.upperCoverage > 0) snap.layers.push_back(layer(3, 5000, 600, s.upperCoverage, 1.0));
    render::FrameInputs in;
    in.camera = s.camera;
    in.weather = &snap;
    in.weatherClock_s = s.clock_s;
    in.frustum = s.frustum;
    in.sunElevation_deg = s.sunElevation_deg;
    auto gpu = r.render(in);
    ASSERT_TRUE(gpu) << describe(gpu.error());
    auto cpu = reference.render(in);
    ASSERT_TRUE(cpu) << describe(cpu.error());
    savePng(*gpu, "gpu_" + prefix + s.name);
    savePng(*cpu, "cpu_" + prefix + s.name);
    const Diff d = diff(*gpu, *cpu);
    const double mean = render::computeStats(*cpu).meanLuminance;
    const double meanError = std::abs(render::computeStats(*gpu).meanLuminance - mean) / mean;
    std::printf("[ gpu/cpu  ] %-26s mean %.4f (gpu %+.3f %%) displayed rmse %.2f %% (linear %.2f %%) max %.4f\n",
                (prefix + s.name).c_str(), mean, 100 * meanError, 100 * d.displayedRmse / d.displayedMean,
                100 * d.rmse / mean, d.maxAbs);
    EXPECT_LT(meanError, kRelativeMeanTolerance);
    EXPECT_EQ(render::computeStats(*gpu).nonFinite, 0u);
    EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean);
  }
}

TEST(GpuVsCpu, RmseWithinTolerance) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const std::vector<Case> scenes = {
      {"clear_sky", pose(47, 8, 800, 0, 10), false, 0.0, 0, 0},
      {"below_uniform", pose(47, 8, 800, 30, 25), false, 0.55, 0, 0},
      {"below_tiled_wind", pose(47, 8, 800, 120, 15), true, 0.6, 12, 900},
      {"inside", pose(-33, 151, 2000, 200, 0), false, 0.7, 5, 60},
      {"above", pose(60, -150, 4000, 45, -30), true, 0.5, 0, 0},
      {"far_above_pole", pose(89.99, 0, 10000, 0, -60), true, 0.7, 0, 0},
      {"type_blend_to_cb", pose(47, 8, 800, 60, 20), true, 0.6, 0, 0, weather::CloudType::Cumulonimbus},
      {"type_blend_to_ci", pose(47, 8, 3000, 60, 20), true, 0.6, 0, 0, weather::CloudType::Cirrus},
  };
  compareScenes(r, *reference, scenes, "", false);
}

render::RenderSettings metresSettings();

// A layer with a transition band of 300 m (the cloud fading across it,
// layer_presence.glsl): from inside the lower band looking up, and from the
// upper band looking down on tiles; the march in metres as well (its long
// steps test for cloud with the cheap density, which fades the same).
TEST(GpuVsCpu, TransitionBandWithinTolerance) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  std::vector<Case> scenes = {
      {"band_below", pose(47, 8, 1350, 30, 25), false, 0.7, 0, 0},
      {"band_above_tiled", pose(60, -150, 2650, 45, -30), true, 0.6, 5, 60},
  };
  for (Case& c : scenes) c.band_m = 300;
  compareScenes(r, *reference, scenes, "", false);
  const render::RenderSettings settings = metresSettings();
  auto metres = render::CloudRenderer::create(settings);
  ASSERT_TRUE(metres) << describe(metres.error());
  auto metresReference = render::CpuReference::create(settings);
  ASSERT_TRUE(metresReference) << describe(metresReference.error());
  compareScenes(**metres, *metresReference, scenes, "metres_", false);
}

// The sky and the aerial perspective read from the air table (the default)
// at the extremes of its layout: the sun low (the glow and the reddened
// light along the horizon) and below the horizon at civil twilight, a camera
// at cruise altitude looking at the horizon, and one above the atmosphere
// (rays entering it from above); and the same scenes with the air marched
// per pixel (MarchSettings::airTable off), the reference's way. Within the
// same bounds as the scenes above.
TEST(GpuVsCpu, AirTableAndAirMarchWithinTolerance) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  const std::vector<Case> scenes = {
      {"low_sun_clear", pose(47, 8, 800, 135, 5), false, 0.0, 0, 0, weather::CloudType::None, 1.0, std::nullopt, 3},
      {"twilight_clear", pose(47, 8, 800, 135, 10), false, 0.0, 0, 0, weather::CloudType::None, 1.0, std::nullopt,
       -4},
      {"low_sun_below_tiled", pose(47, 8, 800, 135, 5), true, 0.5, 0, 0, weather::CloudType::None, 1.0,
       std::nullopt, 6},
      {"cruise_horizon", pose(47, 8, 11000, 300, -2), true, 0.5, 0, 0},
      {"above_atmosphere", pose(20, 100, 90000, 0, -50), true, 0.6, 0, 0},
  };
  for (const bool table : {true, false}) {
    render::RenderSettings settings;
    settings.width = 64;
    settings.height = 36;
    settings.march.airTable.enabled = table;
    auto r = render::CloudRenderer::create(settings);
    ASSERT_TRUE(r) << describe(r.error());
    auto reference = render::CpuReference::create(settings);
    ASSERT_TRUE(reference) << describe(reference.error());
    compareScenes(**r, *reference, scenes, table ? "air_table_" : "air_march_", false);
  }
}

// Two layers drawn, each in the other's shadow where it is below (the
// pipeline variant with the layers' shadow on each other, where one layer
// alone has it compiled out): from below both, between them, and above
// both, within the same bounds. From above both the layers must composite
// upper first: the GPU once drew them the other way round (17.8 % RMSE).
TEST(GpuVsCpu, TwoLayersWithinTolerance) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  std::vector<Case> scenes = {
      {"two_layers_below", pose(47, 8, 800, 30, 25), false, 0.55, 0, 0},
      {"two_layers_between", pose(47, 8, 3500, 120, 10), true, 0.6, 0, 0},
      {"two_layers_above", pose(60, -150, 7000, 45, -30), true, 0.5, 0, 0},
      {"two_layers_steep_above", pose(47, 8, 7000, 45, -80), false, 0.5, 0, 0},
  };
  for (Case& c : scenes) c.upperCoverage = 0.6;
  compareScenes(r, *reference, scenes, "", false);
}

// 64x36 with the march in metres: 100 m steps in cloud, 400 m in clear air,
// growing by 0.01 m per m, at most 256 a span; 2 light steps.
render::RenderSettings metresSettings() {
  render::RenderSettings settings;
  settings.width = 64;
  settings.height = 36;
  settings.march.primarySteps = 256;
  settings.march.lightSteps = 2;
  settings.march.cloudStep_m = 100;
  settings.march.emptyStep_m = 400;
  settings.march.stepGrowth = 0.01;
  return settings;
}

// The march in metres (long steps through clear air on the cheap density,
// short ones in cloud, both growing with distance) and an absent second
// layer: the GPU and the CPU reference still agree within the same bounds.
TEST(GpuVsCpu, MarchInMetresWithinTolerance) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  const render::RenderSettings settings = metresSettings();
  auto r = render::CloudRenderer::create(settings);
  ASSERT_TRUE(r) << describe(r.error());
  auto reference = render::CpuReference::create(settings);
  ASSERT_TRUE(reference) << describe(reference.error());
  const std::vector<Case> scenes = {
      {"below_uniform", pose(47, 8, 800, 30, 25), false, 0.55, 0, 0},
      {"below_tiled_wind", pose(47, 8, 800, 120, 15), true, 0.6, 12, 900},
      {"inside", pose(-33, 151, 2000, 200, 0), false, 0.7, 5, 60},
      {"above", pose(60, -150, 4000, 45, -30), true, 0.5, 0, 0},
      {"type_blend_to_cb", pose(47, 8, 800, 60, 20), true, 0.6, 0, 0, weather::CloudType::Cumulonimbus},
  };
  compareScenes(**r, *reference, scenes, "metres_", true);
}

// Step offsets from the blue-noise tile (MarchSettings::blueNoise): the GPU
// and the CPU reference take the same offset for each pixel. Long steps
// (300 m in cloud) make the offset matter: against the reference with the
// hash's offsets the GPU image differs at the march's noise level, against
// the reference with the tile's offsets only at float's.
TEST(GpuVsCpu, BlueNoiseOffsetsAgree) {
  render::RenderSettings settings = metresSettings();
  settings.march.cloudStep_m = 300;
  settings.march.emptyStep_m = 300;
  settings.march.blueNoise = true;
  auto r = render::CloudRenderer::create(settings);
  if (!r && r.error().code == ErrorCode::NoDevice) GTEST_SKIP() << describe(r.error());
  ASSERT_TRUE(r) << describe(r.error());
  auto blue = render::CpuReference::create(settings);
  ASSERT_TRUE(blue) << describe(blue.error());
  render::RenderSettings whiteSettings = settings;
  whiteSettings.march.blueNoise = false;
  auto white = render::CpuReference::create(whiteSettings);
  ASSERT_TRUE(white) << describe(white.error());
  weather::WeatherSnapshot snap;
  snap.layers.push_back(layer(1, 1500, 1000, 0.55, 1.0));
  render::FrameInputs in;
  in.camera = pose(47, 8, 800, 30, 25);
  in.weather = &snap;
  auto gpu = (*r)->render(in);
  ASSERT_TRUE(gpu) << describe(gpu.error());
  auto cpuBlue = blue->render(in);
  auto cpuWhite = white->render(in);
  ASSERT_TRUE(cpuBlue && cpuWhite);
  const Diff same = diff(*gpu, *cpuBlue), other = diff(*gpu, *cpuWhite);
  std::printf("[ gpu/cpu  ] blue noise: displayed rmse %.3f %% against the tile's offsets, %.3f %% against the hash's\n",
              100 * same.displayedRmse / same.displayedMean, 100 * other.displayedRmse / other.displayedMean);
  EXPECT_LT(same.displayedRmse, kRelativeRmseTolerance * same.displayedMean);
  EXPECT_LT(same.displayedRmse, 0.5 * other.displayedRmse);
}

// The march in metres with Haggstrom 2018's step factors (multmin and divmin
// 0.4, his best) on thin, sparse layers, where they change the steps:
// uniform coverage 0.2 and density 0.2 give 0.4 x 0.4^-0.8 = 0.83, coverage
// 0.35 and density 0.6 give 0.58 x 0.6^-0.8 = 0.87, the tiles their fine
// ring's means. The GPU reads the factor from SkyLayer::coverageShift.z, the
// CPU reference from the frame setup; within the same bounds as above.
TEST(GpuVsCpu, StepFactorsWithinTolerance) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  render::RenderSettings settings = metresSettings();
  settings.march.coverageStepMin = 0.4;
  settings.march.densityStepMin = 0.4;
  auto r = render::CloudRenderer::create(settings);
  ASSERT_TRUE(r) << describe(r.error());
  auto reference = render::CpuReference::create(settings);
  ASSERT_TRUE(reference) << describe(reference.error());
  const std::vector<Case> scenes = {
      {"below_sparse_thin", pose(47, 8, 800, 30, 25), false, 0.2, 0, 0, weather::CloudType::None, 0.2},
      {"below_tiled_thin_wind", pose(47, 8, 800, 120, 15), true, 0.5, 12, 900, weather::CloudType::None, 0.3},
      {"above_sparse", pose(60, -150, 4000, 45, -30), false, 0.35, 0, 0, weather::CloudType::None, 0.6},
  };
  compareScenes(**r, *reference, scenes, "factors_", false);
}

// Off-axis frusta (a side channel of a multi-channel display: View
// Definition half-angles not symmetric about the axis), horizontally and
// vertically, one entirely to one side of the axis: the GPU and the CPU
// reference take their rays from the one formula (core_common.glsl,
// cameraRay) and agree within the same bounds as the symmetric views.
TEST(GpuVsCpu, OffAxisFrustumWithinTolerance) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  const render::ViewFrustum rightChannel{-5, 55, 20, -12}, leftHigh{-50, 10, 35, 5};
  std::vector<Case> scenes = {
      {"offaxis_below_uniform", pose(47, 8, 800, 30, 10), false, 0.55, 0, 0},
      {"offaxis_below_tiled_wind", pose(47, 8, 800, 120, 5), true, 0.6, 12, 900},
      {"offaxis_above", pose(60, -150, 4000, 45, -20), true, 0.5, 0, 0},
      {"offaxis_left_high", pose(47, 8, 800, 200, 0), true, 0.6, 0, 0},
  };
  for (std::size_t i = 0; i < scenes.size(); ++i) scenes[i].frustum = i == 3 ? leftHigh : rightChannel;
  compareScenes(r, *reference, scenes, "", false);
}

// The settings' symmetric frustum given explicitly draws the image the
// default draws, bit for bit: one path, no second formula for the default.
TEST(GpuVsCpu, ExplicitSymmetricFrustumIsTheDefault) {
  SKY_RENDERER(r, 64, 36);
  weather::WeatherSnapshot snap = tiledSnapshot(pose(47, 8, 800, 0, 0).position, layer(1, 1500, 1000, 0.6, 1.0),
                                                0.6f, 1.0f);
  render::FrameInputs in;
  in.camera = pose(47, 8, 800, 120, 15);
  in.weather = &snap;
  auto implicit = r.render(in);
  ASSERT_TRUE(implicit) << describe(implicit.error());
  in.frustum = render::symmetricFrustum(r.settings());
  EXPECT_NEAR(in.frustum->up_deg, 30.0, 1e-12);
  EXPECT_NEAR(in.frustum->right_deg, std::atan(std::tan(M_PI / 6) * 64.0 / 36.0) * 180 / M_PI, 1e-12);
  auto explicitly = r.render(in);
  ASSERT_TRUE(explicitly) << describe(explicitly.error());
  ASSERT_EQ(implicit->rgba.size(), explicitly->rgba.size());
  EXPECT_EQ(std::memcmp(implicit->rgba.data(), explicitly->rgba.data(), implicit->rgba.size() * sizeof(float)), 0);
  EXPECT_EQ(implicit->cloudDepth_m, explicitly->cloudDepth_m);
}

// Frusta the renderer refuses: a half-angle not finite or at 89 deg and past,
// left not left of right, down not below up.
TEST(GpuVsCpu, BadFrustaAreRefused) {
  SKY_RENDERER(r, 64, 36);
  render::FrameInputs in;
  in.camera = pose(47, 8, 800, 0, 0);
  for (const render::ViewFrustum f : {render::ViewFrustum{NAN, 30, 30, -30}, render::ViewFrustum{-30, 89, 30, -30},
                                      render::ViewFrustum{30, -30, 30, -30}, render::ViewFrustum{-30, 30, -10, -10}}) {
    in.frustum = f;
    auto image = r.render(in);
    ASSERT_FALSE(image);
    EXPECT_EQ(image.error().code, ErrorCode::InvalidArgument);
  }
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// Every way of shadowing the clouds from the sun (sun_map.glsl): the column
// march and the four maps, each on the GPU against the CPU reference, on a
// scene below, inside (low sun) and above a tiled layer and with two layers
// (the map holds both), within the same bounds. A 64-texel map of two
// cascades with 16 steps keeps the CPU's build quick. Measured: 0.4-0.7 %
// RMSE, the mean within 0.13 %.
TEST(GpuVsCpu, SunShadowMethodsWithinTolerance) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded (renderer_fixture.hpp)
  (void)shared;
  std::vector<Case> scenes = {
      {"below_tiled", pose(47, 8, 800, 135, 20), true, 0.55, 0, 0},
      {"inside_low_sun", pose(47, 8, 2000, 45, 0), true, 0.6, 0, 0, weather::CloudType::None, 1.0, std::nullopt, 8},
      {"above_tiled", pose(47, 8, 5000, 300, -35), true, 0.5, 0, 0},
      {"two_layers", pose(47, 8, 800, 30, 25), false, 0.55, 0, 0},
  };
  scenes.back().upperCoverage = 0.6;
  for (const render::SunShadow method : {render::SunShadow::Column, render::SunShadow::Esm, render::SunShadow::Bsm,
                                         render::SunShadow::Fom, render::SunShadow::Deep}) {
    render::RenderSettings settings;
    settings.width = 64;
    settings.height = 36;
    settings.march.primarySteps = 24;
    // The column marches above every air step too: 4 steps a layer there,
    // and a 32 x 32 x 16 air table, keep the CPU's frame quick.
    settings.march.sunShadow = {method, 64, 2, 4000, method == render::SunShadow::Column ? 4u : 16u};
    settings.march.airTable = {true, 32, 32, 16};
    auto r = render::CloudRenderer::create(settings);
    ASSERT_TRUE(r) << describe(r.error());
    auto reference = render::CpuReference::create(settings);
    ASSERT_TRUE(reference) << describe(reference.error());
    compareScenes(**r, *reference, scenes, std::string(render::sunShadowName(method)) + "_", false);
  }
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

bool hasPass(const render::CloudRenderer& r, const char* pass) {
  for (const auto& t : r.lastPassTimes())
    if (t.pass == pass) return true;
  return false;
}

// The sun map is built once and read by later frames until what it holds
// has moved by more than it resolves (sun_map_plan.hpp): a still frame
// reads it (no map pass, the same image bit for bit); a camera 300 m away
// reads it through its anchor, within the GPU-vs-CPU bounds of a map built
// around the new position (measured: 3.0 % RMSE, mean +1.3 %: the texels
// fall elsewhere on the clouds); the weather clock 10 s on in a 10 m/s wind
// (the clouds 100 m on, past half a texel of 62.5 m), the camera 1.5 km
// away, the sun 1 degree on and new weather each rebuild it, and say why.
TEST(GpuVsCpu, SunMapIsReusedUntilWhatItHoldsMoves) {
  render::RenderSettings settings;
  settings.width = 64;
  settings.height = 36;
  settings.march.primarySteps = 24;
  settings.march.sunShadow = {render::SunShadow::Deep, 64, 2, 4000, 16};
  auto r = render::CloudRenderer::create(settings);
  ASSERT_TRUE(r) << describe(r.error());
  auto reference = render::CpuReference::create(settings);
  ASSERT_TRUE(reference) << describe(reference.error());
  const geo::GeodeticPose camera = pose(47, 8, 800, 135, 20);
  weather::CloudLayer l = layer(1, 1500, 1000, 0.55, 1.0);
  l.wind = {10.0, 300.0, 0.0};
  const weather::WeatherSnapshot snap = tiledSnapshot(camera.position, l, 0.55f, 1.0f);
  render::FrameInputs in;
  in.camera = camera;
  in.weather = &snap;
  in.weatherClock_s = 0;
  in.sunElevation_deg = 30;

  auto frame = [&](const char* what, bool rebuilt, const std::string& reason) -> std::optional<render::Image> {
    SCOPED_TRACE(what);
    auto image = (*r)->render(in);
    EXPECT_TRUE(image) << describe(image.error());
    EXPECT_EQ((*r)->lastSunMap().rebuilt, rebuilt);
    EXPECT_EQ((*r)->lastSunMap().reason, reason);
    EXPECT_EQ(hasPass(**r, "sun-map"), rebuilt) << "the map pass runs only to rebuild";
    if (!image) return std::nullopt;
    return std::move(*image);
  };
  const auto first = frame("first", true, "first frame");
  const auto still = frame("still", false, "");
  ASSERT_TRUE(first && still);
  EXPECT_EQ(first->rgba, still->rgba) << "a still view reads the same map";

  // The camera `metres` on from `start` (north, south, east or west:
  // whichever keeps the weather map's anchor, which a move across its
  // lattice re-anchors, a new weather map that rebuilds the sun map).
  const geo::Geodetic start = in.camera.position;
  auto moveKeepingWeatherAnchor = [&](double metres) {
    for (const auto& [north, east] :
         {std::pair{1.0, 0.0}, std::pair{-1.0, 0.0}, std::pair{0.0, 1.0}, std::pair{0.0, -1.0}}) {
      in.camera.position.lat_deg = start.lat_deg + north * metres / 111200.0;
      in.camera.position.lon_deg = start.lon_deg + east * metres / (111200.0 * std::cos(start.lat_deg * 3.14159265 / 180));
      if (render::sameAnchor(render::weatherAnchorFor(in.camera.position), render::weatherAnchorFor(start))) return;
    }
    FAIL() << "every direction crosses the weather map's anchor lattice";
  };
  // 300 m on: read through the sun map's anchor, against the CPU's map
  // built around the camera there.
  moveKeepingWeatherAnchor(300);
  const auto moved = frame("moved 300 m", false, "");
  auto cpu = reference->render(in);
  ASSERT_TRUE(moved && cpu) << describe(cpu.error());
  const Diff d = diff(*moved, *cpu);
  const double mean = render::computeStats(*cpu).meanLuminance;
  std::printf("[ sun map  ] reused 300 m from its anchor: displayed rmse %.2f %%, mean %+.3f %%\n",
              100 * d.displayedRmse / d.displayedMean,
              100 * (render::computeStats(*moved).meanLuminance - mean) / mean);
  EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean);

  in.weatherClock_s = 10;
  frame("clock 10 s on", true, "clouds drifted");
  moveKeepingWeatherAnchor(1500);
  frame("camera 1.5 km on", true, "camera moved");
  in.sunElevation_deg = 31;
  frame("sun 1 degree on", true, "sun turned");
  const weather::WeatherSnapshot other = tiledSnapshot(camera.position, l, 0.7f, 1.0f);
  in.weather = &other;
  frame("new weather", true, "weather changed");
  frame("still again", false, "");
}


// A rebuild spread over frames (SunMapSettings::buildFrames, sun_map_plan.hpp):
// with 4, the camera 1.5 km on starts a rebuild of the fine cascade (the
// coarse one resolves that move) that is built a quarter of the rows a frame
// while the frames read the old one (within the GPU-vs-CPU bounds of the map
// built at once there: measured 2.1 % RMSE); the fourth frame reads the new
// cascade, the same image as a renderer that built it whole (to float
// rounding of the anchor's axes: measured 0.000 %). A new
// weather map is built whole at once; with tiles changing every frame the
// build is not restarted: it completes every 4 frames. A jump (the sun 2
// degrees on) is built at once.
TEST(GpuVsCpu, SunMapRebuildIsSpreadOverFrames) {
  render::RenderSettings settings;
  settings.width = 64;
  settings.height = 36;
  settings.march.primarySteps = 24;
  settings.march.sunShadow = {render::SunShadow::Deep, 64, 2, 4000, 16, 1};
  auto whole = render::CloudRenderer::create(settings);
  ASSERT_TRUE(whole) << describe(whole.error());
  settings.march.sunShadow.buildFrames = 4;
  auto spread = render::CloudRenderer::create(settings);
  ASSERT_TRUE(spread) << describe(spread.error());
  const geo::GeodeticPose camera = pose(47, 8, 800, 135, 20);
  weather::CloudLayer l = layer(1, 1500, 1000, 0.55, 1.0);
  const weather::WeatherSnapshot snap = tiledSnapshot(camera.position, l, 0.55f, 1.0f);
  render::FrameInputs in;
  in.camera = camera;
  in.weather = &snap;
  in.sunElevation_deg = 30;
  auto draw = [&](render::CloudRenderer& r) {
    auto image = r.render(in);
    EXPECT_TRUE(image) << describe(image.error());
    return image ? std::move(*image) : render::Image{};
  };
  const render::Image firstWhole = draw(**whole), firstSpread = draw(**spread);
  EXPECT_EQ((*spread)->lastSunMap().reason, "first frame");
  EXPECT_TRUE((*spread)->lastSunMap().completed) << "the first map is built at once: there is nothing to read";
  EXPECT_EQ(firstWhole.rgba, firstSpread.rgba);

  // 1.5 km east, within the weather map's anchor cell (a new weather anchor
  // would be a new weather map).
  const geo::Geodetic start = in.camera.position;
  for (const double east : {1.0, -1.0}) {
    in.camera.position.lon_deg = start.lon_deg + east * 1500 / (111200.0 * std::cos(start.lat_deg * 3.14159265 / 180));
    if (render::sameAnchor(render::weatherAnchorFor(in.camera.position), render::weatherAnchorFor(start))) break;
  }
  ASSERT_TRUE(render::sameAnchor(render::weatherAnchorFor(in.camera.position), render::weatherAnchorFor(start)));
  const render::Image movedWhole = draw(**whole);
  EXPECT_EQ((*whole)->lastSunMap().reason, "camera moved");
  EXPECT_TRUE((*whole)->lastSunMap().completed);
  // 1.5 km is past a quarter of cascade 0's half extent (1 km), within
  // cascade 1's (4 km): only cascade 0 is rebuilt. Against a renderer whose
  // first frame is here (both cascades around this camera), cascade 1 read
  // around the old one differs by its bilinear texels' placement only.
  EXPECT_EQ((*whole)->lastSunMap().firstCascade, 0u);
  EXPECT_EQ((*whole)->lastSunMap().endCascade, 1u);
  {
    settings.march.sunShadow.buildFrames = 1;
    auto fresh = render::CloudRenderer::create(settings);
    ASSERT_TRUE(fresh) << describe(fresh.error());
    const Diff d = diff(draw(**fresh), movedWhole);
    std::printf("[ sun map  ] cascade 1 kept 1.5 km away against both built here: rmse %.3f %%\n",
                100 * d.displayedRmse / d.displayedMean);
    EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean);
  }
  for (std::uint32_t k = 0; k < 4; ++k) {
    SCOPED_TRACE("spread frame " + std::to_string(k));
    const render::Image image = draw(**spread);
    const render::SunMapReport& m = (*spread)->lastSunMap();
    EXPECT_TRUE(m.rebuilt);
    EXPECT_EQ(m.reason, "camera moved");
    EXPECT_EQ(m.rowBegin, 16 * k);
    EXPECT_EQ(m.rowEnd, 16 * (k + 1));
    EXPECT_EQ(m.completed, k == 3);
    EXPECT_EQ(m.endCascade, 1u) << "cascade 0 only";
    EXPECT_TRUE(hasPass(**spread, "sun-map"));
    const Diff d = diff(image, movedWhole);
    std::printf("[ sun map  ] spread over 4 frames, frame %u against the map built at once: rmse %.3f %%\n", k,
                100 * d.displayedRmse / d.displayedMean);
    if (k < 3)
      EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean) << "the old map, read through its anchor";
    else
      EXPECT_LT(d.displayedRmse, 1e-4 * d.displayedMean) << "the new map is the one built at once";
  }
  draw(**spread);
  EXPECT_FALSE((*spread)->lastSunMap().rebuilt) << "still: nothing more to build";

  // Tiles changing every frame (a cell ramping up 3 km from the camera):
  // each completed build starts the next, none is restarted half-way.
  std::vector<weather::WeatherSnapshot> ramp;
  for (int k = 0; k <= 8; ++k)
    ramp.push_back(discSnapshot(l, {47.0, 8.0, 0.0}, 30000.0, 47.02, 8.0, 2000.0, 0.55f + 0.04f * float(k), 0.55f));
  in.weather = &ramp[0];
  draw(**spread);
  EXPECT_EQ((*spread)->lastSunMap().reason, "weather changed") << "a new weather map: the whole map at once";
  EXPECT_TRUE((*spread)->lastSunMap().completed);
  std::vector<bool> completed;
  for (std::size_t k = 1; k < ramp.size(); ++k) {
    in.weather = &ramp[k];
    draw(**spread);
    EXPECT_TRUE((*spread)->lastSunMap().rebuilt);
    EXPECT_EQ((*spread)->lastSunMap().reason, "tiles changed");
    EXPECT_EQ((*spread)->lastSunMap().endCascade - (*spread)->lastSunMap().firstCascade, 2u) << "every cascade";
    completed.push_back((*spread)->lastSunMap().completed);
  }
  EXPECT_EQ(completed, (std::vector<bool>{false, false, false, true, false, false, false, true}));

  // A jump (the host sets the sun 2 degrees on) is built at once, even with
  // a build under way.
  in.sunElevation_deg = 32;
  draw(**spread);
  EXPECT_EQ((*spread)->lastSunMap().reason, "sun turned");
  EXPECT_EQ((*spread)->lastSunMap().rowEnd, 64u);
  EXPECT_TRUE((*spread)->lastSunMap().completed);
}

}  // namespace
}  // namespace sky::test

namespace sky::test {
namespace {

// Showers under cumulus (the rain layer's top inside the cumulus, so it
// falls under their cells: cloud_core.glsl's carrierFootprint): from under
// the rain looking at the shafts, from between the cells, and from above
// the deck, within the same bounds. A GPU that read no carrier would draw
// the rain of its own noise, as much again from the clear sky.
TEST(GpuVsCpu, ShowersUnderTheirCumulusWithinTolerance) {
  SKY_RENDERER(r, 64, 36);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  weather::WeatherSnapshot snap;
  weather::CloudLayer cumulus = layer(1, 1500, 1200, 0.4, 1.0);
  weather::CloudLayer rain = layer(2, 0, 1900, 0.4, 0.1);  // 0.1: ~10 mm/h
  rain.type = weather::CloudType::Rain;
  snap.layers = {cumulus, rain};
  const std::pair<const char*, geo::GeodeticPose> views[] = {
      {"showers_below", pose(47, 8, 300, 70, 5)},
      {"showers_up", pose(47, 8, 600, 200, 35)},
      {"showers_above", pose(47, 8, 4000, 10, -25)},
  };
  for (const auto& [name, camera] : views) {
    SCOPED_TRACE(name);
    render::FrameInputs in;
    in.camera = camera;
    in.weather = &snap;
    in.sunElevation_deg = 40;
    auto gpu = r.render(in);
    ASSERT_TRUE(gpu) << describe(gpu.error());
    auto cpu = reference->render(in);
    ASSERT_TRUE(cpu) << describe(cpu.error());
    savePng(*gpu, std::string("gpu_") + name);
    savePng(*cpu, std::string("cpu_") + name);
    const Diff d = diff(*gpu, *cpu);
    const double mean = render::computeStats(*cpu).meanLuminance;
    const double meanError = std::abs(render::computeStats(*gpu).meanLuminance - mean) / mean;
    std::printf("[ gpu/cpu  ] %-26s mean %.4f (gpu %+.3f %%) displayed rmse %.2f %% (linear %.2f %%) max %.4f\n", name,
                mean, 100 * meanError, 100 * d.displayedRmse / d.displayedMean, 100 * d.rmse / mean, d.maxAbs);
    EXPECT_LT(meanError, kRelativeMeanTolerance);
    EXPECT_EQ(render::computeStats(*gpu).nonFinite, 0u);
    EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean);
  }
}

}  // namespace
}  // namespace sky::test
