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

// Meeus example 48.a, 1992 April 12.0 TD: phase angle 69.0756 deg,
// illuminated fraction (1 + cos i) / 2 = 0.6786. Our moon is good to ~0.3 deg.
TEST(Ephemeris, MoonPhaseMatchesMeeusExample48a) {
  const double i = moonPhaseAngle_deg(unixOf(2448724.5));
  EXPECT_NEAR(i, 69.0756, 0.4);
  EXPECT_NEAR((1 + std::cos(i * 3.14159265358979323846 / 180.0)) / 2, 0.6786, 0.005);
  // Full moon 2024-01-25 17:54 UTC, new moon 2024-01-11 11:57 UTC (USNO): the
  // phase angle is the moon's ecliptic latitude (up to ~5 deg) from 0 or 180.
  EXPECT_LT(moonPhaseAngle_deg(1706205240.0), 6.0);
  EXPECT_GT(moonPhaseAngle_deg(1704974220.0), 174.0);
}

// The moon's light against published magnitudes: full moon V = -12.74 and
// the sun -26.74, so 10^(-0.4 x 14) = 2.5e-6 of the sun; a quarter moon
// (phase angle 90) about -10.1, a tenth of the full moon.
TEST(Ephemeris, MoonlightAgainstPublishedMagnitudes) {
  auto magnitude = [](double alpha) { return -26.74 - 2.5 * std::log10(moonToSunIlluminance(alpha)); };
  EXPECT_NEAR(magnitude(0), -12.74, 0.05);
  EXPECT_NEAR(moonToSunIlluminance(0), 2.5e-6, 0.1e-6);
  EXPECT_NEAR(magnitude(90), -10.1, 0.2);
  EXPECT_NEAR(moonToSunIlluminance(90) / moonToSunIlluminance(0), 0.09, 0.015);
  // Full moon illuminance outside the air, 0.25-0.32 lux (Krisciunas &
  // Schaefer 1991; Allen), against the sun's 127-133 klux.
  EXPECT_GT(moonToSunIlluminance(0) * 133000.0, 0.25);
  EXPECT_LT(moonToSunIlluminance(0) * 127000.0, 0.35);
}

}  // namespace
}  // namespace sky::render
