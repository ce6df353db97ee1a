// Perfect spatial hashing of the shell cells' properties, paper Sec. 5.4, after Lefebvre and
// Hoppe, "Perfect Spatial Hashing" (SIGGRAPH 2006): a sparse set S of (i, j, k) cells is packed
// into a dense table of m0 x m1 x m2 slots (at least |S|, nearly full) through a small offset
// table of r0 x r1 x r2 entries, so that a shader finds the slot of any cell of S with two
// 3D-texture reads.
//
// Contract:
// - Lookup (componentwise, p = (i, j, k), 0-based, Phi = offsets):
//     h(p) = (p mod m + Phi[p mod r]) mod m,   slot = h.x + m0 * (h.y + m1 * h.z),
//   with the offset entry q = (a, b, c) stored at offsets[a + r0 * (b + r1 * c)].
// - Perfect: distinct cells of S get distinct slots, all < m0 m1 m2. A cell outside S also
//   gets a slot (someone else's); callers that need membership must store keys in the table.
// - Tables need not be cubes (LH use cubes): sets as thin as a reservoir's shell (a few layers
//   deep) or as small as a few hundred cells leave a cube of the next side 1.3-1.5 times too
//   big. Tried in order of size, from |S| up to 1.25 |S| slots (a half percent apart; sets
//   over 2^18 cells, where a failed packing costs seconds, from 1.06 |S| three percent apart
//   and fewer shapes): tables shaped like the set's box, as deep as the set with the lateral
//   sides in proportion, near cubes, and the box itself with the identity map; offset tables
//   of |S| / 6 entries (LH's sigma = 1 / (2 d)), then |S| / 4, shaped like the set or cubic,
//   each side coprime with the table's on that axis. The real models' sets fill 0.80-0.99 of
//   their tables (bench/results/build.md).
// - Last resort, for sets spread wider than any such table separates (two cells that agree
//   modulo m r on every axis share a slot: a long line, far-apart cells): cubes growing
//   without bound, offset tables growing up to the table.
// - Every side is at most MaxSide (3D textures every OpenGL 4 offers) and every slot number
//   fits 32 bits.
// - Groups are packed by next fit in a fixed order, no randomness: the result depends on the
//   set of cells only, not on their order.
// - Memory O(|S| + r0 r1 r2) words and m0 m1 m2 bits during construction; the result holds
//   the offsets.
// - Throws std::invalid_argument for a cell listed twice (named 1-based, as Eclipse users
//   count) and for sets no table within MaxSide can hold (a line of millions of cells).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

struct PerfectSpatialHash
{
  using Sides = std::array<uint32_t, 3>;
  /// Largest side of either table: 3D textures of 2048 texels a side are what every OpenGL 4
  /// implementation must offer (GL_MAX_3D_TEXTURE_SIZE), and offsets fit 16 bits.
  static constexpr uint32_t MaxSide = 2048;
  /// Most slots a table may have: slot numbers fit 32 bits.
  static constexpr uint64_t MaxTableSize = 0xFFFFFFFFu;

  Sides tableSides{ 1, 1, 1 };                  // m
  Sides offsetSides{ 1, 1, 1 };                 // r
  std::vector<std::array<uint16_t, 3>> offsets; // r0 r1 r2 entries, component a < m[a]
  uint32_t attempts = 0;                        // packings tried; diagnostic only

  uint64_t TableSize() const { return uint64_t(tableSides[0]) * tableSides[1] * tableSides[2]; }
  uint64_t OffsetTableSize() const { return uint64_t(offsetSides[0]) * offsetSides[1] * offsetSides[2]; }

  /// h(p) as in the contract; defined for any cell of a built hash.
  uint64_t Slot(uint32_t i, uint32_t j, uint32_t k) const
  {
    const Sides& m = this->tableSides;
    const Sides& r = this->offsetSides;
    const std::array<uint16_t, 3>& phi = offsets[i % r[0] + uint64_t(r[0]) * (j % r[1] + uint64_t(r[1]) * (k % r[2]))];
    const uint64_t x = (i % m[0] + phi[0]) % m[0], y = (j % m[1] + phi[1]) % m[1], z = (k % m[2] + phi[2]) % m[2];
    return x + m[0] * (y + m[1] * z);
  }
};

/// Builds a perfect hash of `cells` (0-based (i, j, k), distinct). An empty set gives a table
/// and an offset table of one entry.
PerfectSpatialHash BuildPerfectSpatialHash(const std::vector<std::array<uint32_t, 3>>& cells);

/// One packing with the given sides (each side coprime with the other table's side on that
/// axis, both at most MaxSide): false when it fails or when two cells agree in both h0 and h1.
/// What BuildPerfectSpatialHash tries, for callers exploring table shapes.
bool PackPerfectSpatialHash(const std::vector<std::array<uint32_t, 3>>& cells,
  const PerfectSpatialHash::Sides& tableSides, const PerfectSpatialHash::Sides& offsetSides, PerfectSpatialHash& hash);

/// The slot of every cell, in the order given: the caller scatters per-cell values into a
/// table of TableSize() entries at these slots.
std::vector<uint64_t> CellSlots(const PerfectSpatialHash& hash, const std::vector<std::array<uint32_t, 3>>& cells);

} // namespace resmr
