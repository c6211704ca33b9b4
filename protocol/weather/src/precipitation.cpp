// Precipitation's rate, extinction and reflectivity (see precipitation.hpp).
#include "sky/weather/precipitation.hpp"

#include <algorithm>
#include <cmath>

#include "sky/weather/query.hpp"

namespace sky::weather {
namespace {

// sigma = a R^b, sigma in 1/m.
struct PowerLaw {
  double a_perm;
  double b;
};

constexpr PowerLaw kRain{0.25e-3, 0.63};
constexpr PowerLaw kSnow{3.5e-3, 0.7};

double extinctionOf(PowerLaw law, double rate_mmph) { return law.a_perm * std::pow(rate_mmph, law.b); }

double rateOf(PowerLaw law, double extinction_perm) { return std::pow(extinction_perm / law.a_perm, 1.0 / law.b); }

}  // namespace

bool isPrecipitation(CloudType type) {
  return type == CloudType::Rain || type == CloudType::Snow || type == CloudType::Sleet || type == CloudType::Hail;
}

double precipitationExtinction_perm(CloudType type, double rate_mmph) {
  if (!isPrecipitation(type) || !(rate_mmph > 0)) return 0;
  const double r = std::min(rate_mmph, 1000.0);
  switch (type) {
    case CloudType::Snow: return extinctionOf(kSnow, r);
    case CloudType::Sleet: return 0.5 * (extinctionOf(kRain, r) + extinctionOf(kSnow, r));
    default: return extinctionOf(kRain, r);
  }
}

double precipitationRate_mmph(CloudType type, double extinction_perm) {
  if (!isPrecipitation(type) || !(extinction_perm > 0)) return 0;
  switch (type) {
    case CloudType::Snow: return rateOf(kSnow, extinction_perm);
    case CloudType::Sleet: {
      // The mean of two increasing laws: bisect on log R (R in 1e-4 .. 1e4).
      double lo = -4, hi = 4;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (precipitationExtinction_perm(type, std::pow(10.0, mid)) < extinction_perm ? lo : hi) = mid;
      }
      return std::pow(10.0, 0.5 * (lo + hi));
    }
    default: return rateOf(kRain, extinction_perm);
  }
}

double precipitationDensityForRate(CloudType type, double rate_mmph) {
  return std::clamp(precipitationExtinction_perm(type, rate_mmph) / kPrecipitationExtinctionPerDensity_perm, 0.0, 1.0);
}

double precipitationRateForDensity(CloudType type, double density) {
  return precipitationRate_mmph(type, kPrecipitationExtinctionPerDensity_perm * std::clamp(density, 0.0, 1.0));
}

double precipitationDensityForVisibility(double visibility_m) {
  if (!(visibility_m > 0)) return 1.0;
  return std::clamp(kKoschmiederDepth / (kPrecipitationExtinctionPerDensity_perm * visibility_m), 0.0, 1.0);
}

double reflectivity_dBZ(CloudType type, double rate_mmph) {
  if (!isPrecipitation(type) || !(rate_mmph > 0)) return kNoEcho_dBZ;
  const double rain = 200.0 * std::pow(rate_mmph, 1.6), snow = 2000.0 * std::pow(rate_mmph, 2.0);
  const double z = type == CloudType::Snow ? snow : type == CloudType::Sleet ? 0.5 * (rain + snow) : rain;
  return 10.0 * std::log10(z);
}

double fallSpeed_mps(CloudType type) {
  switch (type) {
    case CloudType::Rain: return 6.0;
    case CloudType::Snow: return 1.0;
    case CloudType::Sleet: return 4.0;
    case CloudType::Hail: return 12.0;
    default: return 0.0;
  }
}

double precipitationWater_gpm3(CloudType type, double rate_mmph) {
  const double v = fallSpeed_mps(type);
  return v > 0 && rate_mmph > 0 ? rate_mmph / (3.6 * v) : 0.0;
}

}  // namespace sky::weather
