// The side of a coarse region masked by a range or a property filter, merged in K (ours; the
// paper's simplified side, Sec. 4.3, spans every layer of the region's border and cannot be
// masked).
//
// Contract:
// - A masked coarse region keeps its exact side (a quad a cell's open face) and gains this one,
//   drawn in its place where the file's simplified side would be (DrawsSimplifiedSide): along
//   each directed column edge, the quads of consecutive layers are merged into one quad while
//   the run stays within `height` (model units) at both of the edge's nodes, two triangles a
//   quad turning as the quads.
// - With `height` the region's own error the merged side lies within that error of the exact
//   one (the nodes' positions at the run's ends are the exact ones; a layer's boundary inside a
//   run moves by less than the run's height), as the simplified side does; a run stops at the
//   first layer whose face is absent, so the side covers what the exact one covers.
#pragma once

#include "RegionMesh.h"

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

/// The exact side of `mesh` (its side quads, ExtractSurfaces) merged in K as in the contract.
std::vector<std::array<uint32_t, 3>> MergedSideTriangles(const RegionMesh& mesh, double height);

} // namespace resmr
