// The shape and detail textures for a seed, from the disk cache
// (noise_cache.hpp) or generated: what the GPU renderer uploads and what the
// CPU core samples (noise_volume.hpp).
#include <map>
#include <mutex>
#include <string>
#include <tuple>

#include "sky/core/assert.hpp"
#include "sky/render/noise_cache.hpp"

#include "noise_volume.hpp"

namespace sky::render {

namespace {

// A noise texture from the cache in cacheDir when it holds it, else from
// generate(size, seed) (and written to the cache); *report says which. The
// fingerprint is the generator's output at fingerprintSize; its bytes per
// texel give the channel count.
NoiseVolume loadOrGenerate(const std::string& cacheDir, std::uint32_t seed, const char* kind,
                           std::uint32_t generatorVersion, std::uint32_t size, std::uint32_t fingerprintSize,
                           NoiseVolume (*generate)(std::uint32_t, std::uint32_t), std::string& report) {
  const std::string what = std::string(kind) + " noise " + std::to_string(size) + "^3 seed " + std::to_string(seed);
  if (cacheDir.empty()) {
    report = what + ": generated (no cache)";
    return generate(size, seed);
  }
  const NoiseVolume tiny = generate(fingerprintSize, seed);
  const std::size_t tinyTexels = std::size_t(fingerprintSize) * fingerprintSize * fingerprintSize;
  SKY_ASSERT(tinyTexels > 0 && tiny.texels.size() % tinyTexels == 0);
  const NoiseKey key{kind, generatorVersion, seed, size, static_cast<std::uint32_t>(tiny.texels.size() / tinyTexels),
                     fnv1a64(tiny.texels)};
  CachedNoise cached = loadOrGenerateNoise(cacheDir, key, [&] { return generate(size, seed).texels; });
  const char* how = cached.source == NoiseSource::Loaded        ? "loaded from "
                    : cached.source == NoiseSource::Regenerated ? "regenerated into "
                    : cached.path.empty()                       ? "generated (no cache)"
                                                                : "generated into ";
  report = what + ": " + how + cached.path.string() + (cached.note.empty() ? "" : " (" + cached.note + ")");
  NoiseVolume volume;
  volume.size = size;
  volume.channels = key.channels;
  volume.texels = std::move(cached.texels);
  return volume;
}

// The texture once per process for each (cache folder, kind, version,
// seed, size): a process creating many renderers (the bench: one per case)
// or a renderer and its exposure meters' CPU references neither regenerates
// it (~1 s in Release) nor reads and fingerprints the cache file again.
// *report gets what was done the first time.
NoiseVolume cachedNoise(const std::string& cacheDir, std::uint32_t seed, const char* kind,
                        std::uint32_t generatorVersion, std::uint32_t size, std::uint32_t fingerprintSize,
                        NoiseVolume (*generate)(std::uint32_t, std::uint32_t), std::string* report) {
  struct Made {
    NoiseVolume volume;
    std::string report;
  };
  static std::mutex mutex;
  static std::map<std::tuple<std::string, std::string, std::uint32_t, std::uint32_t, std::uint32_t>, Made> made;
  const std::lock_guard lock(mutex);
  const auto key = std::make_tuple(cacheDir, std::string(kind), generatorVersion, seed, size);
  auto it = made.find(key);
  if (it == made.end()) {
    Made m;
    m.volume = loadOrGenerate(cacheDir, seed, kind, generatorVersion, size, fingerprintSize, generate, m.report);
    it = made.emplace(key, std::move(m)).first;
  }
  if (report) *report += std::string(report->empty() ? "" : "; ") + it->second.report;
  return it->second.volume;
}

}  // namespace

NoiseVolume shapeNoiseFor(const std::string& cacheDir, std::uint32_t seed, std::string* report) {
  return cachedNoise(cacheDir, seed, "shape", kShapeNoiseGeneratorVersion, kShapeNoiseSize, kShapeNoiseFingerprintSize,
                     makeShapeNoise, report);
}

NoiseVolume detailNoiseFor(const std::string& cacheDir, std::uint32_t seed, std::string* report) {
  return cachedNoise(cacheDir, seed, "detail", kDetailNoiseGeneratorVersion, kDetailNoiseSize,
                     kDetailNoiseFingerprintSize, makeDetailNoise, report);
}

}  // namespace sky::render
