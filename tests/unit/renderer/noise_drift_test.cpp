// The clouds' noise drifts with the wind and stays on the Earth when the
// camera moves, at any weather clock. The noise coordinate of a point is
// what the shaders read (cloud_pass.glsl's sampleShape, noiseCoord): the
// layer's origin plus the point's offset from the camera, less the flow's
// shift (cloud_core.glsl's cloudSample: the own wind times the showing
// phase's age), turned into ECEF. It is computed here from the numbers
// frame_setup.cpp hands the shaders, for an Earth-fixed point seen from two
// cameras 1 km apart: the noise there must be the same from both, to within
// the curvature's share of the phase's drift (the wind times at most a flow
// period, turned by the 1 km's angle: 10 m/s x 600 s x 1/6371 = 0.94 m),
// after a minute and after a week of weather clock alike.
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "atmosphere_tables.hpp"
#include "frame_setup.hpp"
#include "sky/geo/geodetic.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::render {
namespace {

constexpr double kLat = 46.0, kLon = 14.5, kPi = 3.14159265358979323846;

FrameSetup frameAt(const weather::WeatherSnapshot& snap, double lat, double lon, double clock_s) {
  FrameInputs in;
  in.camera.position = {lat, lon, 500.0};
  in.camera.pitch_deg = 20;
  in.sunElevation_deg = 40;
  in.weather = &snap;
  in.weatherClock_s = clock_s;
  RenderSettings settings;
  settings.width = 32;
  settings.height = 18;
  WeatherFieldUpdater updater;
  updater.update(&snap, nullptr, weatherAnchorFor(in.camera.position));
  return prepareFrame(settings, in, updater.field(), sharedAtmosphereTables());
}

// The shape noise's coordinate (metres, ECEF axes, modulo the period) of the
// ECEF point x, in the phase that shows (the flow's phase A outside a
// crossfade).
glm::dvec3 shapeCoordinate(const FrameSetup& s, const glm::dvec3& x) {
  const LayerSetup& l = s.layers.at(0);
  const glm::dvec3 local = glm::transpose(s.localToEcef) * (x - s.cameraEcef_m);
  const double age = l.flow.z > 0 ? l.flow.x : l.flow.y;
  const glm::dvec3 shift = glm::dvec3(l.windRef) * age;
  return l.shapeOrigin * l.shapePeriod_m + s.localToEcef * (local - shift);
}

// The difference of two noise coordinates on the noise's torus.
double torusDistance(const glm::dvec3& a, const glm::dvec3& b, double period) {
  double sum = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::remainder(a[k] - b[k], period);
    sum += d * d;
  }
  return std::sqrt(sum);
}

TEST(NoiseDrift, ACameraThatMovesDoesNotSlideTheNoiseAtAnyClock) {
  weather::WeatherSnapshot snap;
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1200;
  l.thickness_m = 1500;
  l.coverage = 0.5;
  l.density = 1;
  l.wind = {10.0, 270.0, 0.0};
  snap.layers = {l};
  const geo::Vec3d p = geo::toEcef({kLat + 0.15, kLon + 0.2, 1800.0});
  const glm::dvec3 x(p.x, p.y, p.z);
  // Clocks half-way through a flow period (frame_setup.hpp's
  // kWindFlowPeriod_s): phase A alone shows.
  for (double clock_s : {300.0, 86400.0 + 300, 7 * 86400.0 + 300}) {
    SCOPED_TRACE("weather clock " + std::to_string(clock_s) + " s");
    const FrameSetup a = frameAt(snap, kLat, kLon, clock_s);
    ASSERT_EQ(a.layers.at(0).flow.z, 1.0) << "phase A alone";
    const double period = a.layers.at(0).shapePeriod_m;
    // 1 km east (the wind's way: its direction turns with the longitude)
    // and 1 km north.
    const double degPerKm = 1000.0 / 111195.0;
    for (const auto& [dLat, dLon] : {std::pair{0.0, degPerKm / std::cos(kLat * kPi / 180)}, std::pair{degPerKm, 0.0}}) {
      const FrameSetup b = frameAt(snap, kLat + dLat, kLon + dLon, clock_s);
      const double slide = torusDistance(shapeCoordinate(a, x), shapeCoordinate(b, x), period);
      std::printf("[ drift    ] clock %7.0f s: the noise at a point slides %8.3f m when the camera moves 1 km %s\n",
                  clock_s, slide, dLat > 0 ? "north" : "east");
      EXPECT_LT(slide, 1.0) << (dLat > 0 ? "north" : "east");
    }
    // And it drifts with the wind: 10 s later 100 m further east (upwind
    // of x is where its noise comes from).
    const FrameSetup later = frameAt(snap, kLat, kLon, clock_s + 10);
    const glm::dvec3 moved = shapeCoordinate(later, x) + a.localToEcef * glm::dvec3(100, 0, 0);
    EXPECT_LT(torusDistance(shapeCoordinate(a, x), moved, period), 0.01);
  }
}

}  // namespace
}  // namespace sky::render
