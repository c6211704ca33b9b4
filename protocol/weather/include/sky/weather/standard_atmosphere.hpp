// Altitudes in the ICAO standard atmosphere that readers of recorded flights
// need: a barometric (pressure) altitude as a geometric height above mean sea
// level. Built on isaPressure_hpa/isaAltitude_m (query.hpp), so the standard
// atmosphere is written once.
#pragma once

namespace sky::weather {

// Radius of the Earth that relates geopotential and geometric height in the
// standard atmosphere, m (ICAO Doc 7488/3, Manual of the ICAO Standard
// Atmosphere, Table A; the same r0 as the U.S. Standard Atmosphere 1976).
inline constexpr double kIsaEarthRadius_m = 6356766.0;
// Sea-level pressure of the standard atmosphere, hPa (ICAO Doc 7488/3).
inline constexpr double kIsaSeaLevelPressure_hpa = 1013.25;

// Geometric height z of geopotential height h, both m above mean sea level:
// z = r0 h / (r0 - h) (ICAO Doc 7488/3, eq. 8; U.S. Standard Atmosphere
// 1976, eq. 18). Domain: h < r0; the atmosphere's -1 to 20 km is far inside.
double isaGeometricAltitude_m(double geopotential_m);

// The geometric altitude, m MSL, of an aircraft whose altimeter set to
// 1013.25 hPa reads pressureAltitude_m (what ADS-B and Mode C report): the
// static pressure of that pressure altitude, placed in a standard atmosphere
// shifted to sea-level pressure qnh_hpa, then made geometric. Temperature
// deviations from the standard are not known here and not applied.
// pressureAltitude_m is clamped to the -1 to 20 km of isaPressure_hpa;
// qnh_hpa must be positive (a typical range is 950 to 1050).
double pressureToGeometricAltitude_m(double pressureAltitude_m, double qnh_hpa = kIsaSeaLevelPressure_hpa);

}  // namespace sky::weather
