// SplitMix64's finaliser: the integer hash behind every deterministic random choice of the
// generator (its noise lattices) and of the simplification (paper Sec. 4.1's random
// candidates), the same bits on every machine.
#pragma once

#include <cstdint>

namespace resmr
{

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
