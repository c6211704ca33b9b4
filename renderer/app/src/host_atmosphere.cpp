// The host's global atmosphere (see host_atmosphere.hpp).
#include "sky/app/host_atmosphere.hpp"

#include <algorithm>

namespace sky::app {

const char* toString(AtmosphereSource source) {
  switch (source) {
    case AtmosphereSource::Cigi: return "cigi";
    case AtmosphereSource::FlightGear: return "flightgear";
    case AtmosphereSource::Default: break;
  }
  return "default";
}

HostAtmosphere atmosphereFrom(const cigi::AtmosphereControl& c) {
  HostAtmosphere a;
  a.source = AtmosphereSource::Cigi;
  a.visibility_m = std::max(double(c.visibility_m), kMinVisibility_m);
  a.humidity_pct = c.humidity_pct;
  a.seaLevelTemperature_c = c.airTemperature_c;
  a.seaLevelPressure_hpa = c.pressure_hpa;
  a.windSpeed_mps = c.horizontalWind_mps;
  a.windFrom_deg = c.windDirection_deg;
  a.verticalWind_mps = c.verticalWind_mps;
  return a;
}

HostAtmosphere withFlightGearVisibility(HostAtmosphere previous, double visibility_m) {
  previous.source = AtmosphereSource::FlightGear;
  previous.visibility_m = std::max(visibility_m, kMinVisibility_m);
  return previous;
}

}  // namespace sky::app
