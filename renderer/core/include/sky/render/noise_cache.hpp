// Noise textures cached on disk: generated once from their seed, then loaded
// by every later start. A cache file is keyed by what determines its bytes
// (the noise kind, the generator's version, seed and size) plus a
// fingerprint of the generator (a hash of the same noise at a tiny size), so
// a change of the generator that forgot to bump its version still misses the
// cache. Files carry a checksum: a damaged or truncated file is detected and
// regenerated. Writes are atomic (temporary file, then rename).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "sky/core/result.hpp"

namespace sky::render {

struct NoiseKey {
  std::string kind;                     // file-name safe: [a-z0-9_-]
  std::uint32_t generatorVersion = 0;   // bumped whenever the generator's output changes
  std::uint32_t seed = 0;
  std::uint32_t size = 0;               // texels per edge of a cube
  std::uint32_t channels = 1;           // bytes per texel, [1, 4] (R8 ... RGBA8)
  std::uint64_t fingerprint = 0;        // fnv1a64 of the generator's output at a tiny size
};

// FNV-1a (64 bit) of the bytes: the file checksum and the fingerprint hash.
std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes);

// The file name for a key: <kind>-g<version>-s<seed>-n<size>-c<channels>-<fingerprint hex>.noise
std::string noiseFileName(const NoiseKey& key);

// File layout (little-endian): "SKYNOISE", u32 format version, u32 generator
// version, u32 seed, u32 size, u32 channels, u64 fingerprint, u64 payload
// length, u64 FNV-1a of the payload, u8 kind length, the kind, then the
// payload (size^3 texels of `channels` bytes).
std::vector<std::uint8_t> encodeNoiseFile(const NoiseKey& key, std::span<const std::uint8_t> texels);
// The payload of a file that holds exactly this key. Errors: Malformed with
// what is wrong (magic, format version, key field, length, checksum).
Result<std::vector<std::uint8_t>> decodeNoiseFile(std::span<const std::uint8_t> bytes, const NoiseKey& expected);

enum class NoiseSource {
  Generated,    // no cache file (or caching off): generated
  Loaded,       // read from the cache, not generated
  Regenerated,  // the cache file was unreadable or damaged: generated and rewritten
};

struct CachedNoise {
  std::vector<std::uint8_t> texels;
  NoiseSource source = NoiseSource::Generated;
  std::filesystem::path path;  // the cache file (empty when caching is off)
  std::string note;            // why it was regenerated, or why it could not be cached
};

// The texels for key from directory, or from generate() (which must return
// key.size^3 * key.channels bytes) when the file is missing or bad; a generated volume is
// written to the cache. Never fails: a cache that cannot be read or written
// costs a regeneration and says so in note. An empty directory turns caching
// off.
CachedNoise loadOrGenerateNoise(const std::filesystem::path& directory, const NoiseKey& key,
                                const std::function<std::vector<std::uint8_t>()>& generate);

// The default cache folder: $XDG_CACHE_HOME/skyshell, else $HOME/.cache/skyshell,
// else empty (no caching).
std::filesystem::path defaultCacheDirectory();

}  // namespace sky::render
