// The camera's exposure (sky/render/exposure.hpp, auto_exposure.hpp): EV100
// against a reflected-light meter's formula computed here from the images'
// known luminances, the adaptation's time constant, the metering shared by
// the channels of one host pose, and auto-exposed pictures of an overcast
// and of a sunlit cumulus top (the CPU reference, small, no GPU).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "image_output.hpp"
#include "sky/render/auto_exposure.hpp"
#include "sky/render/cpu_reference.hpp"
#include "sky/render/exposure.hpp"

namespace sky::test {
namespace {

using render::Image;

// Renderer units of a grey (r = g = b) pixel of luminance L cd/m^2:
// 1 unit = 128 klx / 20 = 6400 cd/m^2 (the stated photometric unit).
constexpr double kUnit_cdm2 = 128000.0 / 20.0;

Image greyImage(const std::vector<double>& luminances_cdm2) {
  Image img;
  img.width = std::uint32_t(luminances_cdm2.size());
  img.height = 1;
  for (double l : luminances_cdm2) {
    const float v = float(l / kUnit_cdm2);
    img.rgba.insert(img.rgba.end(), {v, v, v, 1.0f});
  }
  return img;
}

// A reflected-light meter at ISO 100, K = 12.5: EV100 = log2(Lavg * 100 / 12.5)
// with Lavg the geometric mean of the luminances (the float pixels' own
// values, so the test does not measure the float rounding).
double expectedEv100(const Image& img) {
  double sum = 0;
  for (std::size_t i = 0; i < img.rgba.size(); i += 4) sum += std::log(double(img.rgba[i]) * kUnit_cdm2);
  return std::log2(std::exp(sum / double(img.rgba.size() / 4)) * 8.0);
}

// The floor added before the log (1e-4 cd/m^2) moves a scene of >= 10 cd/m^2
// by < 1.5e-5 EV; float luminances by ~1e-7 relative.
constexpr double kEvTolerance = 1e-4;

TEST(Exposure, UnitsAreTheStatedPhysicalOnes) {
  EXPECT_NEAR(render::kRadianceUnit_Wpm2sr, 1361.0 / 20.0, 1e-12);
  EXPECT_NEAR(render::kLuminanceUnit_cdm2, 6400.0, 1e-9);
  // Today's fixed exposure 1 is the camera at EV100 log2(6400 / 1.2).
  EXPECT_NEAR(render::kFixedDisplayEv100, std::log2(6400.0 / 1.2), 1e-12);
  EXPECT_NEAR(render::displayExposure(render::kFixedDisplayEv100, 0), 1.0, 1e-12);
}

TEST(Exposure, SaturationBasedExposureOfLagarde2014) {
  // L_max = 1.2 x 2^EV100: EV100 0 saturates at 1.2 cd/m^2, EV100 10 at 1228.8.
  EXPECT_NEAR(render::exposureFromEv100(0), 1.0 / 1.2, 1e-15);
  EXPECT_NEAR(render::exposureFromEv100(10), 1.0 / 1228.8, 1e-15);
  // +1 EV of compensation doubles the display exposure.
  EXPECT_NEAR(render::displayExposure(12, 1), 2 * render::displayExposure(12, 0), 1e-12);
}

TEST(Exposure, Ev100FollowsTheMeanLogLuminance) {
  const Image uniform = greyImage(std::vector<double>(64, 4000.0));  // an overcast's base, cd/m^2
  const Image twoLevel = greyImage({500, 500, 500, 8000, 8000, 500, 8000, 500});
  std::mt19937_64 rng(26);
  std::lognormal_distribution<double> spread(std::log(2500.0), 1.2);  // sigma 1.2: 3.5 EV of spread
  std::vector<double> many(4096);
  for (double& l : many) l = spread(rng);
  const Image logNormal = greyImage(many);
  for (const Image* img : {&uniform, &twoLevel, &logNormal}) {
    const double metered = render::ev100FromMeanLogLuminance(render::meanLogLuminance(*img));
    EXPECT_NEAR(metered, expectedEv100(*img), kEvTolerance);
  }
  // A uniform 4000 cd/m^2: log2(32000) = 14.966.
  EXPECT_NEAR(render::ev100FromMeanLogLuminance(render::meanLogLuminance(uniform)), std::log2(32000.0), kEvTolerance);
  // Coloured pixels meter their Rec. 709 luminance.
  Image blue = greyImage({1000});
  blue.rgba = {0.0f, 0.0f, float(1000 / kUnit_cdm2 / 0.0722), 1.0f};
  EXPECT_NEAR(render::ev100FromMeanLogLuminance(render::meanLogLuminance(blue)), std::log2(8000.0), kEvTolerance);
}

TEST(Exposure, OneEvBrighterSettlesOneEvHigher) {
  std::vector<double> l(256);
  for (std::size_t i = 0; i < l.size(); ++i) l[i] = 200.0 + 30.0 * double(i);
  std::vector<double> twice = l;
  for (double& v : twice) v *= 2;
  render::ExposureAdaptation a, b;
  double evA = 0, evB = 0;
  for (int frame = 0; frame < 300; ++frame) {  // 10 s at 30 Hz: settled
    evA = a.update(render::ev100FromMeanLogLuminance(render::meanLogLuminance(greyImage(l))), frame / 30.0);
    evB = b.update(render::ev100FromMeanLogLuminance(render::meanLogLuminance(greyImage(twice))), frame / 30.0);
  }
  EXPECT_NEAR(evB - evA, 1.0, kEvTolerance);
}

TEST(Exposure, AdaptationReaches63PercentOfAStepAfterTau) {
  const double tau_s = 0.5;
  render::ExposureAdaptation a(tau_s);
  EXPECT_EQ(a.update(10.0, 0.0), 10.0);  // the first metering is taken at once
  // A 3 EV step at t = 0, frames of 1/60 s: after tau, 1 - 1/e of it.
  double ev = 0;
  for (int frame = 1; frame <= 30; ++frame) ev = a.update(13.0, frame / 60.0);
  EXPECT_NEAR((ev - 10.0) / 3.0, 1.0 - std::exp(-1.0), 1e-9);
  // Frames dropped in between do not change where it is at a given time.
  render::ExposureAdaptation sparse(tau_s);
  sparse.update(10.0, 0.0);
  sparse.update(13.0, 7 / 60.0);
  EXPECT_NEAR(sparse.update(13.0, 0.5), ev, 1e-9);
  // A clock that went back, or a gap of over 5 tau, snaps to the target.
  EXPECT_EQ(a.update(9.0, 0.1), 9.0);
  EXPECT_EQ(a.update(12.0, 0.1 + 5.01 * tau_s), 12.0);
}

// --- Metering the host's boresight with the CPU reference ---

weather::WeatherSnapshot oneLayer(weather::CloudType type, double base_m, double thickness_m, double coverage,
                                  double density) {
  weather::WeatherSnapshot snap;
  weather::CloudLayer l;
  l.id = 1;
  l.type = type;
  l.base_m = base_m;
  l.thickness_m = thickness_m;
  l.coverage = coverage;
  l.density = density;
  snap.layers = {l};
  return snap;
}

TEST(AutoExposure, ChannelsOfOneHostPoseShareTheExposure) {
  const auto snap = oneLayer(weather::CloudType::Cumulus, 1200, 1500, 0.5, 0.15);
  render::FrameInputs in;
  in.weather = &snap;
  in.sunAzimuth_deg = 135;
  in.sunElevation_deg = 40;
  geo::GeodeticPose host;
  host.position = {47.0, 8.0, 600.0};
  host.yaw_deg = 100;
  host.pitch_deg = 5;
  // Three channels (left, centre, right: eyepoint yaw -60, 0, +60), each its
  // own process: its own AutoExposure, its own picture's view and frustum.
  std::vector<render::AutoExposure> channels;
  for (int c = 0; c < 3; ++c) {
    auto made = render::AutoExposure::create({}, 1);
    ASSERT_TRUE(made);
    channels.push_back(std::move(*made));
  }
  std::vector<std::vector<double>> ev(3);
  double meter_ms = 0;
  int meterings = 0;
  for (int frame = 0; frame < 12; ++frame) {
    const double t = frame / 30.0;
    host.yaw_deg += 0.5;  // a gentle turn
    for (int c = 0; c < 3; ++c) {
      render::FrameInputs own = in;
      own.camera = host;
      own.camera.yaw_deg += 60.0 * (c - 1);
      own.frustum = render::ViewFrustum{-45, 45, 25, -25};
      auto e = channels[std::size_t(c)].expose(own, host, t);
      ASSERT_TRUE(e) << describe(e.error());
      ev[std::size_t(c)].push_back(e->ev100);
      if (e->meteredNow) {
        meter_ms += e->meter_ms;
        ++meterings;
      }
    }
  }
  std::printf("meter: %d meterings of %ux%u, %.1f ms each (this machine, one thread)\n", meterings,
              render::kMeterWidth, render::kMeterHeight, meter_ms / meterings);
  for (int c : {0, 2}) EXPECT_EQ(ev[std::size_t(c)], ev[1]) << "channel " << c;  // bit for bit
  // The channels' own pictures differ (the test would pass vacuously if the
  // three views saw the same): the left and right views meter apart.
  auto solo = render::AutoExposure::create({}, 1);
  ASSERT_TRUE(solo);
  geo::GeodeticPose left = host, right = host;
  left.yaw_deg -= 60;
  right.yaw_deg += 60;
  const auto evLeft = solo->meter(in, left), evRight = solo->meter(in, right), evCentre = solo->meter(in, host);
  ASSERT_TRUE(evLeft && evRight && evCentre);
  std::printf("own views would meter EV100 %.3f (left) %.3f (centre) %.3f (right)\n", *evLeft, *evCentre, *evRight);
  EXPECT_GT(std::max(std::abs(*evLeft - *evCentre), std::abs(*evRight - *evCentre)), 0.05);
}

TEST(AutoExposure, FixedEv100IsTheSameForEveryChannel) {
  render::ExposureSettings s;
  s.automatic = false;
  s.fixedEv100 = 13.0;
  s.compensation_ev = 0.5;
  auto fixed = render::AutoExposure::create(s, 1);
  ASSERT_TRUE(fixed);
  render::FrameInputs in;
  geo::GeodeticPose host;
  const auto e = fixed->expose(in, host, 0.0);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->ev100, 13.0);
  EXPECT_FALSE(e->meteredNow);
  // Saturation at 1.2 x 2^12.5 cd/m^2 (13 less half an EV), in 6400 cd/m^2 units.
  EXPECT_NEAR(e->exposure, 6400.0 / (1.2 * std::exp2(12.5)), 1e-12);
}

// The auto-exposed picture of a frame: the mean sRGB (0-255) over its pixels
// and the brightest channel value, at 64 x 36 from the CPU reference.
struct Picture {
  double meanSrgb = 0;
  int brightest = 0, brightestFixed = 0;  // the latter at the fixed exposure 1 of before
  double ev100 = 0;
  double pictureEv100 = 0;  // the 64 x 36 picture's own mean log luminance, as EV100
};

Picture autoExposed(const render::FrameInputs& in) {
  render::RenderSettings s;
  s.width = 64;
  s.height = 36;
  s.march.sunShadow = render::SunMapSettings{};  // the secondary march: no map to build for 2304 rays
  s.march.airTable.enabled = false;
  auto ref = render::CpuReference::create(s);
  auto meter = render::AutoExposure::create({}, 1);
  EXPECT_TRUE(ref && meter);
  auto image = ref->render(in);
  auto e = meter->expose(in, in.camera, 0.0);
  EXPECT_TRUE(image && e);
  Picture p;
  if (!image || !e) return p;
  const auto rgb = render::tonemapToSrgb8(*image, e->exposure);
  double sum = 0;
  for (std::uint8_t v : rgb) {
    sum += v;
    p.brightest = std::max<int>(p.brightest, v);
  }
  p.meanSrgb = sum / double(rgb.size());
  for (std::uint8_t v : render::tonemapToSrgb8(*image)) p.brightestFixed = std::max<int>(p.brightestFixed, v);
  p.ev100 = e->ev100;
  p.pictureEv100 = render::ev100FromMeanLogLuminance(render::meanLogLuminance(*image));
  // The meter's cheap view (32 x 18, realtime march) reads the scene as the
  // finer picture (64 x 36, the default march) does.
  EXPECT_NEAR(p.ev100, p.pictureEv100, 0.25);
  return p;
}

TEST(AutoExposure, AnOvercastReadsMidGrey) {
  // A closed nimbostratus deck, 800-3800 m, seen from 300 m looking 10 deg
  // up under a 40 deg sun: only the deck's base and the murk below.
  const auto snap = oneLayer(weather::CloudType::Nimbostratus, 800, 3000, 1.0, 0.6);
  render::FrameInputs in;
  in.weather = &snap;
  in.camera.position = {47.0, 8.0, 300.0};
  in.camera.pitch_deg = 10;
  const Picture p = autoExposed(in);
  std::printf("overcast: EV100 %.2f (the picture's own %.2f), mean sRGB %.1f of 255, brightest %d (at the fixed "
              "exposure, EV100 %.2f: %d)\n",
              p.ev100, p.pictureEv100, p.meanSrgb, p.brightest, render::kFixedDisplayEv100, p.brightestFixed);
  EXPECT_GT(p.meanSrgb, 90);
  EXPECT_LT(p.meanSrgb, 170);
}

TEST(AutoExposure, ASunlitCumulusTopIsNotClipped) {
  // Cumulus 1200-2700 m seen from 4500 m looking 35 deg down, sun 50 deg up
  // behind the camera: the sunlit tops fill most of the view.
  const auto snap = oneLayer(weather::CloudType::Cumulus, 1200, 1500, 0.7, 0.3);
  render::FrameInputs in;
  in.weather = &snap;
  in.camera.position = {47.0, 8.0, 4500.0};
  in.camera.yaw_deg = 0;
  in.camera.pitch_deg = -35;
  in.sunAzimuth_deg = 180;
  in.sunElevation_deg = 50;
  const Picture p = autoExposed(in);
  std::printf("cumulus tops from above: EV100 %.2f (the picture's own %.2f), mean sRGB %.1f, brightest %d of 255 "
              "(at the fixed exposure: %d)\n",
              p.ev100, p.pictureEv100, p.meanSrgb, p.brightest, p.brightestFixed);
  EXPECT_LT(p.brightest, 250);
  EXPECT_GT(p.brightest, 150);  // and they are bright, not dimmed to grey
}

}  // namespace
}  // namespace sky::test
