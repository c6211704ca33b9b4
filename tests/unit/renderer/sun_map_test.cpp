// The sun's shadow (shaders/include/sun_map.glsl, as C++ in double through
// the core harness) against closed forms: a uniform slab of extinction
// sigma seen by a sun at elevation e has optical depth sigma (top - h) / sin e
// above a point at height h inside it (flat to within the curvature over a
// few km, which the stated tolerances hold), sigma thickness / sin e below
// it, 0 above it. Each method as its encoding allows: the column march, the
// deep map, BSM and FOM exactly on a uniform slab (their sums are exact for
// a constant extinction), ESM only where the cloud starts.
#include <cmath>

#include <gtest/gtest.h>

#include "core_harness.hpp"

namespace sky::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kEarth = 6371000;
constexpr double kAlt = 500;     // the camera
constexpr double kBase = 1500;   // the slab
constexpr double kThick = 1000;
constexpr double kSigma = 0.002;  // 1/m: 2 optical depths across the slab, vertically

// A camera at kAlt under a uniform slab lit by a sun at elevation_deg
// towards the north-east, with gSunMap's method and a 2-cascade map.
struct Slab {
  Core c;
  Core::CoreFrame f;
  double sinE;
  Slab(int method, double elevation_deg) {
    f = frameOver(kEarth, kAlt, 1);
    const double e = elevation_deg * kPi / 180;
    sinE = std::sin(e);
    f.air.sunDir = Core::real3(std::cos(e) * 0.6, std::cos(e) * 0.8, sinE);
    c.layers[0] = shellLayer(f, kAlt, kBase, kThick, uniformType(kSigma));
    f.layerCount = 1;
    const Core::real3 u = normalize(cross(Core::real3(0, 0, 1), f.air.sunDir));
    c.gSunMap = Core::SunMap{method, 64, 2, 32, 8000.0, u, cross(f.air.sunDir, u), kBase + kThick, kBase,
                             Core::real3(0.0), Core::real3(0.0), Core::real3(0.0), Core::real3(0.0), 0};
    if (c.sunMapIsMap(method)) c.buildSunMap(f);
  }
  // The depth at p (camera-local) by the frame's method.
  double depth(const Core::real3& p) {
    const double mu = dot(c.upAt(p, f.air.r), f.air.sunDir);
    if (c.gSunMap.method == Core::kSunColumn) return c.sunColumnDepth(f.air, c.gSunMap, p, mu, 16, f.layerCount);
    return c.sunMapDepth(f.air, c.gSunMap, p, mu);
  }
};

// Points inside, below and above the slab, near the camera and 20 km away
// (in the second cascade).
struct Probe {
  Core::real3 p;
  double height;  // above the ground, m
};

const Probe kProbes[] = {{{300, -200, 1600 - kAlt}, 1600}, {{-500, 400, 2300 - kAlt}, 2300},
                         {{0, 0, 1000 - kAlt}, 1000},      {{2000, 1000, 1900 - kAlt}, 1900},
                         {{20000, 5000, 2000 - kAlt}, 2000}, {{-15000, 12000, 800 - kAlt}, 800},
                         {{100, 100, 2600 - kAlt}, 2600}};

// sinE: the sun's sine over the point (20 km out the ground has turned
// 0.18 degrees, 1.5 % of the slant at a sun 12 degrees up).
double exact(double height, double sinE) {
  const double above = std::clamp(kBase + kThick - height, 0.0, kThick);
  return kSigma * above / sinE;
}

void expectExact(int method, double elevation_deg, double relTol) {
  Slab s(method, elevation_deg);
  for (const Probe& probe : kProbes) {
    // The height over the curved ground: the probe's nominal height is
    // above the camera's tangent plane; 20 km out the sphere has dropped 31 m.
    const double h = s.c.heightAboveCameraSphere(probe.p, s.f.air.r) + kAlt;
    const double want = exact(h, dot(s.c.upAt(probe.p, s.f.air.r), s.f.air.sunDir));
    EXPECT_NEAR(s.depth(probe.p), want, relTol * std::max(want, 0.05))
        << "method " << method << " sun " << elevation_deg << " deg, point at " << probe.p.x << ", " << probe.p.y
        << ", height " << h;
  }
}

// The column march, the deep map, BSM and FOM are exact on a uniform slab
// up to the curvature along the slant path, within 1 % at a sun 60 and 12
// degrees up (measured: under 0.3 %).
TEST(SunMap, ColumnDeepBeerAndFourierAreExactOnASlab) {
  for (int method : {Core::kSunColumn, Core::kSunDeep, Core::kSunBsm, Core::kSunFom})
    for (double elevation_deg : {60.0, 12.0}) expectExact(method, elevation_deg, 0.01);
}

// ESM knows where the cloud starts, not how dense it is: full sun above the
// slab, and its transmittance falls with depth past the top, to near 0 below.
TEST(SunMap, ExponentialShadowMapDarkensPastTheFront) {
  Slab s(Core::kSunEsm, 40);
  EXPECT_NEAR(s.depth({100, 100, 2600 - kAlt}), 0.0, 1e-9) << "above the slab";
  const double top = s.depth({0, 0, 2450 - kAlt}), mid = s.depth({0, 0, 2000 - kAlt}), low = s.depth({0, 0, 1000 - kAlt});
  EXPECT_LT(top, mid);
  EXPECT_LE(mid, low);
  EXPECT_GT(low, 5.0) << "below the slab: in its shadow";
}

// Outside the last cascade the map knows nothing: -1, for the caller's
// estimate at the weather map's scale.
TEST(SunMap, BeyondTheLastCascadeTheMapSaysSo) {
  Slab s(Core::kSunDeep, 40);
  EXPECT_EQ(s.depth({200000, 0, 1800 - kAlt + 3140}), -1.0);
}

// Each cascade is read around its own centre (the planner rebuilds the
// fine ones more often, around a camera that moved on), and from the
// image's map its slot bit names: a point is in the first cascade whose
// texel centres reach past it from that cascade's centre.
TEST(SunMap, EachCascadeIsReadAroundItsOwnCentre) {
  Core c;
  const Core::real3 u(1, 0, 0), v(0, 1, 0);
  // 2 parts a cascade (deep), cascade 0 1 km east of the camera, cascade 1
  // 5 km west, cascade 1 read from the second map (slot bit 1).
  Core::SunMap m{Core::kSunDeep, 64, 3, 16, 8000.0, u, v, 3000, 1000,
                 Core::real3(1000, 0, 0), Core::real3(-5000, 0, 0), Core::real3(0.0), Core::real3(0.0), 2};
  const Core::SunMapPlace near = c.sunMapPlace(m, Core::real3(7000, 0, 0));
  EXPECT_EQ(near.layer, 0);
  EXPECT_NEAR(near.uv.x, 0.5 + 6000 / 16000.0, 1e-12);
  // 9 km east of the camera: 8 km from cascade 0's centre, past its last
  // texel centre; 14 km from cascade 1's, within its 32 km. Cascade 1's
  // part 0 in the second map: (1 x 3 + 1) x 2.
  const Core::SunMapPlace mid = c.sunMapPlace(m, Core::real3(9000, 0, 0));
  EXPECT_EQ(mid.layer, 8);
  EXPECT_NEAR(mid.uv.x, 0.5 + 14000 / 64000.0, 1e-12);
  // 30 km west: 25 km from cascade 1's centre, so still cascade 1.
  EXPECT_EQ(c.sunMapPlace(m, Core::real3(-30000, 0, 0)).layer, 8);
  // 40 km east: 45 km from cascade 1's; cascade 2 (around the camera,
  // 128 km, first map): (0 x 3 + 2) x 2.
  const Core::SunMapPlace far = c.sunMapPlace(m, Core::real3(40000, 0, 0));
  EXPECT_EQ(far.layer, 4);
  EXPECT_NEAR(far.uv.x, 0.5 + 40000 / 256000.0, 1e-12);
  EXPECT_EQ(c.sunMapPlace(m, Core::real3(0, 129000, 0)).layer, -1) << "past the last cascade";
}

// The line geometry on the curved shells: from a point at height h, the top
// at height H is (H - h) / mu away for a sun well up, and at grazing sun
// the curvature's distance sqrt(2 R (H - h)) (the tangent), not infinity.
TEST(SunMap, SunLineOnCurvedShells) {
  Core c;
  const Core::SunLine up = c.sunLineAt(1000, 0.5, kEarth, 3000, 2000);
  EXPECT_NEAR(up.entry, 2000 / 0.5, 2.0);
  EXPECT_NEAR(up.span, 1000 / 0.5, 2.0);
  const Core::SunLine grazing = c.sunLineAt(1000, 0.0, kEarth, 3000, 2000);
  EXPECT_NEAR(grazing.entry, std::sqrt(2 * kEarth * 2000), 200.0);
  // From a point below the base, looking flat: the line leaves the base
  // sphere towards the sun and the top again further on; its D is the
  // slab's part between base and top, on the sun's side.
  EXPECT_NEAR(grazing.entry - grazing.span, std::sqrt(2 * kEarth * 1000), 200.0);
  // Above every shell and looking up: the line misses nothing above, its
  // entry behind the point (negative): the point gets no shadow.
  const Core::SunLine above = c.sunLineAt(4000, 0.5, kEarth, 3000, 2000);
  EXPECT_LT(above.entry, 0.0);
}

}  // namespace
}  // namespace sky::test
