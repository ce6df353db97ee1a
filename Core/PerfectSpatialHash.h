// Perfect spatial hashing of the shell cells' properties, paper Sec. 5.4, after Lefebvre and
// Hoppe, "Perfect Spatial Hashing" (SIGGRAPH 2006): a sparse set S of (i, j, k) cells is packed
// into a dense cubic table of side m (m^3 >= |S|, nearly full) through a small cubic offset
// table of side r, so that a shader finds the slot of any cell of S with two texture reads.
//
// Contract:
// - Lookup (componentwise, p = (i, j, k), 0-based, Phi = offsets):
//     h(p) = (p mod m + Phi[p mod r]) mod m,   slot = h.x + m * (h.y + m * h.z),
//   with the offset entry q = (a, b, c) stored at offsets[a + r * (b + r * c)].
// - Perfect: distinct cells of S get distinct slots, all < m^3. A cell outside S also gets a
//   slot (someone else's); callers that need membership must store keys in the table.
// - m starts at the smallest side with m^3 >= |S|, r at ceil((|S| / 6)^(1/3)) (LH's sigma =
//   1 / (2 d)), coprime with m. When packing fails r grows (up to about |S| / 4 entries), then
//   m by one (sets over 2^20 cells: one packing a side, m by a sixty-fourth, about 5% of
//   table, since each failed packing costs seconds); when two cells agree modulo m * r in every component (cells spread wider than
//   m * r, e.g. a long line) no offsets can separate them and r, then m, grow until they
//   differ. IJK shells (planes of cells) fill 0.92-1.0 of the table with r^3 ~ |S| / 5; the
//   cells real builds touch (thin sets, nz < r) fill 0.69-0.95 (bench/results/build.md).
//   Every offset component is < m <= MaxTableSide, so m^3 < 2^32.
// - Groups are packed by next fit in a fixed order, no randomness: the result depends on the
//   set of cells only, not on their order.
// - Memory O(|S| + r^3) words and m^3 bits during construction; the result holds r^3 offsets.
// - Throws std::invalid_argument for a cell listed twice (named 1-based, as Eclipse users
//   count) and for sets no table of side MaxTableSide can hold (a line of millions of cells).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

struct PerfectSpatialHash
{
  /// Largest table side: m^3 fits in 32 bits.
  static constexpr uint32_t MaxTableSide = 1625;

  uint32_t tableSide = 0;  // m
  uint32_t offsetSide = 0; // r
  std::vector<std::array<uint16_t, 3>> offsets; // r^3 entries, each component < m
  uint32_t attempts = 0; // (m, r) pairs tried; diagnostic only

  uint64_t TableSize() const { return uint64_t(tableSide) * tableSide * tableSide; }
  uint64_t OffsetTableSize() const { return uint64_t(offsetSide) * offsetSide * offsetSide; }

  /// h(p) as in the contract; defined for any cell of a built hash.
  uint64_t Slot(uint32_t i, uint32_t j, uint32_t k) const
  {
    const uint32_t m = tableSide, r = offsetSide;
    const std::array<uint16_t, 3>& phi = offsets[i % r + uint64_t(r) * (j % r + uint64_t(r) * (k % r))];
    const uint64_t x = (i % m + phi[0]) % m, y = (j % m + phi[1]) % m, z = (k % m + phi[2]) % m;
    return x + m * (y + m * z);
  }
};

/// Builds a perfect hash of `cells` (0-based (i, j, k), distinct). An empty set gives m = r = 1.
PerfectSpatialHash BuildPerfectSpatialHash(const std::vector<std::array<uint32_t, 3>>& cells);

/// The slot of every cell, in the order given: the caller scatters per-cell values into a
/// table of TableSize() entries at these slots.
std::vector<uint64_t> CellSlots(const PerfectSpatialHash& hash,
  const std::vector<std::array<uint32_t, 3>>& cells);

} // namespace resmr
