// The side of a masked coarse region merged in K (ours, see MergedSides.h; after the paper's
// simplified side, Sec. 4.3).
#include "MergedSides.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace resmr
{

std::vector<std::array<uint32_t, 3>> MergedSideTriangles(const RegionMesh& mesh, double height)
{
  // A side quad of layer k on the directed edge a -> b: (a k, a k+1, b k+1, b k)
  // (ExtractSurfaces). Sorted by edge and layer, a run's quads come one after the other.
  const uint32_t perNode = static_cast<uint32_t>(mesh.layers + 1);
  std::vector<std::tuple<uint32_t, uint32_t, uint32_t>> faces; // node a, node b, layer
  faces.reserve(mesh.side.quads.size());
  for (const auto& q : mesh.side.quads)
  {
    faces.emplace_back(q[0] / perNode, q[3] / perNode, q[0] % perNode);
  }
  std::sort(faces.begin(), faces.end());
  const auto at = [&](uint32_t node, uint32_t interface) {
    return &mesh.positions[(static_cast<std::size_t>(node) * perNode + interface) * 3];
  };
  const auto distance = [&](const double* p, const double* q) {
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
  };
  const auto same = [&](const double* p, const double* q) { return std::equal(p, p + 3, q); };
  std::vector<std::array<uint32_t, 3>> triangles;
  for (std::size_t first = 0; first < faces.size();)
  {
    const auto [a, b, top] = faces[first];
    uint32_t bottom = top + 1; // the run's lower interface
    std::size_t next = first + 1;
    while (next < faces.size() && std::get<0>(faces[next]) == a && std::get<1>(faces[next]) == b &&
      std::get<2>(faces[next]) == bottom && distance(at(a, top), at(a, bottom + 1)) <= height &&
      distance(at(b, top), at(b, bottom + 1)) <= height)
    {
      ++bottom;
      ++next;
    }
    first = next;
    if (same(at(a, top), at(a, bottom)) && same(at(b, top), at(b, bottom)))
    {
      continue; // cells of no thickness: the run covers nothing
    }
    const uint32_t aTop = a * perNode + top, aBottom = a * perNode + bottom;
    const uint32_t bTop = b * perNode + top, bBottom = b * perNode + bottom;
    triangles.push_back({ aTop, aBottom, bBottom });
    triangles.push_back({ aTop, bBottom, bTop });
  }
  return triangles;
}

} // namespace resmr
