// SplitMix64 (Steele, Lea and Flood 2014): the golden-ratio increment, then
// a finaliser that is a bijection of 64-bit words and scatters every input
// bit. Turns (seed, index) words into independent-looking numbers (the
// lightning process, the drops near the camera) and steps a seed's stream
// (the blue-noise tile).
#pragma once

#include <cstdint>

namespace sky {

inline constexpr std::uint64_t kSplitMixIncrement = 0x9e3779b97f4a7c15ull;

constexpr std::uint64_t splitMix64(std::uint64_t x) {
  x += kSplitMixIncrement;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace sky
