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
#include "sky/weather/advection.hpp"
#include "sky/weather/tiling.hpp"
#include "sky/weather/wind_field.hpp"
#include "weather_field.hpp"
#include "weather_field_update.hpp"

namespace sky::render {
namespace {

constexpr double kLat = 46.0, kLon = 14.5, kPi = 3.14159265358979323846;

FrameSetup frameAt(const weather::WeatherSnapshot& snap, double lat, double lon, double clock_s,
                   WeatherField* fieldOut = nullptr) {
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
  if (fieldOut != nullptr) *fieldOut = updater.field();
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

// Cumulus 1200-2700 m in a 10 m/s westerly.
weather::CloudLayer westerlyCumulus(double coverage) {
  weather::CloudLayer l;
  l.id = 1;
  l.type = weather::CloudType::Cumulus;
  l.base_m = 1200;
  l.thickness_m = 1500;
  l.coverage = coverage;
  l.density = 1;
  l.wind = {10.0, 270.0, 0.0};
  return l;
}

TEST(NoiseDrift, ACameraThatMovesDoesNotSlideTheNoiseAtAnyClock) {
  weather::WeatherSnapshot snap;
  snap.layers = {westerlyCumulus(0.5)};
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

// The coverage tiles of a drifting region drift too: the server's tiles are
// the weather at the snapshot's clock, and the map is read that far upwind.
// For a layer with one wind everywhere the shift is the geodesic upwind of
// the camera over the snapshot's age, applied as one flat shift in the
// map's plane (frame_setup.cpp's coverageShift_m); the exact place is the
// geodesic upwind of each point itself (weather::upwindOf, what the point
// query reads). They part with the distance from the camera (the wind's
// direction turns with the longitude) in proportion to the drift: measured
// 1.6 % of it at 100 km east (98 m after 10 minutes of 10 m/s, 590 m after
// an hour, 3.5 km after 6 hours), bounded here at 2 % so that a change for
// the worse is seen. A camera moving 1 km under the same map anchor slides
// the tiles by under 1 m at any age; when the map moves to the next anchor
// (5 km on) the error's share there changes, a step of about 1.6 % of the
// drift per 100 km (9 m after an hour, 177 m after 6 hours). Tiles the server holds in place (a still region, a station, a
// forecast) are not shifted at all.
TEST(TileDrift, TheFlatShiftPartsFromTheGeodesicByDistanceAndAge) {
  constexpr int kLevel = 11;
  weather::WeatherSnapshot snap;
  snap.tileLevel = kLevel;
  weather::CloudLayer l = westerlyCumulus(0);  // only the tiles make cloud
  l.tilesDrift = true;
  snap.layers = {l};
  for (std::uint64_t cell : weather::coverCap({kLat, kLon, 20000.0}, kLevel, 4000)) snap.tiles.push_back({cell, 1, 0.5f, 1.0f});
  const weather::WindVector wind = weather::toVector(l.wind);
  // Where the map is read for the ground point (lat, lon): its plane point
  // less the shift, brought back to the ground by the inverse gnomonic.
  auto readAt = [](const WeatherField& f, const LayerSetup& layer, double lat, double lon) {
    const geo::Vec3d d = geo::toEcef({lat, lon, 0.0}) - f.centreEcef_m;
    const double u = geo::dot(d, f.frame.up);
    const glm::dvec2 plane =
        glm::dvec2(geo::dot(d, f.frame.east), geo::dot(d, f.frame.north)) * (f.radius_m / u) - layer.coverageShift_m;
    const geo::Vec3d dir = geo::normalize(f.frame.east * plane.x + f.frame.north * plane.y + f.frame.up * f.radius_m);
    return geo::fromEcef(f.centreEcef_m + dir * (f.radius_m - f.anchorAlt_m));
  };
  const double kmEast = 1.0 / (111.195 * std::cos(kLat * kPi / 180));
  for (double age_s : {600.0, 3600.0, 6 * 3600.0}) {
    SCOPED_TRACE("snapshot age " + std::to_string(age_s) + " s");
    WeatherField field;
    const FrameSetup s = frameAt(snap, kLat, kLon, age_s, &field);
    ASSERT_TRUE(field.tiled.at(0));
    const LayerSetup& layer = s.layers.at(0);
    double worst = 0;
    for (const auto& [name, dLat, dLon] : {std::tuple{"at the camera", 0.0, 0.0}, std::tuple{"50 km east", 0.0, 50 * kmEast},
                                           std::tuple{"100 km east", 0.0, 100 * kmEast},
                                           std::tuple{"100 km north", 100 / 111.195, 0.0}}) {
      const geo::Geodetic read = readAt(field, layer, kLat + dLat, kLon + dLon);
      const weather::SurfacePoint exact = weather::upwindOf({kLat + dLat, kLon + dLon}, wind, age_s);
      const double off = geo::geodesicDistance_m(read.lat_deg, read.lon_deg, exact.lat_deg, exact.lon_deg);
      worst = std::max(worst, off);
      std::printf("[ tiles    ] snapshot %5.0f s old, point %-13s: the map is read %7.1f m from the geodesic upwind\n",
                  age_s, name, off);
    }
    EXPECT_LT(worst, 0.02 * 10.0 * age_s);
    // The camera 1 km east, the same anchor: the same point reads the same place.
    WeatherField fieldB;
    const FrameSetup b = frameAt(snap, kLat, kLon + kmEast, age_s, &fieldB);
    ASSERT_TRUE(sameAnchor(field.anchor, fieldB.anchor));
    const geo::Geodetic ra = readAt(field, layer, kLat, kLon + 50 * kmEast);
    const geo::Geodetic rb = readAt(fieldB, b.layers.at(0), kLat, kLon + 50 * kmEast);
    const double slide = geo::geodesicDistance_m(ra.lat_deg, ra.lon_deg, rb.lat_deg, rb.lon_deg);
    std::printf("[ tiles    ] snapshot %5.0f s old: the camera 1 km east slides the tiles %.3f m\n", age_s, slide);
    EXPECT_LT(slide, 1.0);
    // Held in place: read where they are.
    weather::WeatherSnapshot held = snap;
    held.layers[0].tilesDrift = false;
    const FrameSetup h = frameAt(held, kLat, kLon, age_s);
    EXPECT_EQ(h.layers.at(0).coverageShift_m, glm::dvec2(0.0));
    EXPECT_EQ(h.layers.at(0).windRef.w, 0.0);
  }
}

}  // namespace
}  // namespace sky::render
