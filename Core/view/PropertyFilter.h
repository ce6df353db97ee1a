// Property filter on the multiresolution surface (ours; the paper's Sec. 8 leaves regions of
// interest to future work): only the cells whose values of chosen arrays, at the time step
// shown, lie in ranges are drawn (several filters: all must hold, as ParaView's Threshold
// applied one after the other), together with an I/J/K range (CellRange.h).
//
// Contract:
// - A cell passes a ValueFilter when its value v of the array at the step satisfies
//   low <= v <= high; a cell with no value (NaN) never passes. An array with no table at the
//   step but a static one (step -1) is filtered by the static one.
// - Which regions a filter leaves whole, removes whole or crosses is decided from the
//   property file's block ranges (PropertyFile::ReadBlockRanges): the blocks under a region's
//   footprint widened by `margin` cells. Inside: every active cell of those blocks passes (and
//   the cells one across the region's border too, with a margin of 1). Outside: none does.
//   Conservative both ways: a block range is a bound of its cells' values.
// - Leaves (original columns) are masked cell by cell from the cells' own values, read for
//   the region's box from the layer bands (PropertyFile::ReadBox): exact, the cells shown are
//   the cells that pass.
// - A coarse region a filter crosses is masked by the layer blocks (PropertyFile::
//   ReadLayerBlocks): a coarse cell (column c, layer k) stays when a block of layer k under
//   the column's cells may pass, so every passing cell's coarse cell stays (nothing kept is
//   lost) and what is drawn besides lies within the column, or the LayerBlockSide-cell block,
//   around a passing cell of its layer; K is exact to the layer. The selection splits such a
//   region while that width (FilterError) projects above the tolerance, so at a tolerance
//   of t pixels the cells drawn are the passing cells widened by at most about t pixels in I
//   and J; at 0 every crossed region is a leaf, exact.
// - Faces of a filtered view carry the value of their cell in the painted array (FaceValues):
//   the faces a filter exposes lie inside the model, where the packed table has no value. A
//   coarse crossed region's faces carry the mean of the painted array over their layer block
//   (FaceMeans): within the block's range of values.
#pragma once

#include "CellRange.h"
#include "PropertyFile.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace resmr
{

struct ValueFilter
{
  std::string name;
  float low = 0, high = 0; ///< inclusive
  bool operator==(const ValueFilter& o) const { return name == o.name && low == o.low && high == o.high; }
  bool Passes(float v) const { return v >= this->low && v <= this->high; } ///< false for NaN
};

/// Parses value filters written as Multiresolution Threshold writes them, one a line: "low
/// high name", the name the rest of the line (names may hold spaces); blank lines are skipped.
/// False, `filters` unchanged, when a line is not of that form.
bool ParseValueFilters(const std::string& text, std::vector<ValueFilter>& filters);

/// The table of `name` at `step` in `file`, else its static table, else -1.
int FindFilterTable(const PropertyFile& file, const std::string& name, int32_t step);

/// Value filters resolved against a property file at a step, with their tables' block ranges.
class ValueFilterSet
{
public:
  /// Throws std::invalid_argument naming the array when the file has no table for a filter.
  ValueFilterSet(std::shared_ptr<const PropertyFile> file, std::vector<ValueFilter> filters, int32_t step);
  const std::vector<ValueFilter>& Filters() const { return this->Wanted; }
  int32_t Step() const { return this->AtStep; }
  const std::vector<int>& Tables() const { return this->TableIndices; }
  const PropertyFile& File() const { return *this->Properties; }
  bool SameAs(const ValueFilterSet& other) const
  {
    return this->Wanted == other.Wanted && this->TableIndices == other.TableIndices &&
      this->Properties == other.Properties;
  }
  /// Where a footprint (ti min, ti max, tj min, tj max) lies against the filters, with `margin`
  /// cells around it (Outside, Inside, or Crossed; Crossed in files without block ranges).
  RangeClass Classify(const std::array<float, 4>& footprint, float margin) const;
  /// Whether a cell of columns [lo, hi] (inclusive, i then j) in layer k may pass by the
  /// layer blocks under them (false: none passes); true in files without layer blocks.
  bool LayerBlocksMayPass(const std::array<int64_t, 2>& lo, const std::array<int64_t, 2>& hi, int64_t k) const;

private:
  std::shared_ptr<const PropertyFile> Properties;
  std::vector<ValueFilter> Wanted;
  int32_t AtStep = -1;
  std::vector<int> TableIndices;
  std::vector<std::vector<ValueRange>> Blocks;        ///< per filter; empty in files without them
  std::vector<std::vector<BlockSummary>> LayerBlocks; ///< per filter; empty in files without them
};

/// A coarse region's I/J width, model units, within which a property filter's masking by
/// layer blocks may draw cells that do not pass (see the contract): twice its columns' mean
/// width, or a block, in cells (from its footprint's area and its column count), times its
/// cells' mean width (from its bounds' area over its footprint's).
float FilterError(const RegionRecord& region, const std::array<float, 4>& footprint);

/// What a filtered view draws: the cells of `range` that pass `values` (none: every cell of
/// the range), their faces carrying the values of table `paintTable` (-1: none).
struct CellFilter
{
  CellRange range;
  std::shared_ptr<const ValueFilterSet> values;
  int paintTable = -1;
  /// The painted table's layer blocks (PropertyFile::ReadLayerBlocks), for coarse regions'
  /// faces; null or empty: those faces carry NaN.
  std::shared_ptr<const std::vector<BlockSummary>> paintBlocks;
  bool operator==(const CellFilter& o) const
  {
    const bool sameValues =
      (!this->values && !o.values) || (this->values && o.values && this->values->SameAs(*o.values));
    return this->range == o.range && sameValues && this->paintTable == o.paintTable;
  }
  bool operator!=(const CellFilter& o) const { return !(*this == o); }
  bool HasValues() const { return this->values && !this->values->Filters().empty(); }
};

/// The layers (first, last; 0-based) in which a region whose nodes have the topological
/// coordinates `topology` may keep a cell under `filter`: the range's, narrowed to those where
/// a layer block under the region's cells may pass (ValueFilterSet::LayerBlocksMayPass); one
/// layer of the range when none may (its cells are masked then). `dims`: the grid's.
std::array<int32_t, 2> FilterLayers(
  const CellFilter& filter, const std::vector<std::array<float, 2>>& topology, const std::array<int64_t, 3>& dims);

/// The values a region's filter reads: the tables' values over a box of cells.
struct CellBox
{
  std::array<int64_t, 3> lo{}, hi{ -1, -1, -1 };
  std::vector<std::vector<float>> tables; ///< one per filter, then the painted table's (if any)
  float At(std::size_t table, int64_t i, int64_t j, int64_t k) const
  {
    const int64_t w = this->hi[0] - this->lo[0] + 1, h = this->hi[1] - this->lo[1] + 1;
    return this
      ->tables[table][static_cast<std::size_t>((i - this->lo[0]) + w * ((j - this->lo[1]) + h * (k - this->lo[2])))];
  }
};

/// The box of cells under `mesh`'s columns widened by one cell (the cells across its border),
/// in the mesh's layers within the filter's range, within a grid of `dims`, with every filter's
/// values and the painted table's read for it.
CellBox ReadCellBox(const RegionMesh& mesh, const CellFilter& filter, const std::array<int64_t, 3>& dims);

/// Leaves in `mesh` only the cells `filter` keeps active and opens their sides towards cells
/// it removes (MaskToRange, with values): with `box` (a leaf), from each cell's own values;
/// without (a coarse region), by the layer blocks under each column's cells.
void MaskToFilter(RegionMesh& mesh, const CellFilter& filter, const CellBox* box);

/// One value a triangle: the mean of the painted table over the layer block of the cell under
/// the triangle's centroid (NaN without layer blocks). `dims`: the grid's.
std::vector<float> FaceMeans(const std::vector<float>& vertices, const std::vector<uint32_t>& indices,
  const std::vector<BlockSummary>& blocks, const std::array<int64_t, 3>& dims);

/// One value a triangle of `vertices`/`indices` (RegionDrawBuffers' layout): the painted
/// table's value of the cell under the triangle's centroid, from `box` (NaN outside it).
std::vector<float> FaceValues(
  const std::vector<float>& vertices, const std::vector<uint32_t>& indices, const CellBox& box);

} // namespace resmr
