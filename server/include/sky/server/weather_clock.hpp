// The server runs the one weather clock defined in protocol/ (every process
// advects clouds with it); this header keeps the server's names for it.
#pragma once

#include "sky/weather/clock.hpp"

namespace sky::server {

using WallClock = weather::WallClock;
using WeatherClock = weather::WeatherClock;

}  // namespace sky::server
