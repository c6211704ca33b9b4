// Tileable 3D shape noise for the cloud density, generated on the CPU,
// deterministically from a seed: the GPU uploads it as an R8 3D texture, the
// CPU reference samples it here with the same trilinear-repeat filter.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace sky::render {

struct NoiseVolume {
  std::uint32_t size = 0;            // texels per edge
  std::vector<std::uint8_t> texels;  // size^3 unorm8, x fastest, then y, then z

  // Trilinear filtering with repeat addressing and texel centres at
  // (i + 0.5) / size, as Vulkan's linear sampler; uvw in periods (any value).
  double sample(const glm::dvec3& uvw) const;
};

// Edge of the noise texture, texels: 64^3 = 256 KiB at R8, 78 m per texel at
// the renderer's 5 km period; enough for the skeleton's single shape octave.
inline constexpr std::uint32_t kNoiseSize = 64;

// Version of makeShapeNoise's output, part of its cache key (noise_cache.hpp):
// bump it with any change that alters the texels. (A change that forgets is
// still caught by the cache's fingerprint: the noise at kNoiseFingerprintSize.)
inline constexpr std::uint32_t kShapeNoiseGeneratorVersion = 1;
// Edge of the fingerprint volume: the smallest size the generator accepts
// (its finest Worley octave has 16 cells), 4096 texels, about 1 ms.
inline constexpr std::uint32_t kNoiseFingerprintSize = 16;

// Worley (inverted F1, three octaves) blended with value-noise fBm, then
// histogram-equalised so the values are uniform in [0, 1]: the fraction of
// volume with noise > 1 - c is c, which makes "coverage" an area fraction.
NoiseVolume makeShapeNoise(std::uint32_t size, std::uint32_t seed);

}  // namespace sky::render
