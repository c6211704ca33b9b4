// The renderer draws at most render::kMaxLayers (4) cloud layers; the server
// may hold more (an operator can add up to 32). The channel draws the layers
// that matter most and says what it left out, instead of refusing the frame.
#pragma once

#include <cstddef>
#include <vector>

#include "sky/weather/model.hpp"

namespace sky::app {

// The snapshot with at most maxLayers layers: fog with any cover first, then
// those with the most cloud (coverage x density, the layer's own or its
// densest tile's), ties by lower id; their tiles only. `dropped` gets the ids left out (empty when all fit).
// Layer order is kept.
weather::WeatherSnapshot drawableWeather(const weather::WeatherSnapshot& snapshot, std::size_t maxLayers,
                                         std::vector<std::uint32_t>* dropped = nullptr);

// The coarse area's snapshot cut to the layers `drawable` (the detailed
// area's drawableWeather) draws, so both rings of the map hold the same
// layers whatever the coarse area's own ranking would be.
weather::WeatherSnapshot drawableCoarse(const weather::WeatherSnapshot& coarse, const weather::WeatherSnapshot& drawable);

}  // namespace sky::app
