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

/// Packings tried at one table side before it grows.
constexpr int PackingsPerSide = 3;

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

/// Whether no two cells agree modulo `product` in every component. With gcd(m, r) = 1 that is
/// (by the Chinese remainder theorem) whether (h0, h1) = (p mod m, p mod r) is injective on the
/// cells, which LH require: cells agreeing in both share an entry and hence a slot.
bool Separable(const std::vector<Cell>& cells, uint64_t product)
{
  std::vector<std::pair<Cell, uint32_t>> keyed(cells.size());
  for (uint32_t n = 0; n < cells.size(); ++n)
  {
    const Cell& c = cells[n];
    keyed[n] = { { uint32_t(c[0] % product), uint32_t(c[1] % product), uint32_t(c[2] % product) }, n };
  }
  std::sort(keyed.begin(), keyed.end());
  bool separable = true;
  for (std::size_t n = 1; n < keyed.size(); ++n)
  {
    if (keyed[n].first == keyed[n - 1].first)
    {
      if (cells[keyed[n].second] == cells[keyed[n - 1].second])
      {
        ThrowDuplicate(cells[keyed[n].second]);
      }
      separable = false; // keep looking: a duplicate elsewhere is the caller's error, not ours
    }
  }
  return separable;
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
  Packing(const std::vector<Cell>& cells, uint32_t m, uint32_t r)
    : Cells(cells)
    , M(m)
    , R(r)
    , Slots(m * m * m)
  {
    while ((uint64_t(this->G) * r) % m != 1 % m)
    {
      ++this->G;
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
    result.tableSide = this->M;
    result.offsetSide = this->R;
    result.offsets.assign(this->R * this->R * this->R, { 0, 0, 0 });
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
    return c[0] % this->R + this->R * (c[1] % this->R + this->R * (c[2] % this->R));
  }

  /// Counting sort of the cells by entry; the non-empty entries, largest group first (ties by
  /// entry, so that the result ignores the input order).
  void Group()
  {
    const uint32_t entries = this->R * this->R * this->R;
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

  uint32_t Wrap(uint32_t value) const { return value >= this->M ? value - this->M : value; }

  /// The permuted slot of a cell of permuted h0 `h` under permuted offset `psi`.
  uint32_t SlotOf(const std::array<uint32_t, 3>& h, const std::array<uint32_t, 3>& psi) const
  {
    const uint32_t x = this->Wrap(h[0] + psi[0]), y = this->Wrap(h[1] + psi[1]);
    return x + this->M * (y + this->M * this->Wrap(h[2] + psi[2]));
  }

  /// Whether offset psi (permuted) puts every cell of the current group in a free slot.
  bool Fits(const std::array<uint32_t, 3>& psi) const
  {
    for (const std::array<uint32_t, 3>& h : this->H0)
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
    const uint32_t m = this->M, r = this->R, g = this->G;
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
      this->H0.push_back({ g * (c[0] % m) % m, g * (c[1] % m) % m, g * (c[2] % m) % m });
      this->H0Cells.push_back(this->Members[n]);
      const Cell block{ c[2] / r, c[1] / r, c[0] / r };
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
    const std::array<uint32_t, 3>& h = this->H0[0];
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
        const uint32_t x = slot % m, y = slot / m % m, z = slot / m / m;
        const std::array<uint32_t, 3> psi{ this->Wrap(x + m - h[0]), this->Wrap(y + m - h[1]),
          this->Wrap(z + m - h[2]) };
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
          offsets[q] = { static_cast<uint16_t>(r * psi[0] % m), static_cast<uint16_t>(r * psi[1] % m),
            static_cast<uint16_t>(r * psi[2] % m) };
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
  const uint32_t M, R;
  const uint32_t Slots;
  uint32_t G = 0;                // r^-1 mod m
  std::vector<uint32_t> First;   // group q is Members[First[q] .. First[q + 1])
  std::vector<uint32_t> Members; // cell indices grouped by entry
  std::vector<uint32_t> Order;   // non-empty entries, largest group first
  std::vector<uint64_t> Occupied; // permuted slots taken
  std::vector<std::array<uint32_t, 3>> H0; // the current group's permuted h0, anchor first
  std::vector<uint32_t> H0Cells;           // and its cells
  uint32_t LastSize = 0; // size of the last group placed
  uint32_t Resume = 0;   // where its anchor went
};
} // namespace

PerfectSpatialHash BuildPerfectSpatialHash(const std::vector<Cell>& cells)
{
  constexpr uint32_t maxSide = PerfectSpatialHash::MaxTableSide;
  PerfectSpatialHash hash;
  if (cells.empty())
  {
    hash.tableSide = hash.offsetSide = 1;
    hash.offsets.assign(1, { 0, 0, 0 });
    return hash;
  }
  const uint64_t n = cells.size();
  if (n > uint64_t(maxSide) * maxSide * maxSide)
  {
    throw std::invalid_argument("perfect spatial hash: " + std::to_string(n) + " cells are too many");
  }
  // Any m * r >= extent separates the cells (their differences are smaller); with m >= extent,
  // h0 alone is injective and r = 1 always works (the last resort).
  uint64_t extent = 0;
  for (int axis = 0; axis < 3; ++axis)
  {
    const auto [low, high] = std::minmax_element(cells.begin(), cells.end(),
      [axis](const Cell& a, const Cell& b) { return a[axis] < b[axis]; });
    extent = std::max<uint64_t>(extent, uint64_t((*high)[axis]) - (*low)[axis] + 1);
  }
  const uint64_t firstR = CeilCbrt((n + 5) / 6); // LH: sigma = 1 / (2 d)
  // Packing failures grow r up to about |S| / 4 entries (6 bytes each), then m.
  const uint64_t packingR = std::max(firstR + 2, CeilCbrt((n + 3) / 4));
  uint64_t inseparable = 0; // the largest m * r known to leave two cells inseparable
  // Big sets: a failed packing costs seconds, so tables grow by about 5% a step (a
  // sixty-fourth of the side) and get one packing a side.
  const int packingsPerSide = n > (uint64_t(1) << 20) ? 1 : PackingsPerSide;
  for (uint32_t m = static_cast<uint32_t>(CeilCbrt(n));; m += std::max<uint32_t>(1, m / 64))
  {
    if (m > maxSide)
    {
      throw std::invalid_argument("perfect spatial hash: " + std::to_string(n) +
        " cells spread too thinly for a table of side " + std::to_string(maxSide));
    }
    // Products just above an inseparable one rarely help: ask for an eighth more.
    const uint64_t separatingR = (inseparable + inseparable / 8) / m + 1;
    const uint64_t lastR = std::min<uint64_t>(m, separatingR > packingR ? m : packingR);
    uint32_t r = CoprimeAtLeast(m, std::max(firstR, separatingR));
    for (int packings = 0; r <= m && (packings == 0 || r <= lastR) && packings < packingsPerSide;)
    {
      ++hash.attempts;
      const uint64_t product = uint64_t(m) * r;
      if (product < extent && !Separable(cells, product))
      {
        inseparable = std::max(inseparable, product);
        r = CoprimeAtLeast(m, (inseparable + inseparable / 8) / m + 1);
        continue;
      }
      if (Packing(cells, m, r).Run(hash))
      {
        return hash;
      }
      ++packings;
      r = CoprimeAtLeast(m, r + 1);
    }
    if (m >= extent)
    {
      ++hash.attempts;
      if (Packing(cells, m, 1).Run(hash))
      {
        return hash;
      }
    }
  }
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
