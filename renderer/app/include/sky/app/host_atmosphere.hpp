// The global atmosphere a channel's host sets (CIGI Atmosphere Control, or
// FlightGear's visibility): the clear air's visibility, which becomes the
// haze of the view ray's air (FrameInputs::visibility_m), and the humidity,
// temperature and pressure the channel answers Environmental Conditions
// Requests with. The weather server's layers say where cloud is; inside
// cloud its extinction sets the visibility, outside it the host's value.
#pragma once

#include <optional>

#include "sky/cigi/packets.hpp"

namespace sky::app {

enum class AtmosphereSource { Default, Cigi, FlightGear };
// "default", "cigi", "flightgear" (frames.jsonl "atmosphere.source").
const char* toString(AtmosphereSource source);

// Without a host's atmosphere: humidity outside cloud (50 %; 100 % in
// cloud), visibility in clear air (50 km, the answers' value; the image
// keeps the standard aerosol, whose own range is 218 km), the ISA's sea level.
inline constexpr int kClearAirHumidity_pct = 50;
inline constexpr double kClearVisibility_m = 50000.0;
inline constexpr double kIsaSeaLevelTemperature_c = 15.0;
inline constexpr double kIsaSeaLevelPressure_hpa = 1013.25;
// The shortest visibility a host may set, m: CIGI and FlightGear allow 0,
// whose Koschmieder extinction is infinite. 10 m is thicker than any fog
// a runway visual range reports (RVR reporting stops at 50 m).
inline constexpr double kMinVisibility_m = 10.0;

struct HostAtmosphere {
  AtmosphereSource source = AtmosphereSource::Default;
  double visibility_m = kClearVisibility_m;  // clear air, sea level, >= kMinVisibility_m
  int humidity_pct = kClearAirHumidity_pct;  // clear air, [0, 100]
  // At sea level; the answers lapse them with the ISA to the asked altitude.
  double seaLevelTemperature_c = kIsaSeaLevelTemperature_c;
  double seaLevelPressure_hpa = kIsaSeaLevelPressure_hpa;
  // Atmosphere Control's global wind: the answers' wind where the weather
  // has no layers (the clouds move with the server's layer winds, and where
  // there are layers the answers give those).
  double windSpeed_mps = 0, windFrom_deg = 0, verticalWind_mps = 0;

  // The haze the image is drawn with: the host's visibility, none (the
  // standard aerosol) by default.
  std::optional<double> hazeVisibility_m() const {
    return source == AtmosphereSource::Default ? std::nullopt : std::optional(visibility_m);
  }
};

// The atmosphere of an Atmosphere Control (already range-checked by the
// decoder). Air temperature and pressure are taken as sea level's.
HostAtmosphere atmosphereFrom(const cigi::AtmosphereControl& control);

// `previous` with FlightGear's visibility (m, finite, >= 0) in it.
HostAtmosphere withFlightGearVisibility(HostAtmosphere previous, double visibility_m);

}  // namespace sky::app
