// I/J/K range filter on the multiresolution surface (ours; the paper's Sec. 8 leaves regions
// of interest to future work, its Sec. 3 argues that keeping columns and hexahedra makes them
// possible): only the cells with i, j, k in a box are drawn, and the faces where the box cuts
// the model close the solid.
//
// Contract:
// - A range is a box of cells, 0-based and inclusive on each axis: [lo, hi] in i, j and k,
//   less any boxes excluded from it (ResInsight's exclude range filters; ours here too): a
//   cell is in the range when it is in the box and in none of the excluded boxes. An
//   excluded box's K is exact at every level as the box's is; its I and J sides split the
//   regions they cross to the leaves as the box's do.
// - K is exact at every level: column collapse keeps every layer interface in every column
//   (Sec. 4.1), so masking layers out of a coarse region leaves its top of layer lo[2] and
//   bottom of layer hi[2] on the same interfaces as the original grid's, within the region's
//   error.
// - I and J are exact at the leaves (original columns, integer topology). A coarse column's
//   topology is an average of the nodes it merged, so a box side through a coarse region has
//   no exact place in it: such a region is split down to the leaves (ClassifyFootprint says
//   which regions it crosses). The leaves along a box side are few: a side crosses a row of
//   leaves, not an area.
// - Where a range lies against a region is decided by the region's footprint in (i, j): the
//   file's (ModelChunk::Footprints, exact: its leaves' node boxes together), or, in files
//   without them, the box of the region's own nodes widened by its widest column and one cell
//   (a coarse node is an average of the nodes it merged, so its box may fall short of its
//   leaves'; measured: by at most its widest column). A region is Inside only with a cell to
//   spare on each side of the range, so the cells across its border are in the range too.
#pragma once

#include "RegionMesh.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace resmr
{

/// A box of cells, 0-based and inclusive: i lo, i hi, j lo, j hi, k lo, k hi.
using CellBoxBounds = std::array<int64_t, 6>;

struct CellRange
{
  std::array<int64_t, 3> lo{ 0, 0, 0 }, hi{ -1, -1, -1 }; ///< inclusive, 0-based
  std::vector<CellBoxBounds> excluded;                    ///< boxes whose cells are left out
  bool operator==(const CellRange& other) const
  {
    return this->lo == other.lo && this->hi == other.hi && this->excluded == other.excluded;
  }
  bool operator!=(const CellRange& other) const { return !(*this == other); }
  bool Contains(int64_t i, int64_t j, int64_t k) const
  {
    return i >= this->lo[0] && i <= this->hi[0] && j >= this->lo[1] && j <= this->hi[1] && k >= this->lo[2] &&
      k <= this->hi[2] && !this->Excluded(i, j, k);
  }
  /// Whether cell (i, j, k) lies in an excluded box.
  bool Excluded(int64_t i, int64_t j, int64_t k) const
  {
    for (const CellBoxBounds& e : this->excluded)
    {
      if (i >= e[0] && i <= e[1] && j >= e[2] && j <= e[3] && k >= e[4] && k <= e[5])
      {
        return true;
      }
    }
    return false;
  }
  /// Whether no cell of a grid of `dims` is in the range.
  bool Empty(const std::array<int64_t, 3>& dims) const;
  /// Whether every cell of a grid of `dims` is in the range.
  bool Whole(const std::array<int64_t, 3>& dims) const;
  /// The range as ECLIPSE writes it, from 1: "I 3-10, J 1-5, K 2-2", then each excluded box:
  /// " without I 4-6, J 1-5, K 1-3".
  std::string Describe() const;
};

/// Parses a range as the descriptor carries it, counted from 1 and inclusive: a line of six
/// whole numbers "I0 I1 J0 J1 K0 K1" (the box; without one, every cell of a grid of `dims`),
/// and a line "exclude I0 I1 J0 J1 K0 K1" for each excluded box. False, `range` unchanged,
/// for any other line.
bool ParseCellRange(const std::string& text, const std::array<int64_t, 3>& dims, CellRange& range);

/// Box of a region mesh's topology: (ti min, ti max, tj min, tj max), widened as the contract says.
std::array<float, 4> RegionFootprint(const RegionMesh& mesh);

enum class RangeClass : uint8_t
{
  Unknown, ///< footprint not known yet (region not decoded)
  Outside, ///< no cell of the region or its descendants is in the range
  Inside,  ///< every column of the region and its descendants is in the range in (i, j)
  Crossed  ///< a side of the range in i or j may pass through: split to the leaves
};

/// Where a region of footprint `footprint` lies against `range` in a grid of `dims`: range
/// sides on the grid's own limits cut nothing. Inside needs `insideMargin` cells to spare on
/// each side (1 for the file's exact footprints; 0 for RegionFootprint's, already widened).
/// An excluded box that holds the footprint and every layer of the range makes it Outside;
/// one whose I or J side may pass through it makes it Crossed.
RangeClass ClassifyFootprint(const std::array<float, 4>& footprint, const CellRange& range,
  const std::array<int64_t, 3>& dims, float insideMargin = 0);

/// Leaves in `mesh` only the cells in `range` active, and opens their sides towards cells out of
/// it: across an edge inside the region from the masked cells, across a cut edge (the region's
/// border) from where the column across lies (its centre mirrored through the edge's midpoint;
/// at the leaves, exactly the neighbour's cell). A column is in the range when its centre is.
/// The mesh's surfaces must be extracted again (ExtractSurfaces) afterwards.
void MaskToRange(RegionMesh& mesh, const CellRange& range);

/// Whether the range's excluded boxes take cells out of a region of footprint `footprint`
/// (exposing faces inside the model there): a box that meets the footprint and neither misses
/// the range's layers nor leaves the region Outside.
bool ExclusionExposes(
  const std::array<float, 4>& footprint, const CellRange& range, const std::array<int64_t, 3>& dims);

/// The masking MaskToRange and the property filter share: leaves active only the cells for
/// which keep(centre, k, column) holds (centre: the column's, in topological coordinates; k:
/// the model's layer, RegionMesh::firstLayer on), and
/// opens a kept cell's side across a cut edge when keep fails for the cell across (the column's
/// centre mirrored through the edge's midpoint, same layer; column: AcrossCutEdge).
constexpr std::size_t AcrossCutEdge = ~std::size_t(0);
void MaskCells(RegionMesh& mesh, const std::function<bool(const std::array<double, 2>&, int64_t, std::size_t)>& keep);
/// The box of a column's four nodes' topological coordinates: ti min, ti max, tj min, tj max.
std::array<float, 4> ColumnTopologyBox(const RegionMesh& mesh, std::size_t column);
/// The mean of a column's four nodes' topological coordinates.
std::array<double, 2> ColumnCentreOf(const RegionMesh& mesh, std::size_t column);

} // namespace resmr
