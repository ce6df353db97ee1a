// The first, streaming pass of the hierarchy build (paper Sec. 4.2 and 7, "partitioning"):
// layers are read once, top to bottom, and written to scratch files of square tiles of
// columns, so that any box of columns can later be read back with all its layers while
// memory holds one layer at most. The pass also records which columns hold an active cell,
// where each column stands (x, y) and the model's extent.
//
// Contract:
// - Scratch: one file a tile in `folder`, holding one LZO-compressed block a layer, appended
//   in layer order: the tile's ZCORN (ECLIPSE corner order) as residuals of a prediction from
//   the cell above and the neighbours at the same pillars, then its active flags, one bit a
//   cell. Decoding is exact (the same float bits). Where each block lies and its CRC-32 are
//   held in memory and in `folder`/partition.state; a corrupt or short block throws
//   std::runtime_error naming the tile file and the layer.
// - The state file is rewritten atomically (temporary file, then rename) as a checkpoint after
//   a layer once the tiles have grown by its own size since the last one or
//   PartitionHooks::checkpointSeconds have passed, after a write that failed (a full disk)
//   when it can still be written, and after the last layer, marked complete. COORD is
//   written once, in `folder`/coord.bin. A writer that finds an incomplete checkpoint of the same
//   grid and tile size in `folder` resumes after its layers instead of starting over.
// - ReadBox() gives the cells of [i0, i1) x [j0, j1) in the same layout as the source grid
//   restricted to the box: corners [k][j][i][8] and active [k][j][i].
// - Retain()/Release() count the readers of each tile; the owner removes a tile's file once
//   its count falls back to 0. The destructor of the owner removes every tile and the state.
// - Column centres are the mean of their four pillars' midpoints (COORD only), so they are
//   known before any depth is read and never depend on the layering.
#pragma once

#include "LayerSource.h"

#include <array>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace resmr
{

/// What the caller of the partition pass learns as it goes, and what a checkpoint keeps for it.
struct PartitionHooks
{
  /// Fraction of layers done.
  std::function<void(double)> progress;
  /// Each layer's active flags (i fastest), for the layers this call streams.
  std::function<void(int64_t k, const std::vector<uint8_t>& active)> onLayer;
  /// Bytes stored with each checkpoint, so the caller can resume its own work with the pass.
  std::function<std::vector<uint8_t>()> checkpointNote;
  /// A pass resumed after `layers` layers, with the note of that checkpoint.
  std::function<void(int64_t layers, const std::vector<uint8_t>& note)> onResume;
  /// Most time between two checkpoints (they also come whenever the tiles have grown by a
  /// checkpoint's size); 0: after every layer.
  double checkpointSeconds = 5;
};

class LeafPartition
{
public:
  /// Streams every layer of `source` into tiles of `tileSize` x `tileSize` columns in
  /// `folder` (created if missing). When `folder` holds an incomplete checkpoint of the same
  /// dimensions, tile size and COORD, the tile files are cut back to it, hooks.onResume gets
  /// its layer count and note, the source's first layers are read and dropped (the last one
  /// must match the one the checkpoint saw) and the pass goes on; otherwise it starts over.
  /// hooks.onLayer sees only the layers streamed by this call. Throws std::runtime_error
  /// naming the file on a failed write.
  LeafPartition(LayerSource& source, const std::string& folder, int64_t tileSize, const PartitionHooks& hooks = {});
  /// Opens the finished partition another process wrote in `folder`, read-only; this object
  /// leaves it in place. Tile files already removed (freed by a resumed build) are allowed:
  /// only reading them fails. Throws std::runtime_error naming the file, also for a
  /// partition whose pass is not finished.
  explicit LeafPartition(const std::string& folder);
  /// Whether `folder` holds a readable partition state, and in `complete` whether its pass
  /// finished (so LeafPartition(folder) opens it) or stopped part-way (so the writing
  /// constructor resumes it).
  static bool HasCheckpoint(const std::string& folder, bool* complete);
  /// Writes the state for LeafPartition(folder): the writer already has, after the last
  /// layer; kept for callers that write it again once they are done.
  void SaveState() const;
  /// Whether the destructor (and Release) remove the tiles and the state: by default the
  /// writer does and a reader does not; a failed build keeps them to resume, and a resumed
  /// build's rank 0 takes them over to remove them once the leaves are built.
  void SetRemoveOnDestroy(bool remove) { this->Owner = remove; }
  ~LeafPartition();
  LeafPartition(const LeafPartition&) = delete;
  LeafPartition& operator=(const LeafPartition&) = delete;

  const std::array<int64_t, 3>& Dims() const { return this->Dimensions; }
  const std::vector<double>& Coord() const { return this->CoordValues; }
  /// One flag a column (i fastest): the column holds an active cell.
  const std::vector<uint8_t>& ColumnHasActive() const { return this->AnyActive; }
  /// Column centre (x, y) of column i + nx j.
  std::array<double, 2> ColumnCentre(int64_t i, int64_t j) const;
  /// x, y, depth minimum then maximum over every pillar end and every active cell corner.
  const std::array<double, 6>& Extent() const { return this->Bounds; }
  int64_t ActiveCells() const { return this->ActiveCount; }

  /// Thread-safe (several threads may read at once). The tiles of the box must not be
  /// released meanwhile: retain the box first where other threads release tiles.
  void ReadBox(
    int64_t i0, int64_t i1, int64_t j0, int64_t j1, std::vector<float>& zcorn, std::vector<uint8_t>& active) const;

  /// Adds one reader to every tile the box [i0, i1) x [j0, j1) overlaps. Thread-safe.
  void Retain(int64_t i0, int64_t i1, int64_t j0, int64_t j1);
  /// Removes one reader from those tiles; a tile whose count falls to 0 is closed and, by
  /// the owner, removed, so the scratch shrinks as the leaves are built. A tile never
  /// retained is left alone. Thread-safe.
  void Release(int64_t i0, int64_t i1, int64_t j0, int64_t j1);
  /// Bytes of the tile files still on disk.
  uint64_t TileBytes() const;

  /// Corner (x, y, depth) of a cell corner at `depth` on pillar (pi, pj), by COORD.
  void PillarPoint(int64_t pi, int64_t pj, double depth, double xyz[3]) const;

private:
  /// Where one layer of one tile lies in the tile's file.
  struct Block
  {
    uint64_t offset = 0;
    uint32_t stored = 0; ///< compressed bytes
    uint32_t crc = 0;    ///< CRC-32 of the stored bytes
    uint32_t planes = 0; ///< which byte planes of the residuals it holds (the others are zero)
  };
  struct State; // a checkpoint as read from the state file
  static bool LoadState(const std::string& path, State& state, std::string& why);
  uint64_t TileEnd(std::size_t t) const;
  std::string TilePath(int64_t ti, int64_t tj) const;
  std::string StatePath() const { return this->Folder + "/partition.state"; }
  void StartBounds();
  bool TakeCheckpoint();
  void OpenTiles(bool resume);
  void SkipLayers(LayerSource& source, std::vector<std::vector<uint32_t>>& above);
  std::vector<uint8_t> EncodeTile(int64_t k, int64_t ti, int64_t tj, const std::vector<float>& zcorn,
    const std::vector<uint8_t>& active, const std::vector<std::vector<uint32_t>>& above, std::vector<uint32_t>& cells,
    uint32_t& planes) const;
  void SaveCoord() const;
  static bool LoadCoord(
    const std::string& folder, const std::array<int64_t, 3>& dims, std::vector<double>& coord, std::string& why);
  void CheckpointAfterFailure(const PartitionHooks& hooks);
  void StreamLayers(LayerSource& source, const PartitionHooks& hooks, std::vector<std::vector<uint32_t>>& above);
  void AddLayerStatistics(
    const LayerSource& source, int64_t k, const std::vector<float>& zcorn, const std::vector<uint8_t>& active);
  void WriteLayer(int64_t k, const std::vector<float>& zcorn, const std::vector<uint8_t>& active,
    std::vector<std::vector<uint32_t>>& above);
  void CloseTiles();
  std::array<int64_t, 4> TileRange(int64_t i0, int64_t i1, int64_t j0, int64_t j1) const;
  void ReadTile(int64_t ti, int64_t tj, int64_t i0, int64_t i1, int64_t j0, int64_t j1, std::vector<float>& zcorn,
    std::vector<uint8_t>& active) const;

  std::array<int64_t, 3> Dimensions{};
  std::vector<double> CoordValues;
  std::vector<uint8_t> AnyActive;
  std::array<double, 6> Bounds{};
  int64_t ActiveCount = 0;
  int64_t Tile = 64, TilesX = 0, TilesY = 0;
  int64_t LayersDone = 0;
  bool Complete = false;
  std::vector<uint8_t> Note; ///< the caller's bytes of the last checkpoint
  std::string Folder;
  std::vector<std::vector<Block>> Blocks; ///< per tile, one a layer
  mutable std::mutex Lock;                ///< guards the three below
  std::vector<int> Descriptors;           ///< per tile, -1 once closed or when missing
  std::vector<int64_t> Readers;           ///< per tile, Retain() minus Release()
  std::vector<uint8_t> Removed;           ///< per tile, its file is gone
  bool Owner = true;                      ///< created the tiles, so removes them
};

} // namespace resmr
