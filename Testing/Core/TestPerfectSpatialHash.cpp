// Tests of the shell cells' storage (paper Sec. 5.3, 5.4): the perfect spatial hash is perfect
// (distinct slots, all inside the table) for dense, shell, sparse, wide, linear and tiny sets,
// compact on IJK shells, independent of the input order, and rejects duplicate cells; the
// octahedral normal code round-trips within its stated angle and keeps the sign of z.
#include "CoreTesting.h"

#include "NormalQuantization.h"
#include "PerfectSpatialHash.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

using namespace resmr;

namespace
{
using Cells = std::vector<std::array<uint32_t, 3>>;

Cells Box(uint32_t ni, uint32_t nj, uint32_t nk)
{
  Cells cells;
  for (uint32_t k = 0; k < nk; ++k)
  {
    for (uint32_t j = 0; j < nj; ++j)
    {
      for (uint32_t i = 0; i < ni; ++i)
      {
        cells.push_back({ i, j, k });
      }
    }
  }
  return cells;
}

/// The cells of a box with an external face, like a reservoir's outer shell in IJK space.
Cells Shell(uint32_t ni, uint32_t nj, uint32_t nk)
{
  Cells cells;
  for (const auto& c : Box(ni, nj, nk))
  {
    if (c[0] == 0 || c[1] == 0 || c[2] == 0 || c[0] == ni - 1 || c[1] == nj - 1 || c[2] == nk - 1)
    {
      cells.push_back(c);
    }
  }
  return cells;
}

/// About `count` distinct random cells of an ni x nj x nk grid.
Cells Sparse(uint64_t count, uint32_t ni, uint32_t nj, uint32_t nk, uint64_t seed)
{
  std::mt19937_64 random(seed);
  std::vector<uint64_t> linear(count);
  for (uint64_t& l : linear)
  {
    l = random() % (uint64_t(ni) * nj * nk);
  }
  std::sort(linear.begin(), linear.end());
  linear.erase(std::unique(linear.begin(), linear.end()), linear.end());
  std::shuffle(linear.begin(), linear.end(), random);
  Cells cells;
  for (uint64_t l : linear)
  {
    cells.push_back({ uint32_t(l % ni), uint32_t(l / ni % nj), uint32_t(l / ni / nj) });
  }
  return cells;
}

/// Perfect: offsets in range, every cell in its own slot of the table, and Slot() is the
/// documented lookup h(p) = (p mod m + Phi[p mod r]) mod m.
PerfectSpatialHash CheckPerfect(const char* label, const Cells& cells)
{
  const PerfectSpatialHash hash = BuildPerfectSpatialHash(cells);
  const PerfectSpatialHash::Sides m = hash.tableSides, r = hash.offsetSides;
  for (int a = 0; a < 3; ++a)
  {
    CHECK(m[a] >= 1 && r[a] >= 1 && m[a] <= PerfectSpatialHash::MaxSide && r[a] <= PerfectSpatialHash::MaxSide);
  }
  CHECK(hash.TableSize() == uint64_t(m[0]) * m[1] * m[2] && hash.TableSize() >= cells.size());
  CHECK(hash.offsets.size() == uint64_t(r[0]) * r[1] * r[2] && hash.OffsetTableSize() == hash.offsets.size());
  CHECK(std::all_of(hash.offsets.begin(), hash.offsets.end(),
    [m](const std::array<uint16_t, 3>& o) { return o[0] < m[0] && o[1] < m[1] && o[2] < m[2]; }));
  const std::vector<uint64_t> slots = CellSlots(hash, cells);
  CHECK(slots.size() == cells.size());
  std::vector<uint8_t> taken(hash.TableSize(), 0);
  bool perfect = true;
  for (uint64_t slot : slots)
  {
    perfect = perfect && slot < hash.TableSize() && !taken[slot];
    if (slot < hash.TableSize())
    {
      taken[slot] = 1;
    }
  }
  CHECK(perfect);
  for (std::size_t n = 0; n < cells.size(); n += 1 + cells.size() / 1000)
  {
    const auto& p = cells[n];
    const auto& phi = hash.offsets[p[0] % r[0] + uint64_t(r[0]) * (p[1] % r[1] + uint64_t(r[1]) * (p[2] % r[2]))];
    const uint64_t x = (p[0] % m[0] + phi[0]) % m[0], y = (p[1] % m[1] + phi[1]) % m[1],
                   z = (p[2] % m[2] + phi[2]) % m[2];
    CHECK(slots[n] == x + m[0] * (y + uint64_t(m[1]) * z));
  }
  std::printf("%-22s %9zu cells: m %4ux%4ux%4u (fill %.3f), r %3ux%3ux%3u (r / cells %.3f), %u tries\n", label,
    cells.size(), m[0], m[1], m[2], cells.empty() ? 0.0 : double(cells.size()) / double(hash.TableSize()), r[0], r[1],
    r[2], cells.empty() ? 0.0 : double(hash.OffsetTableSize()) / double(cells.size()), hash.attempts);
  return hash;
}

void TestPerfectHash()
{
  CheckPerfect("dense box", Box(23, 17, 9));
  const PerfectSpatialHash cube = CheckPerfect("dense cube", Box(20, 20, 20));
  CHECK(cube.TableSize() == 8000); // a full table

  const Cells shell = Shell(200, 150, 40);
  const PerfectSpatialHash shellHash = CheckPerfect("shell 200x150x40", shell);
  CHECK(double(shellHash.TableSize()) <= 1.1 * double(shell.size())); // 1.025 achieved
  // |S| / 4 entries, each side rounded up to one coprime with the table's.
  CHECK(double(shellHash.OffsetTableSize()) <= 0.3 * double(shell.size())); // 0.272 achieved

  const Cells bigShell = Shell(700, 700, 10);
  const PerfectSpatialHash bigShellHash = CheckPerfect("shell 700x700x10", bigShell);
  CHECK(double(bigShellHash.TableSize()) <= 1.15 * double(bigShell.size()));       // 1.126 achieved
  CHECK(double(bigShellHash.OffsetTableSize()) <= 0.25 * double(bigShell.size())); // 0.003 achieved

  // Thin and small shells, as real models' touched cells are (a few layers: SPE1 10x10x3,
  // Brugge 139x48x9): the packed-texture target, 1.25 x the cells, holds. Cubic tables gave
  // 1.3-1.5 here.
  const std::array<uint32_t, 3> thinShells[] = { { 10, 10, 3 }, { 139, 48, 9 }, { 60, 48, 6 }, { 24, 25, 15 },
    { 400, 90, 4 }, { 7, 5, 2 } };
  for (const auto& dims : thinShells)
  {
    const Cells thin = Shell(dims[0], dims[1], dims[2]);
    const std::string label =
      "shell " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" + std::to_string(dims[2]);
    const PerfectSpatialHash thinHash = CheckPerfect(label.c_str(), thin);
    CHECK(double(thinHash.TableSize()) <= 1.25 * double(thin.size()));
    CHECK(double(thinHash.OffsetTableSize()) <= 0.4 * double(thin.size()));
  }

  const Cells sparse = Sparse(1500000, 2000, 2000, 300, 11);
  const PerfectSpatialHash sparseHash = CheckPerfect("random 2000x2000x300", sparse);
  CHECK(double(sparseHash.TableSize()) <= 1.1 * double(sparse.size())); // 1.014 achieved

  // Wider than m * r at first: the first (m, r) leaves pairs of cells agreeing in h0 and h1.
  CheckPerfect("random 1e5x1e5x300", Sparse(100000, 100000, 100000, 300, 12));
  Cells line;
  for (uint32_t j = 0; j < 1000; ++j)
  {
    line.push_back({ 7, j, 3 });
  }
  const PerfectSpatialHash lineHash = CheckPerfect("line of 1000", line);
  CHECK(lineHash.TableSize() == 1000); // the line's box itself
  CheckPerfect("far apart", { { 4294967295u, 0, 0 }, { 0, 4294967295u, 4294967295u }, { 123, 456, 789 } });

  const PerfectSpatialHash single = CheckPerfect("single cell", { { 5, 6, 7 } });
  CHECK(single.TableSize() == 1 && single.Slot(5, 6, 7) == 0);
  const PerfectSpatialHash empty = CheckPerfect("empty", {});
  CHECK(empty.TableSize() == 1 && empty.OffsetTableSize() == 1 && empty.Slot(3, 2, 1) == 0);

  // Deterministic and independent of the input order.
  Cells shuffled = shell;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(5));
  const PerfectSpatialHash again = BuildPerfectSpatialHash(shell), other = BuildPerfectSpatialHash(shuffled);
  CHECK(again.offsets == shellHash.offsets && again.tableSides == shellHash.tableSides);
  CHECK(other.offsets == shellHash.offsets && other.tableSides == shellHash.tableSides &&
    other.offsetSides == shellHash.offsetSides);

  // A cell listed twice is named 1-based, whether found while packing or while separating.
  Cells twice = Box(6, 5, 4);
  twice.push_back({ 3, 2, 1 });
  resmr_testing::ExpectError<std::invalid_argument>(
    "duplicate in a box", [&] { BuildPerfectSpatialHash(twice); }, { "(4, 3, 2)", "twice" });
  Cells lineTwice = line;
  lineTwice.insert(lineTwice.begin() + 10, { 7, 500, 3 });
  resmr_testing::ExpectError<std::invalid_argument>(
    "duplicate in a line", [&] { BuildPerfectSpatialHash(lineTwice); }, { "(8, 501, 4)", "twice" });
}

double AngleDegrees(const std::array<float, 3>& a, double x, double y, double z)
{
  const double cosine = (a[0] * x + a[1] * y + a[2] * z) / std::sqrt(x * x + y * y + z * z);
  return std::acos(std::min(1.0, cosine)) * 180.0 / 3.14159265358979323846;
}

void TestNormals()
{
  constexpr double boundDegrees = 0.64; // the header's contract
  std::mt19937_64 random(3);
  std::normal_distribution<double> gauss;
  double worst = 0;
  bool signKept = true, unit = true;
  for (int n = 0; n < 120000; ++n)
  {
    const double x = gauss(random), y = gauss(random), z = gauss(random) * (n % 4 == 0 ? 1e-3 : 1.0);
    const std::array<float, 3> d = DecodeUnitNormal(EncodeUnitNormal(x, y, z));
    worst = std::max(worst, AngleDegrees(d, x, y, z));
    signKept = signKept && !(z > 0 && d[2] < 0) && !(z < 0 && d[2] > 0);
    unit = unit && std::abs(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1) < 1e-6;
  }
  std::printf("normals: worst round trip %.3f degrees\n", worst);
  CHECK(worst <= boundDegrees && worst > 0.3); // > 0.3: the test reaches the worst case's order
  CHECK(signKept && unit);
  // The axes come back exactly; zero and non-finite input give +z (code 0).
  const double axes[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
  for (const auto& a : axes)
  {
    const std::array<float, 3> d = DecodeUnitNormal(EncodeUnitNormal(3 * a[0], 3 * a[1], 3 * a[2]));
    CHECK(std::abs(d[0] - a[0]) < 1e-6 && std::abs(d[1] - a[1]) < 1e-6 && std::abs(d[2] - a[2]) < 1e-6);
  }
  CHECK(EncodeUnitNormal(0, 0, 0) == 0 && EncodeUnitNormal(std::nan(""), 1, 0) == 0);
  const std::array<float, 3> up = DecodeUnitNormal(0);
  CHECK(up[0] == 0 && up[1] == 0 && up[2] == 1);
  // Every code's direction is found again exactly: the encoder keeps the nearest code.
  bool exact = true;
  for (uint32_t code = 0; code < 65536; ++code)
  {
    const std::array<float, 3> d = DecodeUnitNormal(static_cast<uint16_t>(code));
    const std::array<float, 3> e = DecodeUnitNormal(EncodeUnitNormal(d[0], d[1], d[2]));
    for (int axis = 0; axis < 3; ++axis)
    {
      exact = exact && std::abs(e[axis] - d[axis]) < 1e-6;
    }
  }
  CHECK(exact);
}
} // namespace

int main()
{
  TestPerfectHash();
  TestNormals();
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d check(s) failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("all perfect spatial hash and normal checks passed\n");
  return 0;
}
