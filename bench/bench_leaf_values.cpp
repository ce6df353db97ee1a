// The property values a filtered leaf region reads (PropertyFilter.h, ReadCellBox): for every
// leaf region of a .resmr, the box of its columns' cells over all layers, read with
// PropertyFile::ReadBox from each property file given (the same table in each: files of
// different format versions, so their layouts are measured side by side in one run).
//
//   bench_leaf_values MODEL.resmr TABLE STEP A.resmrp [B.resmrp ...]
//
// Prints one JSON line a file: leaves, cells read, milliseconds a leaf (a cold pass after
// dropping the file's pages from the cache, then a warm one), and whether every file gave the
// same values.
#include "MultiresolutionFile.h"
#include "PropertyFile.h"

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

/// Drops the file's pages from the page cache (a cold read), as far as the kernel lets us.
void DropPages(const std::string& path)
{
  const int fd = open(path.c_str(), O_RDONLY);
  if (fd >= 0)
  {
    fdatasync(fd);
    posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    close(fd);
  }
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 5)
  {
    std::fprintf(stderr, "usage: %s MODEL.resmr TABLE STEP A.resmrp [B.resmrp ...]\n", argv[0]);
    return 2;
  }
  const MultiresolutionFile geometry(argv[1]);
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
  for (int f = 4; f < argc; ++f)
  {
    DropPages(argv[f]);
    const PropertyFile properties(argv[f]);
    const int table = properties.Find(argv[2], std::atoi(argv[3]));
    if (table < 0)
    {
      std::fprintf(stderr, "%s: no table %s of step %s\n", argv[f], argv[2], argv[3]);
      return 1;
    }
    double ms[2] = { 0, 0 };
    std::vector<double> sums;
    for (int pass = 0; pass < 2; ++pass)
    {
      const auto start = std::chrono::steady_clock::now();
      for (const auto& [lo, hi] : boxes)
      {
        const std::vector<float> values = properties.ReadBox(static_cast<std::size_t>(table), lo, hi);
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
    std::printf("{\"file\": \"%s\", \"band_rows\": %lld, \"band_columns\": %lld, \"leaves\": %zu, \"cells\": %lld, "
                "\"cold_ms_per_leaf\": %.2f, \"warm_ms_per_leaf\": %.2f, \"same_values\": %s}\n",
      argv[f], static_cast<long long>(properties.BandRows()), static_cast<long long>(properties.BandColumns()),
      boxes.size(), static_cast<long long>(cells), ms[0] / double(boxes.size()), ms[1] / double(boxes.size()),
      same ? "true" : "false");
    std::fflush(stdout);
  }
  return 0;
}
