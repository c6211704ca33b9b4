// Sun and moon positions against published values: NREL's SPA paper example
// (Reda & Andreas 2004), Meeus's worked examples 25.a (sun) and 47.a (moon),
// and the 2021 equinox and solstice instants (USNO), where the sun's
// declination is 0 and the obliquity.
#include <cmath>

#include <gtest/gtest.h>

#include "sky/render/ephemeris.hpp"

namespace sky::render {
namespace {

// Unix seconds of a Julian date.
double unixOf(double jd) { return (jd - 2440587.5) * 86400.0; }

// The bound for the sun.
constexpr double kSunTolerance_deg = 0.05;

TEST(Ephemeris, SunMatchesTheSpaPaperExample) {
  // 2003-10-17 12:30:30 at UTC-7 = 19:30:30 UTC; 39.742476 N, 105.1786 W.
  // SPA: topocentric elevation before refraction 39.872046, azimuth
  // 194.340241 (parallax there is 0.002 deg; refraction is not ours to add).
  const double t = 1066419030.0;  // 2003-10-17T19:30:30Z
  const SkyDirection s = sunDirection(t, 39.742476, -105.1786);
  EXPECT_NEAR(s.elevation_deg, 39.872046, kSunTolerance_deg);
  EXPECT_NEAR(s.azimuth_deg, 194.340241, kSunTolerance_deg);
}

TEST(Ephemeris, SunMatchesMeeusExample25a) {
  // 1992 October 13.0 TD: apparent RA 13h13m31.4s = 198.38083, dec -7.78507.
  const EquatorialDirection q = sunEquatorial(unixOf(2448908.5));
  EXPECT_NEAR(q.rightAscension_deg, 198.38083, 0.01);
  EXPECT_NEAR(q.declination_deg, -7.78507, 0.01);
}

TEST(Ephemeris, SunAtTheEquinoxAndSolstice) {
  // March equinox 2021-03-20 09:37 UTC: declination 0, so the sun sits on the
  // horizon at both poles. June solstice 2021-06-21 03:32 UTC: declination =
  // obliquity (23.4366 deg in 2021).
  const double equinox = 1616233020.0, solstice = 1624246320.0;
  EXPECT_NEAR(sunEquatorial(equinox).declination_deg, 0.0, 0.01);
  EXPECT_NEAR(sunDirection(equinox, 90, 0).elevation_deg, 0.0, kSunTolerance_deg);
  EXPECT_NEAR(sunDirection(equinox, -90, 0).elevation_deg, 0.0, kSunTolerance_deg);
  EXPECT_NEAR(sunEquatorial(solstice).declination_deg, 23.4366, 0.01);
  EXPECT_NEAR(sunDirection(solstice, 90, 123).elevation_deg, 23.4366, kSunTolerance_deg);
  // Geocentric: at the antipode the sun is as far below the horizon as it is above here.
  const SkyDirection here = sunDirection(solstice, 47.0, 8.0), there = sunDirection(solstice, -47.0, -172.0);
  EXPECT_NEAR(here.elevation_deg, -there.elevation_deg, 1e-9);
}

TEST(Ephemeris, MoonMatchesMeeusExample47aToItsStatedPrecision) {
  // 1992 April 12.0 TD: apparent RA 134.688470, dec 13.768368. Six + four
  // periodic terms: within 0.3 degree.
  const EquatorialDirection q = moonEquatorial(unixOf(2448724.5));
  EXPECT_NEAR(q.rightAscension_deg, 134.688470, 0.3);
  EXPECT_NEAR(q.declination_deg, 13.768368, 0.3);
}

}  // namespace
}  // namespace sky::render
