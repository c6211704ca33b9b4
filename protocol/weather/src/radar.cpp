// A weather radar's picture (see radar.hpp).
#include "sky/weather/radar.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/precipitation.hpp"

namespace sky::weather {

namespace {

// Standard refraction: the beam bends as if the Earth's radius were 4/3 of
// its mean (the radar equation's usual geometry, Doviak and Zrnic).
constexpr double kEffectiveEarthRadius_m = 4.0 / 3.0 * 6371000.0;
constexpr double kDegToRad = std::numbers::pi / 180.0;

}  // namespace

double radarBeamHeight_m(double slantRange_m, double tilt_deg) {
  const double r = slantRange_m, k = kEffectiveEarthRadius_m, s = std::sin(tilt_deg * kDegToRad);
  return std::sqrt(r * r + k * k + 2 * r * k * s) - k;
}

double radarGroundDistance_m(double slantRange_m, double tilt_deg) {
  const double k = kEffectiveEarthRadius_m, c = std::cos(tilt_deg * kDegToRad);
  return k * std::asin(std::clamp(slantRange_m * c / (k + radarBeamHeight_m(slantRange_m, tilt_deg)), -1.0, 1.0));
}

std::vector<float> radarPicture(std::span<const CloudLayer> layers, const CoverageLookup& lookup, const RadarSite& site) {
  const int n = std::max(site.size, 1);
  std::vector<float> out(static_cast<std::size_t>(n) * n, static_cast<float>(kNoEcho_dBZ));
  std::vector<CloudLayer> echoing;
  for (const CloudLayer& l : layers)
    if (isPrecipitation(l.type)) echoing.push_back(l);
  if (echoing.empty()) return out;
  const geo::EnuFrame enu = geo::enuFrameAt({site.lat_deg, site.lon_deg, 0});
  const double cell_m = 2 * site.range_m / n;
  for (int i = 0; i < n; ++i) {
    const double north = (0.5 * n - i - 0.5) * cell_m;
    for (int j = 0; j < n; ++j) {
      const double east = (j + 0.5 - 0.5 * n) * cell_m;
      const double ground_m = std::hypot(east, north);
      if (ground_m > site.range_m) continue;
      // The slant range whose beam has covered this ground distance (the two
      // differ by under 0.1 % at these tilts), then its height.
      double slant = ground_m;
      for (int k = 0; k < 3 && ground_m > 0; ++k)
        slant *= ground_m / std::max(radarGroundDistance_m(slant, site.tilt_deg), 1e-9);
      const double alt_m = site.alt_m + radarBeamHeight_m(slant, site.tilt_deg);
      // The cell's centre on the ellipsoid under its tangent-plane point
      // (gnomonic: 0.07 % short at 300 km).
      const geo::Geodetic at = geo::fromEcef(enu.originEcef_m + enu.east * east + enu.north * north);
      const PointWeather pw = weatherAt(echoing, lookup, at.lat_deg, at.lon_deg, alt_m);
      out[static_cast<std::size_t>(i) * n + j] =
          static_cast<float>(reflectivity_dBZ(pw.precipitationType, pw.precipitationRate_mmph));
    }
  }
  return out;
}

}  // namespace sky::weather
