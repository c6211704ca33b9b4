// Regions (CIGI Environmental Region Control geometry): validation names the
// field; the edge distance matches hand-computed values for points placed
// with GeographicLib's direct geodesic problem at known (along, across)
// offsets, rotated and rounded; the transition weight is smoothstep; the
// measure holds across the antimeridian and at the pole; a drifting region
// moves with its first layer's wind by speed x time.
#include <cmath>
#include <numbers>

#include <GeographicLib/Geodesic.hpp>
#include <gtest/gtest.h>

#include "sky/weather/region.hpp"

namespace sky::weather {
namespace {

Region box(double lat, double lon, double sizeX, double sizeY, double rotation = 0, double corner = 0,
           double transition = 0) {
  Region r;
  r.id = 3;
  r.centerLat_deg = lat;
  r.centerLon_deg = lon;
  r.sizeX_m = sizeX;
  r.sizeY_m = sizeY;
  r.rotation_deg = rotation;
  r.cornerRadius_m = corner;
  r.transition_m = transition;
  return r;
}

// The point at (u along the region's x axis, v along its y axis) metres from
// its centre, along the geodesic from the centre.
void at(const Region& r, double u, double v, double& lat, double& lon) {
  const double azimuth = r.rotation_deg + std::atan2(u, v) * 180.0 / std::numbers::pi;
  GeographicLib::Geodesic::WGS84().Direct(r.centerLat_deg, r.centerLon_deg, azimuth, std::hypot(u, v), lat, lon);
}

double edge(const Region& r, double u, double v) {
  double lat = 0, lon = 0;
  at(r, u, v, lat, lon);
  return regionEdgeDistance_m(r, lat, lon);
}

TEST(Region, ValidateNamesTheFieldAndRange) {
  Region ok = box(45, 10, 20000, 10000, 30, 2000, 5000);
  EXPECT_TRUE(validate(ok));
  struct Case {
    void (*spoil)(Region&);
    const char* field;
  };
  const Case cases[] = {
      {[](Region& r) { r.id = 0; }, "id outside [1, 65535]"},
      {[](Region& r) { r.centerLat_deg = 91; }, "center_lat_deg 91 outside [-90, 90]"},
      {[](Region& r) { r.centerLon_deg = NAN; }, "center_lon_deg must be finite"},
      {[](Region& r) { r.sizeX_m = 0; }, "size_x_m 0 outside (0, 2000000]"},
      {[](Region& r) { r.sizeY_m = 3e6; }, "size_y_m 3000000 outside (0, 2000000]"},
      {[](Region& r) { r.cornerRadius_m = 6000; }, "corner_radius_m 6000 outside [0, 5000]"},
      {[](Region& r) { r.rotation_deg = 181; }, "rotation_deg 181 outside [-180, 180]"},
      {[](Region& r) { r.transition_m = -1; }, "transition_m -1 outside [0, 2000000]"},
      {[](Region& r) { r.driftsWithWind = true; }, "drifts_with_wind needs a layer"},
  };
  for (const Case& c : cases) {
    Region r = ok;
    c.spoil(r);
    const auto e = validate(r);
    ASSERT_FALSE(e) << c.field;
    EXPECT_NE(e.error().detail.find(c.field), std::string::npos) << e.error().detail;
    EXPECT_EQ(e.error().detail.rfind("region ", 0), 0u) << e.error().detail;
  }
  Region twice = ok;
  CloudLayer l;
  l.id = 4;
  l.thickness_m = 500;
  l.coverage = 0.5;
  twice.layers = {l, l};
  const auto e = validate(twice);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().detail.find("layers[1]: layer id 4 given twice"), std::string::npos) << e.error().detail;
  Region badLayer = ok;
  l.coverage = 1.5;
  badLayer.layers = {l};
  const auto e2 = validate(badLayer);
  ASSERT_FALSE(e2);
  EXPECT_NE(e2.error().detail.find("layers[0]: layer 4: coverage"), std::string::npos) << e2.error().detail;
}

TEST(Region, EdgeDistanceOfARectangle) {
  // 20 km along x (east), 10 km along y (north): half sizes 10 and 5 km.
  const Region r = box(45, 10, 20000, 10000);
  EXPECT_NEAR(edge(r, 0, 0), -5000, 1e-6);        // centre: 5 km from the nearer (north/south) edges
  EXPECT_NEAR(edge(r, 15000, 0), 5000, 0.01);     // 5 km east of the east edge
  EXPECT_NEAR(edge(r, 0, -7000), 2000, 0.01);     // 2 km south of the south edge
  EXPECT_NEAR(edge(r, 9000, 1000), -1000, 0.01);  // 1 km inside the east edge
  EXPECT_NEAR(edge(r, 13000, 9000), 5000, 0.01);  // off the corner: hypot(3, 4) km
}

TEST(Region, EdgeDistanceRotatedAndRounded) {
  // Rotation 90: the y axis points east, the x axis south.
  const Region turned = box(-33, 151, 20000, 10000, 90);
  double lat = 0, lon = 0;
  GeographicLib::Geodesic::WGS84().Direct(-33, 151, 90.0, 15000, lat, lon);  // 15 km due east
  EXPECT_NEAR(regionEdgeDistance_m(turned, lat, lon), 10000, 0.01);  // y half size is 5 km
  GeographicLib::Geodesic::WGS84().Direct(-33, 151, 180.0, 15000, lat, lon);  // 15 km due south
  EXPECT_NEAR(regionEdgeDistance_m(turned, lat, lon), 5000, 0.01);   // x half size is 10 km

  // Corner radius 2 km: the corner arc's centre is at (8, 3) km; a point 5 km
  // from it diagonally is 3 km outside the rounded edge; the sharp corner
  // (10, 5) km itself is outside by 2*sqrt(2) - 2 km.
  const Region round = box(60, -20, 20000, 10000, 0, 2000);
  EXPECT_NEAR(edge(round, 8000 + 3000, 3000 + 4000), 3000, 0.01);
  EXPECT_NEAR(edge(round, 10000, 5000), 2000 * std::sqrt(2.0) - 2000, 0.01);
  EXPECT_NEAR(edge(round, 12000, 0), 2000, 0.01);  // straight edges are unchanged
}

TEST(Region, WeightIsSmoothAcrossTheTransitionPerimeter) {
  const Region r = box(45, 10, 20000, 10000, 0, 0, 4000);
  double lat = 0, lon = 0;
  at(r, 0, 0, lat, lon);
  EXPECT_EQ(regionWeight(r, lat, lon), 1.0);
  at(r, 10000 - 1, 0, lat, lon);
  EXPECT_EQ(regionWeight(r, lat, lon), 1.0);  // inside, up to the edge
  at(r, 12000, 0, lat, lon);                  // middle of the perimeter
  EXPECT_NEAR(regionWeight(r, lat, lon), 0.5, 1e-5);
  at(r, 11000, 0, lat, lon);  // a quarter in: t = 0.75, 3t^2 - 2t^3
  EXPECT_NEAR(regionWeight(r, lat, lon), 0.84375, 1e-5);
  at(r, 14001, 0, lat, lon);
  EXPECT_EQ(regionWeight(r, lat, lon), 0.0);
  double previous = 1.0;
  for (double u = 9000; u <= 15000; u += 100) {  // monotone outwards
    at(r, u, 0, lat, lon);
    const double w = regionWeight(r, lat, lon);
    EXPECT_LE(w, previous + 1e-12) << u;
    previous = w;
  }
  // No perimeter: a hard edge.
  const Region hard = box(45, 10, 20000, 10000);
  at(hard, 10001, 0, lat, lon);
  EXPECT_EQ(regionWeight(hard, lat, lon), 0.0);
}

TEST(Region, AcrossTheAntimeridianAndAtThePole) {
  // Centred 0.05 deg west of the antimeridian, 20 km wide: a point 0.05 deg
  // east of it (lon -179.95) is ~7.9 km east of the centre at 0 deg latitude.
  const Region dateline = box(0, 179.95, 20000, 20000);
  EXPECT_NEAR(regionEdgeDistance_m(dateline, 0, -179.95), 11131.9 - 10000, 1.0);
  EXPECT_NEAR(regionEdgeDistance_m(dateline, 0, 180.0 - 360.0 * 3), -4434.0, 1.0);  // lon -900 = 180
  // At the North Pole every longitude is the same point; a point 5 km from
  // the pole is inside a 20 km square whatever its longitude.
  const Region pole = box(90, 0, 20000, 20000);
  for (double lon = -180; lon < 180; lon += 45) {
    double lat = 0, lon2 = 0;
    GeographicLib::Geodesic::WGS84().Direct(90, lon, 180, 5000, lat, lon2);
    EXPECT_LT(regionEdgeDistance_m(pole, lat, lon2), -4999.0) << lon;
    EXPECT_EQ(regionWeight(pole, lat, lon2), 1.0) << lon;
  }
  EXPECT_NEAR(regionEdgeDistance_m(pole, 90, 123), -10000, 1e-6);
}

TEST(Region, DriftsWithItsFirstLayersWind) {
  Region r = box(45, 10, 20000, 10000);
  CloudLayer storm;
  storm.id = 9;
  storm.type = CloudType::Cumulonimbus;
  storm.thickness_m = 8000;
  storm.coverage = 0.8;
  storm.wind = {15, 270, 0};  // from the west: blows east
  r.layers = {storm};
  r.driftsWithWind = true;
  r.placedAtClock_s = 1000;
  const Region later = regionAt(r, 1000 + 600);  // 9 km downwind
  double s12 = 0, azi1 = 0, azi2 = 0;
  GeographicLib::Geodesic::WGS84().Inverse(45, 10, later.centerLat_deg, later.centerLon_deg, s12, azi1, azi2);
  EXPECT_NEAR(s12, 9000, 1e-6);
  EXPECT_NEAR(azi1, 90, 1e-9);
  EXPECT_EQ(later.placedAtClock_s, 1600);
  // Evaluating again from the new placement goes on from there.
  const Region evenLater = regionAt(later, 2200);
  GeographicLib::Geodesic::WGS84().Inverse(later.centerLat_deg, later.centerLon_deg, evenLater.centerLat_deg,
                                           evenLater.centerLon_deg, s12, azi1, azi2);
  EXPECT_NEAR(s12, 9000, 1e-6);
  // A region that does not drift stays where it is.
  r.driftsWithWind = false;
  const Region still = regionAt(r, 5000);
  EXPECT_EQ(still.centerLat_deg, 45);
  EXPECT_EQ(still.centerLon_deg, 10);
}

}  // namespace
}  // namespace sky::weather
