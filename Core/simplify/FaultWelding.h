// Welding a fault's two sides into one surface where a coarse level cannot keep them apart
// (ours, not the paper's). The hierarchy keeps the columns along faults whole while they fit a
// region (HierarchyBuilder's LockFaultColumns); the coarsest levels of a large model hold
// faults longer than that. Simplified block by block there, the two sides of a fault that
// bends or meets another would part and open gaps one sees through. Welded, the level draws
// the fault's throw as a slope within its error instead: no gap, no false wall.
//
// Contract:
// - A fault edge is a boundary edge whose two pillars (the nodes' topological coordinates)
//   another boundary edge runs between the other way: the fault's other side.
// - Both edges of a pair weld: the nodes at each of the two pillars merge into one at their
//   mean position at every interface, with the sum of their quadrics, so the columns on the
//   two sides become neighbours. Nodes merge only along welded edges, so a merged node's
//   columns form one fan (the mesh stays manifold); a group that would give a column the same
//   node twice is left apart with the edges that touch it. A node of a locked column never
//   moves, so a locked region border keeps its fault sides.
// - Returns the edges welded and the farthest a vertex moved; the region's error must cover it
//   (the quadrics, dominated by the faults' heavy side planes, do not).
#pragma once

#include "ColumnMesh.h"

#include <cstdint>

namespace resmr
{

struct FaultWeld
{
  int64_t edges = 0;      ///< fault edge pairs welded
  int64_t nodes = 0;      ///< nodes merged away
  double largestMove = 0; ///< farthest a vertex moved (model units)
};

FaultWeld WeldFaults(ColumnMesh& mesh);

} // namespace resmr
