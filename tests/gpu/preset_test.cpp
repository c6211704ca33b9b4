// The quality presets on the GPU (lavapipe): for a uniform stratus deck seen
// from below, thin and thick, each preset's image stays within a stated
// distance of the `reference` preset's (mean view-ray transmittance, mean
// luminance), and an unknown march setting is refused at create().
#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/render/presets.hpp"

namespace sky::test {
namespace {

struct Means {
  double transmittance = 0, luminance = 0;
};

Means means(const render::Image& im) {
  Means m;
  for (std::size_t i = 3; i < im.rgba.size(); i += 4) m.transmittance += im.rgba[i];
  m.transmittance /= double(im.rgba.size() / 4);
  m.luminance = render::computeStats(im).meanLuminance;
  return m;
}

// Bounds against reference, every preset. Measured (64x36, lavapipe): thin
// deck T 0.4399 reference, realtime +0.005, luminance +0.2 %; thick deck T
// 0.021 reference, each preset within its early-exit threshold (realtime
// 0.046), luminance within 2.8 % (realtime -2.8 %, high -0.7 %: the presets'
// deep shadow map against reference's 64-step column; the thick deck follows
// the thin one as a step of the weather, so every map is rebuilt at once).
constexpr double kThinTransmittanceBound = 0.01;  // mean transmittance, thin deck
constexpr double kLuminanceBound = 0.03;          // mean luminance, relative

TEST(Presets, UniformDeckCloseToReferenceForEveryPreset) {
  SKY_RENDERER(shared, 64, 36);  // keeps the driver loaded while these come and go (renderer_fixture.hpp)
  (void)shared;
  render::FrameInputs in;
  in.camera = pose(47.0, 8.0, 500.0, 0.0, 45.0);
  // Thin: coverage 1, density 0.05 (tau about 1-3 along these rays); thick:
  // the 1 km stratus deck of the overcast test.
  weather::CloudLayer deck = layer(1, 1500, 1000, 0, 1);
  deck.type = weather::CloudType::Stratus;
  const weather::WeatherSnapshot thin = tiledSnapshot(in.camera.position, deck, 1.0f, 0.05f);
  const weather::WeatherSnapshot thick = tiledSnapshot(in.camera.position, deck, 1.0f, 1.0f);
  std::vector<Means> thinMeans, thickMeans;
  for (const render::Preset& p : render::presets()) {
    render::RenderSettings settings;
    settings.width = 64;
    settings.height = 36;
    settings.march = p.march;
    auto r = render::CloudRenderer::create(settings);
    ASSERT_TRUE(r) << describe(r.error());
    in.weather = &thin;
    auto a = (*r)->render(in);
    ASSERT_TRUE(a) << describe(a.error());
    in.weather = &thick;
    auto b = (*r)->render(in);
    ASSERT_TRUE(b) << describe(b.error());
    EXPECT_EQ(render::computeStats(*a).nonFinite + render::computeStats(*b).nonFinite, 0u) << p.name;
    thinMeans.push_back(means(*a));
    thickMeans.push_back(means(*b));
    std::printf("%-9s thin T %.4f L %.5g   thick T %.5f L %.5g\n", p.name.c_str(), thinMeans.back().transmittance,
                thinMeans.back().luminance, thickMeans.back().transmittance, thickMeans.back().luminance);
  }
  const Means& refThin = thinMeans[0];
  const Means& refThick = thickMeans[0];
  ASSERT_GT(refThin.transmittance, 0.05) << "the thin deck lets light through";
  ASSERT_LT(refThin.transmittance, 0.9) << "the thin deck is there";
  for (std::size_t i = 1; i < thinMeans.size(); ++i) {
    const std::string& name = render::presets()[i].name;
    EXPECT_NEAR(thinMeans[i].transmittance, refThin.transmittance, kThinTransmittanceBound) << name;
    EXPECT_NEAR(thinMeans[i].luminance / refThin.luminance, 1.0, kLuminanceBound) << name;
    // The early exit may leave up to its threshold of the background.
    const double exitBound = std::max(0.005, render::presets()[i].march.minTransmittance);
    EXPECT_NEAR(thickMeans[i].transmittance, refThick.transmittance, exitBound) << name;
    EXPECT_NEAR(thickMeans[i].luminance / refThick.luminance, 1.0, kLuminanceBound) << name;
  }
}

// Settings the renderer must refuse, with an InvalidArgument naming `what`.
void expectRefusedNaming(const render::RenderSettings& settings, const std::string& what) {
  auto r = render::CloudRenderer::create(settings);
  ASSERT_FALSE(r) << what;
  EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument) << what;
  EXPECT_NE(r.error().detail.find(what), std::string::npos) << r.error().detail;
}

TEST(Presets, BadMarchSettingsAreRefused) {
  render::RenderSettings settings;
  settings.width = 16;
  settings.height = 16;
  settings.march.primarySteps = 0;
  expectRefusedNaming(settings, "primarySteps");
  settings.march.primarySteps = 48;
  settings.march.minTransmittance = 1.0;
  expectRefusedNaming(settings, "minTransmittance");
  settings.march.minTransmittance = 0.01;
  // The sun map: a size the map pass's 8x8 groups do not tile, too many
  // cascades, an unknown method, and the column's 1024-step limit.
  for (auto bad : {render::SunMapSettings{render::SunShadow::Deep, 100}, render::SunMapSettings{render::SunShadow::Bsm, 128, 5},
                   render::SunMapSettings{render::SunShadow(6)}}) {
    settings.march.sunShadow = bad;
    expectRefusedNaming(settings, "sunShadow");
  }
  settings.march.sunShadow = {render::SunShadow::Column};
  settings.march.lightSteps = 1025;
  expectRefusedNaming(settings, "lightSteps");
  // On lavapipe, a column march past its loop budget (256 x 1000 nested
  // steps; 256 x 64 is within it).
  settings.march.primarySteps = 256;
  settings.march.lightSteps = 1000;
  expectRefusedNaming(settings, "65535");
  settings.march.lightSteps = 64;
  EXPECT_TRUE(render::CloudRenderer::create(settings));
  settings.march.primarySteps = 48;
  settings.march.sunShadow = {render::SunShadow::March};
  settings.march.lightSteps = 65;
  EXPECT_FALSE(render::CloudRenderer::create(settings)) << "65 light steps: only the column march takes more than 64";
}

// The renderer's sun map is sized when it is built: a budget level or a
// caller may change the map's build steps and extent, not its method or size.
TEST(Presets, SunShadowMethodIsFixedAtCreation) {
  render::RenderSettings settings;
  settings.width = 16;
  settings.height = 16;
  settings.march.sunShadow = {render::SunShadow::Deep, 64, 2};
  auto r = render::CloudRenderer::create(settings);
  ASSERT_TRUE(r) << describe(r.error());
  render::MarchSettings m = settings.march;
  m.sunShadow.buildSteps = 8;
  m.sunShadow.extent_m = 9000;
  EXPECT_TRUE((*r)->setMarch(m));
  m.sunShadow.method = render::SunShadow::Fom;
  auto refused = (*r)->setMarch(m);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().detail.find("sun shadow"), std::string::npos) << refused.error().detail;
}

}  // namespace
}  // namespace sky::test
