// The first, streaming pass of the hierarchy build (paper Sec. 4.2 and 7, "partitioning"):
// layers are read once, top to bottom, and written to scratch files of square tiles of
// columns, so that any box of columns can later be read back with all its layers while
// memory holds one layer at most. The pass also records which columns hold an active cell,
// where each column stands (x, y) and the model's extent.
//
// Contract:
// - Scratch: one file a tile in `folder`, layer after layer: the tile's ZCORN (8 floats a
//   cell, ECLIPSE corner order) then its active flags; removed by the destructor.
// - ReadBox() gives the cells of [i0, i1) x [j0, j1) in the same layout as the source grid
//   restricted to the box: corners [k][j][i][8] and active [k][j][i].
// - Column centres are the mean of their four pillars' midpoints (COORD only), so they are
//   known before any depth is read and never depend on the layering.
#pragma once

#include "LayerSource.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace resmr
{

class LeafPartition
{
public:
  /// Streams every layer of `source` into tiles of `tileSize` x `tileSize` columns in
  /// `folder` (created if missing). `progress` gets the fraction of layers done. Throws
  /// std::runtime_error naming the file on a failed write.
  /// `onLayer`, if given, sees each layer's active flags (one a cell, i fastest) as it
  /// streams by.
  LeafPartition(LayerSource& source, const std::string& folder, int64_t tileSize,
    const std::function<void(double)>& progress = {},
    const std::function<void(int64_t k, const std::vector<uint8_t>& active)>& onLayer = {});
  /// Opens the tiles another process wrote in `folder` (after its SaveState()), read-only;
  /// this object leaves them in place. Throws std::runtime_error naming the file.
  explicit LeafPartition(const std::string& folder);
  /// Writes what the constructor learnt (columns, extent, tiles) for LeafPartition(folder).
  void SaveState() const;
  /// Whether the destructor removes the tiles and the state: by default the writer does and
  /// a reader does not; a failed build keeps them to resume, and a resumed build's rank 0
  /// takes them over to remove them once the leaves are built.
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

  void ReadBox(
    int64_t i0, int64_t i1, int64_t j0, int64_t j1, std::vector<float>& zcorn, std::vector<uint8_t>& active) const;

  /// Corner (x, y, depth) of a cell corner at `depth` on pillar (pi, pj), by COORD.
  void PillarPoint(int64_t pi, int64_t pj, double depth, double xyz[3]) const;

private:
  std::string TilePath(int64_t ti, int64_t tj) const;
  std::array<int64_t, 3> Dimensions{};
  std::vector<double> CoordValues;
  std::vector<uint8_t> AnyActive;
  std::array<double, 6> Bounds{};
  int64_t ActiveCount = 0;
  int64_t Tile = 64, TilesX = 0, TilesY = 0;
  std::string Folder;
  std::vector<int> Descriptors;
  bool Owner = true; ///< created the tiles, so removes them
};

} // namespace resmr
