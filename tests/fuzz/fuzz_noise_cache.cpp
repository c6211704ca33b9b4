// libFuzzer target: noise cache files (renderer/core, read from the cache
// folder at every start) on arbitrary bytes. The decoder may refuse, never
// crash, allocate from a damaged length or read out of bounds; a file it
// accepts re-encodes to exactly the input (one canonical layout), with the
// expected size^3 texels. Seeds: tests/fuzz/corpus/noise_cache/.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "sky/render/noise_cache.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The key the seeds were written for: a 4^3 "shape" volume.
  const sky::render::NoiseKey key{"shape", 1, 1, 4, 1, 0x0123456789abcdefull};
  const auto bytes = std::span(data, size);
  const auto texels = sky::render::decodeNoiseFile(bytes, key);
  if (!texels) return 0;
  if (texels->size() != 64) std::abort();
  const auto again = sky::render::encodeNoiseFile(key, *texels);
  if (again.size() != size || !std::equal(again.begin(), again.end(), data)) std::abort();
  return 0;
}
