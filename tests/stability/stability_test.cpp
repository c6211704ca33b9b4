// Stability at the extremes (issue 7): cameras at and next to the poles, on
// the antimeridian, from below sea level to orbit, rays grazing the horizon
// and the layer's own boundaries, the sun from zenith to astronomical night,
// coverage, density, wind and clock steps at their limits. Every frame must be
// finite on the GPU and agree with the double-precision CPU reference (the
// same model) within the bounds below; flights across the antimeridian and
// over the pole must not jump between consecutive frames beyond what the
// motion explains.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "renderer_fixture.hpp"
#include "scenes.hpp"
#include "sky/flight/flight.hpp"
#include "sky/render/cpu_reference.hpp"

namespace sky::test {
namespace {

// GPU against the CPU reference, as in tests/gpu/gpu_vs_cpu_test.cpp: RMSE
// over rgb of the displayed value x / (1 + x) relative to the reference's mean
// displayed value (a cloud edge in the sun's forward lobe reaches radiance
// ~800 here, antimeridian_east: linearly those few pixels would be the whole
// error), and the relative difference of the linear means. The extremes get
// the same bounds as ordinary scenes: a float-precision failure (cancellation
// at Earth-radius magnitudes, a degenerate frame at a pole) shows up as a
// pattern error far above them.
constexpr double kRelativeRmseTolerance = 0.05;
constexpr double kRelativeMeanTolerance = 0.01;
// The relative difference of the blue channel between the top and the bottom
// row of a view that sees the sky at its top. Measured (ASan tree,
// lavapipe, 2026-12-02): 0.043 at the top of a layer looking level (cloud
// on both rows), 0.071 in clear air pitched up 20 degrees (coverage 0, density
// 1e-6), 0.52-0.99 in the other scenes; a one-colour image gives 0. The bound
// is half the lowest measured value.
constexpr double kMinSkyContrast = 0.02;
constexpr std::uint32_t kW = 64, kH = 36;

struct Extreme {
  const char* name;
  geo::GeodeticPose camera;
  double coverage = 0.6;
  double density = 1.0;
  double windSpeed_mps = 0;
  double clock_s = 0;
  double sunElevation_deg = 40;
  bool tiled = false;
};

render::FrameInputs inputsFor(const Extreme& s, weather::WeatherSnapshot& snap) {
  weather::CloudLayer l = layer(1, 1500, 1000, s.coverage, s.density);
  l.wind = {s.windSpeed_mps, 300.0, 0.0};
  if (s.tiled)
    snap = tiledSnapshot(s.camera.position, l, float(s.coverage), float(s.density));
  else
    snap.layers = {l};
  render::FrameInputs in;
  in.camera = s.camera;
  in.weather = &snap;
  in.weatherClock_s = s.clock_s;
  in.sunElevation_deg = s.sunElevation_deg;
  return in;
}

TEST(Stability, ExtremesAreFiniteAndMatchTheCpuReference) {
  SKY_RENDERER(r, kW, kH);
  auto reference = render::CpuReference::create(r.settings());
  ASSERT_TRUE(reference) << describe(reference.error());
  std::vector<Extreme> scenes = {
      {"north_pole_exact", pose(90, 0, 800, 0, 20)},
      {"south_pole_exact", pose(-90, 0, 800, 137, 20)},
      {"near_north_pole", pose(89.9999, 45, 2000, 10, 5)},                 // inside the layer
      {"near_south_pole_above", pose(-89.9999, -120, 12000, 200, -30)},
      {"north_pole_tiled", pose(90, 0, 800, 250, 25), 0.6, 1.0, 0, 0, 40, true},
      {"antimeridian_east", pose(10, 180, 800, 90, 20), 0.6, 1.0, 0, 0, 40, true},
      {"antimeridian_west", pose(10, -180, 800, 270, 20), 0.6, 1.0, 0, 0, 40, true},
      {"dead_sea_-430m", pose(31.5, 35.5, -430, 60, 10)},
      {"sea_level", pose(47, 8, 0, 0, 15)},
      {"grazing_at_base", pose(47, 8, 1500, 30, 0)},
      {"grazing_at_top", pose(47, 8, 2500, 30, 0)},
      {"grazing_horizon_below", pose(47, 8, 800, 30, 0)},
      {"above_15km", pose(47, 8, 15000, 0, -20)},
      {"above_100km", pose(47, 8, 100000, 0, -45)},
      {"orbit_400km_nadir", pose(47, 8, 400000, 0, -90)},
      {"orbit_400km_limb", pose(47, 8, 400000, 0, -19)},
      {"sun_zenith", pose(47, 8, 800, 0, 30), 0.6, 1.0, 0, 0, 90},
      {"sun_horizon", pose(47, 8, 800, 0, 10), 0.6, 1.0, 0, 0, 0},
      {"sun_civil_twilight", pose(47, 8, 800, 0, 10), 0.6, 1.0, 0, 0, -6},
      {"sun_astronomical_night", pose(47, 8, 800, 0, 10), 0.6, 1.0, 0, 0, -18},
      {"coverage_0", pose(47, 8, 800, 0, 20), 0.0},
      {"coverage_1", pose(47, 8, 800, 0, 20), 1.0},
      {"density_tiny", pose(47, 8, 800, 0, 20), 0.6, 1e-6},
      {"wind_150_clock_1h", pose(47, 8, 800, 0, 20), 0.6, 1.0, 150, 3600},
  };
  for (const Extreme& s : scenes) {
    SCOPED_TRACE(s.name);
    weather::WeatherSnapshot snap;
    const render::FrameInputs in = inputsFor(s, snap);
    auto gpu = r.render(in);
    ASSERT_TRUE(gpu) << describe(gpu.error());
    auto cpu = reference->render(in);
    ASSERT_TRUE(cpu) << describe(cpu.error());
    savePng(*gpu, std::string("stability_") + s.name);
    EXPECT_EQ(render::computeStats(*gpu).nonFinite, 0u);
    EXPECT_EQ(render::computeStats(*cpu).nonFinite, 0u);
    const Diff d = diff(*gpu, *cpu);
    const double mean = render::computeStats(*cpu).meanLuminance;
    const double meanError = std::abs(render::computeStats(*gpu).meanLuminance - mean) / mean;
    std::printf("[ extreme  ] %-24s mean %.4g (gpu %+.3f %%) displayed rmse %.2f %% (linear %.2f %%)\n", s.name, mean,
                100 * meanError, 100 * d.displayedRmse / d.displayedMean, 100 * d.rmse / mean);
    EXPECT_GT(mean, 0.0);
    // Every camera here sees the sky above the horizon (pitch up to level),
    // except those looking down from above: the top row is not ground.
    if (s.camera.pitch_deg >= 0) {
      double top = 0, bottom = 0;
      for (std::uint32_t x = 0; x < kW; ++x) {
        top += gpu->rgba[x * 4 + 2];
        bottom += gpu->rgba[((kH - 1) * kW + x) * 4 + 2];
      }
      const double contrast = std::abs(top - bottom) / std::max(top, bottom);
      std::printf("[ extreme  ] %-24s top/bottom blue contrast %.3f\n", s.name, contrast);
      EXPECT_GT(contrast, kMinSkyContrast) << "top row " << top << ", bottom row " << bottom << ": no sky";
    }
    EXPECT_LT(meanError, kRelativeMeanTolerance);
    EXPECT_LT(d.displayedRmse, kRelativeRmseTolerance * d.displayedMean);
  }
}

// A sun direction in ECEF: above 80N's horizon everywhere on the flight
// (unit vector towards 60N 100W, nearly overhead far north).
const geo::Vec3d kSunEcef = geo::toEcef({60.0, -100.0, 0.0}) * (1.0 / geo::length(geo::toEcef({60.0, -100.0, 0.0})));

// Frames along a flight, a fixed time apart: the change between consecutive
// frames where the flight crosses a seam (the antimeridian, a pole) must be
// like the change between consecutive frames away from it.
std::vector<double> consecutiveChanges(render::CloudRenderer& r, const flight::Flight& f, double from_s,
                                       double step_s, int frames, const weather::WeatherSnapshot& snap,
                                       const char* name) {
  std::vector<double> changes;
  render::Image previous;
  for (int i = 0; i < frames; ++i) {
    render::FrameInputs in;
    in.camera = flight::sample(f, from_s + step_s * i);
    in.weather = &snap;
    // The sun is fixed in Earth axes (as the ephemeris puts it), not in the
    // camera's local frame, whose north flips at the pole: its local azimuth
    // and elevation follow from a fixed ECEF direction.
    const geo::EnuFrame e = geo::enuFrameAt(in.camera.position);
    in.sunAzimuth_deg = std::atan2(geo::dot(kSunEcef, e.east), geo::dot(kSunEcef, e.north)) * 180 / 3.14159265358979323846;
    in.sunElevation_deg = std::asin(geo::dot(kSunEcef, e.up)) * 180 / 3.14159265358979323846;
    auto img = r.render(in);
    EXPECT_TRUE(img) << describe(img.error());
    if (!img) return changes;
    EXPECT_EQ(render::computeStats(*img).nonFinite, 0u) << name << " frame " << i;
    if (i == frames / 2) savePng(*img, std::string("seam_") + name);
    if (i > 0) changes.push_back(diff(previous, *img).meanAbs);
    previous = std::move(*img);
  }
  return changes;
}

flight::Flight bundledPolarFlight() {
  std::ifstream in(std::string(SKY_SOURCE_DIR) + "/deploy/flights/polar-antimeridian.csv");
  std::ostringstream text;
  text << in.rdbuf();
  auto f = flight::parseCsv(text.str(), "polar-antimeridian.csv");
  EXPECT_TRUE(f) << f.error().detail;
  return f ? *f : flight::Flight{};
}

// The first time at which the flight's longitude changes sign across +-180
// (antimeridian) or its latitude peaks (the pole).
double crossingTime(const flight::Flight& f, bool pole) {
  for (std::size_t i = 1; i < f.fixes.size(); ++i) {
    const auto& a = f.fixes[i - 1].pose.position;
    const auto& b = f.fixes[i].pose.position;
    if (!pole && a.lon_deg > 170 && b.lon_deg < -170) return 0.5 * (f.fixes[i - 1].time_s + f.fixes[i].time_s);
    if (pole && a.lat_deg > 89.9 && std::abs(a.lon_deg - b.lon_deg) > 90)
      return 0.5 * (f.fixes[i - 1].time_s + f.fixes[i].time_s);
  }
  ADD_FAILURE() << "no crossing found";
  return 0;
}

TEST(Stability, NoJumpAcrossTheAntimeridianOrOverThePole) {
  SKY_RENDERER(r, kW, kH);
  const flight::Flight f = bundledPolarFlight();
  ASSERT_GE(f.fixes.size(), 2u);
  // A broken deck at 6-7 km under the 10 km flight level: the lower half of
  // every frame looks down on it, out to the horizon. (Inside a layer,
  // flying in and out of single puffs changes a frame wholesale: that is
  // motion, and would hide a seam.)
  weather::WeatherSnapshot snap;
  snap.layers = {layer(1, 6000, 1000, 0.6, 1.0)};
  for (bool pole : {false, true}) {
    const char* name = pole ? "pole" : "antimeridian";
    SCOPED_TRACE(name);
    const double tc = crossingTime(f, pole);
    // 11 frames 1 s apart (250 m of flight each), centred on the crossing.
    const auto changes = consecutiveChanges(r, f, tc - 5.0, 1.0, 11, snap, name);
    ASSERT_EQ(changes.size(), 10u);
    // Changes 4 and 5 straddle the crossing; 0-2 and 7-9 are the same flight
    // a few seconds away from it.
    const double atSeam = std::max(changes[4], changes[5]);
    const double away = std::max({changes[0], changes[1], changes[2], changes[7], changes[8], changes[9]});
    std::printf("[ seam     ] %-12s largest change away from the seam %.4f, at the seam %.4f\n", name, away, atSeam);
    // A seam artefact (a flipped frame, a noise or sun jump, a swung camera)
    // changes the whole image; motion changes it by about as much as nearby.
    // (Measured when the sun still flipped with local north at the pole: 0.113
    // at the seam against 0.060 nearby; now 1.0x.)
    EXPECT_LT(atSeam, 1.5 * away + 1e-3);
  }
}

// The same local weather and the same local view, placed anywhere on Earth,
// render the same image: at the equator, mid-latitudes, on both sides of the
// antimeridian and next to and at both poles. A float-precision failure at
// Earth-radius magnitudes (cancellation in the shell intersections, a
// degenerate local frame at a pole) shows as an error far above the bounds.
// The clear sky (the atmosphere, the Earth's horizon) must agree pixel by
// pixel. Clouds cannot: their noise is Earth-fixed (it drifts with the wind
// over the ground), so the puffs over two places differ; what must agree is
// a wide view's statistics, looking down on a closed stratus deck (hundreds
// of km² of it in view; only its texture differs). A cumulus field will not
// do: its cloud map modulates the cover over ~23 km, so one view's mean
// differs by up to 10 % from place to place (measured with the cloud-type
// model) whatever the precision. The stratus deck's texture still moves
// the mean: measured 2.7 % at mid-latitude (where precision is no issue),
// 0.6-3.1 % at the antimeridian and the poles; the bound is 5 %, so a
// precision failure (garbage or bands over the view) stands out, a
// difference of a few puffs does not. Clear sky: under 0.1 % RMSE everywhere.
constexpr double kClearSkyRelativeRmse = 1e-3;
constexpr double kDeckRelativeMean = 0.05;

TEST(Stability, TheSameLocalSceneRendersTheSameAnywhereOnEarth) {
  SKY_RENDERER(r, kW, kH);
  struct Place {
    const char* name;
    double lat_deg, lon_deg;
  };
  const std::vector<Place> places = {
      {"equator_greenwich", 0, 0},      {"mid_latitude", 47, 8},         {"southern", -33.9, 151.2},
      {"antimeridian_east", 10, 180},   {"antimeridian_west", 10, -180}, {"near_north_pole", 89.999, 0},
      {"near_south_pole", -89.999, 77}, {"north_pole_exact", 90, 0},     {"south_pole_exact", -90, 0}};
  struct View {
    const char* name;
    double alt_m, yaw_deg, pitch_deg, sunElevation_deg;
    double coverage;  // 0: clear sky, compared pixel by pixel
  };
  const std::vector<View> views = {{"clear_horizon", 800, 120, 2, 35, 0.0},
                                   {"clear_from_12km", 12000, 300, -10, 35, 0.0},
                                   {"clear_low_sun", 800, 135, 5, 2, 0.0},
                                   {"over_deck", 6000, 200, -35, 35, 1.0}};
  for (const View& v : views) {
    SCOPED_TRACE(v.name);
    std::optional<render::Image> first;
    double firstMean = 0;
    for (const Place& p : places) {
      SCOPED_TRACE(p.name);
      weather::WeatherSnapshot snap;
      snap.layers = {layer(1, 1500, 1000, v.coverage, 1.0)};
      snap.layers[0].type = weather::CloudType::Stratus;
      render::FrameInputs in;
      in.camera = pose(p.lat_deg, p.lon_deg, v.alt_m, v.yaw_deg, v.pitch_deg);
      in.weather = &snap;
      in.sunAzimuth_deg = 135;  // in the local frame: the same sun over every place
      in.sunElevation_deg = v.sunElevation_deg;
      auto img = r.render(in);
      ASSERT_TRUE(img) << describe(img.error());
      const auto stats = render::computeStats(*img);
      ASSERT_EQ(stats.nonFinite, 0u);
      ASSERT_GT(stats.meanLuminance, 0.0);
      if (!first) {
        savePng(*img, std::string("invariant_") + v.name);
        first = std::move(*img);
        firstMean = stats.meanLuminance;
        continue;
      }
      const Diff d = diff(*first, *img);
      const double meanError = std::abs(stats.meanLuminance - firstMean) / firstMean;
      std::printf("[ invariant] %-15s %-18s mean %+.3f %% rmse %.3f %% of the equator's\n", v.name, p.name,
                  100 * meanError, 100 * d.rmse / firstMean);
      if (v.coverage == 0) {
        EXPECT_LT(d.rmse, kClearSkyRelativeRmse * firstMean);
      } else {
        EXPECT_LT(meanError, kDeckRelativeMean);
      }
    }
  }
}

}  // namespace
}  // namespace sky::test
