// Perfect spatial hash construction, paper Sec. 5.4 (Lefebvre and Hoppe 2006, Sec. 4).
#include "PerfectSpatialHash.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace resmr
{
namespace
{
using Cell = std::array<uint32_t, 3>;
using Sides = PerfectSpatialHash::Sides;

uint64_t CeilCbrt(uint64_t n)
{
  uint64_t c = static_cast<uint64_t>(std::llround(std::cbrt(static_cast<double>(n))));
  while (c * c * c < n)
  {
    ++c;
  }
  while (c > 0 && (c - 1) * (c - 1) * (c - 1) >= n)
  {
    --c;
  }
  return c;
}

uint32_t CoprimeAtLeast(uint32_t m, uint64_t r)
{
  r = std::max<uint64_t>(r, 1);
  while (std::gcd(uint64_t(m), r) != 1)
  {
    ++r;
  }
  return static_cast<uint32_t>(std::min<uint64_t>(r, UINT32_MAX));
}

int LowestBit(uint64_t word)
{
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctzll(word);
#else
  int bit = 0;
  while (!(word & 1))
  {
    word >>= 1;
    ++bit;
  }
  return bit;
#endif
}

[[noreturn]] void ThrowDuplicate(const Cell& c)
{
  throw std::invalid_argument("perfect spatial hash: cell (" + std::to_string(uint64_t(c[0]) + 1) + ", " +
    std::to_string(uint64_t(c[1]) + 1) + ", " + std::to_string(uint64_t(c[2]) + 1) + ") listed twice");
}

/// The first cell listed twice, thrown; `n` agrees with an earlier cell in every residue.
void ThrowIfListedBefore(const std::vector<Cell>& cells, std::size_t n)
{
  if (std::find(cells.begin(), cells.begin() + static_cast<std::ptrdiff_t>(n), cells[n]) !=
    cells.begin() + static_cast<std::ptrdiff_t>(n))
  {
    ThrowDuplicate(cells[n]);
  }
}

/// Whether no two cells agree modulo `modulus` on every axis. Residues are marked in a bitset
/// when their space is at most 64 bits a cell (a shell in its box: a bit or two a cell), so
/// that the largest sets need no per-cell keys; else (sparse sets) keys are sorted. A cell
/// listed twice throws when it is the collision found; sorting finds every one.
bool ResiduesDistinct(const std::vector<Cell>& cells, const std::array<uint64_t, 3>& modulus)
{
  if (cells.empty())
  {
    return true;
  }
  // One pass for the box (this runs once a table shape tried, over every cell).
  Cell low{ UINT32_MAX, UINT32_MAX, UINT32_MAX }, high{ 0, 0, 0 };
  for (const Cell& c : cells)
  {
    for (int a = 0; a < 3; ++a)
    {
      low[a] = std::min(low[a], c[a]);
      high[a] = std::max(high[a], c[a]);
    }
  }
  std::array<uint64_t, 3> span;
  double space = 1;
  for (int a = 0; a < 3; ++a)
  {
    span[a] = std::min<uint64_t>(modulus[a], uint64_t(high[a]) - low[a] + 1);
    space *= static_cast<double>(span[a]);
  }
  const auto residue = [&](const Cell& c, int a) { return (uint64_t(c[a]) - low[a]) % modulus[a]; };
  if (space <= 64.0 * static_cast<double>(cells.size()) + 4096)
  {
    std::vector<uint64_t> seen(static_cast<std::size_t>((static_cast<uint64_t>(space) + 63) / 64), 0);
    for (std::size_t n = 0; n < cells.size(); ++n)
    {
      const uint64_t key = residue(cells[n], 0) + span[0] * (residue(cells[n], 1) + span[1] * residue(cells[n], 2));
      uint64_t& word = seen[static_cast<std::size_t>(key >> 6)];
      if (word >> (key & 63) & 1)
      {
        ThrowIfListedBefore(cells, n);
        return false;
      }
      word |= uint64_t(1) << (key & 63);
    }
    return true;
  }
  std::vector<std::pair<Cell, uint32_t>> keyed(cells.size());
  for (uint32_t n = 0; n < cells.size(); ++n)
  {
    const Cell& c = cells[n];
    keyed[n] = { { uint32_t(residue(c, 0)), uint32_t(residue(c, 1)), uint32_t(residue(c, 2)) }, n };
  }
  std::sort(keyed.begin(), keyed.end());
  bool distinct = true;
  for (std::size_t n = 1; n < keyed.size(); ++n)
  {
    if (keyed[n].first == keyed[n - 1].first)
    {
      if (cells[keyed[n].second] == cells[keyed[n - 1].second])
      {
        ThrowDuplicate(cells[keyed[n].second]);
      }
      distinct = false; // keep looking: a duplicate elsewhere is the caller's error, not ours
    }
  }
  return distinct;
}

/// Whether no two cells agree modulo m[a] r[a] on every axis a. With gcd(m[a], r[a]) = 1 that
/// is (by the Chinese remainder theorem) whether (h0, h1) = (p mod m, p mod r) is injective on
/// the cells, which LH require: cells agreeing in both share an entry and hence a slot.
bool Separable(const std::vector<Cell>& cells, const Sides& m, const Sides& r)
{
  return ResiduesDistinct(cells, { uint64_t(m[0]) * r[0], uint64_t(m[1]) * r[1], uint64_t(m[2]) * r[2] });
}

/// One construction with sides m and r (LH Sec. 4.2): cells grouped by offset entry h1, groups
/// placed largest first, each at the first offset that puts all its cells in free slots.
///
/// The search runs in permuted table coordinates u = g x mod m, g = r^-1 mod m (a bijection of
/// the table), where a cell p = r s + a (a = p mod r) lands at (g a + s + g Phi[a]) mod m: a
/// group is its set of blocks s = p div r, translated. The groups of a plane of cells are all
/// the same box of blocks; packing them corner to corner in raster order (next fit, from where
/// the last group of the same size went) fills IJK shells nearly full, where LH's randomised
/// search leaves gaps that only a larger table absorbs.
class Packing
{
public:
  Packing(const std::vector<Cell>& cells, const Sides& m, const Sides& r)
    : Cells(cells)
    , M(m)
    , R(r)
    , Slots(m[0] * m[1] * m[2])
  {
    for (int a = 0; a < 3; ++a)
    {
      while ((uint64_t(this->G[a]) * r[a]) % m[a] != 1 % m[a])
      {
        ++this->G[a];
      }
    }
  }

  bool Run(PerfectSpatialHash& result)
  {
    this->Group();
    this->Occupied.assign((this->Slots + 63) / 64, 0);
    if (this->Slots % 64)
    {
      this->Occupied.back() = ~uint64_t(0) << (this->Slots % 64); // past the table: never free
    }
    result.tableSides = this->M;
    result.offsetSides = this->R;
    result.offsets.assign(this->R[0] * this->R[1] * this->R[2], { 0, 0, 0 });
    for (uint32_t q : this->Order)
    {
      if (!this->Place(q, result.offsets))
      {
        return false;
      }
    }
    return true;
  }

private:
  uint32_t Entry(const Cell& c) const
  {
    return c[0] % this->R[0] + this->R[0] * (c[1] % this->R[1] + this->R[1] * (c[2] % this->R[2]));
  }

  /// Counting sort of the cells by entry; the non-empty entries, largest group first (ties by
  /// entry, so that the result ignores the input order).
  void Group()
  {
    const uint32_t entries = this->R[0] * this->R[1] * this->R[2];
    this->First.assign(entries + 1, 0);
    for (const Cell& c : this->Cells)
    {
      ++this->First[this->Entry(c) + 1];
    }
    std::partial_sum(this->First.begin(), this->First.end(), this->First.begin());
    std::vector<uint32_t> cursor(this->First.begin(), this->First.end() - 1);
    this->Members.resize(this->Cells.size());
    for (uint32_t index = 0; index < this->Cells.size(); ++index)
    {
      this->Members[cursor[this->Entry(this->Cells[index])]++] = index;
    }
    this->Order.clear();
    for (uint32_t q = 0; q < entries; ++q)
    {
      if (this->First[q + 1] > this->First[q])
      {
        this->Order.push_back(q);
      }
    }
    std::sort(this->Order.begin(), this->Order.end(), [this](uint32_t a, uint32_t b) {
      const uint32_t sizeA = this->First[a + 1] - this->First[a], sizeB = this->First[b + 1] - this->First[b];
      return sizeA != sizeB ? sizeA > sizeB : a < b;
    });
  }

  bool Free(uint32_t slot) const { return !(this->Occupied[slot >> 6] >> (slot & 63) & 1); }

  uint32_t Wrap(uint32_t value, int axis) const { return value >= this->M[axis] ? value - this->M[axis] : value; }

  /// The permuted slot of a cell of permuted h0 `h` under permuted offset `psi`.
  uint32_t SlotOf(const Sides& h, const Sides& psi) const
  {
    const uint32_t x = this->Wrap(h[0] + psi[0], 0), y = this->Wrap(h[1] + psi[1], 1);
    return x + this->M[0] * (y + this->M[1] * this->Wrap(h[2] + psi[2], 2));
  }

  /// Whether offset psi (permuted) puts every cell of the current group in a free slot.
  bool Fits(const Sides& psi) const
  {
    for (const Sides& h : this->H0)
    {
      if (!this->Free(this->SlotOf(h, psi)))
      {
        return false;
      }
    }
    return true;
  }

  /// Cell n of the current group shares its h0 (and entry) with an earlier one: only a
  /// duplicate can, as the caller made (h0, h1) injective on distinct cells.
  [[noreturn]] void ThrowShared(std::size_t n) const
  {
    const Cell& cell = this->Cells[this->H0Cells[n]];
    for (std::size_t other = 0; other < n; ++other)
    {
      if (this->H0[other] == this->H0[n] && this->Cells[this->H0Cells[other]] == cell)
      {
        ThrowDuplicate(cell);
      }
    }
    throw std::logic_error("perfect spatial hash: distinct cells share an entry and a slot");
  }

  bool Place(uint32_t q, std::vector<std::array<uint16_t, 3>>& offsets)
  {
    const Sides& m = this->M;
    const uint32_t begin = this->First[q], end = this->First[q + 1];
    // Permuted h0; the member with the least block (the corner of a box of blocks) first, as
    // the anchor that the search puts in free slots.
    this->H0.clear();
    this->H0Cells.clear();
    std::size_t anchor = 0;
    Cell least{};
    for (uint32_t n = begin; n < end; ++n)
    {
      const Cell& c = this->Cells[this->Members[n]];
      Sides h;
      for (int a = 0; a < 3; ++a)
      {
        h[a] = uint32_t(uint64_t(this->G[a]) * (c[a] % m[a]) % m[a]);
      }
      this->H0.push_back(h);
      this->H0Cells.push_back(this->Members[n]);
      const Cell block{ c[2] / this->R[2], c[1] / this->R[1], c[0] / this->R[0] };
      if (n == begin || block < least)
      {
        least = block;
        anchor = n - begin;
      }
    }
    std::swap(this->H0[0], this->H0[anchor]);
    std::swap(this->H0Cells[0], this->H0Cells[anchor]);
    if (end - begin != this->LastSize)
    {
      this->LastSize = end - begin;
      this->Resume = 0;
    }
    // Every offset that puts the anchor in a free slot, from Resume on, wrapping: the search
    // fails only when no offset exists.
    const Sides& h = this->H0[0];
    const uint64_t words = this->Occupied.size();
    const uint32_t start = this->Resume;
    uint64_t w = start >> 6;
    uint64_t word = ~this->Occupied[w] & (~uint64_t(0) << (start & 63));
    for (uint64_t visited = 0; visited <= words;)
    {
      while (word)
      {
        const uint32_t slot = static_cast<uint32_t>(w * 64 + LowestBit(word));
        word &= word - 1;
        const uint32_t x = slot % m[0], y = slot / m[0] % m[1], z = slot / m[0] / m[1];
        const Sides psi{ this->Wrap(x + m[0] - h[0], 0), this->Wrap(y + m[1] - h[1], 1),
          this->Wrap(z + m[2] - h[2], 2) };
        if (this->Fits(psi))
        {
          for (std::size_t n = 0; n < this->H0.size(); ++n)
          {
            const uint32_t taken = this->SlotOf(this->H0[n], psi);
            if (!this->Free(taken))
            {
              this->ThrowShared(n); // free before this group: another of its cells took it
            }
            this->Occupied[taken >> 6] |= uint64_t(1) << (taken & 63);
          }
          // Back to table coordinates: Phi = r psi.
          for (int a = 0; a < 3; ++a)
          {
            offsets[q][a] = static_cast<uint16_t>(uint64_t(this->R[a]) * psi[a] % m[a]);
          }
          this->Resume = slot;
          return true;
        }
      }
      ++visited;
      w = w + 1 == words ? 0 : w + 1;
      word = ~this->Occupied[w];
      if (visited == words)
      {
        word &= (uint64_t(1) << (start & 63)) - 1; // the start word's slots before start
      }
    }
    return false;
  }

  const std::vector<Cell>& Cells;
  const Sides M, R;
  const uint32_t Slots;
  Sides G{};                      // r^-1 mod m, per axis
  std::vector<uint32_t> First;    // group q is Members[First[q] .. First[q + 1])
  std::vector<uint32_t> Members;  // cell indices grouped by entry
  std::vector<uint32_t> Order;    // non-empty entries, largest group first
  std::vector<uint64_t> Occupied; // permuted slots taken
  std::vector<Sides> H0;          // the current group's permuted h0, anchor first
  std::vector<uint32_t> H0Cells;  // and its cells
  uint32_t LastSize = 0;          // size of the last group placed
  uint32_t Resume = 0;            // where its anchor went
};

/// The largest table tried before cubes grow without bound: the packed-texture target.
constexpr double MaxFill = 1.25;

/// Side lengths of the set's bounding box.
Sides Extent(const std::vector<Cell>& cells)
{
  Sides extent{ 1, 1, 1 };
  for (int a = 0; a < 3; ++a)
  {
    const auto [low, high] =
      std::minmax_element(cells.begin(), cells.end(), [a](const Cell& x, const Cell& y) { return x[a] < y[a]; });
    extent[a] = static_cast<uint32_t>(std::min<uint64_t>(uint64_t((*high)[a]) - (*low)[a] + 1, UINT32_MAX));
  }
  return extent;
}

/// Sides in proportion to `extent` whose product is about `target`, each in [1, cap[a]]:
/// axes that reach their cap (or 1) are fixed and the rest rescaled.
Sides ProportionalSides(const Sides& extent, double target, const Sides& cap)
{
  Sides sides{ 1, 1, 1 };
  bool fixed[3] = { false, false, false };
  for (int pass = 0; pass < 3; ++pass)
  {
    double freeVolume = 1, fixedProduct = 1;
    int freeAxes = 0;
    for (int a = 0; a < 3; ++a)
    {
      if (fixed[a])
      {
        fixedProduct *= sides[a];
      }
      else
      {
        freeVolume *= extent[a];
        ++freeAxes;
      }
    }
    if (freeAxes == 0)
    {
      break;
    }
    const double scale = std::pow(target / fixedProduct / freeVolume, 1.0 / freeAxes);
    bool changed = false;
    for (int a = 0; a < 3; ++a)
    {
      const double side = extent[a] * scale;
      if (!fixed[a] && (side >= cap[a] || side < 1))
      {
        sides[a] = side < 1 ? 1 : cap[a];
        fixed[a] = changed = true;
      }
    }
    if (!changed)
    {
      for (int a = 0; a < 3; ++a)
      {
        if (!fixed[a])
        {
          sides[a] = static_cast<uint32_t>(std::max<double>(1, std::round(extent[a] * scale)));
        }
      }
      break;
    }
  }
  return sides;
}

/// Table shapes of `target` slots or a little less (never under n), a side at most MaxSide:
/// shaped like the set (in proportion to its box, or as deep as it with the lateral sides in
/// proportion, which suits thin sets: a few layers of shell), near cubes (a a b, b b a), and
/// the set's box itself (whose identity map needs no offsets at all).
std::vector<Sides> TableShapes(const Sides& extent, uint64_t n, uint64_t target, bool big)
{
  constexpr uint32_t maxSide = PerfectSpatialHash::MaxSide;
  const Sides cap{ std::min(extent[0], maxSide), std::min(extent[1], maxSide), std::min(extent[2], maxSide) };
  std::vector<Sides> shapes;
  if (extent[2] <= maxSide)
  {
    Sides deep = ProportionalSides({ extent[0], extent[1], 1 }, double(target) / extent[2], { maxSide, maxSide, 1 });
    deep[2] = extent[2];
    shapes.push_back(deep);
  }
  shapes.push_back(ProportionalSides(extent, double(target), cap));
  const uint32_t a = static_cast<uint32_t>(std::max<double>(1, std::floor(std::cbrt(double(target)))));
  const uint32_t b = static_cast<uint32_t>(std::ceil(double(target) / a / a));
  const uint32_t c = static_cast<uint32_t>(std::ceil(std::sqrt(double(target) / a)));
  shapes.push_back({ a, a, b });
  if (!big)
  {
    shapes.push_back({ c, c, a });
    shapes.push_back(extent);
  }
  std::vector<Sides> kept;
  for (const Sides& m : shapes)
  {
    const uint64_t slots = uint64_t(m[0]) * m[1] * m[2];
    if (slots >= n && double(slots) <= double(target) * 1.005 + 1 && m[0] <= maxSide && m[1] <= maxSide &&
      m[2] <= maxSide)
    {
      kept.push_back(m);
    }
  }
  return kept;
}

/// Offset tables for table `m`: shaped like the set, then cubes, with |S| / 6 entries (LH's
/// sigma = 1 / (2 d)) and |S| / 4 (small sets only), each side coprime with the table's and
/// at most the table's (1 where the table is flat). The set's box as table: the identity
/// (one offset) first.
std::vector<Sides> OffsetShapes(const Sides& extent, uint64_t n, const Sides& m, bool big)
{
  std::vector<Sides> shapes;
  if (m == extent)
  {
    shapes.push_back({ 1, 1, 1 });
  }
  for (double sigma : { 1.0 / 6, 1.0 / 4 })
  {
    if (big && sigma > 0.2)
    {
      continue;
    }
    const double entries = std::max(1.0, sigma * double(n));
    const uint32_t cube = static_cast<uint32_t>(std::ceil(std::cbrt(entries)));
    for (Sides r : { ProportionalSides(extent, entries, m), Sides{ cube, cube, cube } })
    {
      for (int a = 0; a < 3; ++a)
      {
        r[a] = m[a] == 1 ? 1 : CoprimeAtLeast(m[a], std::min(r[a], m[a]));
        if (r[a] > m[a])
        {
          r[a] = 1;
        }
      }
      if (std::find(shapes.begin(), shapes.end(), r) == shapes.end())
      {
        shapes.push_back(r);
      }
    }
  }
  return shapes;
}
} // namespace

bool PackPerfectSpatialHash(
  const std::vector<Cell>& cells, const Sides& tableSides, const Sides& offsetSides, PerfectSpatialHash& hash)
{
  ++hash.attempts;
  for (int a = 0; a < 3; ++a)
  {
    if (tableSides[a] < 1 || offsetSides[a] < 1 || tableSides[a] > PerfectSpatialHash::MaxSide ||
      offsetSides[a] > PerfectSpatialHash::MaxSide || std::gcd(tableSides[a], offsetSides[a]) != 1)
    {
      throw std::invalid_argument("perfect spatial hash: table sides must be 1 to " +
        std::to_string(PerfectSpatialHash::MaxSide) + " and coprime with the offset table's");
    }
  }
  if (cells.empty())
  {
    hash.tableSides = tableSides;
    hash.offsetSides = offsetSides;
    hash.offsets.assign(static_cast<std::size_t>(hash.OffsetTableSize()), { 0, 0, 0 });
    return true;
  }
  const Sides extent = Extent(cells);
  const uint64_t slots = uint64_t(tableSides[0]) * tableSides[1] * tableSides[2];
  if (slots < cells.size() || slots > PerfectSpatialHash::MaxTableSize)
  {
    return false;
  }
  // Distinct cells no wider apart than m r on every axis are always separated; else check.
  bool wide = false;
  for (int a = 0; a < 3; ++a)
  {
    wide = wide || uint64_t(tableSides[a]) * offsetSides[a] < extent[a];
  }
  if (wide && !Separable(cells, tableSides, offsetSides))
  {
    return false;
  }
  return Packing(cells, tableSides, offsetSides).Run(hash);
}

PerfectSpatialHash BuildPerfectSpatialHash(const std::vector<Cell>& cells)
{
  PerfectSpatialHash hash;
  if (cells.empty())
  {
    hash.offsets.assign(1, { 0, 0, 0 });
    return hash;
  }
  const uint64_t n = cells.size();
  if (n > PerfectSpatialHash::MaxTableSize)
  {
    throw std::invalid_argument("perfect spatial hash: " + std::to_string(n) + " cells are too many");
  }
  const Sides extent = Extent(cells);
  ResiduesDistinct(cells, { extent[0], extent[1], extent[2] }); // throws for a cell listed twice

  // Shaped tables first: every table of at most 1.25 |S| slots the shapes below give, smallest
  // first, each with an offset table of |S| / 6 or |S| / 4 entries shaped like the set.
  // Small sets try sizes a half percent apart; big ones, where a packing costs seconds, a few.
  const bool big = n > (uint64_t(1) << 18);
  const double step = big ? 0.03 : 0.005;
  std::vector<Sides> tried;
  for (double target = double(n) * (big ? 1.06 : 1.0); target <= MaxFill * double(n);
       target = std::max(target + 1, target * (1 + step)))
  {
    for (const Sides& m : TableShapes(extent, n, static_cast<uint64_t>(target), big))
    {
      if (std::find(tried.begin(), tried.end(), m) != tried.end())
      {
        continue;
      }
      tried.push_back(m);
      for (const Sides& r : OffsetShapes(extent, n, m, big))
      {
        if (PackPerfectSpatialHash(cells, m, r, hash))
        {
          return hash;
        }
      }
    }
  }

  // Then cubes growing without bound (about 2% a step), offset tables growing up to the table:
  // sets spread wider than m r (a long line, far-apart cells) separate only when m r grows.
  for (uint32_t m = static_cast<uint32_t>(CeilCbrt(n)); m <= PerfectSpatialHash::MaxSide;
       m += std::max<uint32_t>(1, m / 48))
  {
    const uint64_t slots = uint64_t(m) * m * m;
    if (slots > PerfectSpatialHash::MaxTableSize)
    {
      break;
    }
    for (uint64_t r = CeilCbrt((n + 5) / 6); r <= m; r += 1 + r / 4)
    {
      const uint32_t coprime = CoprimeAtLeast(m, r);
      if (coprime <= m && PackPerfectSpatialHash(cells, { m, m, m }, { coprime, coprime, coprime }, hash))
      {
        return hash;
      }
    }
    if (PackPerfectSpatialHash(cells, { m, m, m }, { 1, 1, 1 }, hash))
    {
      return hash;
    }
  }
  throw std::invalid_argument("perfect spatial hash: " + std::to_string(n) +
    " cells spread too thinly for a table of side " + std::to_string(PerfectSpatialHash::MaxSide));
}

std::vector<uint64_t> CellSlots(const PerfectSpatialHash& hash, const std::vector<Cell>& cells)
{
  std::vector<uint64_t> slots(cells.size());
  for (std::size_t n = 0; n < cells.size(); ++n)
  {
    slots[n] = hash.Slot(cells[n][0], cells[n][1], cells[n][2]);
  }
  return slots;
}

} // namespace resmr
