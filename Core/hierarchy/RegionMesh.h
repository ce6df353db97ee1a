// What the multiresolution file holds for one triangular region (paper Sec. 4.2, 4.3, 6.1): the
// region's simplified hexahedral column mesh and the external surfaces extracted from it.
//
// Contract:
// - Vertices are numbered node * (layers + 1) + interface; a vertex's topological coordinate
//   is (ti, tj) of its node and tk = its interface (Sec. 5.1: cell [i, j, k] spans
//   [i, i+1] x [j, j+1] x [k, k+1], 0-based). Positions are (x, y, depth), depth down.
// - `cutEdges` bit e of a column: the edge from corner e to e + 1 borders another region of
//   the same level, not the outside of the model, so it yields no side face.
// - `openSides` bit e of a cell: its side face on edge e is external (no active cell across:
//   fault, model limit or inactive neighbour, Fig. 4 types 2-4), across a cut edge too, where
//   the cell across lies in another region.
// - Surfaces are quads of four vertex numbers: top faces of active cells with no active cell
//   above, bottom faces with none below, the open side faces of active cells. Each quad turns
//   counter-clockwise seen from outside its cell in a z-up frame (z = -depth).
// - Sealed pinch-outs (files of version 5 on; Sec. 4.3's simplification of the external
//   faces): a run of inactive cells between two active cells of its column, no thicker at
//   any corner than the region's own error (`sealedPinchThickness`), counts as solid. The
//   faces between it and active or sealed cells are inside the solid and not extracted; its
//   faces open to the outside are, so the surface stays closed. The surface moves by at most
//   the run's thickness, within the error the region already has; on many-layer models this
//   removes most of the coarse levels' stacked top faces (half the frame time of an overview
//   of the synthetic 100M model under llvmpipe). Columns with a cut edge are never sealed,
//   so regions meet as before; nor are the leaves, which keep the original faces exactly
//   (the viewer seals their runs of no thickness, whose faces hide nothing).
// - The file stores top and bottom quads and the simplified side triangles
//   (SideSurfaceSimplification.h); side quads are derived on demand (ExtractSurfaces).
// - The single-layer view needs no stored surface: ExtractLayerSurfaces() derives it from the
//   hexahedral mesh on load.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace resmr
{

struct RegionSurface
{
  std::vector<std::array<uint32_t, 4>> quads;
  /// Normal cone (Sec. 6.1): unit axis (z up) and the cosine of its half angle; cosine -2
  /// when the surface is empty.
  std::array<float, 4> cone{ 0.f, 0.f, 1.f, -2.f };
};

struct RegionMesh
{
  int32_t layers = 0;
  /// The model layer of the mesh's layer 0: 0, or a window of the model's layers
  /// (MultiresolutionFile::ReadRegionLayers). Vertex interfaces and cell layers are the
  /// mesh's own; a topological tk is firstLayer + interface.
  int32_t firstLayer = 0;
  std::vector<double> positions;              ///< [node][interface][xyz]
  std::vector<std::array<float, 2>> topology; ///< (ti, tj) per node
  std::vector<std::array<uint32_t, 4>> corners;
  std::vector<uint8_t> active;    ///< [column][layer]
  std::vector<uint8_t> cutEdges;  ///< per column, bit e
  std::vector<uint8_t> openSides; ///< [column][layer], bit e
  RegionSurface top, bottom, side;
  /// Thickest inactive run (model units, at every corner) that ExtractSurfaces() seals: the
  /// region's own error (RegionRecord::ownError); 0: none (leaves, files before version 5).
  double sealedPinchThickness = 0;
  /// The side surface simplified for the whole-model view (Sec. 4.3), triangles of mesh
  /// vertices turning as the quads; what the file stores for the side.
  std::vector<std::array<uint32_t, 3>> sideTriangles;

  int64_t NodeCount() const { return static_cast<int64_t>(this->topology.size()); }
  int64_t ColumnCount() const { return static_cast<int64_t>(this->corners.size()); }
  int64_t VertexCount() const { return this->NodeCount() * (this->layers + 1); }
  /// The column's (i, j): the lowest topological coordinates of its corners (the column's
  /// cell indices, 0-based, in a mesh of whole cells).
  std::array<float, 2> ColumnCell(std::size_t column) const
  {
    const auto& q = this->corners[column];
    std::array<float, 2> low = this->topology[q[0]];
    for (int n = 1; n < 4; ++n)
    {
      low[0] = std::min(low[0], this->topology[q[n]][0]);
      low[1] = std::min(low[1], this->topology[q[n]][1]);
    }
    return low;
  }
  uint32_t Vertex(uint32_t node, int32_t interface) const
  {
    return node * static_cast<uint32_t>(this->layers + 1) + static_cast<uint32_t>(interface);
  }
};

/// Sets the open sides of every edge that is not cut from the columns across it (cut edges
/// keep theirs; none if openSides was empty).
void ComputeOpenSides(RegionMesh& mesh);

/// Top, bottom and side surfaces of the region's hexahedral mesh (Sec. 4.3), with normal
/// cones for top and bottom, with pinch-outs sealed (see above). Replaces any surfaces the
/// mesh held.
void ExtractSurfaces(RegionMesh& mesh);

/// The single-layer view of layer k (Sec. 6.1): the top and bottom faces of its active cells
/// and their side faces where the neighbour across is absent or inactive in that layer.
void ExtractLayerSurfaces(
  const RegionMesh& mesh, int32_t layer, RegionSurface& top, RegionSurface& bottom, RegionSurface& side);

/// The box of the mesh's nodes' topological coordinates: ti min, ti max, tj min, tj max
/// (0, -1, 0, -1 without columns).
std::array<float, 4> TopologyBox(const RegionMesh& mesh);

/// +1 if the columns turn counter-clockwise in (x, y) seen from above, -1 otherwise.
int RegionOrientation(const RegionMesh& mesh);

} // namespace resmr
