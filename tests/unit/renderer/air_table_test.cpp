// The air table (shaders/include/air_table.glsl, as C++ in double through the
// core harness): what a pixel reads from it against the air marched along its
// own ray with many steps, for cameras low, high and above the atmosphere,
// the sun high and low, directions across the sky, the horizon and the
// ground, and the clouds' shadow in the air. The harness's air has the real
// extinction profiles and its sunlight no table (unattenuated), which leaves
// the table's own error: its directions, slices and interpolation.
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "core_harness.hpp"

namespace sky::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Error {
  double inscatter = 0;      // largest relative error of the in-scattered light (per channel)
  double transmittance = 0;  // largest absolute error of the transmittance
};

// The table's answers against a 64-step march along directions at elevations
// elevations_deg (every 37 degrees of azimuth round the turn), each queried
// at 1 km, 10 km, 60 km and the end of its ray.
Error compare(Core& c, Core::CoreFrame f, const std::vector<double>& elevations_deg) {
  f.airFromTable = true;
  f.airTable = Core::AirTableShape{64, 64, 32};
  c.buildAirTable(f);
  Core::AirFrame fine = f.air;
  fine.airSteps = 64;
  Error e;
  for (double el : elevations_deg)
    for (double az = 5; az < 360; az += 37) {
      const double a = az * kPi / 180, b = el * kPi / 180;
      const Core::real3 dir(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b));
      const double tEnd = c.airRayEnd(f.air, dir.z);
      Core::real q[Core::kAirQueries] = {1000, 10000, 60000, tEnd, tEnd};
      const int count = tEnd < 60000 ? 1 : 4;
      if (count == 1) q[0] = tEnd;
      const Core::AirPath table = c.airPathFromTable(f.air, f.airTable, dir, tEnd, q, count);
      const Core::AirPath march = c.marchAir(fine, dir, tEnd, q, count);
      for (int k = 0; k < count; ++k)
        for (int ch = 0; ch < 3; ++ch) {
          const double want = march.inscatter[k][ch];
          if (want > 0) e.inscatter = std::max(e.inscatter, std::abs(table.inscatter[k][ch] - want) / want);
          e.transmittance =
              std::max(e.transmittance, std::abs(table.transmittance[k][ch] - march.transmittance[k][ch]));
        }
    }
  return e;
}

Core::CoreFrame sunAt(double alt, double elevation_deg) {
  Core::CoreFrame f = frameOver(6371000, alt, 1);
  const double e = elevation_deg * kPi / 180;
  f.air.sunDir = Core::real3(std::cos(e) * 0.6, std::cos(e) * 0.8, std::sin(e));
  return f;
}

// Across the sky and the ground (and next to the camera's horizon: 0.5 and
// 2 degrees above and below it), the table is within a few percent of the
// fine march. Measured (64 x 64 x 32): at most 1.6 % in-scattering and 3.5e-3
// transmittance away from the horizon, 1.3 % and 4.0e-3 next to it (from
// above the atmosphere, the limb: 1.0 %, because its rows all lie there).
TEST(AirTable, ReadsWhatTheMarchGives) {
  Core c;
  struct Case {
    const char* name;
    double alt, sun;
  };
  for (const Case& s : {Case{"low camera, high sun", 500, 50}, Case{"low camera, low sun", 500, 4},
                        Case{"cruise altitude", 11000, 20}, Case{"above the atmosphere", 100000, 30}}) {
    const Error away = compare(c, sunAt(s.alt, s.sun), {-60, -20, 5, 30, 80});
    const double horizon_deg = -std::acos(6371000 / (6371000 + s.alt)) * 180 / kPi;
    const Error horizon = compare(c, sunAt(s.alt, s.sun),
                                  {horizon_deg - 0.5, horizon_deg + 0.5, horizon_deg - 2, horizon_deg + 2});
    std::printf("[ air table ] %-22s inscatter %.3f %% transmittance %.2e; by the horizon %.3f %% %.2e\n", s.name,
                100 * away.inscatter, away.transmittance, 100 * horizon.inscatter, horizon.transmittance);
    EXPECT_LT(away.inscatter, 0.03) << s.name;
    EXPECT_LT(away.transmittance, 0.01) << s.name;
    EXPECT_LT(horizon.inscatter, 0.03) << s.name;
    EXPECT_LT(horizon.transmittance, 0.01) << s.name;
  }
}

// The clouds' shadow reaches the table: under a uniform overcast the air's
// light read from it is the unshadowed one times the beam (as the march's,
// CloudCore.TheAirIsInTheCloudsShadow), and with coverage 0 it is unshaded.
TEST(AirTable, HoldsTheCloudsShadow) {
  Core c;
  const double alt = 500;
  Core::CoreFrame f = sunAt(alt, 37);
  f.layerCount = 1;
  Core::CloudType t = uniformType(0.01);
  t.columnFill = 0.8;
  c.layers[0] = shellLayer(f, alt, 1500, 1000, t);
  c.coverage = 1.0;
  c.density = 0.7;
  const double mu = f.air.sunDir.z, tau = 0.01 * 0.7 * 0.8 * 1000;
  const Core::real3 dir(std::cos(30 * kPi / 180), 0, -std::sin(30 * kPi / 180));
  const double tEnd = c.airRayEnd(f.air, dir.z);
  Core::real q[Core::kAirQueries] = {tEnd};
  f.airFromTable = true;
  f.airTable = Core::AirTableShape{64, 64, 32};
  f.air.shadowLayers = 0;
  c.buildAirTable(f);
  const Core::AirPath lit = c.airPathFromTable(f.air, f.airTable, dir, tEnd, q, 1);
  f.air.shadowLayers = 1;
  c.buildAirTable(f);
  const Core::AirPath shaded = c.airPathFromTable(f.air, f.airTable, dir, tEnd, q, 1);
  ASSERT_GT(lit.inscatter[0].x, 0.0);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(shaded.inscatter[0][k] / lit.inscatter[0][k], std::exp(-tau / mu), 2e-3) << k;
  c.coverage = 0.0;
  c.buildAirTable(f);
  const Core::AirPath clear = c.airPathFromTable(f.air, f.airTable, dir, tEnd, q, 1);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(clear.inscatter[0][k], lit.inscatter[0][k], 1e-12 * lit.inscatter[0][k]);
}

// Queries before the air starts (a camera above the atmosphere) read
// nothing; a ray that misses the atmosphere reads nothing at any distance.
TEST(AirTable, NothingBeforeTheAir) {
  Core c;
  Core::CoreFrame f = sunAt(100000, 30);
  f.airFromTable = true;
  f.airTable = Core::AirTableShape{32, 32, 16};
  c.buildAirTable(f);
  const Core::real3 down(0, 0, -1);
  Core::real q[Core::kAirQueries] = {20000, 39000, 100000};
  const Core::AirPath p = c.airPathFromTable(f.air, f.airTable, down, c.airRayEnd(f.air, -1.0), q, 3);
  EXPECT_EQ(p.inscatter[0], Core::real3(0.0));
  EXPECT_EQ(p.transmittance[1], Core::real3(1.0));
  EXPECT_GT(p.inscatter[2].x, 0.0);
  const Core::real3 up(0, 0, 1);
  const Core::AirPath sky = c.airPathFromTable(f.air, f.airTable, up, c.kFarAway_m, q, 3);
  EXPECT_EQ(sky.inscatter[2], Core::real3(0.0));
  EXPECT_EQ(sky.transmittance[2], Core::real3(1.0));
}

}  // namespace
}  // namespace sky::test
