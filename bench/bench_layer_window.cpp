// A leaf region read for a window of a few layers (an I/J/K range's K slab, a property filter's
// layer blocks; MultiresolutionFile::ReadRegionLayers) against the same region read whole, from
// each .resmr given: this version's files keep a region's positions in layer groups, so a
// window decompresses the groups it reaches; files before version 10 decompress the whole mesh
// chunk for any window (pass one of each, of the same model, to compare).
//
//   bench_layer_window FIRST_LAYER LAST_LAYER MODEL.resmr [MODEL.resmr ...]
//
// Prints one JSON line a file: format version, leaf regions read, their mean stored bytes, and
// milliseconds a leaf for the window and for the whole region, each a cold pass (the file's
// pages dropped from the cache first) and a warm one.
#include "MultiresolutionFile.h"
#include "bench_pages.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace resmr;

namespace
{
/// Milliseconds a region to read `leaves` with `read`.
template<typename Read>
double MeanMs(const std::vector<std::size_t>& leaves, Read&& read)
{
  const auto start = std::chrono::steady_clock::now();
  std::size_t cells = 0;
  for (std::size_t r : leaves)
  {
    cells += read(r).active.size();
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return cells > 0 ? ms / static_cast<double>(leaves.size()) : 0;
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 4)
  {
    std::fprintf(stderr, "usage: %s FIRST_LAYER LAST_LAYER MODEL.resmr [MODEL.resmr ...]\n", argv[0]);
    return 2;
  }
  const int32_t first = std::atoi(argv[1]), last = std::atoi(argv[2]);
  for (int a = 3; a < argc; ++a)
  {
    const std::string path = argv[a];
    std::vector<std::size_t> leaves;
    double stored = 0;
    {
      const MultiresolutionFile file(path);
      for (std::size_t r = 0; r < file.Regions().size(); ++r)
      {
        const RegionRecord& record = file.Regions()[r];
        if (record.level == file.Header().leafLevel)
        {
          leaves.push_back(r);
          const uint64_t groups =
            record.layerGroups > 0 ? record.chunks[RegionRecord::Mesh].offset - record.layerGroups : 0;
          stored += double(record.chunks[RegionRecord::Mesh].stored + groups);
        }
      }
    }
    double ms[2][2]; // [window, whole][cold, warm]
    uint32_t version = 0;
    for (int whole = 0; whole < 2; ++whole)
    {
      for (int warm = 0; warm < 2; ++warm)
      {
        if (!warm)
        {
          DropPages(path);
        }
        const MultiresolutionFile file(path);
        version = file.Header().version;
        ms[whole][warm] = whole ? MeanMs(leaves, [&](std::size_t r) { return file.ReadRegion(r); })
                                : MeanMs(leaves, [&](std::size_t r) { return file.ReadRegionLayers(r, first, last); });
      }
    }
    std::printf("{\"file\": \"%s\", \"version\": %u, \"leaves\": %zu, \"mesh_bytes_per_leaf\": %.0f, "
                "\"layers\": [%d, %d], \"window_cold_ms\": %.2f, \"window_warm_ms\": %.2f, "
                "\"whole_cold_ms\": %.2f, \"whole_warm_ms\": %.2f}\n",
      path.c_str(), version, leaves.size(), leaves.empty() ? 0 : stored / double(leaves.size()), first + 1, last + 1,
      ms[0][0], ms[0][1], ms[1][0], ms[1][1]);
    std::fflush(stdout);
  }
  return 0;
}
