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
// parallax, up to ~1 degree, is applied for the moon's elevation).
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

}  // namespace sky::render
