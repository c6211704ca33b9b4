// Sun and moon positions (see ephemeris.hpp). Angles in degrees unless named _rad.
#include "sky/render/ephemeris.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sky::render {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kJ2000 = 2451545.0;
constexpr double kUnixEpochJd = 2440587.5;

double wrap360(double a) {
  a = std::fmod(a, 360.0);
  return a < 0 ? a + 360.0 : a;
}

// Greenwich mean sidereal time, degrees (Meeus eq. 12.4).
double gmst(double jd) {
  const double d = jd - kJ2000, t = d / 36525.0;
  return wrap360(280.46061837 + 360.98564736629 * d + t * t * (0.000387933 - t / 38710000.0));
}

// Mean obliquity of the ecliptic (Meeus eq. 22.2), degrees.
double meanObliquity(double t) {
  return 23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
}

struct Equatorial {
  double ra, dec;  // degrees
};

Equatorial toEquatorial(double lambda, double beta, double eps) {
  const double l = lambda * kDeg, b = beta * kDeg, e = eps * kDeg;
  const double ra = std::atan2(std::sin(l) * std::cos(e) - std::tan(b) * std::sin(e), std::cos(l)) / kDeg;
  const double dec = std::asin(std::sin(b) * std::cos(e) + std::cos(b) * std::sin(e) * std::sin(l)) / kDeg;
  return {wrap360(ra), dec};
}

SkyDirection toHorizon(const Equatorial& q, double jd, double lat_deg, double lon_deg) {
  const double h = (gmst(jd) + lon_deg - q.ra) * kDeg;
  const double phi = lat_deg * kDeg, dec = q.dec * kDeg;
  const double sinEl = std::sin(phi) * std::sin(dec) + std::cos(phi) * std::cos(dec) * std::cos(h);
  // Azimuth from north, clockwise (Meeus 13.5 measures from south: + 180).
  const double az = std::atan2(std::sin(h), std::cos(h) * std::sin(phi) - std::tan(dec) * std::cos(phi)) / kDeg + 180.0;
  return {wrap360(az), std::asin(std::clamp(sinEl, -1.0, 1.0)) / kDeg};
}

}  // namespace

double julianDate(double unix_s) { return kUnixEpochJd + unix_s / 86400.0; }

EquatorialDirection sunEquatorial(double unix_s) {
  const double jd = julianDate(unix_s);
  const double t = (jd - kJ2000) / 36525.0;
  const double l0 = wrap360(280.46646 + t * (36000.76983 + t * 0.0003032));
  const double m = wrap360(357.52911 + t * (35999.05029 - t * 0.0001537)) * kDeg;
  const double c = std::sin(m) * (1.914602 - t * (0.004817 + t * 0.000014)) + std::sin(2 * m) * (0.019993 - t * 0.000101) +
                   std::sin(3 * m) * 0.000289;
  const double omega = (125.04 - 1934.136 * t) * kDeg;
  const double lambda = l0 + c - 0.00569 - 0.00478 * std::sin(omega);
  const double eps = meanObliquity(t) + 0.00256 * std::cos(omega);
  const Equatorial q = toEquatorial(lambda, 0.0, eps);
  return {q.ra, q.dec};
}

SkyDirection sunDirection(double unix_s, double lat_deg, double lon_deg) {
  const EquatorialDirection q = sunEquatorial(unix_s);
  return toHorizon({q.rightAscension_deg, q.declination_deg}, julianDate(unix_s), lat_deg, lon_deg);
}

EquatorialDirection moonEquatorial(double unix_s) {
  const double jd = julianDate(unix_s);
  const double t = (jd - kJ2000) / 36525.0;
  // Mean elements (Meeus 47.1-47.5), degrees.
  const double lp = wrap360(218.3164477 + 481267.88123421 * t);
  const double d = wrap360(297.8501921 + 445267.1114034 * t) * kDeg;
  const double m = wrap360(357.5291092 + 35999.0502909 * t) * kDeg;
  const double mp = wrap360(134.9633964 + 477198.8675055 * t) * kDeg;
  const double f = wrap360(93.2720950 + 483202.0175233 * t) * kDeg;
  // The largest periodic terms of table 47.A (longitude) and 47.B (latitude), degrees.
  const double lambda = lp + 6.288774 * std::sin(mp) + 1.274027 * std::sin(2 * d - mp) + 0.658314 * std::sin(2 * d) +
                        0.213618 * std::sin(2 * mp) - 0.185116 * std::sin(m) - 0.114332 * std::sin(2 * f);
  const double beta = 5.128122 * std::sin(f) + 0.280602 * std::sin(mp + f) + 0.277693 * std::sin(mp - f) +
                      0.173237 * std::sin(2 * d - f);
  const double omega = (125.04 - 1934.136 * t) * kDeg;
  const double eps = meanObliquity(t) + 0.00256 * std::cos(omega);
  const Equatorial q = toEquatorial(lambda, beta, eps);
  return {q.ra, q.dec};
}

SkyDirection moonDirection(double unix_s, double lat_deg, double lon_deg) {
  const EquatorialDirection q = moonEquatorial(unix_s);
  SkyDirection s = toHorizon({q.rightAscension_deg, q.declination_deg}, julianDate(unix_s), lat_deg, lon_deg);
  // Topocentric: the moon is ~60 Earth radii away, so it sits lower by its
  // horizontal parallax (0.95 deg mean) times cos(elevation).
  s.elevation_deg -= 0.9507 * std::cos(s.elevation_deg * kDeg);
  return s;
}

double moonPhaseAngle_deg(double unix_s) {
  const EquatorialDirection sun = sunEquatorial(unix_s), moon = moonEquatorial(unix_s);
  const double ds = sun.declination_deg * kDeg, dm = moon.declination_deg * kDeg;
  const double cosPsi = std::sin(ds) * std::sin(dm) +
                        std::cos(ds) * std::cos(dm) * std::cos((sun.rightAscension_deg - moon.rightAscension_deg) * kDeg);
  const double psi = std::acos(std::clamp(cosPsi, -1.0, 1.0));
  // tan i = R sin psi / (Delta - R cos psi) with Delta / R = 385000 / 149.6e6
  // (Meeus 48.3) is 180 - psi - (Delta / R) sin psi to first order.
  constexpr double kMoonOverSunDistance = 385000.56 / 149597870.7;
  return std::clamp(180.0 - psi / kDeg - kMoonOverSunDistance * std::sin(psi) / kDeg, 0.0, 180.0);
}

double moonToSunIlluminance(double phaseAngle_deg) {
  const double a = std::abs(phaseAngle_deg);
  const double moonMagnitude = -12.73 + 0.026 * a + 4e-9 * a * a * a * a;
  constexpr double kSunMagnitude = -26.74;
  return std::pow(10.0, -0.4 * (moonMagnitude - kSunMagnitude));
}

}  // namespace sky::render
