// Advection along WGS84 geodesics (GeographicLib::Geodesic::Direct).
#include "sky/weather/advection.hpp"

#include <GeographicLib/Geodesic.hpp>

#include "sky/geo/geodetic.hpp"
#include "sky/weather/wind_field.hpp"

namespace sky::weather {

SurfacePoint advect(const SurfacePoint& p, const LayerWind& wind, double dt_s) {
  const double distance_m = wind.speed_mps * dt_s;
  if (distance_m == 0.0) return p;
  const double downwindAzimuth_deg = wind.fromDirection_deg + 180.0;
  SurfacePoint out;
  GeographicLib::Geodesic::WGS84().Direct(p.lat_deg, p.lon_deg, downwindAzimuth_deg, distance_m,
                                          out.lat_deg, out.lon_deg);
  out.lon_deg = geo::normalizeLon_deg(out.lon_deg);
  return out;
}

SurfacePoint upwindOf(const SurfacePoint& p, const WindVector& windAtP, double age_s) {
  return advect(p, fromVector(windAtP), -age_s);
}

}  // namespace sky::weather
