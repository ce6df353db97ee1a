// Out-of-core build of the multiresolution hierarchy (paper Sec. 4.2, 4.3, 6.1, 6.2): a
// streaming partition pass into scratch tiles, leaf meshes saved with their quadrics, then
// bottom-up per diamond: the children's meshes merged, the columns touching the diamond's
// external boundary locked, the rest simplified by column collapse (Sec. 4.1), the result
// split into the diamond's two triangles and saved; every region's surfaces extracted and
// written to the .resmr file as soon as its mesh is final.
//
// Contract:
// - Crack-free: a node on an edge between two regions (a "cut" edge) is never moved or
//   merged while those regions belong to different diamonds, so any conformal cut of the
//   tree matches exactly (the diamond's two triangles are always shown together).
// - Each diamond is simplified to half its children's columns and at most Cmax a region (the
//   paper's rule is Cmax a region; halving as well keeps every level a real simplification
//   where leaves hold fewer than Cmax columns). Locked borders may leave a few more.
// - Bounding volumes and errors are made equal for a diamond's two regions and monotone up
//   the tree (Sec. 6.2).
// - Memory: one layer of the input during the partition pass, then one diamond's meshes a
//   worker thread (worker threads are cut to fit `memoryBytes`), plus a few arrays of one
//   value a column (flags, centres, leaf codes), and at the end one bit a cell (which cells
//   the extracted faces touch) and the perfect hash's tables (Sec. 5.4).
// - Property side (Sec. 5.3-5.4), built once per geometry: the cells the extracted faces of
//   every level touch are hashed perfectly; the file holds each slot's cell and its top and
//   bottom face normals (2 bytes each), and every layer's active flags.
// - Resumable: scratch files (`scratch`) keep each finished level (region meshes, chunks,
//   a manifest a level); a build killed after its leaf level resumes from the last finished
//   level when run again with the same input and options. The scratch folder is removed
//   when the file is in place; after a failure it stays for resuming.
// - The input's MAPAXES, MAPUNITS and GRIDUNIT go to the file's header; meshes, errors and
//   bounds stay in grid coordinates (viewers place them on the map).
// - Deterministic: the same input and Cmax give the same region meshes whatever the thread
//   count (chunks may lie in another order in the file).
#pragma once

#include "LayerSource.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>

namespace resmr
{

struct HierarchyOptions
{
  /// Columns a region holds at most; 0 (the default): 4096 (a 64 x 64 patch, about 16k
  /// triangles of top and bottom surface a region, the batch size at which GPUs reach full
  /// speed), but no more than a 32nd of the model's columns, at least 256, so that small
  /// models get several levels.
  int64_t cmax = 0;
  /// 0: every core, but one a 16,384 cells (models that small build in milliseconds, less
  /// than threads cost to start and join)
  int threads = 0;
  int64_t memoryBytes = 0; ///< 0: half the available memory
  std::string scratch;     ///< scratch folder (default: OUTPUT.scratch, beside the output)
  uint64_t seed = 1;
  /// Continue a build killed in the same scratch folder (same input and options) from its
  /// last finished level; false: start over.
  bool resume = true;
  /// Refuse to start when the disks of the scratch folder and the output have less free
  /// space than the build needs (see BuildDiskNeed).
  bool checkDisk = true;
  /// Keep the faults' columns whole (LockFaultColumns) at every level where they fit
  /// (`faultColumns`): no gap where faults bend or meet there. Where they do not (the
  /// coarsest levels of a large model) the two sides of each fault weld into one surface
  /// (FaultWelding.h), the throw drawn as a slope within the level's error. false: each fault
  /// block simplified on its own at every level (gaps up to each level's error may open where
  /// faults bend or meet).
  bool keepFaults = true;
  /// Columns a triangle of a diamond may keep whole along faults and region borders; 0: a
  /// full-size region's (4,096) or Cmax, whichever is larger.
  int64_t faultColumns = 0;
  /// MPI (through ParaView's controller, vtkBuildMultiresolutionHierarchy): this process's
  /// rank among `ranks`, which share the scratch folder and split the leaves and each
  /// level's diamonds. `barrier` must return once every rank has called it (required when
  /// ranks > 1). Rank 0 streams the input and writes the file; the result is the same file
  /// whatever the ranks and threads (chunks may lie in another order).
  int rank = 0, ranks = 1;
  std::function<void()> barrier;
};

struct HierarchyReport
{
  int64_t cells = 0, activeCells = 0, columns = 0;
  int leafLevel = 0;
  int64_t regions = 0, nonEmptyRegions = 0;
  int threadsUsed = 0;
  int resumedFromLevel = -1;         ///< the last finished level a resumed build started from, or -1
  bool resumedFromPartition = false; ///< a resumed build reused the finished partition pass
  int64_t resumedLayers = 0;         ///< layers a partition pass stopped part-way had done
  int64_t tasks = 0;                 ///< leaves and diamonds a one-process build runs (BuildSchedule)
  int64_t resumedTasks = 0;          ///< of those, the ones a resumed build found finished
  uint64_t hashedCells = 0, hashSlots = 0, hashOffsets = 0; ///< perfect hash (Sec. 5.4)
  uint64_t wallFaces = 0;                                   ///< faces of the wall depth table (WallDepthTable.h)
  /// Why the file has no wall depth table though the model has walls (empty: it has one, or
  /// no walls); the file is whole without it, its walls painted from their coordinates.
  std::string wallsLeftOut;
  uint64_t fileBytes = 0;
  /// Peak bytes of the scratch folder, and of the scratch folder with the file being written.
  uint64_t peakScratchBytes = 0, peakDiskBytes = 0;
  double partitionSeconds = 0, leafSeconds = 0, simplifySeconds = 0, totalSeconds = 0;
};

/// Disk a build needs at its peak: the scratch folder and the file, a bound with some margin
/// over what the build benchmark measures (docs/benchmarks.md). One process builds depth
/// first: compressed partition tiles, the regions waiting to be merged and the chunks; region
/// meshes carry every interface of every column, so thin models cost more a cell, hence the
/// part a column. MPI ranks build level by level, with two levels of region meshes and their
/// quadrics in scratch. Small models cost more a cell, hence the fixed parts.
struct BuildDiskNeed
{
  static constexpr uint64_t ScratchBytesPerCell = 24, ScratchBytesPerColumn = 64;
  static constexpr uint64_t LevelScratchBytesPerCell = 150; ///< MPI ranks, level by level
  static constexpr uint64_t ScratchFixedBytes = uint64_t(256) << 20;
  static constexpr uint64_t FileBytesPerCell = 16, FileFixedBytes = uint64_t(64) << 20;
  uint64_t scratch = 0, file = 0;
  BuildDiskNeed(const std::array<int64_t, 3>& dims, int ranks)
    : scratch((ranks > 1 ? uint64_t(dims[0] * dims[1] * dims[2]) * LevelScratchBytesPerCell
                         : uint64_t(dims[0] * dims[1] * dims[2]) * ScratchBytesPerCell +
                    uint64_t(dims[0] * dims[1]) * ScratchBytesPerColumn) +
        ScratchFixedBytes)
    , file(uint64_t(dims[0] * dims[1] * dims[2]) * FileBytesPerCell + FileFixedBytes)
  {
  }
};

/// Phase name and fraction of the whole build done (0..1).
using BuildProgress = std::function<void(const char* phase, double fraction)>;

/// The scratch folder a build of `output` uses: options.scratch, else OUTPUT.scratch. Also
/// where OpenLayerSource is told to spool a deck's grid (its files are unlinked at once, so
/// the builder's clearing of the folder never meets them).
std::string ScratchFolder(const std::string& output, const HierarchyOptions& options);

/// Builds `output` (.resmr) from the layers of `source`. Throws std::runtime_error (or a
/// subclass) naming the input or file on failure; the output is then not created and any
/// older file of that name is left as it was.
HierarchyReport BuildHierarchy(
  LayerSource& source, const std::string& output, const HierarchyOptions& options, const BuildProgress& progress = {});

} // namespace resmr
