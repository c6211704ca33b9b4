// A layer's transition band drawn as the answers give it: the renderer's
// layer shell (frame_setup.cpp: the cloud with its band below and above)
// and the density it draws there (the shared model compiled as C++, the CPU
// reference's core) against the point query that answers CIGI and the HTTP
// API (weather::weatherAt). Both fade the cloud across the band by the same
// function (protocol/weather's layer_presence.glsl); what is checked here is
// that each side places the band where the other does, at every height.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "atmosphere_tables.hpp"
#include "core_harness.hpp"
#include "frame_setup.hpp"
#include "sky/weather/query.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::test {
namespace {

struct Drawn {
  render::LayerSetup layer;
  double cameraAlt_m;
};

// The renderer's setup of a uniform stratus deck (coverage 1) from base to
// base + thickness with the given band, for a camera at alt straight under it.
Drawn drawnLayer(const weather::CloudLayer& l, double alt) {
  weather::WeatherSnapshot snap;
  snap.layers = {l};
  render::FrameInputs in;
  in.camera.position = {46.0, 14.5, alt};
  in.camera.pitch_deg = 30;
  in.sunElevation_deg = 40;
  in.weather = &snap;
  render::RenderSettings settings;
  settings.width = 32;
  settings.height = 18;
  render::WeatherFieldUpdater updater;
  updater.update(&snap, nullptr, render::weatherAnchorFor(in.camera.position));
  const render::FrameSetup setup = render::prepareFrame(settings, in, updater.field(), render::sharedAtmosphereTables());
  EXPECT_EQ(setup.layers.size(), 1u);
  return {setup.layers.at(0), alt};
}

// The density the renderer draws at altitude a straight over the camera, over
// the density it draws inside the cloud: the harness's uniform type with
// the drawn shell's heights and band.
double drawnPresence(const Drawn& d, double a) {
  Core c;
  c.coverage = 1.0;
  c.density = 1.0;
  c.noise = 0.9;
  c.cloudMap = Core::real2(0.5, 1.0);
  Core::CoreFrame f = frameOver(6371000, d.cameraAlt_m, 0);
  const render::LayerSetup& s = d.layer;
  const double shellBase = d.cameraAlt_m - s.hBase_m;
  Core::CoreLayer L = shellLayer(f, d.cameraAlt_m, shellBase, s.thickness_m, uniformType(1e-3));
  L.band = s.band;
  const Core::real3 p(0, 0, a - d.cameraAlt_m);
  const double ph = (c.heightAboveCameraSphere(p, f.air.r) + L.hBase) / L.thickness;
  const double inside = c.cloudSample(L, Core::real3(0, 0, s.thickness_m / 2 + shellBase - d.cameraAlt_m), 0.5, false, 1.0).rho;
  return c.cloudSample(L, p, ph, false, 1.0).rho / inside;
}

TEST(TransitionBand, TheRendererDrawsTheBandWhereTheAnswersFadeIt) {
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Stratus;
  l.base_m = 1000;
  l.thickness_m = 600;
  l.coverage = 1;
  l.density = 1;
  for (double band : {0.0, 150.0, 400.0}) {
    SCOPED_TRACE("band " + std::to_string(band) + " m");
    l.transitionBand_m = band;
    const Drawn d = drawnLayer(l, 300);
    EXPECT_NEAR(d.cameraAlt_m - d.layer.hBase_m, l.base_m - band, 1e-6) << "the shell starts a band under the base";
    EXPECT_NEAR(d.cameraAlt_m - d.layer.hTop_m, l.base_m + l.thickness_m + band, 1e-6);
    const std::vector<weather::CloudLayer> layers = {l};
    // Off the shell's ends, where one side counts the end in and the other out.
    for (double a = l.base_m - band - 99.5; a <= l.base_m + l.thickness_m + band + 100; a += 7) {
      const double answered = weather::weatherAt(layers, {}, 46.0, 14.5, a).cloudDensity;
      EXPECT_NEAR(drawnPresence(d, a), answered, 1e-3) << "at " << a << " m";
    }
    if (band > 0) {
      // Half-way through the lower band both give half the cloud: the
      // renderer drew none there before it drew the band.
      EXPECT_NEAR(drawnPresence(d, l.base_m - band / 2), 0.5, 1e-3);
      EXPECT_NEAR(weather::weatherAt(layers, {}, 46.0, 14.5, l.base_m - band / 2).cloudDensity, 0.5, 1e-9);
    }
  }
}

}  // namespace
}  // namespace sky::test
