// resmr build: a model to a .resmr multiresolution file (paper Sec. 4.2, 4.3, 6.1), and
// resmr info FILE.resmr: what the file holds, level by level.
#include "ResmrCommands.h"

#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "GrdeclParser.h"
#include "HierarchyBuilder.h"
#include "LayerSource.h"
#include "MultiresolutionFile.h"
#include "SyntheticReservoir.h"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <sys/resource.h>
#include <unistd.h>

namespace
{
const char* BuildUsage =
  "usage: resmr build INPUT -o OUT.resmr [--cmax N] [--threads N] [--memory SIZE] [--scratch DIR]\n"
  "  INPUT: a GRDECL/DATA deck, an EGRID, or synth:NIxNJxNK[:SEED] (streamed from the generator)\n"
  "  --cmax N      columns a region holds at most (default: 4096, or a 32nd of the model's\n"
  "                columns if fewer, at least 256)\n"
  "  --threads N   worker threads (default: every core)\n"
  "  --memory SIZE memory budget, e.g. 4G or 512M (default: half the available memory)\n"
  "  --scratch DIR scratch folder (default OUT.resmr.scratch, removed at the end; a build\n"
  "                killed or stopped by a full disk, run again with the same arguments, resumes\n"
  "                from what it finished: the partition pass's last checkpoint and every leaf\n"
  "                and diamond it recorded)\n"
  "  --fresh       ignore a killed build's scratch folder and start over\n"
  "  --no-disk-check  start even when the disks hold less free space than the build needs\n"
  "  --fault-columns N  columns a region keeps whole along its faults and borders (default:\n"
  "                   4096, or Cmax if larger); where the faults need more (the coarsest\n"
  "                   levels of a large model) the two sides of each fault weld into one\n"
  "                   surface, the throw drawn as a slope within the level's error\n"
  "  --simplify-faults  simplify each fault block's outline on its own at every level\n"
  "                   instead (smaller coarse levels; gaps open where faults bend or meet)\n"
  "  Prints a progress bar on stderr and a JSON report on stdout.\n";

int64_t ParseSize(const std::string& text)
{
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  double scale = 1;
  if (end && *end)
  {
    switch (*end)
    {
      case 'k':
      case 'K':
        scale = 1024.0;
        break;
      case 'm':
      case 'M':
        scale = 1024.0 * 1024;
        break;
      case 'g':
      case 'G':
        scale = 1024.0 * 1024 * 1024;
        break;
      default:
        throw std::invalid_argument("--memory " + text + ": expected a size such as 4G or 512M");
    }
  }
  if (!(value > 0))
  {
    throw std::invalid_argument("--memory " + text + ": expected a positive size");
  }
  return static_cast<int64_t>(value * scale);
}

std::string Duration(double seconds)
{
  char text[32];
  const long s = static_cast<long>(std::max(0.0, seconds) + 0.5);
  if (s >= 3600)
  {
    std::snprintf(text, sizeof(text), "%ldh%02ldm", s / 3600, (s / 60) % 60);
  }
  else
  {
    std::snprintf(text, sizeof(text), "%ldm%02lds", s / 60, s % 60);
  }
  return text;
}

} // namespace

int BuildCommand(int argc, char** argv)
{
  std::string input, output;
  resmr::HierarchyOptions options;
  bool quiet = false;
  try
  {
    for (int a = 2; a < argc; ++a)
    {
      const std::string arg = argv[a];
      if (arg == "-h" || arg == "--help")
      {
        std::fputs(BuildUsage, stdout);
        return 0;
      }
      if (arg == "-o")
      {
        output = OptionValue(a, argc, argv);
      }
      else if (arg == "--cmax")
      {
        options.cmax = ParseInteger(OptionValue(a, argc, argv), "--cmax");
      }
      else if (arg == "--threads")
      {
        options.threads = static_cast<int>(ParseInteger(OptionValue(a, argc, argv), "--threads"));
      }
      else if (arg == "--memory")
      {
        options.memoryBytes = ParseSize(OptionValue(a, argc, argv));
      }
      else if (arg == "--scratch")
      {
        options.scratch = OptionValue(a, argc, argv);
      }
      else if (arg == "--seed")
      {
        options.seed = std::stoull(OptionValue(a, argc, argv));
      }
      else if (arg == "--fault-columns")
      {
        options.faultColumns = ParseInteger(OptionValue(a, argc, argv), "--fault-columns");
        if (options.faultColumns < 1)
        {
          throw std::invalid_argument("--fault-columns must be at least 1");
        }
      }
      else if (arg == "--fresh")
      {
        options.resume = false;
      }
      else if (arg == "--keep-faults" || arg == "--simplify-faults")
      {
        options.keepFaults = arg == "--keep-faults"; // --keep-faults: the default, still accepted
      }
      else if (arg == "--no-disk-check")
      {
        options.checkDisk = false;
      }
      else if (arg == "--quiet")
      {
        quiet = true;
      }
      else if (input.empty() && (arg.empty() || arg[0] != '-'))
      {
        input = arg;
      }
      else
      {
        throw std::invalid_argument("unknown option " + arg);
      }
    }
    if (input.empty() || output.empty())
    {
      std::fputs(BuildUsage, stderr);
      return 2;
    }
    // A deck's grid is spooled to the scratch folder: memory stays O(one layer) for any input.
    auto source = resmr::OpenLayerSource(input, resmr::ScratchFolder(output, options));
    for (const std::string& warning : source->Warnings())
    {
      std::fprintf(stderr, "resmr: warning: %s\n", warning.c_str());
    }
    const auto start = std::chrono::steady_clock::now();
    const bool terminal = isatty(2);
    double lastShown = -1;
    std::string lastPhase;
    const auto progress = [&](const char* phase, double fraction) {
      if (quiet)
      {
        return;
      }
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!terminal && fraction - lastShown < 0.05 && fraction < 1.0 && lastPhase == phase)
      {
        return;
      }
      lastShown = fraction;
      lastPhase = phase;
      const int width = 30;
      const int filled = static_cast<int>(fraction * width + 0.5);
      const std::string bar = std::string(filled, '#') + std::string(width - filled, '.');
      const std::string eta = fraction > 0.02 ? Duration(elapsed * (1 - fraction) / fraction) : std::string("?");
      std::fprintf(stderr, "%s[%s] %5.1f%% %-9s elapsed %s ETA %s%s", terminal ? "\r" : "", bar.c_str(), 100 * fraction,
        phase, Duration(elapsed).c_str(), eta.c_str(), terminal ? "" : "\n");
      std::fflush(stderr);
    };
    const resmr::HierarchyReport report = resmr::BuildHierarchy(*source, output, options, progress);
    if (!quiet && terminal)
    {
      std::fputc('\n', stderr);
    }
    if (!report.wallsLeftOut.empty())
    {
      std::fprintf(stderr, "resmr: warning: %s: no wall depth table (%s); walls are painted from their coordinates\n",
        output.c_str(), report.wallsLeftOut.c_str());
    }
    struct rusage usage;
    getrusage(RUSAGE_SELF, &usage);
    std::printf(
      "{\"input\": \"%s\", \"output\": \"%s\", \"cells\": %lld, \"active_cells\": %lld, \"columns\": %lld, "
      "\"leaf_level\": %d, \"regions\": %lld, \"threads\": %d, \"file_bytes\": %llu, \"bytes_per_cell\": %.3f, "
      "\"partition_s\": %.2f, \"leaves_s\": %.2f, \"simplify_s\": %.2f, \"total_s\": %.2f, "
      "\"cells_per_s\": %.0f, \"peak_rss_mb\": %.1f, \"resumed_from_level\": %d, \"resumed_partition\": %s, "
      "\"resumed_layers\": %lld, \"tasks\": %lld, \"resumed_tasks\": %lld, "
      "\"hashed_cells\": %llu, \"hash_slots\": %llu, \"hash_offsets\": %llu, \"peak_scratch_bytes\": %llu, "
      "\"peak_disk_bytes\": %llu}\n",
      input.c_str(), output.c_str(), static_cast<long long>(report.cells), static_cast<long long>(report.activeCells),
      static_cast<long long>(report.columns), report.leafLevel, static_cast<long long>(report.regions),
      report.threadsUsed, static_cast<unsigned long long>(report.fileBytes),
      double(report.fileBytes) / double(report.cells), report.partitionSeconds, report.leafSeconds,
      report.simplifySeconds, report.totalSeconds, double(report.cells) / std::max(report.totalSeconds, 1e-9),
      usage.ru_maxrss / 1024.0, report.resumedFromLevel, report.resumedFromPartition ? "true" : "false",
      static_cast<long long>(report.resumedLayers), static_cast<long long>(report.tasks),
      static_cast<long long>(report.resumedTasks), static_cast<unsigned long long>(report.hashedCells),
      static_cast<unsigned long long>(report.hashSlots), static_cast<unsigned long long>(report.hashOffsets),
      static_cast<unsigned long long>(report.peakScratchBytes), static_cast<unsigned long long>(report.peakDiskBytes));
    return 0;
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "\nresmr build: error: %s\n", error.what());
    return 1;
  }
}

int MultiresolutionInfo(const char* path, bool listRegions)
{
  const resmr::MultiresolutionFile file(path);
  const auto& h = file.Header();
  struct Level
  {
    int64_t regions = 0, columns = 0, cells = 0, vertices = 0;
    uint64_t bytes = 0, meshBytes = 0, rawBytes = 0;
    double error = 0;
  };
  std::map<int, Level> levels;
  for (const auto& r : file.Regions())
  {
    Level& level = levels[r.level];
    ++level.regions;
    level.columns += r.columns;
    level.cells += r.activeCells;
    level.vertices += r.vertices;
    for (const auto& c : r.chunks)
    {
      level.bytes += c.stored;
      level.rawBytes += c.raw;
    }
    level.meshBytes += r.chunks[resmr::RegionRecord::Mesh].stored;
    if (r.layerGroups > 0 && r.layerGroups <= r.chunks[resmr::RegionRecord::Mesh].offset)
    {
      // The layer groups' chunks, written back to back just before the mesh chunk: the
      // positions, 12 bytes a vertex.
      const uint64_t groups = r.chunks[resmr::RegionRecord::Mesh].offset - r.layerGroups;
      level.bytes += groups;
      level.rawBytes += 12 * static_cast<uint64_t>(r.vertices);
      level.meshBytes += groups;
    }
    level.error = std::max<double>(level.error, r.error);
  }
  const double cells = double(h.dims[0]) * double(h.dims[1]) * double(h.dims[2]);
  std::printf(
    "{\"file\": \"%s\", \"kind\": \"resmr\", \"version\": %u, \"bytes\": %llu, \"dims\": [%lld, %lld, %lld], "
    "\"cells\": %.0f, \"bytes_per_cell\": %.3f, \"leaf_level\": %d, \"cmax\": %d, \"regions\": %llu, \"levels\": [",
    path, h.version, static_cast<unsigned long long>(file.FileSize()), static_cast<long long>(h.dims[0]),
    static_cast<long long>(h.dims[1]), static_cast<long long>(h.dims[2]), cells, double(file.FileSize()) / cells,
    h.leafLevel, h.cmax, static_cast<unsigned long long>(h.regionCount));
  bool first = true;
  for (const auto& entry : levels)
  {
    const Level& l = entry.second;
    std::printf(
      "%s\n  {\"level\": %d, \"regions\": %lld, \"columns\": %lld, \"active_cells\": %lld, \"vertices\": %lld, "
      "\"bytes\": %llu, \"mesh_bytes\": %llu, \"surface_bytes\": %llu, \"uncompressed_bytes\": %llu, "
      "\"max_error\": %.6g}",
      first ? "" : ",", entry.first, static_cast<long long>(l.regions), static_cast<long long>(l.columns),
      static_cast<long long>(l.cells), static_cast<long long>(l.vertices), static_cast<unsigned long long>(l.bytes),
      static_cast<unsigned long long>(l.meshBytes), static_cast<unsigned long long>(l.bytes - l.meshBytes),
      static_cast<unsigned long long>(l.rawBytes), l.error);
    first = false;
  }
  // Sec. 5.4: the packed 3D textures, against the cells they hold and the full grid.
  const auto& m = h.hashTableSides;
  const auto& r = h.hashOffsetSides;
  const double slots = double(m[0]) * m[1] * m[2];
  const double offsets = double(r[0]) * r[1] * r[2];
  uint64_t modelBytes = 0;
  for (const auto& m : file.ModelChunks())
  {
    modelBytes += m.chunk.stored;
  }
  std::printf("],\n \"model_chunk_bytes\": %llu, \"geometry_id\": \"%016llx\", \"hash\": {\"cells\": %llu, "
              "\"table_sides\": [%u, %u, %u], \"offset_sides\": [%u, %u, %u], \"slots\": %.0f, \"offsets\": %.0f, "
              "\"fill\": %.4f, "
              "\"packed_over_cells_float\": %.4f, \"packed_over_cells_float_with_offsets\": %.4f, "
              "\"packed_over_full_grid\": %.6f}",
    static_cast<unsigned long long>(modelBytes), static_cast<unsigned long long>(h.geometryId),
    static_cast<unsigned long long>(h.hashedCells), m[0], m[1], m[2], r[0], r[1], r[2], slots, offsets,
    slots > 0 ? double(h.hashedCells) / slots : 0.0, h.hashedCells ? slots / double(h.hashedCells) : 0.0,
    h.hashedCells ? (slots * 4 + offsets * 6) / (double(h.hashedCells) * 4) : 0.0,
    (slots * 4 + offsets * 6) / (cells * 4));
  // MAPAXES as the input gave it; viewers apply it when "applies" (as the grid readers do).
  const resmr::MapPlacement& map = h.map;
  std::array<double, 6> transform;
  if (map.hasMapAxes || !map.mapUnits.empty() || !map.gridUnit.empty())
  {
    const auto& a = map.mapAxes;
    std::printf(",\n \"map_axes\": {\"given\": %s, \"applies\": %s, \"y_axis_point\": [%.17g, %.17g], "
                "\"origin\": [%.17g, %.17g], \"x_axis_point\": [%.17g, %.17g], \"map_units\": %s, \"grid_unit\": %s, "
                "\"grid_in_map_units\": %s}",
      map.hasMapAxes ? "true" : "false",
      resmr::CornerPointGeometry::PlacementTransform(map, transform) ? "true" : "false", a.yAxisPoint[0],
      a.yAxisPoint[1], a.origin[0], a.origin[1], a.xAxisPoint[0], a.xAxisPoint[1], JsonString(map.mapUnits).c_str(),
      JsonString(map.gridUnit).c_str(), map.gridUnitIsMap ? "true" : "false");
  }
  else
  {
    std::printf(",\n \"map_axes\": null");
  }
  // Regions no cut reaches (built by an earlier version): holes in the view until rebuilt.
  std::printf(",\n \"unreachable_regions\": %zu", resmr::UnreachableRegions(file).size());
  if (listRegions)
  {
    std::printf(",\n \"region_list\": [");
    bool firstRegion = true;
    for (const auto& r : file.Regions())
    {
      std::printf(
        "%s\n  [%d, %lld, %lld, %lld, %lld, %.9g, %.9g, [%.9g, %.9g, %.9g, %.9g, %.9g, %.9g], [%u, %u, %u, %u]]",
        firstRegion ? "" : ",", r.level, static_cast<long long>(r.index), static_cast<long long>(r.columns),
        static_cast<long long>(r.activeCells), static_cast<long long>(r.vertices), r.error, r.ownError, r.bounds[0],
        r.bounds[1], r.bounds[2], r.bounds[3], r.bounds[4], r.bounds[5], r.chunks[0].crc, r.chunks[1].crc,
        r.chunks[2].crc, r.chunks[3].crc);
      firstRegion = false;
    }
    std::printf("]");
  }
  std::printf("}\n");
  return 0;
}
