// Where the sun and the moon are, from UTC and a place: the directions the
// renderer lights the clouds from when a host sends CIGI Celestial Sphere
// Control (or a replay knows the recorded date).
//
// Sun: the low-precision solar coordinates of Meeus, "Astronomical
// Algorithms" (2nd ed.), ch. 25 (apparent longitude with nutation and
// aberration, true obliquity), Greenwich mean sidereal time (ch. 12), then
// the local horizon; ~0.01 degree for 1950-2050. Moon: Meeus ch. 47's main
// periodic terms (the largest six in longitude, four in latitude), ~0.3 degree:
// enough to place it in the sky, not for eclipses.
// Geocentric directions; no refraction, no parallax (the moon's horizontal
// parallax, up to ~1 degree, is applied for the moon's elevation). And how
// bright the moon is: its phase angle and its light relative to the sun's.
#pragma once

namespace sky::render {

struct SkyDirection {
  double azimuth_deg = 0;    // true, clockwise from north, [0, 360)
  double elevation_deg = 0;  // above the horizon, [-90, 90]
};

struct EquatorialDirection {
  double rightAscension_deg = 0;  // [0, 360)
  double declination_deg = 0;     // [-90, 90]
};

// Julian date of a UTC instant in seconds since 1970-01-01T00:00:00Z.
double julianDate(double unix_s);

// Apparent geocentric right ascension and declination.
EquatorialDirection sunEquatorial(double unix_s);
EquatorialDirection moonEquatorial(double unix_s);

SkyDirection sunDirection(double unix_s, double lat_deg, double lon_deg);
SkyDirection moonDirection(double unix_s, double lat_deg, double lon_deg);

// The moon's phase angle (sun - moon - Earth), deg in [0, 180]: 0 full, 180
// new. From the geocentric elongation psi (Meeus 48.2-48.3, the moon at its
// mean distance: i = 180 - psi - 0.147 sin psi deg, within ~0.02 deg of the
// exact form; the moon's position limits it to ~0.3 deg).
double moonPhaseAngle_deg(double unix_s);

// The moon's illuminance over the sun's, both outside the air, at phase
// angle alpha (deg): V magnitudes -26.74 for the sun and -12.73 + 0.026
// |alpha| + 4e-9 alpha^4 for the moon at its mean distance (Allen, as
// Krisciunas & Schaefer 1991 eq. 9 use it): 2.5e-6 at full moon.
double moonToSunIlluminance(double phaseAngle_deg);

}  // namespace sky::render
