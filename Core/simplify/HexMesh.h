// A plain hexahedral mesh: what the column simplification (paper Sec. 4.1) and the naive
// coarsening it is compared with both produce, and what the quality measures read.
//
// Contract:
// - Points are (x, y, depth), depth down, shared between cells that share corners.
// - Each cell lists 8 points: its top face (interface k) then its bottom face (k + 1), each
//   in the same turning order; `active` marks active cells; `topology` holds the (ti, tj, tk)
//   coordinate of every point (Sec. 5.1 convention).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

class ColumnMesh;

struct HexMesh
{
  std::vector<double> points;   ///< x, y, depth per point
  std::vector<double> topology; ///< ti, tj, tk per point
  std::vector<std::array<int64_t, 8>> cells;
  std::vector<uint8_t> active;
  int64_t layers = 0; ///< cells per column

  int64_t PointCount() const { return static_cast<int64_t>(this->points.size() / 3); }
  int64_t CellCount() const { return static_cast<int64_t>(this->cells.size()); }
};

/// Every cell of every alive column, layer by layer (inactive cells included).
HexMesh ToHexMesh(const ColumnMesh& mesh);

} // namespace resmr
