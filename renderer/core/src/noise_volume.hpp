// Tileable 3D noise for the cloud density, generated on the CPU,
// deterministically from a seed: the GPU uploads it as 3D textures (RGBA8
// shape, R8 detail), the CPU reference samples it here with the same
// trilinear-repeat filter.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace sky::render {

struct NoiseVolume {
  std::uint32_t size = 0;            // texels per edge
  std::uint32_t channels = 1;        // 1 (R8) or 4 (RGBA8)
  std::vector<std::uint8_t> texels;  // size^3 * channels unorm8, channels fastest, then x, y, z

  // Trilinear filtering with repeat addressing and texel centres at
  // (i + 0.5) / size, as Vulkan's linear sampler; uvw in periods (any value).
  // Channels beyond `channels` read 0.
  glm::dvec4 sample(const glm::dvec3& uvw) const;
};

// Edge of the shape texture, texels: 64^3 RGBA8 = 1 MiB, 78 m per texel at
// cumulus' 5 km period (lavapipe.md: RGBA8 costs no more per fetch than R8).
inline constexpr std::uint32_t kShapeNoiseSize = 64;
// Edge of the detail texture, texels: 32^3 R8 as Haggstrom 2018 (sec. 3.1.4),
// ~31 m per texel at cumulus' 1 km detail period.
inline constexpr std::uint32_t kDetailNoiseSize = 32;

// Versions of makeShapeNoise's and makeDetailNoise's output, part of their
// cache keys (noise_cache.hpp): bump one with any change that alters its
// texels. (A change that forgets is still caught by the cache's fingerprint:
// the noise at the fingerprint size.) Shape 2: the cloud model's RGBA8
// Perlin-Worley (1 was the skeleton's R8 noise).
inline constexpr std::uint32_t kShapeNoiseGeneratorVersion = 2;
inline constexpr std::uint32_t kDetailNoiseGeneratorVersion = 1;
// Edges of the fingerprint volumes: the smallest sizes the generators accept
// (the shape's finest Worley octave has 32 cells, the detail's 8): the shape
// fingerprint costs 1/8 of generating the full texture.
inline constexpr std::uint32_t kShapeNoiseFingerprintSize = 32;
inline constexpr std::uint32_t kDetailNoiseFingerprintSize = 8;

// Shape noise, each channel histogram-equalised so its values are uniform in
// [0, 1] (then the fraction of volume with noise > 1 - c is c, which makes
// "coverage" an area fraction):
//   R: Perlin-Worley (Schneider 2015: Perlin fBm dilated by Worley, then
//      Haggstrom 2018 eq. 11 with three finer Worley octaves): billowy cells
//   G: ridged Perlin fBm: thin ridges, the fibrous look of ice clouds
//   B: smooth Perlin fBm: the cloud map's coverage modulation
//   A: inverted Worley fBm: the cloud map's tall and low tops
NoiseVolume makeShapeNoise(std::uint32_t size, std::uint32_t seed);

// Detail noise, R: inverted Worley fBm of three octaves weighted 0.625, 0.25,
// 0.125 (Haggstrom 2018 eq. 13), histogram-equalised.
NoiseVolume makeDetailNoise(std::uint32_t size, std::uint32_t seed);

// The shape and detail textures at their sizes for a seed, as every renderer
// and CPU core uses them (cached_noise.cpp): loaded from the disk cache in
// cacheDir when it holds them, else generated (and written there when
// cacheDir is not empty); once per process for each folder and seed.
// *report, when given, gets what was done (appended, "; "-separated).
NoiseVolume shapeNoiseFor(const std::string& cacheDir, std::uint32_t seed, std::string* report = nullptr);
NoiseVolume detailNoiseFor(const std::string& cacheDir, std::uint32_t seed, std::string* report = nullptr);

}  // namespace sky::render
