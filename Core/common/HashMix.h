// SplitMix64's finaliser: the integer hash behind every deterministic random choice of the
// generator (its noise lattices) and of the simplification (paper Sec. 4.1's random
// candidates, each diamond's seed in the hierarchy build), the same bits on every machine.
// The one integer mixer of the project: use it, not another.
#pragma once

#include <cstdint>

namespace resmr
{

/// SplitMix64's increment (2^64 divided by the golden ratio).
constexpr uint64_t GoldenGamma = 0x9e3779b97f4a7c15ull;

inline uint64_t HashMix(uint64_t x)
{
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  x ^= x >> 31;
  return x;
}

} // namespace resmr
