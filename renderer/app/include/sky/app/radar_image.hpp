// A headless replay's radar pictures (--radar): at each frame, the weather
// radar's reflectivity round the camera (weather::radarPicture over the
// snapshot the frame drew, at its weather clock), in the usual weather
// radar colours, written beside the frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sky/core/result.hpp"
#include "sky/geo/geodetic.hpp"
#include "sky/weather/model.hpp"

namespace sky::app {

// Cells a side of a replay's radar picture, and the tilt of its beam: an
// airborne radar's, level with the aircraft.
inline constexpr int kReplayRadarSize = 160;
inline constexpr double kReplayRadarTilt_deg = 0;

// The colour of a reflectivity (dBZ): none below 5 dBZ (black), then 5-dBZ
// steps from light blue through green, yellow and red to magenta and white
// over 70 (the scale weather radars show, NWS-like).
void radarColour(double dbz, std::uint8_t rgb[3]);

// dBZ per cell (radarPicture's layout) as RGB, with a grey ring at the range
// and a white dot at the radar.
std::vector<std::uint8_t> radarRgb(const std::vector<float>& dbz, int size);

// The picture round `at` (range_m) over the snapshot's layers at weather
// clock clock_s, written to path as a PNG.
Result<void> writeRadarPicture(const weather::WeatherSnapshot& snapshot, double clock_s, const geo::Geodetic& at,
                               double range_m, const std::string& path);

}  // namespace sky::app
