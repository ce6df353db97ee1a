// Unit tests of the synthetic reservoir generator and its writers: every cell of non-negative
// volume and one orientation, the geology asked for (faults incl. oblique ones, pinch-outs,
// contact, outline, sloping pillars, layered properties, a moving water front) measured back
// from the written files by the project's readers, byte-identical output for a seed on every
// machine, and bad arguments refused with nothing left under the final names.
#include "CoreTesting.h"
#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "EclipseResults.h"
#include "Errors.h"
#include "GrdeclParser.h"
#include "SyntheticReservoir.h"
#include "SyntheticReservoirWriter.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <sys/resource.h>
#include <unistd.h>
#include <vector>

namespace
{
std::string Directory;

std::string ReadBytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

bool Exists(const std::string& path)
{
  return access(path.c_str(), F_OK) == 0;
}

int CountFiles(const std::string& pattern)
{
  int count = 0;
  const std::string command = "ls " + Directory + "/" + pattern + " 2>/dev/null | wc -l";
  if (std::FILE* pipe = popen(command.c_str(), "r"))
  {
    if (std::fscanf(pipe, "%d", &count) != 1)
    {
      count = -1;
    }
    pclose(pipe);
  }
  return count;
}

uint64_t Fnv1a(const std::string& bytes, uint64_t hash = 1469598103934665603ull)
{
  for (unsigned char c : bytes)
  {
    hash = (hash ^ c) * 1099511628211ull;
  }
  return hash;
}

/// Signed volumes of the six tetrahedra around the 0-7 diagonal, in (x, y, depth) with
/// ECLIPSE corner order: all >= 0 for a cell that is neither inverted nor folded.
void TetrahedronVolumes(const double c[8][3], double volumes[6])
{
  static const int tets[6][4] = { { 0, 1, 3, 7 }, { 0, 3, 2, 7 }, { 0, 2, 6, 7 }, { 0, 6, 4, 7 }, { 0, 4, 5, 7 },
    { 0, 5, 1, 7 } };
  for (int t = 0; t < 6; ++t)
  {
    const double* a = c[tets[t][0]];
    double e[3][3];
    for (int v = 0; v < 3; ++v)
    {
      for (int d = 0; d < 3; ++d)
      {
        e[v][d] = c[tets[t][v + 1]][d] - a[d];
      }
    }
    volumes[t] =
      (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
        e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) /
      6.0;
  }
}

struct Written
{
  resmr::SyntheticOutput output;
  std::string egrid;
};

Written WriteModel(const resmr::SyntheticParameters& parameters, const std::string& name)
{
  const resmr::SyntheticReservoir model(parameters);
  Written written;
  written.egrid = Directory + "/" + name + ".EGRID";
  written.output = resmr::WriteSyntheticEclipse(model, written.egrid);
  return written;
}

void TestValidityAndGeology()
{
  resmr::SyntheticParameters parameters;
  parameters.nx = 72;
  parameters.ny = 56;
  parameters.nz = 18;
  parameters.seed = 11;
  parameters.steps = 4;
  const resmr::SyntheticReservoir model(parameters);
  const Written written = WriteModel(parameters, "GEOLOGY");
  const resmr::SyntheticStatistics& stats = written.output.statistics;
  CHECK(written.output.files.size() == 3);

  resmr::EclipseGrid grid = resmr::ReadEclipseGrid(written.egrid);
  CHECK(grid.deck.dims[0] == 72 && grid.deck.dims[1] == 56 && grid.deck.dims[2] == 18);
  CHECK(grid.activeCells == stats.active);
  const std::vector<double> coord = grid.deck.coord;
  const resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(grid.deck, false);
  const int64_t nx = 72, ny = 56, nz = 18;

  // Every cell: no tetrahedron of negative volume (non-negative volume, one orientation);
  // zero-thickness cells inactive; the layer thickness varies.
  int64_t inverted = 0, zeroThickness = 0, zeroActive = 0;
  double thicknessSum = 0, thicknessSquares = 0;
  int64_t thicknessCount = 0;
  std::vector<int> activeInColumn(static_cast<std::size_t>(nx * ny), 0);
  for (int64_t k = 0; k < nz; ++k)
  {
    for (int64_t j = 0; j < ny; ++j)
    {
      for (int64_t i = 0; i < nx; ++i)
      {
        double corners[8][3];
        geometry.CellCorners(i, j, k, corners);
        double volumes[6];
        TetrahedronVolumes(corners, volumes);
        const double scale = model.CellSizeX() * model.CellSizeY() * 1e-6;
        inverted += std::any_of(volumes, volumes + 6, [&](double v) { return v < -scale; }) ? 1 : 0;
        double thickness = 0;
        for (int c = 0; c < 4; ++c)
        {
          thickness += corners[c + 4][2] - corners[c][2];
        }
        const int64_t cell = (k * ny + j) * nx + i;
        const bool active = grid.IsActive(cell);
        activeInColumn[j * nx + i] += active ? 1 : 0;
        if (thickness == 0)
        {
          ++zeroThickness;
          zeroActive += active ? 1 : 0;
        }
        if (active)
        {
          thicknessSum += thickness / 4;
          thicknessSquares += thickness * thickness / 16;
          ++thicknessCount;
        }
      }
    }
  }
  CHECK(inverted == 0);
  CHECK(zeroThickness > 0);
  CHECK(zeroActive == 0);
  const double meanThickness = thicknessSum / static_cast<double>(thicknessCount);
  const double spread =
    std::sqrt(thicknessSquares / static_cast<double>(thicknessCount) - meanThickness * meanThickness);
  CHECK(spread > 0.2 * meanThickness);

  // Requested fractions (defaults: outside 0.25, pinched 0.05, water 0.2).
  const double inside = static_cast<double>(stats.cells - stats.outside);
  const double outside = static_cast<double>(stats.outside) / static_cast<double>(stats.cells);
  const double pinched = static_cast<double>(stats.pinched) / inside;
  const double water = static_cast<double>(stats.water) / inside;
  std::printf("72x56x18: active %lld, outside %.3f, pinched %.3f, water %.3f, fault faces %lld of %lld\n",
    static_cast<long long>(stats.active), outside, pinched, water, static_cast<long long>(stats.faultFaces),
    static_cast<long long>(stats.lateralFaces));
  CHECK(std::fabs(outside - 0.25) < 0.01);
  CHECK(pinched > 0.6 * 0.05 && pinched < 1.4 * 0.05);
  CHECK(water > 0.75 * 0.2 && water < 1.25 * 0.2);
  CHECK(stats.cells == nx * ny * nz);
  CHECK(stats.active + stats.outside + stats.pinched + stats.water == stats.cells);

  // Ragged outline with partly active columns (paper Fig. 3).
  int64_t emptyColumns = 0, partlyActive = 0;
  for (int count : activeInColumn)
  {
    emptyColumns += count == 0;
    partlyActive += count > 0 && count < nz;
  }
  CHECK(emptyColumns >= stats.outside / nz);
  CHECK(partlyActive > (nx * ny - emptyColumns) / 10);

  // Faults: faces whose neighbours do not share corners, measured from the file's corners,
  // equal the generator's count; some run oblique to i and j (a staircase over many i).
  int64_t faultFaces = 0;
  std::set<int64_t> faultColumnsI;
  for (int64_t k = 0; k < nz; ++k)
  {
    for (int64_t j = 0; j < ny; ++j)
    {
      for (int64_t i = 0; i < nx; ++i)
      {
        double a[8][3], b[8][3];
        geometry.CellCorners(i, j, k, a);
        if (i + 1 < nx)
        {
          geometry.CellCorners(i + 1, j, k, b);
          if (a[1][2] != b[0][2] || a[3][2] != b[2][2] || a[5][2] != b[4][2] || a[7][2] != b[6][2])
          {
            ++faultFaces;
            faultColumnsI.insert(i);
          }
        }
        if (j + 1 < ny)
        {
          geometry.CellCorners(i, j + 1, k, b);
          faultFaces += (a[2][2] != b[0][2] || a[3][2] != b[1][2] || a[6][2] != b[4][2] || a[7][2] != b[5][2]) ? 1 : 0;
        }
      }
    }
  }
  CHECK(faultFaces == stats.faultFaces);
  const double faultFraction = static_cast<double>(faultFaces) / static_cast<double>(stats.lateralFaces);
  CHECK(faultFraction > 0.01 && faultFraction < 0.2);
  CHECK(faultColumnsI.size() >= 10);

  // Sloping pillars: top and bottom points differ laterally.
  int64_t sloping = 0;
  for (std::size_t p = 0; p < coord.size(); p += 6)
  {
    sloping += (coord[p] != coord[p + 3] || coord[p + 1] != coord[p + 4]) ? 1 : 0;
  }
  CHECK(sloping > static_cast<int64_t>(coord.size() / 6) * 9 / 10);

  // Properties: PORO varies more between layers than within them; PERMX follows PORO.
  const resmr::EclipseResults results(written.egrid, grid);
  std::vector<float> poro(static_cast<std::size_t>(nx * ny * nz)), permx(poro.size());
  CHECK(results.ReadStatic("PORO", poro.data(), std::nanf("")));
  CHECK(results.ReadStatic("PERMX", permx.data(), std::nanf("")));
  double total = 0, between = 0, within = 0;
  int64_t count = 0;
  std::vector<double> layerMean(static_cast<std::size_t>(nz), 0);
  std::vector<int64_t> layerCount(static_cast<std::size_t>(nz), 0);
  for (int64_t c = 0; c < nx * ny * nz; ++c)
  {
    if (!std::isnan(poro[c]))
    {
      layerMean[c / (nx * ny)] += poro[c];
      ++layerCount[c / (nx * ny)];
      total += poro[c];
      ++count;
    }
  }
  total /= static_cast<double>(count);
  for (int64_t k = 0; k < nz; ++k)
  {
    layerMean[k] /= std::max<int64_t>(1, layerCount[k]);
    between += static_cast<double>(layerCount[k]) * (layerMean[k] - total) * (layerMean[k] - total);
  }
  int64_t permFollows = 0, pairs = 0;
  for (int64_t c = 0; c + 1 < nx * ny * nz; ++c)
  {
    if (!std::isnan(poro[c]))
    {
      within += (poro[c] - layerMean[c / (nx * ny)]) * (poro[c] - layerMean[c / (nx * ny)]);
      if (!std::isnan(poro[c + 1]) && poro[c] != poro[c + 1])
      {
        ++pairs;
        permFollows += ((poro[c] < poro[c + 1]) == (permx[c] < permx[c + 1])) ? 1 : 0;
      }
    }
  }
  CHECK(between > within);
  CHECK(permFollows == pairs);

  // Report steps: the water front advances step by step.
  CHECK(results.Steps().size() == 4);
  int64_t previous = -1;
  std::vector<float> swat(poro.size()), pressure(poro.size());
  for (std::size_t s = 0; s < results.Steps().size(); ++s)
  {
    CHECK(results.ReadDynamic(s, "SWAT", swat.data(), std::nanf("")));
    CHECK(results.ReadDynamic(s, "PRESSURE", pressure.data(), std::nanf("")));
    int64_t flooded = 0;
    for (std::size_t c = 0; c < swat.size(); ++c)
    {
      flooded += !std::isnan(swat[c]) && swat[c] > 0.5 ? 1 : 0;
      if (!std::isnan(swat[c]) && (swat[c] < 0 || swat[c] > 1 || pressure[c] < 50 || pressure[c] > 500))
      {
        ++resmr_testing::Failures;
        std::fprintf(stderr, "step %zu cell %zu: SWAT %g PRESSURE %g out of range\n", s, c, swat[c], pressure[c]);
        break;
      }
    }
    CHECK(flooded > previous);
    previous = flooded;
  }
  CHECK(previous > stats.active / 50);
  CHECK(results.Steps().back().days == 3650);
}

void TestFaultsAndFractionsFollowKnobs()
{
  resmr::SyntheticParameters none;
  none.nx = 40;
  none.ny = 30;
  none.nz = 6;
  none.faults = 0;
  const resmr::SyntheticReservoir flat(none);
  CHECK(flat.FaultFacesPerLayer() == 0);

  resmr::SyntheticParameters more = none;
  more.nx = 120;
  more.ny = 90;
  more.nz = 12;
  more.faults = 12;
  more.pinchedFraction = 0.15;
  more.waterFraction = 0.4;
  more.outsideFraction = 0.5;
  const resmr::SyntheticReservoir model(more);
  resmr::SyntheticLayerStream stream(model);
  resmr::SyntheticLayer layer;
  while (stream.Next(layer))
  {
  }
  const resmr::SyntheticStatistics& s = stream.Statistics();
  const double inside = static_cast<double>(s.cells - s.outside);
  std::printf("120x90x12, 12 faults: outside %.3f pinched %.3f water %.3f fault faces %.3f\n",
    static_cast<double>(s.outside) / static_cast<double>(s.cells), static_cast<double>(s.pinched) / inside,
    static_cast<double>(s.water) / inside, static_cast<double>(s.faultFaces) / static_cast<double>(s.lateralFaces));
  CHECK(std::fabs(static_cast<double>(s.outside) / static_cast<double>(s.cells) - 0.5) < 0.01);
  CHECK(static_cast<double>(s.pinched) / inside > 0.6 * 0.15 && static_cast<double>(s.pinched) / inside < 1.4 * 0.15);
  CHECK(static_cast<double>(s.water) / inside > 0.75 * 0.4 && static_cast<double>(s.water) / inside < 1.25 * 0.4);
  CHECK(s.faultFaces > 0);
  CHECK(layer.k == 11);
}

void TestDeterminismAndGrdecl()
{
  resmr::SyntheticParameters parameters;
  parameters.nx = 30;
  parameters.ny = 20;
  parameters.nz = 6;
  parameters.seed = 7;
  parameters.steps = 2;
  const Written first = WriteModel(parameters, "SAME1");
  const Written second = WriteModel(parameters, "SAME2");
  uint64_t hash = 1469598103934665603ull;
  for (std::size_t f = 0; f < first.output.files.size(); ++f)
  {
    const std::string bytes = ReadBytes(first.output.files[f]);
    CHECK(!bytes.empty());
    CHECK(bytes == ReadBytes(second.output.files[f]));
    hash = Fnv1a(bytes, hash);
  }
  // The same bits on every machine: this hash was taken when the generator was written; a
  // change of the generator's output must update it knowingly.
  std::printf("30x20x6 seed 7, 2 steps: EGRID+INIT+UNRST hash %016llx\n", static_cast<unsigned long long>(hash));
  CHECK(hash == 0xc8f30ebbd3351979ull);
  parameters.seed = 8;
  const Written other = WriteModel(parameters, "OTHER");
  CHECK(ReadBytes(other.egrid) != ReadBytes(first.egrid));

  // The GRDECL deck holds the same grid: dims, ACTNUM and every corner depth.
  parameters.seed = 7;
  parameters.steps = 0;
  const resmr::SyntheticReservoir model(parameters);
  const std::string deckPath = Directory + "/SAME.GRDECL";
  resmr::WriteSyntheticGrdecl(model, deckPath);
  const resmr::CornerPointModel deck = resmr::ParseGrdeclFile(deckPath);
  const resmr::EclipseGrid grid = resmr::ReadEclipseGrid(first.egrid);
  CHECK(deck.dims == grid.deck.dims);
  CHECK(deck.zcorn.size() == grid.deck.zcornSingle.size());
  int64_t differing = 0;
  for (std::size_t z = 0; z < std::min(deck.zcorn.size(), grid.deck.zcornSingle.size()); ++z)
  {
    differing += static_cast<float>(deck.zcorn[z]) != grid.deck.zcornSingle[z] ? 1 : 0;
  }
  CHECK(differing == 0);
  const resmr::CellArray* actnum = deck.FindArray("ACTNUM");
  CHECK(actnum && std::count(actnum->values.begin(), actnum->values.end(), 1.0) == grid.activeCells);
  CHECK(deck.FindArray("PORO") && deck.FindArray("PERMX") && deck.FindArray("NTG"));
  CHECK(ReadBytes(deckPath) == [&] {
    resmr::WriteSyntheticGrdecl(model, Directory + "/SAME2.GRDECL");
    return ReadBytes(Directory + "/SAME2.GRDECL");
  }());
}

void TestBadArguments()
{
  using resmr_testing::ExpectError;
  auto invalid = [](resmr::SyntheticParameters p) { resmr::SyntheticReservoir model(p); };
  resmr::SyntheticParameters p;
  p.nx = 0;
  ExpectError<std::invalid_argument>("zero dims", [&] { invalid(p); }, { "at least 1", "0 x 100 x 20" });
  p = {};
  p.nz = 2000000;
  ExpectError<std::invalid_argument>("huge nz", [&] { invalid(p); }, { "at most 1000000" });
  p = {};
  p.nx = 20000;
  p.ny = 20000;
  ExpectError<std::invalid_argument>("huge columns", [&] { invalid(p); }, { "100 million columns" });
  p = {};
  p.waterFraction = 1.5;
  ExpectError<std::invalid_argument>("water", [&] { invalid(p); }, { "water fraction" });
  p = {};
  p.faults = 40;
  ExpectError<std::invalid_argument>("faults", [&] { invalid(p); }, { "faults must be 0 to 32" });

  // Over the 32-bit EGRID limit: refused before anything is written.
  p = {};
  p.nx = 1000;
  p.ny = 1000;
  p.nz = 269;
  const resmr::SyntheticReservoir big(p);
  ExpectError<resmr::InputError>("EGRID limit", [&] { resmr::WriteSyntheticEclipse(big, Directory + "/BIG.EGRID"); },
    { "BIG.EGRID", "268,435,455", "269000000", "synth:1000x1000x269:1" });
  CHECK(CountFiles("BIG*") == 0);

  p = {};
  p.nx = 20;
  p.ny = 20;
  p.nz = 4;
  const resmr::SyntheticReservoir small(p);
  ExpectError<resmr::InputError>("unwritable folder",
    [&] { resmr::WriteSyntheticEclipse(small, Directory + "/no/such/X.EGRID"); }, { "X.EGRID", "cannot create" });
  ExpectError<resmr::InputError>("steps in GRDECL",
    [&] {
      resmr::SyntheticParameters stepped = p;
      stepped.steps = 2;
      resmr::WriteSyntheticGrdecl(resmr::SyntheticReservoir(stepped), Directory + "/STEPS.GRDECL");
    },
    { "STEPS.GRDECL", "report steps need EGRID" });

  // A full disk (a file-size limit): the error names the file; an older model under the
  // final names is untouched, and no temporary is left.
  resmr::SyntheticParameters medium = p;
  medium.nx = 100;
  medium.ny = 100;
  medium.nz = 10;
  medium.steps = 1;
  resmr::SyntheticParameters noSteps = medium;
  noSteps.steps = 0;
  const std::string target = Directory + "/FULL.EGRID";
  std::ofstream(target) << "older model";
  std::ofstream(Directory + "/FULL.INIT") << "older init";
  struct rlimit saved;
  getrlimit(RLIMIT_FSIZE, &saved);
  struct rlimit limited = saved;
  limited.rlim_cur = 256 << 10;
  std::signal(SIGXFSZ, SIG_IGN);
  setrlimit(RLIMIT_FSIZE, &limited);
  ExpectError<resmr::InputError>("disk full",
    [&] { resmr::WriteSyntheticEclipse(resmr::SyntheticReservoir(medium), target); }, { "FULL.EGRID", "write failed" });
  ExpectError<resmr::InputError>("disk full GRDECL",
    [&] { resmr::WriteSyntheticGrdecl(resmr::SyntheticReservoir(noSteps), Directory + "/FULL.GRDECL"); },
    { "FULL.GRDECL", "write failed" });
  setrlimit(RLIMIT_FSIZE, &saved);
  CHECK(ReadBytes(target) == "older model");
  CHECK(ReadBytes(Directory + "/FULL.INIT") == "older init");
  CHECK(!Exists(Directory + "/FULL.UNRST") && !Exists(Directory + "/FULL.GRDECL"));
  CHECK(CountFiles("*partial*") == 0);
}
} // namespace

int main()
{
  char pattern[] = "/tmp/resmr-synthetic-test-XXXXXX";
  Directory = mkdtemp(pattern);
  TestValidityAndGeology();
  TestFaultsAndFractionsFollowKnobs();
  TestDeterminismAndGrdecl();
  TestBadArguments();
  std::system(("rm -rf '" + Directory + "'").c_str());
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d check(s) failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("all synthetic reservoir checks passed\n");
  return 0;
}
