// A tileable blue-noise tile for the march's per-pixel step offset
// (MarchSettings::jitter): void-and-cluster (Ulichney 1993, "The
// void-and-cluster method for dither array generation"), deterministic
// from a seed. Every value (k + 0.5) / n of the tile's n pixels occurs
// once, and neighbouring pixels hold values far apart, so the march's
// banding turns into noise of high spatial frequency, which averages out
// over a few pixels (and is what the eye and SSIM forgive most).
#pragma once

#include <cstdint>
#include <vector>

#include "sky_shared.h"

namespace sky::render {

// Pixels per edge of the tile the cloud pass repeats over the image.
inline constexpr std::uint32_t kBlueNoiseSize = gpu::kBlueNoiseSize;

// size x size values in [0, 1), row-major; size a power of two >= 4. The
// same (size, seed) gives the same tile. ~50 ms at 64 in Release.
std::vector<float> makeBlueNoise(std::uint32_t size, std::uint32_t seed);

// The tile for the renderer (kBlueNoiseSize, this seed), made once per
// process and seed.
const std::vector<float>& blueNoiseTile(std::uint32_t seed);

}  // namespace sky::render
