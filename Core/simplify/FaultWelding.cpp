// Welding a fault's two sides where a coarse level cannot keep them apart (ours, not the
// paper's; see FaultWelding.h).
#include "FaultWelding.h"

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <vector>

namespace resmr
{
namespace
{
/// One fault edge and its other side: a -> b walked by one column, b2 -> a2 by the other
/// (a and a2 at one pillar, b and b2 at the other).
struct EdgePair
{
  int32_t a, b, a2, b2;
};

bool Pinned(const ColumnMesh& mesh, int32_t node)
{
  const auto& columns = mesh.NodeColumns(node);
  return std::any_of(columns.begin(), columns.end(), [&](int32_t c) { return mesh.IsLocked(c); });
}

std::vector<EdgePair> FaultEdgePairs(const ColumnMesh& mesh)
{
  std::map<std::array<double, 4>, std::array<int32_t, 2>> walked;
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    for (int e = 0; mesh.IsColumnAlive(c) && e < 4; ++e)
    {
      if (mesh.IsBoundaryEdge(c, e))
      {
        const auto& q = mesh.ColumnCorners(c);
        const auto& ta = mesh.TopologicalCoordinate(q[e]);
        const auto& tb = mesh.TopologicalCoordinate(q[(e + 1) % 4]);
        walked.emplace(
          std::array<double, 4>{ ta[0], ta[1], tb[0], tb[1] }, std::array<int32_t, 2>{ q[e], q[(e + 1) % 4] });
      }
    }
  }
  std::vector<EdgePair> pairs;
  for (const auto& edge : walked)
  {
    const auto& key = edge.first;
    const std::array<double, 4> reversed{ key[2], key[3], key[0], key[1] };
    const auto other = walked.find(reversed);
    if (other == walked.end() || !(key < reversed))
    {
      continue; // no other side, or the pair is listed from its other edge
    }
    const EdgePair pair{ edge.second[0], edge.second[1], other->second[1], other->second[0] };
    if (!Pinned(mesh, pair.a) && !Pinned(mesh, pair.b) && !Pinned(mesh, pair.a2) && !Pinned(mesh, pair.b2))
    {
      pairs.push_back(pair);
    }
  }
  return pairs;
}

/// The node each node merges into (the smallest of its group) along the edges of `pairs`
/// flagged in `use`.
std::vector<int32_t> Groups(int32_t nodes, const std::vector<EdgePair>& pairs, const std::vector<uint8_t>& use)
{
  std::vector<int32_t> parent(static_cast<std::size_t>(nodes));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int32_t n) {
    while (parent[n] != n)
    {
      n = parent[n] = parent[parent[n]];
    }
    return n;
  };
  const auto unite = [&](int32_t x, int32_t y) {
    x = root(x);
    y = root(y);
    parent[std::max(x, y)] = std::min(x, y);
  };
  for (std::size_t p = 0; p < pairs.size(); ++p)
  {
    if (use[p])
    {
      unite(pairs[p].a, pairs[p].a2);
      unite(pairs[p].b, pairs[p].b2);
    }
  }
  for (int32_t n = 0; n < nodes; ++n)
  {
    parent[n] = root(n);
  }
  return parent;
}
} // namespace

FaultWeld WeldFaults(ColumnMesh& mesh)
{
  const std::vector<EdgePair> pairs = FaultEdgePairs(mesh);
  std::vector<uint8_t> use(pairs.size(), 1);
  std::vector<int32_t> into;
  for (;;)
  {
    into = Groups(mesh.NodeCount(), pairs, use);
    // A group holding two corners of one column (a fault whose sides a chain of welds joins
    // back to one block) stays apart, with every edge that touches it.
    std::vector<uint8_t> apart(static_cast<std::size_t>(mesh.NodeCount()), 0);
    bool any = false;
    for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
    {
      const auto& q = mesh.ColumnCorners(c);
      for (int i = 0; mesh.IsColumnAlive(c) && i < 4; ++i)
      {
        for (int j = i + 1; j < 4; ++j)
        {
          if (into[q[i]] == into[q[j]])
          {
            apart[into[q[i]]] = 1;
            any = true;
          }
        }
      }
    }
    if (!any)
    {
      break;
    }
    bool changed = false;
    for (std::size_t p = 0; p < pairs.size(); ++p)
    {
      const EdgePair& e = pairs[p];
      const bool keep = use[p] && !apart[into[e.a]] && !apart[into[e.b]];
      changed = changed || keep != (use[p] != 0);
      use[p] = keep;
    }
    if (!changed)
    {
      // A column with a repeated node in the input: weld nothing.
      std::fill(use.begin(), use.end(), 0);
      std::iota(into.begin(), into.end(), 0);
      break;
    }
  }
  FaultWeld weld;
  weld.edges = std::count(use.begin(), use.end(), 1);
  for (int32_t n = 0; n < mesh.NodeCount(); ++n)
  {
    weld.nodes += into[n] != n;
  }
  weld.largestMove = mesh.MergeNodes(into);
  return weld;
}

} // namespace resmr
