// Pressure altitude to geometric altitude in the ICAO standard atmosphere
// (standard_atmosphere.hpp), over the pressure functions of query.hpp.
#include "sky/weather/standard_atmosphere.hpp"

#include "sky/weather/query.hpp"

namespace sky::weather {

double isaGeometricAltitude_m(double geopotential_m) {
  return kIsaEarthRadius_m * geopotential_m / (kIsaEarthRadius_m - geopotential_m);
}

double pressureToGeometricAltitude_m(double pressureAltitude_m, double qnh_hpa) {
  // The altimeter's pressure altitude is a geopotential height in the
  // standard atmosphere; with QNH the same static pressure sits higher (QNH
  // above 1013.25) or lower in an atmosphere scaled by the ratio of the two.
  // With QNH 1013.25 the round trip returns the (clamped) pressure altitude.
  const double geopotential_m =
      isaAltitude_m(isaPressure_hpa(pressureAltitude_m) * kIsaSeaLevelPressure_hpa / qnh_hpa);
  return isaGeometricAltitude_m(geopotential_m);
}

}  // namespace sky::weather
