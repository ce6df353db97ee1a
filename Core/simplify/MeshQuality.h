// Quality of simplified reservoir meshes (paper Sec. 4.1 aims at well-shaped hexahedra and
// accurate boundaries): scaled Jacobians, inverted cells, and the two-sided Hausdorff
// distance between the external boundaries of two meshes.
#pragma once

#include "HexMesh.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>

namespace resmr
{

/// Scaled Jacobian of one hexahedron given as in HexMesh (top face then bottom face, each in
/// the mesh's turning order, (x, y, depth)): the smallest normalised corner Jacobian in a
/// z-up frame, 1 for a cube, negative for an inverted or folded cell. `degenerate` is set
/// (and 0 returned) when an edge has no length (a pinched-out cell).
double HexScaledJacobian(const glm::dvec3 corners[8], int orientation, bool& degenerate);

/// The same test as HexScaledJacobian(...) < -1e-9 on a non-degenerate cell, without the
/// normalisation on the usual path (every corner Jacobian positive): for tight loops.
bool HexInverted(const glm::dvec3 corners[8], int orientation);

struct HexQuality
{
  int64_t cells = 0;
  int64_t degenerate = 0; ///< cells with a zero-length edge (pinched out): not measured
  int64_t inverted = 0;   ///< cells with a negative corner Jacobian (folded or inverted)
  double minScaledJacobian = 1;
  double meanScaledJacobian = 0;
};

/// Verdict's scaled Jacobian of every non-degenerate cell (in a z-up frame, so a right-handed
/// hexahedron scores 1). `orientation` is +1 if cells turn counter-clockwise in (x, y) seen
/// from above, -1 otherwise.
HexQuality MeasureHexahedra(const HexMesh& mesh, int orientation);

struct BoundaryDistance
{
  double forward = 0;  ///< largest distance from a sample of `a`'s boundary to `b`'s
  double backward = 0; ///< the same from `b` to `a`
  double hausdorff = 0;
  double diagonal = 0; ///< bounding-box diagonal of `a`
  double relative = 0; ///< hausdorff / diagonal
  int64_t samples = 0;
  std::array<double, 3> worstForward{}, worstBackward{}; ///< where each largest distance was met
};

/// Two-sided Hausdorff distance between the external boundaries (faces of active cells not
/// shared with another active cell: top, bottom, faults, active limits) of two meshes, each
/// face split in two triangles, sampled at triangle centroids and `perTriangle` more points
/// a triangle. Deterministic.
BoundaryDistance MeasureBoundaryDistance(const HexMesh& a, const HexMesh& b, int perTriangle = 3);

} // namespace resmr
