// Simplification of a region's side surface for the whole-model view (paper Sec. 4.3): the side
// quads become triangles, which half-edge collapses thin out up to the region's error, with the
// vertices that other surfaces and other regions share locked so that no crack opens.
//
// Contract:
// - Input: every quad of mesh.side split along its shorter diagonal (q0-q2 on a tie), less the
//   triangles without area (twice the area at most 1e-12 times the longest edge squared:
//   pinched corners); TriangulateSideSurface() returns exactly this.
// - Output: triangles of the mesh's own vertex numbers, turning as the quads (counter-clockwise
//   seen from outside in a z-up frame). A collapse removes a vertex by merging it into a
//   neighbour: no position is created or moved, so vertices stay on the file's lattice.
// - Locked, never removed: (1) every vertex of a quad of mesh.top or mesh.bottom; (2) every
//   vertex of a node that ends a cut edge (the region's border, where the next region's side
//   surface goes on); (3) every vertex around which the input is not one closed disc turning
//   one way (border of the side surface, non-manifold edges or fans), or that lies on a fold
//   (an edge whose two triangles face opposite ways, as where a fault ends and its two faces
//   meet back to back: a quadric cannot tell them apart). Rule 1 holds most of the border,
//   rule 3 the rest (walls ending at a fault tip, pinched faces), so the output's border
//   edges (used by one triangle) are exactly the input's and the side meets the top and
//   bottom surfaces and the next regions as before.
// - Error, in model units of distance: every removed vertex lies within maxError + 1e-9 x the
//   diagonal of the side surface's bounding box (rounding) of the output triangles, and of
//   the point where the output paints its topological coordinate (ti, tj, tk): the point of
//   the triangle whose interpolated coordinates equal the vertex's, as the viewer paints the
//   original cells (maxError below 0 or NaN counts as 0). So a wall's layers and columns are
//   drawn within the error of their place: a wall of thin layers, flat but of uneven
//   thickness, is no longer one pair of triangles whose interpolated layers stray by many
//   layers. The bound is exact, not an estimate: each removed vertex rides on the triangle
//   that paints it and is measured again whenever that triangle changes. It is one-sided:
//   between vertices, the output may leave the input farther.
// - Order: cheapest quadric error first (Garland-Heckbert: the area-weighted planes of the
//   input triangles merged into the kept vertex) as a root-mean-square distance, the measure
//   of RegionRecord::error; it must not pass maxError + 1e-6 x that diagonal either (the
//   quadric's own rounding). Costs within 1e-7 of the diagonal tie and go shorter edge first
//   (coplanar collapses cost 0: walls thin out evenly instead of piling fans onto one
//   vertex), then the vertex with fewer triangles, then by vertex numbers. Coplanar collapses
//   that paint every cell in place are always done, so leaf regions (maxError 0) still
//   simplify planar walls of even layers; positions
//   already rounded to the file's lattice are planar only to within it, so add the lattice
//   step's length to maxError for them.
// - A collapse is refused if it would break the link condition or duplicate a triangle, turn
//   a triangle more than 60 degrees from its current normal, make it face against the input
//   triangle it started as or against every input triangle at one of its corners, or make it
//   thinner than 1e-6 (twice the area over the longest edge squared). Half-edge collapses
//   alone can leave a few removable vertices (one fanned out to a straight row of locked
//   vertices, which every target would flatten).
// - Deterministic. Time O(n log n) for n triangles plus the removed vertices measured again;
//   about 0.3 s for 100,000 triangles.
#pragma once

#include "RegionMesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

struct SideSimplificationStats
{
  int64_t inputTriangles = 0, outputTriangles = 0;
  int64_t lockedVertices = 0; ///< side surface vertices locked by any rule
  double largestError = 0;    ///< largest distance of a removed vertex to the output
};

/// The side quads as triangles, before simplification (see the contract).
std::vector<std::array<uint32_t, 3>> TriangulateSideSurface(const RegionMesh& mesh);

/// Triangles of the region's side surface simplified by half-edge collapses within `maxError`
/// (model units of distance, see the contract); `stats` is filled when given.
std::vector<std::array<uint32_t, 3>> SimplifySideSurface(
  const RegionMesh& mesh, double maxError, SideSimplificationStats* stats = nullptr);

} // namespace resmr
