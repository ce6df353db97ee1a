// Inspecting one original cell (ours; what makes it possible is the paper's Sec. 5.1: every
// fragment of every level knows its original cell through its topological coordinate). A
// pick names the cell whose colour shows under a pixel: a pick pass draws the frame's own cut
// into one pixel, each fragment painting its cell as the Cell Id colouring finds it, so the
// answer is exact at whatever level is drawn, with no search structure. What is then said of
// the cell comes from the files, never from a whole-model array:
// - its values: one layer chunk of each table of the property file, decoded up to the cell,
//   static arrays and the tables of the step (the layer tables hold NaN where a cell has no
//   value);
// - its eight corners and whether it is active: the column of the leaf region (the finest
//   level, which keeps the original grid's corners) that holds it, found by the model point
//   the pick hit or, without one, by the leaves' boxes around the column's place in a coarse
//   region (GoTo needs no pixel).
//
// Contract:
// - Cells are 0-based (i, j, k) here; the viewer shows ECLIPSE's I, J, K, from 1.
// - Corners are model coordinates (x, y, z up: z = -depth), in ECLIPSE's order: (i, j),
//   (i + 1, j), (i, j + 1), (i + 1, j + 1) on the cell's top, then the same on its bottom.
// - Failures to read a file throw FileFormatError naming it (the caller reports them); a cell
//   outside the grid is std::out_of_range.
#pragma once

#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "RegionCache.h"

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace resmr
{

struct CellValue
{
  std::string name;
  int32_t step = -1; ///< -1: a static array
  float value = 0;   ///< NaN: no value (an inactive cell, or none in the run)
};

struct CellGeometry
{
  bool found = false;  ///< the cell's column was found in a leaf region
  bool active = false; ///< the cell is active in the grid
  std::array<std::array<double, 3>, 8> corners{};
  std::size_t leafRegion = 0;
  /// The mean of the corners (model coordinates), what a camera goes to.
  std::array<double, 3> Centre() const;
};

/// Every table of `properties` for `cell` at report step `step` (static arrays first, then
/// the step's, in file order). Decodes one layer chunk a table, up to the cell.
std::vector<CellValue> CellValues(const PropertyFile& properties, const std::array<int64_t, 3>& cell, int32_t step);

/// What the viewer says of one cell: its geometry and, with a property file, its values.
struct CellReport
{
  CellGeometry geometry;
  std::vector<CellValue> values;
};

/// InspectCellGeometry and CellValues at once (the tables read on other threads while the leaf
/// is), then the decoding buffers handed back to the system, so a pick leaves no memory behind.
CellReport InspectCell(const MultiresolutionFile& file, const PropertyFile* properties,
  const std::array<int64_t, 3>& cell, int32_t step, const std::array<double, 3>* near = nullptr);

/// Most leaf regions read to find a column: the nearest boxes to where it stands.
constexpr std::size_t MaxLeavesSearched = 16;

/// The corners and activity of `cell` from the leaf region that holds its column. `near`,
/// when given (a model point the pick hit), says where to look first; without it the column
/// is placed from the coarsest region that holds it.
CellGeometry InspectCellGeometry(
  const MultiresolutionFile& file, const std::array<int64_t, 3>& cell, const std::array<double, 3>* near = nullptr);

/// Whether the box [low, high] (z up) may cover the pixel centred at window point (x, y) of a
/// `width` x `height` viewport seen through the row-major `toClip`: false only when its
/// projection lies wholly beside the pixel, a pixel of margin around it for the rasterizer's
/// snapping (a box reaching behind the eye may cover anything).
bool BoxMayCoverPixel(const std::array<double, 3>& low, const std::array<double, 3>& high,
  const std::array<double, 16>& toClip, double x, double y, double width, double height);

/// The same for a region's box (RegionRecord::bounds: x, y, depth minima then maxima). The pick
/// pass draws only such regions: a handful, where the frame drew the whole cut.
bool RegionMayCoverPixel(const std::array<float, 6>& bounds, const std::array<double, 16>& modelToClip, double x,
  double y, double width, double height);

/// Triangles a chunk box of TriangleChunkBoxes bounds: of the regions that may cover a pixel,
/// the pick pass draws only the chunks that may (a few thousand triangles instead of hundreds
/// of thousands); a box is 24 bytes, 0.1 byte a triangle.
constexpr uint32_t PickChunkTriangles = 256;
/// Most bytes of chunk boxes kept between picks (those of the regions picked last): what
/// picking adds to memory, whatever the model and the budget.
constexpr std::size_t MaxPickBoxBytes = std::size_t(512) << 10;

/// The boxes (x, y, z minima then maxima, the buffers' coordinates) of each run of
/// PickChunkTriangles triangles of `buffers.indices`, from its start.
std::vector<std::array<float, 6>> TriangleChunkBoxes(const RegionDrawBuffers& buffers);

/// The runs (first index, index count) of indices [first, first + count) whose chunk boxes may
/// cover the pixel (BoxMayCoverPixel, `toClip` taking the buffers' coordinates to clip space).
std::vector<std::pair<uint32_t, uint32_t>> IndexRunsCoveringPixel(const std::vector<std::array<float, 6>>& boxes,
  uint32_t first, uint32_t count, const std::array<double, 16>& toClip, double x, double y, double width,
  double height);

/// The cell a pick pass painted in a pixel: its RGB holds i, j, k (0-based) as floats, its
/// alpha 1; alpha 0 (nothing drawn there) or a value off the grid gives false.
bool CellFromPickPixel(
  const std::array<float, 4>& rgba, const std::array<int64_t, 3>& dims, std::array<int64_t, 3>& cell);

} // namespace resmr
