// The column-structured hexahedral mesh that paper Sec. 4.1 simplifies: a quadrilateral mesh
// seen from above whose every quad is a column of nk cells and whose every node carries nk+1
// vertices, one per layer interface. Faults split nodes, so the quad mesh has boundaries along
// faults as well as around the model (Fig. 4, face types 3 and 4).
//
// Contract:
// - Built from a corner-point grid (any sub-box of it): the columns with at least one active
//   cell, completed with their inactive cells (Fig. 3). Interface k of a column is the top of
//   its cell k (the bottom of the last cell for k = nk); vertical gaps between cells close.
// - Neighbouring columns share a node at a pillar when their corner depths agree at every
//   interface, and an edge when they share both its nodes.
// - Each node has a topological coordinate (ti, tj): the pillar (i, j) it came from, 0-based
//   (Sec. 5.1: cell [i, j] spans [i, i+1] x [j, j+1]); a vertex adds tk = its interface k.
//   Operations interpolate (ti, tj); tk never changes.
// - Positions are (x, y, depth), depth down, as CornerPointGeometry gives them.
// - Quadrics (Sec. 4.1): top and bottom faces of active cells with weight 1 (type 1); side
//   faces of active cells that are external, weighted by SideWeight (10,000): against an
//   inactive cell (type 2), across a fault or a removed column (type 3), at the grid limits
//   (type 4).
#pragma once

#include "HexMesh.h"
#include "Quadric.h"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace resmr
{

class CornerPointGeometry;

/// A column mesh as plain arrays, quadrics included: what the hierarchy builder (Sec. 4.2)
/// saves for each region and merges again one level up.
struct ColumnMeshData
{
  int32_t layers = 0;
  std::vector<double> positions; ///< [node][interface][xyz]
  std::vector<Quadric> quadrics; ///< [node][interface]
  std::vector<std::array<double, 2>> topology;
  std::vector<std::array<int32_t, 4>> corners;
  std::vector<uint8_t> activeCells; ///< [column][layer]
  std::vector<std::array<int32_t, 2>> origin;

  int64_t NodeCount() const { return static_cast<int64_t>(this->topology.size()); }
  int64_t ColumnCount() const { return static_cast<int64_t>(this->corners.size()); }
};

class ColumnMesh
{
public:
  static constexpr double SideWeight = 10000.0;

  /// Columns of cells i in [i0, i1), j in [j0, j1) of `geometry` with at least one active
  /// cell (`active`: one flag a cell, ECLIPSE order). Throws std::invalid_argument for an
  /// empty box or non-finite corners.
  static ColumnMesh FromCornerPoints(const CornerPointGeometry& geometry, const std::vector<bool>& active, int64_t i0,
    int64_t i1, int64_t j0, int64_t j1);
  /// The whole grid.
  static ColumnMesh FromCornerPoints(const CornerPointGeometry& geometry, const std::vector<bool>& active);

  /// The same from any source of cell corners: `corners(i, j, k, out)` gives the 8 corners
  /// (x, y, depth) of cell (i, j, k) in ECLIPSE order (di + 2 dj + 4 dk, dk = 1 deeper).
  using CellCornersFunction = std::function<void(int64_t, int64_t, int64_t, double[8][3])>;
  /// `selected` (optional, one flag a column of the box, i fastest) leaves out the columns
  /// whose flag is 0.
  static ColumnMesh FromCells(const std::array<int64_t, 3>& dims, const CellCornersFunction& corners,
    const std::vector<bool>& active, int64_t i0, int64_t i1, int64_t j0, int64_t j1,
    const std::vector<uint8_t>* selected = nullptr);

  /// A mesh from explicit data, for tests and other sources: `positions` holds
  /// (layers + 1) * 3 values a node, `corners` four nodes a column (counter-clockwise in
  /// (ti, tj)), `activeCells` `layers` flags a column. Quadrics are computed.
  static ColumnMesh FromParts(int32_t layers, std::vector<double> positions,
    std::vector<std::array<double, 2>> topology, std::vector<std::array<int32_t, 4>> corners,
    std::vector<uint8_t> activeCells);

  /// A mesh from saved arrays; the quadrics are kept as given (not recomputed), so merged
  /// regions go on measuring error against the original faces. Throws std::invalid_argument
  /// for inconsistent arrays.
  static ColumnMesh FromData(ColumnMeshData data);

  /// The alive columns (those flagged in `keepColumns` too, when given, one flag a column
  /// slot) and the nodes they use, renumbered in order; `nodeMap` (optional) gets the new
  /// index of every node slot, -1 for those left out.
  ColumnMeshData Export(
    const std::vector<uint8_t>* keepColumns = nullptr, std::vector<int32_t>* nodeMap = nullptr) const;

  int32_t Layers() const { return this->LayerCount; }
  int32_t NodeCount() const { return static_cast<int32_t>(this->Topology.size()); }
  int32_t ColumnSlots() const { return static_cast<int32_t>(this->Corners.size()); }
  int64_t AliveColumns() const { return this->AliveColumnCount; }
  int64_t CellCount() const { return this->AliveColumnCount * this->LayerCount; }

  bool IsColumnAlive(int32_t column) const { return this->ColumnAlive[column] != 0; }
  const std::array<int32_t, 4>& ColumnCorners(int32_t column) const { return this->Corners[column]; }
  bool IsCellActive(int32_t column, int32_t layer) const
  {
    return this->ActiveCells[static_cast<std::size_t>(column) * this->LayerCount + layer] != 0;
  }
  /// Column and layer of the original grid a column came from (-1 for FromParts meshes).
  const std::array<int32_t, 2>& ColumnOrigin(int32_t column) const { return this->Origin[column]; }

  bool IsNodeAlive(int32_t node) const { return this->NodeAlive[node] != 0; }
  glm::dvec3 Position(int32_t node, int32_t interface) const
  {
    const double* p = &this->Positions[(static_cast<std::size_t>(node) * (this->LayerCount + 1) + interface) * 3];
    return { p[0], p[1], p[2] };
  }
  void SetPosition(int32_t node, int32_t interface, const glm::dvec3& p)
  {
    double* out = &this->Positions[(static_cast<std::size_t>(node) * (this->LayerCount + 1) + interface) * 3];
    out[0] = p.x;
    out[1] = p.y;
    out[2] = p.z;
  }
  const Quadric& NodeQuadric(int32_t node, int32_t interface) const
  {
    return this->Quadrics[static_cast<std::size_t>(node) * (this->LayerCount + 1) + interface];
  }
  Quadric& NodeQuadric(int32_t node, int32_t interface)
  {
    return this->Quadrics[static_cast<std::size_t>(node) * (this->LayerCount + 1) + interface];
  }
  const std::array<double, 2>& TopologicalCoordinate(int32_t node) const { return this->Topology[node]; }
  const std::vector<int32_t>& NodeColumns(int32_t node) const { return this->ColumnsOfNode[node]; }

  /// Lateral neighbours of a node (nodes joined to it by a column edge) and, for each, whether
  /// that edge is on the boundary (one column only).
  void Neighbours(int32_t node, std::vector<int32_t>& nodes, std::vector<uint8_t>& boundary) const;
  /// Number of side faces sharing the node (its edges), as Sec. 4.1 defines lateral valence.
  int LateralValence(int32_t node) const;
  bool IsBoundaryNode(int32_t node) const;
  /// Whether the edge between corners c and c+1 of a column has a column on its other side.
  bool IsBoundaryEdge(int32_t column, int corner) const;

  /// Pieces of the mesh joined by no shared edge (fault blocks cut off all round, isolated
  /// columns): collapses never join two, so no simplification leaves fewer columns.
  int64_t ConnectedParts() const;

  /// +1 if columns run counter-clockwise in (x, y) seen from above (depth down), -1 if
  /// clockwise: fold-over checks compare with it.
  int Orientation() const { return this->OrientationSign; }

  /// Merges nodes (ours: the hierarchy welds a fault's two sides, see FaultWelding.h):
  /// node n becomes `into[n]` (n itself: kept), a node that maps to itself. A group takes its
  /// members' mean position at each interface and the sum of their quadrics, and its columns
  /// refer to it. Returns the farthest any member's vertex moved. Throws std::logic_error,
  /// changing nothing, if a column would hold a node twice or a locked column's node would move.
  double MergeNodes(const std::vector<int32_t>& into);

  /// Locked columns are never collapsed (the hierarchy locks diamond boundaries).
  void SetLocked(int32_t column, bool locked) { this->Locked[column] = locked ? 1 : 0; }
  bool IsLocked(int32_t column) const { return this->Locked[column] != 0; }

private:
  friend class ColumnCollapse;
  void BuildAdjacency();
  void BuildAdjacencyAndQuadrics();
  void ComputeOrientation();

  int32_t LayerCount = 0;
  std::vector<double> Positions; ///< [node][interface][xyz]
  std::vector<Quadric> Quadrics; ///< [node][interface]
  std::vector<std::array<double, 2>> Topology;
  std::vector<uint8_t> NodeAlive;
  std::vector<std::vector<int32_t>> ColumnsOfNode;

  std::vector<std::array<int32_t, 4>> Corners;
  std::vector<uint8_t> ColumnAlive;
  std::vector<uint8_t> Locked;
  std::vector<uint8_t> ActiveCells; ///< [column][layer]
  std::vector<std::array<int32_t, 2>> Origin;
  int64_t AliveColumnCount = 0;
  int OrientationSign = 1;
};

} // namespace resmr
