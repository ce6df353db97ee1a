// The property values a filtered leaf region reads (PropertyFilter.h, ReadCellBox): for every
// leaf region of a .resmr, the box of its columns' cells over all layers, read with
// PropertyFile::ReadBox. One table of a property file is written twice into SCRATCH, cut into
// this version's tiles of 64 x 64 columns and into bands of whole rows of at most 1 MB (the
// layout of version 4 files, the peer), and both are read in the same run.
//
//   bench_leaf_values MODEL.resmr PROPS.resmrp TABLE STEP SCRATCH
//
// Prints one JSON line a layout: leaves, cells read, file bytes of the table's layers,
// milliseconds a leaf (a cold pass after dropping the file's pages from the cache, then a
// warm one), and whether both layouts gave the same values.
#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "bench_pages.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace resmr;

namespace
{
/// The cells of a leaf's columns: its nodes' topology box (as ReadCellBox), all layers.
std::pair<std::array<int64_t, 3>, std::array<int64_t, 3>> LeafBox(const MultiresolutionFile& file, std::size_t region)
{
  const RegionMesh mesh = file.ReadRegion(region);
  const auto& dims = file.Header().dims;
  float lo[2] = { INFINITY, INFINITY }, hi[2] = { -INFINITY, -INFINITY };
  for (const auto& t : mesh.topology)
  {
    for (int a = 0; a < 2; ++a)
    {
      lo[a] = std::min(lo[a], t[a]);
      hi[a] = std::max(hi[a], t[a]);
    }
  }
  std::array<int64_t, 3> boxLo{ 0, 0, 0 }, boxHi{ -1, -1, dims[2] - 1 };
  for (int a = 0; a < 2; ++a)
  {
    boxLo[a] = std::clamp<int64_t>(static_cast<int64_t>(std::floor(lo[a])) - 1, 0, dims[a] - 1);
    boxHi[a] = std::clamp<int64_t>(static_cast<int64_t>(std::ceil(hi[a])), 0, dims[a] - 1);
  }
  return { boxLo, boxHi };
}

/// Writes table `table` of `from` alone into a new file at `path`, its layers cut into bands of
/// `rows` x `columns` (0: the default tiles).
void WriteTable(const PropertyFile& from, std::size_t table, const MultiresolutionFile& geometry,
  const std::string& path, int64_t rows, int64_t columns)
{
  PropertyFileWriter writer(path, geometry, rows, columns);
  const std::size_t handle = writer.BeginTable(from.Tables()[table]);
  for (int64_t k = 0; k < from.Dimensions()[2]; ++k)
  {
    const std::vector<float> layer = from.ReadLayer(table, k);
    writer.AddLayer(handle, layer.data());
  }
  writer.EndTable(handle);
  writer.Commit();
}
} // namespace

int main(int argc, char** argv)
{
  if (argc != 6)
  {
    std::fprintf(stderr, "usage: %s MODEL.resmr PROPS.resmrp TABLE STEP SCRATCH\n", argv[0]);
    return 2;
  }
  const MultiresolutionFile geometry(argv[1]);
  const auto& dims = geometry.Header().dims;
  std::vector<std::string> paths;
  {
    const PropertyFile source(argv[2]);
    const int table = source.Find(argv[3], std::atoi(argv[4]));
    if (table < 0)
    {
      std::fprintf(stderr, "%s: no table %s of step %s\n", argv[2], argv[3], argv[4]);
      return 1;
    }
    const std::string scratch = argv[5];
    paths = { scratch + "/tiles.resmrp", scratch + "/whole-rows.resmrp" };
    WriteTable(source, static_cast<std::size_t>(table), geometry, paths[0], 0, 0);
    const int64_t rows = std::clamp<int64_t>((int64_t(1) << 18) / std::max<int64_t>(dims[0], 1), 1, dims[1]);
    WriteTable(source, static_cast<std::size_t>(table), geometry, paths[1], rows, dims[0]);
  }
  std::vector<std::pair<std::array<int64_t, 3>, std::array<int64_t, 3>>> boxes;
  int64_t cells = 0;
  for (std::size_t r = 0; r < geometry.Regions().size(); ++r)
  {
    if (geometry.Regions()[r].level == geometry.Header().leafLevel)
    {
      boxes.push_back(LeafBox(geometry, r));
      const auto& [lo, hi] = boxes.back();
      cells += (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
    }
  }
  std::vector<double> firstSums;
  for (const std::string& path : paths)
  {
    DropPages(path);
    const PropertyFile properties(path);
    uint64_t stored = 0;
    for (int64_t k = 0; k < dims[2]; ++k)
    {
      for (int64_t b = 0; b < properties.Bands(); ++b)
      {
        stored += properties.LayerBand(0, k, b).stored;
      }
    }
    double ms[2] = { 0, 0 };
    std::vector<double> sums;
    for (int pass = 0; pass < 2; ++pass)
    {
      const auto start = std::chrono::steady_clock::now();
      for (const auto& [lo, hi] : boxes)
      {
        const std::vector<float> values = properties.ReadBox(0, lo, hi);
        double sum = 0;
        for (const float v : values)
        {
          sum += std::isnan(v) ? 0.0 : v;
        }
        if (pass == 0)
        {
          sums.push_back(sum);
        }
      }
      ms[pass] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    const bool same = firstSums.empty() || sums == firstSums;
    if (firstSums.empty())
    {
      firstSums = sums;
    }
    std::printf("{\"layout\": \"%s\", \"band_rows\": %lld, \"band_columns\": %lld, \"bands_a_layer\": %lld, "
                "\"leaves\": %zu, \"cells\": %lld, \"layer_bytes\": %llu, \"cold_ms_per_leaf\": %.2f, "
                "\"warm_ms_per_leaf\": %.2f, \"same_values\": %s}\n",
      path == paths[0] ? "tiles" : "whole rows", static_cast<long long>(properties.BandRows()),
      static_cast<long long>(properties.BandColumns()), static_cast<long long>(properties.Bands()), boxes.size(),
      static_cast<long long>(cells), static_cast<unsigned long long>(stored), ms[0] / double(boxes.size()),
      ms[1] / double(boxes.size()), same ? "true" : "false");
    std::fflush(stdout);
    std::remove(path.c_str());
  }
  return 0;
}
