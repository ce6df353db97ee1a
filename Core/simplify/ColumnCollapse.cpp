// Column-collapse simplification (paper Sec. 4.1, Figs. 5-7).
#include "ColumnCollapse.h"

#include "HashMix.h"

#include "MeshQuality.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace resmr
{
namespace
{
uint64_t Mix(uint64_t x)
{
  return HashMix(x);
}

int IndexOf(const std::array<int32_t, 4>& q, int32_t node)
{
  for (int i = 0; i < 4; ++i)
  {
    if (q[i] == node)
    {
      return i;
    }
  }
  return -1;
}
} // namespace

ColumnCollapse::ColumnCollapse(ColumnMesh& mesh, uint64_t seed)
  : Mesh(mesh)
  , RandomState(Mix(seed + GoldenGamma))
  , Seed(seed)
{
  this->AliveIndex.assign(static_cast<std::size_t>(mesh.ColumnSlots()), -1);
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (mesh.IsColumnAlive(c) && !mesh.IsLocked(c))
    {
      this->AliveIndex[c] = static_cast<int32_t>(this->AliveList.size());
      this->AliveList.push_back(c);
    }
  }
}

double ColumnCollapse::RandomUnit()
{
  this->RandomState += GoldenGamma;
  return static_cast<double>(Mix(this->RandomState) >> 11) * (1.0 / 9007199254740992.0);
}

namespace
{
/// Interfaces are placed one by one, so where a layer thins out, the (x, y) of a vertex and
/// of the one above it can differ by more than the thickness left between them: the cell's
/// vertical edge turns nearly horizontal and, against faces that slope, inverts the cell. A
/// placed vertex therefore leans from the one above it (x, y offset over depth) at most as
/// steeply as the vertices it was placed from do, or as half the inverse of the slope of
/// the faces there (where the edge still stands clear of them), whichever allows more; in a
/// pinched-out layer (no thickness) it stands right below.
glm::dvec3 LimitLean(const glm::dvec3& p, const glm::dvec3& above, double steepest, double slope)
{
  const glm::dvec2 lean(p.x - above.x, p.y - above.y);
  const double length = glm::length(lean), thickness = p.z - above.z;
  const double factor = std::max(steepest, slope > 0 ? 0.5 / slope : std::numeric_limits<double>::infinity());
  if (!(length > thickness * factor))
  {
    return p;
  }
  const glm::dvec2 kept = thickness > 0 ? lean * (thickness * factor / length) : glm::dvec2(0.0);
  return { above.x + kept.x, above.y + kept.y, p.z };
}
} // namespace

void ColumnCollapse::Smooth(int32_t node)
{
  // Laplacian smoothing in each layer (x, y and the topological coordinate), then the z of
  // least quadric error at that (x, y) (Sec. 4.1).
  ColumnMesh& m = this->Mesh;
  std::vector<int32_t>& neighbours = this->SmoothNeighbours;
  std::vector<uint8_t>& boundary = this->SmoothBoundary;
  m.Neighbours(node, neighbours, boundary);
  if (neighbours.empty())
  {
    return;
  }
  const double weight = 1.0 / static_cast<double>(neighbours.size());
  std::array<double, 2> topology = { 0, 0 };
  for (int32_t other : neighbours)
  {
    topology[0] += m.Topology[other][0] * weight;
    topology[1] += m.Topology[other][1] * weight;
  }
  m.Topology[node] = topology;
  glm::dvec3 above(0.0);
  for (int32_t k = 0; k <= m.LayerCount; ++k)
  {
    glm::dvec3 average(0.0);
    DepthBounds bounds;
    for (int32_t other : neighbours)
    {
      const glm::dvec3 p = m.Position(other, k);
      average += p * weight;
      bounds.Add(p, k > 0 ? m.Position(other, k - 1) : p, this->Stalled);
    }
    average.z = this->PlaceDepth(node, k, average, bounds, above.z);
    average = k > 0 && this->Stalled ? LimitLean(average, above, bounds.steepest, bounds.Slope()) : average;
    above = average;
    m.SetPosition(node, k, average);
  }
}

double ColumnCollapse::PlaceDepth(
  int32_t node, int32_t k, const glm::dvec3& xy, const DepthBounds& bounds, double above) const
{
  // The z of least quadric error (Sec. 4.1), kept within the depths around it (a nearly
  // vertical side plane alone would throw it far), then below the interface above by a
  // thickness within those of the same layer around it: interfaces placed one by one would
  // otherwise cross or pinch thin layers, and a thin cell pinched at one corner inverts.
  const double z = std::clamp(this->Mesh.NodeQuadric(node, k).OptimalZ(xy.x, xy.y, xy.z), bounds.low, bounds.high);
  return k == 0 ? z : std::clamp(z, above + bounds.thinnest, above + bounds.thickest);
}

bool ColumnCollapse::Manifold(int32_t node) const
{
  // Each edge at the node in at most two columns, and the columns around it one fan.
  const ColumnMesh& m = this->Mesh;
  const std::vector<int32_t>& columns = m.ColumnsOfNode[node];
  const std::size_t n = columns.size();
  if (n == 0)
  {
    return true;
  }
  std::vector<int32_t>& ends = this->ManifoldEnds; // the two neighbours of the node in each column
  ends.clear();
  for (int32_t column : columns)
  {
    const auto& q = m.Corners[column];
    const int at = IndexOf(q, node);
    ends.push_back(q[(at + 1) % 4]);
    ends.push_back(q[(at + 3) % 4]);
  }
  int boundaryEdges = 0;
  std::vector<int>& component = this->ManifoldComponents;
  component.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    component[i] = static_cast<int>(i);
  }
  for (std::size_t e = 0; e < ends.size(); ++e)
  {
    int count = 0;
    for (std::size_t f = 0; f < ends.size(); ++f)
    {
      if (ends[f] == ends[e])
      {
        ++count;
        if (f / 2 != e / 2)
        {
          // Columns sharing this edge belong to one fan.
          const int a = component[e / 2], b = component[f / 2];
          if (a != b)
          {
            for (int& c : component)
            {
              c = c == b ? a : c;
            }
          }
        }
      }
    }
    if (count > 2)
    {
      return false;
    }
    boundaryEdges += count == 1 ? 1 : 0;
  }
  if (boundaryEdges != 0 && boundaryEdges != 2)
  {
    return false;
  }
  return std::all_of(component.begin(), component.end(), [&](int c) { return c == component[0]; });
}

bool ColumnCollapse::InvertsCells(int32_t column) const
{
  // Every hexahedron of the column must keep non-negative corner Jacobians: faces that stay
  // convex seen from above can still invert a cell whose vertical edges lean too far.
  const ColumnMesh& m = this->Mesh;
  const auto& q = m.Corners[column];
  glm::dvec3 corners[8];
  for (int i = 0; i < 4; ++i)
  {
    corners[i + 4] = m.Position(q[i], 0);
  }
  for (int32_t k = 0; k < m.LayerCount; ++k)
  {
    for (int i = 0; i < 4; ++i)
    {
      corners[i] = corners[i + 4];
      corners[i + 4] = m.Position(q[i], k + 1);
    }
    if (HexInverted(corners, m.OrientationSign))
    {
      return true;
    }
  }
  return false;
}

bool ColumnCollapse::FoldsOver(int32_t column) const
{
  // Top and bottom faces seen from above: no corner may turn against the mesh.
  const ColumnMesh& m = this->Mesh;
  const auto& q = m.Corners[column];
  const double sign = m.OrientationSign;
  for (int32_t k = 0; k <= m.LayerCount; ++k)
  {
    glm::dvec3 p[4];
    for (int i = 0; i < 4; ++i)
    {
      p[i] = m.Position(q[i], k);
    }
    for (int i = 0; i < 4; ++i)
    {
      const glm::dvec3& a = p[(i + 3) % 4];
      const glm::dvec3& b = p[i];
      const glm::dvec3& c = p[(i + 1) % 4];
      // Straight corners are allowed (a boundary collapse along a straight outline makes
      // them); a corner turning the wrong way is a fold.
      const double turn = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
      if (turn * sign >= 0)
      {
        continue;
      }
      const double scale2 = ((b.x - a.x) * (b.x - a.x) + (b.y - a.y) * (b.y - a.y)) *
        ((c.x - b.x) * (c.x - b.x) + (c.y - b.y) * (c.y - b.y));
      if (!(turn * turn <= 1e-18 * scale2))
      {
        return true;
      }
    }
  }
  return false;
}

void ColumnCollapse::SaveNodeState(NodeState& state, int32_t node) const
{
  const ColumnMesh& m = this->Mesh;
  const std::size_t interfaces = static_cast<std::size_t>(m.LayerCount) + 1;
  const std::size_t first = static_cast<std::size_t>(node) * interfaces;
  state.node = node;
  state.alive = m.NodeAlive[node];
  state.topology = m.Topology[node];
  state.positions.assign(m.Positions.begin() + first * 3, m.Positions.begin() + (first + interfaces) * 3);
  state.quadricsSaved = false; // most trials merge into one node: the others' quadrics stay
  state.columns.assign(m.ColumnsOfNode[node].begin(), m.ColumnsOfNode[node].end());
}

void ColumnCollapse::MergeNode(int32_t node, int32_t into)
{
  ColumnMesh& m = this->Mesh;
  if (node == into)
  {
    return;
  }
  const auto saved = std::find_if(
    this->SavedNodes.begin(), this->SavedNodes.end(), [into](const NodeState& state) { return state.node == into; });
  if (saved != this->SavedNodes.end() && !saved->quadricsSaved)
  {
    const std::size_t first = static_cast<std::size_t>(into) * (m.LayerCount + 1);
    saved->quadrics.assign(m.Quadrics.begin() + first, m.Quadrics.begin() + first + m.LayerCount + 1);
    saved->quadricsSaved = true;
  }
  for (int32_t k = 0; k <= m.LayerCount; ++k)
  {
    m.NodeQuadric(into, k) += m.NodeQuadric(node, k);
  }
  for (int32_t column : m.ColumnsOfNode[node])
  {
    this->SavedCorners.push_back({ column, m.Corners[column] });
    std::replace(m.Corners[column].begin(), m.Corners[column].end(), node, into);
    auto& list = m.ColumnsOfNode[into];
    if (std::find(list.begin(), list.end(), column) == list.end())
    {
      list.push_back(column);
    }
  }
  m.ColumnsOfNode[node].clear();
  m.NodeAlive[node] = 0;
}

void ColumnCollapse::PlaceAtAverage(int32_t node, const NodeState* const* states, int count)
{
  ColumnMesh& m = this->Mesh;
  const double weight = 1.0 / count;
  std::array<double, 2> topology = { 0, 0 };
  for (int i = 0; i < count; ++i)
  {
    topology[0] += states[i]->topology[0] * weight;
    topology[1] += states[i]->topology[1] * weight;
  }
  glm::dvec3 above(0.0);
  for (int32_t k = 0; k <= m.LayerCount; ++k)
  {
    glm::dvec3 average(0.0);
    DepthBounds bounds;
    for (int i = 0; i < count; ++i)
    {
      const std::vector<double>& p = states[i]->positions;
      const glm::dvec3 at(p[k * 3], p[k * 3 + 1], p[k * 3 + 2]);
      average += at * weight;
      bounds.Add(at, k > 0 ? glm::dvec3(p[(k - 1) * 3], p[(k - 1) * 3 + 1], p[(k - 1) * 3 + 2]) : at, this->Stalled);
    }
    average.z = this->PlaceDepth(node, k, average, bounds, above.z);
    average = k > 0 && this->Stalled ? LimitLean(average, above, bounds.steepest, bounds.Slope()) : average;
    above = average;
    m.SetPosition(node, k, average);
  }
  m.Topology[node] = topology;
}

bool ColumnCollapse::TopologyValidAt(int32_t node) const
{
  for (int32_t column : this->Mesh.ColumnsOfNode[node])
  {
    auto q = this->Mesh.Corners[column];
    std::sort(q.begin(), q.end());
    if (std::adjacent_find(q.begin(), q.end()) != q.end())
    {
      return false;
    }
  }
  return this->Manifold(node);
}

bool ColumnCollapse::ShapeKeptAround(const std::vector<int32_t>& nodes)
{
  const ColumnMesh& m = this->Mesh;
  std::vector<int32_t>& around = this->Around;
  around.clear();
  for (int32_t node : nodes)
  {
    around.insert(around.end(), m.ColumnsOfNode[node].begin(), m.ColumnsOfNode[node].end());
  }
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  if (!this->Exempt.empty())
  {
    around.erase(
      std::remove_if(around.begin(), around.end(), [&](int32_t c) { return this->Exempt[c] != 0; }), around.end());
  }
  for (int32_t column : around)
  {
    if (this->FoldsOver(column))
    {
      ++this->Stats.rejectedFoldOver;
      return false;
    }
  }
  for (int32_t column : around)
  {
    if (this->InvertsCells(column))
    {
      ++this->Stats.rejectedInverted;
      return false;
    }
  }
  return true;
}

bool ColumnCollapse::Apply(const Plan& plan, double& cost)
{
  ColumnMesh& m = this->Mesh;
  const int32_t c = plan.column;
  const auto corners = m.Corners[c];
  this->SavedCorners.clear();
  this->SavedMoves.clear();
  this->Pending = true;
  // The four saved states keep their buffers from one plan to the next: planning tries
  // several options for each of many candidates, and allocation dominated it.
  this->SavedNodes.resize(4);
  for (int i = 0; i < 4; ++i)
  {
    this->SaveNodeState(this->SavedNodes[i], corners[i]);
  }
  this->RemovedColumns.assign(1, c);

  // The column goes; the merged nodes become the survivor (and for a strip collapse, the
  // second pair becomes a second survivor).
  const int32_t survivor = plan.placeAt >= 0 ? plan.placeAt : plan.merged[0];
  m.ColumnAlive[c] = 0;
  --m.AliveColumnCount;
  for (int32_t node : corners)
  {
    auto& list = m.ColumnsOfNode[node];
    list.erase(std::remove(list.begin(), list.end(), c), list.end());
  }
  // Nodes of locked columns stay where they are: they may only be the survivor, placed at
  // itself (the hierarchy relies on locked columns matching their neighbours exactly).
  for (int i = 0; i < plan.mergedCount; ++i)
  {
    if ((plan.merged[i] != plan.placeAt || plan.placeAt < 0) && this->Pinned(plan.merged[i]))
    {
      ++this->Stats.rejectedTopology;
      return false;
    }
  }
  for (int i = 0; i < 2 && plan.op == Strip; ++i)
  {
    if (plan.mergedSecond[i] != plan.placeSecondAt && this->Pinned(plan.mergedSecond[i]))
    {
      ++this->Stats.rejectedTopology;
      return false;
    }
  }
  for (int i = 0; i < plan.mergedCount; ++i)
  {
    this->MergeNode(plan.merged[i], survivor);
  }
  for (int i = 0; i < 2 && plan.op == Strip; ++i)
  {
    this->MergeNode(plan.mergedSecond[i], plan.placeSecondAt);
  }

  // Topology first: no column may repeat a node, and nodes must stay manifold.
  bool valid = this->TopologyValidAt(survivor) && (plan.op != Strip || this->TopologyValidAt(plan.placeSecondAt));
  for (int i = 0; i < plan.keptCount && valid; ++i)
  {
    valid = this->Manifold(plan.kept[i]);
  }
  if (!valid)
  {
    ++this->Stats.rejectedTopology;
    return false;
  }

  // Geometry: place or smooth, then reject fold-overs.
  if (plan.placeAt < 0 && !plan.gentle)
  {
    this->Smooth(survivor);
  }
  else if (plan.placeAt < 0)
  {
    // Midpoint of the merged nodes (as they were), z at the quadric minimum.
    const NodeState* merged[3];
    int count = 0;
    for (const NodeState& state : this->SavedNodes)
    {
      if (std::find(plan.merged, plan.merged + plan.mergedCount, state.node) != plan.merged + plan.mergedCount)
      {
        merged[count++] = &state;
      }
    }
    this->PlaceAtAverage(survivor, merged, count);
  }
  this->Scratch.assign(1, survivor);
  if (plan.op == Strip)
  {
    this->Scratch.push_back(plan.placeSecondAt);
  }
  for (int i = 0; i < plan.keptCount; ++i)
  {
    if (!plan.gentle && !m.IsBoundaryNode(plan.kept[i]) && !this->Pinned(plan.kept[i]))
    {
      this->Smooth(plan.kept[i]);
      this->Scratch.push_back(plan.kept[i]);
    }
  }
  if (plan.ring)
  {
    this->SmoothRing(plan.placeAt < 0);
  }
  cost = 0;
  for (int32_t node : this->Scratch)
  {
    cost = std::max(cost, this->NodeError(node));
  }
  for (int i = 0; i < plan.keptCount && !plan.gentle; ++i)
  {
    if (m.IsBoundaryNode(plan.kept[i]) && !this->Pinned(plan.kept[i]) && this->SlideAlongBoundary(plan.kept[i], cost))
    {
      this->Scratch.push_back(plan.kept[i]);
    }
  }
  return this->ShapeKeptAround(this->Scratch);
}

double ColumnCollapse::NodeError(int32_t node) const
{
  double error = 0;
  for (int32_t k = 0; k <= this->Mesh.LayerCount; ++k)
  {
    error = std::max(error, this->Mesh.NodeQuadric(node, k).Error(this->Mesh.Position(node, k)));
  }
  return error;
}

bool ColumnCollapse::SlideAlongBoundary(int32_t node, double allowed)
{
  // A kept boundary node slides to the midpoint of its two boundary neighbours, which evens
  // out the slivers boundary collapses leave, but only where that costs no more than the
  // collapse already does (the heavy side planes keep corners and bends where they are).
  ColumnMesh& m = this->Mesh;
  std::vector<int32_t>& neighbours = this->SlideNeighbours;
  std::vector<uint8_t>& boundary = this->SlideBoundary;
  m.Neighbours(node, neighbours, boundary);
  int32_t ends[2];
  int count = 0;
  for (std::size_t i = 0; i < neighbours.size(); ++i)
  {
    if (boundary[i])
    {
      if (count == 2)
      {
        return false;
      }
      ends[count++] = neighbours[i];
    }
  }
  if (count != 2)
  {
    return false;
  }
  const double before = this->NodeError(node);
  const int32_t interfaces = m.LayerCount + 1;
  std::vector<double>& saved = this->SlideSaved;
  const std::size_t first = static_cast<std::size_t>(node) * interfaces * 3;
  saved.assign(m.Positions.begin() + first, m.Positions.begin() + first + interfaces * 3);
  glm::dvec3 above(0.0);
  for (int32_t k = 0; k < interfaces; ++k)
  {
    const glm::dvec3 a = m.Position(ends[0], k), b = m.Position(ends[1], k);
    glm::dvec3 middle = 0.5 * (a + b);
    DepthBounds bounds;
    bounds.Add(a, k > 0 ? m.Position(ends[0], k - 1) : a, this->Stalled);
    bounds.Add(b, k > 0 ? m.Position(ends[1], k - 1) : b, this->Stalled);
    middle.z = this->PlaceDepth(node, k, middle, bounds, above.z);
    middle = k > 0 && this->Stalled ? LimitLean(middle, above, bounds.steepest, bounds.Slope()) : middle;
    above = middle;
    m.SetPosition(node, k, middle);
  }
  if (this->NodeError(node) > std::max(allowed, before))
  {
    std::copy(saved.begin(), saved.end(), m.Positions.begin() + first);
    return false;
  }
  m.Topology[node] = { 0.5 * (m.Topology[ends[0]][0] + m.Topology[ends[1]][0]),
    0.5 * (m.Topology[ends[0]][1] + m.Topology[ends[1]][1]) };
  return true;
}

namespace
{
/// Shape of a quadrilateral seen from above at one interface: its smallest corner area over
/// the mean squared edge length (1 for a square, near 0 for a sliver or a straight corner,
/// negative where a corner turns against the mesh).
double ShapeQuality(const ColumnMesh& m, const std::array<int32_t, 4>& q, int32_t k)
{
  double smallest = std::numeric_limits<double>::infinity(), squares = 0;
  for (int i = 0; i < 4; ++i)
  {
    const glm::dvec3 a = m.Position(q[(i + 3) % 4], k), b = m.Position(q[i], k), c = m.Position(q[(i + 1) % 4], k);
    const double ux = b.x - a.x, uy = b.y - a.y, vx = c.x - b.x, vy = c.y - b.y;
    smallest = std::min(smallest, m.Orientation() * (ux * vy - uy * vx));
    squares += vx * vx + vy * vy;
  }
  return squares > 0 ? 4 * smallest / squares : -1.0;
}
} // namespace

bool ColumnCollapse::EdgeHexagon(int32_t column, int corner, int32_t& other, int32_t hexagon[6]) const
{
  const ColumnMesh& m = this->Mesh;
  const auto& a = m.Corners[column];
  const int32_t h = a[corner], x = a[(corner + 1) % 4];
  other = -1;
  int at = -1;
  for (int32_t candidate : m.ColumnsOfNode[h])
  {
    const auto& o = m.Corners[candidate];
    for (int f = 0; candidate != column && f < 4; ++f)
    {
      if (o[f] == x && o[(f + 1) % 4] == h)
      {
        other = candidate;
        at = f;
      }
    }
  }
  if (other < 0 || m.IsLocked(column) || m.IsLocked(other))
  {
    return false;
  }
  const auto& b = m.Corners[other];
  // The hexagon of the two columns, in their orientation: h, b2, b3, x, a2, a3.
  const int32_t nodes[6] = { h, b[(at + 2) % 4], b[(at + 3) % 4], x, a[(corner + 2) % 4], a[(corner + 3) % 4] };
  for (int i = 0; i < 6; ++i)
  {
    hexagon[i] = nodes[i];
    for (int j = 0; j < i; ++j)
    {
      if (nodes[i] == nodes[j])
      {
        return false;
      }
    }
  }
  return true;
}

std::pair<std::array<int32_t, 4>, std::array<int32_t, 4>> ColumnCollapse::SplitHexagon(
  const int32_t hexagon[6], int shift)
{
  // The two columns the diagonal from hexagon[shift] to hexagon[shift + 3] makes.
  return { { hexagon[shift], hexagon[shift + 1], hexagon[shift + 2], hexagon[shift + 3] },
    { hexagon[shift + 3], hexagon[(shift + 4) % 6], hexagon[(shift + 5) % 6], hexagon[shift] } };
}

void ColumnCollapse::Rewire(int32_t column, int32_t other, const int32_t hexagon[6],
  const std::array<int32_t, 4>& first, const std::array<int32_t, 4>& second)
{
  ColumnMesh& m = this->Mesh;
  for (int i = 0; i < 6; ++i)
  {
    auto& list = m.ColumnsOfNode[hexagon[i]];
    list.erase(
      std::remove_if(list.begin(), list.end(), [&](int32_t c) { return c == column || c == other; }), list.end());
  }
  m.Corners[column] = first;
  m.Corners[other] = second;
  for (int32_t c : { column, other })
  {
    for (int32_t node : m.Corners[c])
    {
      m.ColumnsOfNode[node].push_back(c);
    }
  }
}

bool ColumnCollapse::DiagonalIsEdge(const int32_t hexagon[6], int shift) const
{
  const std::vector<int32_t>& columns = this->Mesh.ColumnsOfNode[hexagon[shift]];
  const int32_t to = hexagon[shift + 3];
  return std::any_of(columns.begin(), columns.end(), [&](int32_t c) {
    const auto& q = this->Mesh.Corners[c];
    const int at = IndexOf(q, hexagon[shift]);
    return q[(at + 1) % 4] == to || q[(at + 3) % 4] == to;
  });
}

bool ColumnCollapse::HexagonManifold(const int32_t hexagon[6]) const
{
  return std::all_of(hexagon, hexagon + 6, [this](int32_t node) { return this->Manifold(node); });
}

bool ColumnCollapse::RotateEdge(int32_t column, int corner)
{
  ColumnMesh& m = this->Mesh;
  int32_t other = -1;
  int32_t hexagon[6];
  if (!this->EdgeHexagon(column, corner, other, hexagon))
  {
    return false;
  }
  const auto a = m.Corners[column];
  const auto b = m.Corners[other];
  auto quality = [&](const std::array<int32_t, 4>& q) {
    return std::min(ShapeQuality(m, q, 0), ShapeQuality(m, q, m.LayerCount));
  };
  const double before = std::min(quality(a), quality(b));
  double bestQuality = before;
  int bestShift = -1;
  for (int shift = 1; shift <= 2; ++shift)
  {
    if (this->DiagonalIsEdge(hexagon, shift))
    {
      continue;
    }
    const auto columns = SplitHexagon(hexagon, shift);
    const double after = std::min(quality(columns.first), quality(columns.second));
    if (after > bestQuality)
    {
      bestQuality = after;
      bestShift = shift;
    }
  }
  if (bestShift < 0)
  {
    return false;
  }
  const auto chosen = SplitHexagon(hexagon, bestShift);
  this->Rewire(column, other, hexagon, chosen.first, chosen.second);
  if (!this->KeepsShape(column) || !this->KeepsShape(other) || !this->HexagonManifold(hexagon))
  {
    this->Rewire(column, other, hexagon, a, b);
    return false;
  }
  // Each new column covers parts of both old ones: a layer is active in it where it was in
  // either (a rotation never opens a hole in the active volume).
  for (int32_t k = 0; k < m.LayerCount; ++k)
  {
    uint8_t& first = m.ActiveCells[static_cast<std::size_t>(column) * m.LayerCount + k];
    uint8_t& second = m.ActiveCells[static_cast<std::size_t>(other) * m.LayerCount + k];
    first = second = (first || second) ? 1 : 0;
  }
  return true;
}

bool ColumnCollapse::MergeAlongBoundary(int32_t column, int corner)
{
  // The pair becomes one column and a column of three boundary nodes in a row (a straight
  // corner), which the corner operator removes: the boundary loses two nodes.
  ColumnMesh& m = this->Mesh;
  int32_t other = -1;
  int32_t hexagon[6];
  if (!this->EdgeHexagon(column, corner, other, hexagon) || !m.IsBoundaryNode(hexagon[0]))
  {
    return false;
  }
  const auto a = m.Corners[column];
  const auto b = m.Corners[other];
  std::vector<uint8_t> activeA(m.ActiveCells.begin() + static_cast<std::ptrdiff_t>(column) * m.LayerCount,
    m.ActiveCells.begin() + static_cast<std::ptrdiff_t>(column + 1) * m.LayerCount);
  for (int shift = 1; shift <= 2; ++shift)
  {
    if (this->DiagonalIsEdge(hexagon, shift))
    {
      continue;
    }
    const auto columns = SplitHexagon(hexagon, shift);
    this->Rewire(column, other, hexagon, columns.first, columns.second);
    const bool valid = this->HexagonManifold(hexagon);
    // The new column holding h and both its boundary neighbours goes by the corner operator
    // (its straight corner at h would not pass a shape test on its own; the corner
    // collapse's own tests judge the result, which includes the other column).
    for (int32_t corners : { column, other })
    {
      Plan plan;
      if (valid && IndexOf(m.Corners[corners], hexagon[0]) >= 0 && this->PlanColumn(corners, plan) && plan.op == Corner)
      {
        const int32_t kept = corners == column ? other : column;
        for (int32_t k = 0; k < m.LayerCount; ++k)
        {
          uint8_t& flag = m.ActiveCells[static_cast<std::size_t>(kept) * m.LayerCount + k];
          flag = (flag || activeA[k] || m.ActiveCells[static_cast<std::size_t>(other) * m.LayerCount + k]) ? 1 : 0;
        }
        this->Perform(plan);
        return true;
      }
    }
    this->Rewire(column, other, hexagon, a, b);
  }
  return false;
}

int64_t ColumnCollapse::MergeAlongBoundaries(int64_t targetColumns)
{
  const int64_t before = this->Mesh.AliveColumns();
  for (int32_t column = 0; column < this->Mesh.ColumnSlots() && this->Mesh.AliveColumns() > targetColumns; ++column)
  {
    for (int corner = 0; corner < 4 && this->Mesh.IsColumnAlive(column) && this->Mesh.AliveColumns() > targetColumns;
         ++corner)
    {
      this->MergeAlongBoundary(column, corner);
    }
  }
  return before - this->Mesh.AliveColumns();
}

int64_t ColumnCollapse::RotateEdges()
{
  int64_t rotations = 0;
  for (int32_t column = 0; column < this->Mesh.ColumnSlots(); ++column)
  {
    for (int corner = 0; corner < 4 && this->Mesh.IsColumnAlive(column); ++corner)
    {
      if (this->RotateEdge(column, corner))
      {
        ++rotations;
      }
    }
  }
  this->Stats.rotations += rotations;
  return rotations;
}

ColumnCollapse::MovedNode ColumnCollapse::SaveNode(int32_t node) const
{
  const std::size_t first = static_cast<std::size_t>(node) * (this->Mesh.LayerCount + 1) * 3;
  const auto& positions = this->Mesh.Positions;
  return { node, this->Mesh.Topology[node],
    std::vector<double>(positions.begin() + first, positions.begin() + first + (this->Mesh.LayerCount + 1) * 3) };
}

void ColumnCollapse::RestoreNode(const MovedNode& saved)
{
  this->Mesh.Topology[saved.node] = saved.topology;
  std::copy(saved.positions.begin(), saved.positions.end(),
    this->Mesh.Positions.begin() + static_cast<std::size_t>(saved.node) * (this->Mesh.LayerCount + 1) * 3);
}

bool ColumnCollapse::KeepsShape(int32_t column) const
{
  return !this->FoldsOver(column) && !this->InvertsCells(column);
}

bool ColumnCollapse::Pinned(int32_t node) const
{
  const auto& columns = this->Mesh.ColumnsOfNode[node];
  return std::any_of(columns.begin(), columns.end(), [this](int32_t c) { return this->Mesh.IsLocked(c); });
}

int64_t ColumnCollapse::Relax(double allowed)
{
  // Collapses leave fans of slivers around the nodes they merged into, and a sliver's own
  // collapse folds its neighbours: the simplification stalls far above small targets.
  // Evening the mesh out, within the error already spent, frees them.
  ColumnMesh& m = this->Mesh;
  int64_t moved = 0;
  for (int32_t node = 0; node < m.NodeCount(); ++node)
  {
    if (!m.IsNodeAlive(node) || m.ColumnsOfNode[node].empty() || this->Pinned(node))
    {
      continue;
    }
    const MovedNode saved = this->SaveNode(node);
    bool keep;
    if (m.IsBoundaryNode(node))
    {
      keep = this->SlideAlongBoundary(node, allowed);
    }
    else
    {
      const double before = this->NodeError(node);
      this->Smooth(node);
      keep = this->NodeError(node) <= std::max(allowed, before);
    }
    for (std::size_t i = 0; keep && i < m.ColumnsOfNode[node].size(); ++i)
    {
      keep = this->KeepsShape(m.ColumnsOfNode[node][i]);
    }
    if (!keep)
    {
      this->RestoreNode(saved);
      continue;
    }
    ++moved;
  }
  return moved;
}

void ColumnCollapse::SmoothRing(bool smoothSurvivor)
{
  // The interior neighbours of the nodes moved so far (this->Scratch, the survivor first)
  // are smoothed with them a few times: a Gauss-Seidel sweep that spreads the collapse over
  // the fan around it.
  ColumnMesh& m = this->Mesh;
  const std::size_t centres = this->Scratch.size();
  std::vector<int32_t> neighbours;
  std::vector<uint8_t> boundary;
  std::vector<int32_t> ring;
  for (std::size_t i = 0; i < centres; ++i)
  {
    m.Neighbours(this->Scratch[i], neighbours, boundary);
    for (int32_t node : neighbours)
    {
      const bool corner = std::any_of(this->SavedNodes.begin(), this->SavedNodes.end(),
        [node](const NodeState& state) { return state.node == node; });
      if (!corner && std::find(ring.begin(), ring.end(), node) == ring.end() && !m.IsBoundaryNode(node) &&
        !this->Pinned(node))
      {
        ring.push_back(node);
      }
    }
  }
  for (int32_t node : ring)
  {
    this->SavedMoves.push_back(this->SaveNode(node));
  }
  for (int sweep = 0; sweep < 3; ++sweep)
  {
    for (int32_t node : ring)
    {
      this->Smooth(node);
    }
    for (std::size_t i = smoothSurvivor ? 0 : 1; i < centres; ++i)
    {
      if (!m.IsBoundaryNode(this->Scratch[i]))
      {
        this->Smooth(this->Scratch[i]);
      }
    }
  }
  this->Scratch.insert(this->Scratch.end(), ring.begin(), ring.end());
}

void ColumnCollapse::Undo()
{
  if (!this->Pending)
  {
    return; // undone or committed already
  }
  this->Pending = false;
  ColumnMesh& m = this->Mesh;
  const int32_t interfaces = m.LayerCount + 1;
  for (const MovedNode& moved : this->SavedMoves)
  {
    this->RestoreNode(moved);
  }
  this->SavedMoves.clear();
  for (auto it = this->SavedCorners.rbegin(); it != this->SavedCorners.rend(); ++it)
  {
    m.Corners[it->first] = it->second;
  }
  for (NodeState& state : this->SavedNodes)
  {
    const std::size_t first = static_cast<std::size_t>(state.node) * interfaces;
    m.NodeAlive[state.node] = state.alive;
    m.Topology[state.node] = state.topology;
    std::copy(state.positions.begin(), state.positions.end(), m.Positions.begin() + first * 3);
    if (state.quadricsSaved)
    {
      std::copy(state.quadrics.begin(), state.quadrics.end(), m.Quadrics.begin() + first);
    }
    m.ColumnsOfNode[state.node].swap(state.columns);
  }
  for (int32_t column : this->RemovedColumns)
  {
    m.ColumnAlive[column] = 1;
    ++m.AliveColumnCount;
  }
  this->SavedCorners.clear();
  this->RemovedColumns.clear();
}

void ColumnCollapse::Commit()
{
  this->Pending = false;
  for (int32_t c : this->RemovedColumns)
  {
    if (this->AliveIndex[c] >= 0)
    {
      const int32_t at = this->AliveIndex[c];
      const int32_t last = this->AliveList.back();
      this->AliveList[at] = last;
      this->AliveIndex[last] = at;
      this->AliveList.pop_back();
      this->AliveIndex[c] = -1;
    }
  }
  this->SavedMoves.clear();
  this->SavedCorners.clear();
  this->RemovedColumns.clear();
}

void ColumnCollapse::TryOption(const Plan& option, Plan& best, bool& found)
{
  double cost = 0;
  const int64_t folds = this->Stats.rejectedFoldOver + this->Stats.rejectedInverted;
  bool valid = this->Apply(option, cost);
  this->Undo();
  Plan chosen = option;
  if (!valid && this->Stats.rejectedFoldOver + this->Stats.rejectedInverted > folds && !option.gentle)
  {
    // The paper's smoothing folded a face: try without it, the survivor at the merged
    // nodes' midpoint, then at each of them.
    chosen.gentle = true;
    valid = this->Apply(chosen, cost);
    this->Undo();
    for (int i = 0; i < option.mergedCount && !valid && option.placeAt < 0; ++i)
    {
      chosen.placeAt = option.merged[i];
      valid = this->Apply(chosen, cost);
      this->Undo();
    }
  }
  if (!valid && this->Stalled && this->Stats.rejectedFoldOver + this->Stats.rejectedInverted > folds)
  {
    chosen = option;
    chosen.gentle = false;
    chosen.ring = true;
    valid = this->Apply(chosen, cost);
    this->Undo();
  }

  if (valid && (!found || cost < best.cost))
  {
    best = chosen;
    best.cost = cost;
    found = true;
  }
}

bool ColumnCollapse::PlanColumn(int32_t column, Plan& best)
{
  const ColumnMesh& m = this->Mesh;
  if (column < 0 || column >= m.ColumnSlots() || !m.IsColumnAlive(column) || m.IsLocked(column))
  {
    return false;
  }
  const auto q = m.Corners[column];
  bool edge[4], onBoundary[4];
  int edges = 0, boundaryNodes = 0;
  for (int i = 0; i < 4; ++i)
  {
    edge[i] = m.IsBoundaryEdge(column, i); // between corners i and i+1
    onBoundary[i] = m.IsBoundaryNode(q[i]);
    edges += edge[i];
    boundaryNodes += onBoundary[i];
  }
  bool found = false;
  Plan option;
  option.column = column;
  auto diagonal = [&](int first, Operator op) {
    // Merge corners first and first+2, keep the other two.
    const int a = first, b = first + 2;
    if (onBoundary[a] && onBoundary[b])
    {
      return; // would join two boundary stretches
    }
    option.op = op;
    option.mergedCount = 2;
    option.merged[0] = q[a];
    option.merged[1] = q[b];
    option.placeAt = onBoundary[a] ? q[a] : (onBoundary[b] ? q[b] : -1);
    option.keptCount = 2;
    option.kept[0] = q[(a + 1) % 4];
    option.kept[1] = q[(a + 3) % 4];
    this->TryOption(option, best, found);
  };
  auto threeIntoOne = [&](int keep, Operator op) {
    // Corners keep+1..keep+3 become one, at whichever of their positions costs least.
    option.op = op;
    option.mergedCount = 3;
    for (int i = 0; i < 3; ++i)
    {
      option.merged[i] = q[(keep + 1 + i) % 4];
    }
    option.keptCount = 1;
    option.kept[0] = q[keep];
    for (int i = 0; i < 3; ++i)
    {
      option.placeAt = option.merged[i];
      this->TryOption(option, best, found);
    }
  };

  if (edges == 0 && boundaryNodes == 0)
  {
    // Operator 1: one direction, by lateral valence (the diagonal holding the lowest valence;
    // on a tie the smaller new valence; then at random).
    int valence[4];
    for (int i = 0; i < 4; ++i)
    {
      valence[i] = m.LateralValence(q[i]);
    }
    const int low0 = std::min(valence[0], valence[2]), low1 = std::min(valence[1], valence[3]);
    int first;
    if (low0 != low1)
    {
      first = low0 < low1 ? 0 : 1;
    }
    else
    {
      const int new0 = valence[0] + valence[2] - 2, new1 = valence[1] + valence[3] - 2;
      // A persisting tie goes one way at random, but the same way each time this column is
      // planned with the same corners (plans are compared again and again).
      const uint64_t coin =
        Mix(this->Seed ^ Mix(static_cast<uint64_t>(q[0]) * GoldenGamma + static_cast<uint64_t>(q[2])));
      first = new0 != new1 ? (new0 < new1 ? 0 : 1) : static_cast<int>(coin & 1);
    }
    diagonal(first, Internal);
    if (!found && this->Stalled)
    {
      // Stalled: the direction the valence rule turned down, if it is the only one valid.
      diagonal(1 - first, Internal);
    }
  }
  else if (edges <= 1)
  {
    // Operator 2: one or two nodes on the boundary; both directions, the cheaper wins.
    diagonal(0, Boundary);
    diagonal(1, Boundary);
  }
  else if (edges == 2 && edge[0] == edge[2])
  {
    // Two opposite boundary edges: a column of a strip one column wide, which none of the
    // paper's operators removes (rings and thin arms of a model stall on them). Each
    // boundary edge collapses to one of its nodes, which keeps the strip's outline; the
    // columns on either side become neighbours.
    const int first = edge[0] ? 0 : 1;
    option.op = Strip;
    option.gentle = true;
    option.mergedCount = 2;
    option.merged[0] = q[first];
    option.merged[1] = q[first + 1];
    option.mergedSecond[0] = q[first + 2];
    option.mergedSecond[1] = q[(first + 3) % 4];
    option.keptCount = 0;
    for (int a = 0; a < 2; ++a)
    {
      for (int b = 0; b < 2; ++b)
      {
        option.placeAt = option.merged[a];
        option.placeSecondAt = option.mergedSecond[b];
        this->TryOption(option, best, found);
      }
    }
  }
  else if (edges == 2)
  {
    // Operator 3: two consecutive boundary edges (a corner column).
    for (int i = 0; i < 4; ++i)
    {
      if (edge[i] && edge[(i + 1) % 4])
      {
        const int keep = (i + 3) % 4; // the corner opposite the boundary corner i+1
        if (!onBoundary[keep])
        {
          threeIntoOne(keep, Corner);
        }
      }
    }
  }
  else if (edges == 3)
  {
    // Operator 4: one internal edge; either of its nodes stays.
    for (int i = 0; i < 4; ++i)
    {
      if (!edge[i])
      {
        threeIntoOne(i, FourBoundary);
        threeIntoOne((i + 1) % 4, FourBoundary);
      }
    }
  }
  return found;
}

void ColumnCollapse::Perform(const Plan& plan)
{
  double cost = 0;
  if (!this->Apply(plan, cost))
  {
    this->Undo();
    return;
  }
  this->Commit();
  ++this->Stats.collapses;
  ++this->Stats.operatorCounts[plan.op];
  this->Stats.maxError = std::max(this->Stats.maxError, cost);
  const int32_t survivor = plan.placeAt >= 0 ? plan.placeAt : plan.merged[0];
  std::vector<int32_t> worklist = { survivor };
  if (plan.op == Strip)
  {
    worklist.push_back(plan.placeSecondAt);
  }
  for (int i = 0; i < plan.keptCount; ++i)
  {
    worklist.push_back(plan.kept[i]);
  }
  this->RemoveDoublets(std::move(worklist));
}

void ColumnCollapse::RemoveDoublets(std::vector<int32_t> worklist)
{
  // A non-boundary node of lateral valence 2 sits between two columns sharing two
  // consecutive edges (Fig. 7): it moves onto the opposite corner of one of them, which
  // may form new doublets around it.
  ColumnMesh& m = this->Mesh;
  std::vector<int32_t> neighbours;
  std::vector<uint8_t> boundary;
  for (std::size_t i = 0, n = worklist.size(); i < n; ++i)
  {
    m.Neighbours(worklist[i], neighbours, boundary);
    worklist.insert(worklist.end(), neighbours.begin(), neighbours.end());
  }
  while (!worklist.empty())
  {
    const int32_t node = worklist.back();
    worklist.pop_back();
    if (!m.IsNodeAlive(node) || m.ColumnsOfNode[node].size() != 2 || m.LateralValence(node) != 2 ||
      m.IsBoundaryNode(node))
    {
      continue;
    }
    Plan best;
    bool found = false;
    const std::vector<int32_t> columns = m.ColumnsOfNode[node]; // TryOption rewrites the list
    for (int32_t column : columns)
    {
      if (m.IsLocked(column))
      {
        continue;
      }
      const auto& q = m.Corners[column];
      Plan option;
      option.column = column;
      option.op = Doublet;
      option.mergedCount = 2;
      const int at = IndexOf(q, node);
      option.merged[0] = node;
      option.merged[1] = q[(at + 2) % 4];
      option.placeAt = option.merged[1];
      // The doublet node's two neighbours are smoothed (the paper's rule for nodes that
      // remain): they often sit at the bend that made the doublet, and the one column left
      // would fold over them. TryOption falls back to leaving them if smoothing folds.
      option.keptCount = 2;
      option.kept[0] = q[(at + 1) % 4];
      option.kept[1] = q[(at + 3) % 4];
      this->TryOption(option, best, found);
    }
    if (!found)
    {
      continue;
    }
    const auto q = m.Corners[best.column];
    double cost = 0;
    if (!this->Apply(best, cost))
    {
      this->Undo();
      continue;
    }
    this->Commit();
    ++this->Stats.doublets;
    ++this->Stats.operatorCounts[Doublet];
    this->Stats.maxError = std::max(this->Stats.maxError, cost);
    for (int32_t corner : q)
    {
      if (m.IsNodeAlive(corner))
      {
        worklist.push_back(corner);
        m.Neighbours(corner, neighbours, boundary);
        worklist.insert(worklist.end(), neighbours.begin(), neighbours.end());
      }
    }
  }
}

bool ColumnCollapse::TraceChord(int32_t column, int axis, ChordPath& chord, std::vector<uint8_t>* visited) const
{
  const ColumnMesh& m = this->Mesh;
  chord.columns.clear();
  chord.edges.clear();
  chord.closed = false;
  // The column across edge `e` of column `c` and the index of that edge in it, or -1.
  auto across = [&m](int32_t c, int e, int& entry) {
    const auto& q = m.Corners[c];
    const int32_t u = q[e], v = q[(e + 1) % 4];
    for (int32_t other : m.ColumnsOfNode[u])
    {
      const auto& o = m.Corners[other];
      for (int f = 0; other != c && f < 4; ++f)
      {
        if (o[f] == v && o[(f + 1) % 4] == u)
        {
          entry = f;
          return other;
        }
      }
    }
    return -1;
  };
  // Back to one end (a boundary edge), or round to the column again along the same axis.
  int32_t start = column;
  int in = axis;
  const int64_t limit = 2 * static_cast<int64_t>(m.ColumnSlots()) + 2;
  for (int64_t step = 0;; ++step)
  {
    int entry = -1;
    const int32_t previous = across(start, in, entry);
    if (previous < 0)
    {
      break;
    }
    if (step > limit)
    {
      return false;
    }
    if (previous == column && entry % 2 == axis % 2)
    {
      chord.closed = true;
      start = column;
      in = axis;
      break;
    }
    start = previous;
    in = (entry + 2) % 4;
  }
  // Forward from there, each column entered through edge `in` and left through `in + 2`.
  int32_t c = start;
  const int startAxis = in % 2;
  const auto& first = m.Corners[c];
  chord.edges.push_back({ first[in], first[(in + 1) % 4] });
  for (;;)
  {
    if (std::find(chord.columns.begin(), chord.columns.end(), c) != chord.columns.end() || m.IsLocked(c) ||
      (m.IsBoundaryEdge(c, (in + 1) % 4) && m.IsBoundaryEdge(c, (in + 3) % 4)))
    {
      // Crosses itself or a locked column, or runs through a column with no neighbour on
      // either side, which would vanish with nothing to take its place (a strip of a model
      // one column wide, or a whole fault block).
      return false;
    }
    chord.columns.push_back(c);
    if (visited)
    {
      (*visited)[static_cast<std::size_t>(c) * 2 + in % 2] = 1;
    }
    const auto& q = m.Corners[c];
    const int out = (in + 2) % 4;
    int entry = -1;
    const int32_t next = across(c, out, entry);
    if (next == start && chord.closed && entry % 2 == startAxis)
    {
      break; // the loop closes on the first edge
    }
    chord.edges.push_back({ q[out], q[(out + 1) % 4] });
    if (next < 0)
    {
      break;
    }
    c = next;
    in = entry;
  }
  std::vector<int32_t> nodes;
  for (const auto& edge : chord.edges)
  {
    nodes.push_back(edge[0]);
    nodes.push_back(edge[1]);
  }
  std::sort(nodes.begin(), nodes.end());
  return std::adjacent_find(nodes.begin(), nodes.end()) == nodes.end();
}

bool ColumnCollapse::ApplyChord(const ChordPath& chord, bool ring, double& cost)
{
  ColumnMesh& m = this->Mesh;
  this->SavedCorners.clear();
  this->SavedMoves.clear();
  this->Pending = true;
  const std::size_t edgeCount = chord.edges.size();
  this->SavedNodes.resize(2 * edgeCount);
  // How each crossed edge becomes one node, decided on the mesh as it is: the survivor is
  // a pinned node (placed at itself), else a boundary node (an end of an open chord, a
  // boundary edge, chooses between its nodes and their midpoint), else the midpoint,
  // smoothed.
  enum Placement
  {
    AtSurvivor,
    AlongBoundary,
    Smoothed
  };
  struct Collapse
  {
    int32_t survivor, other;
    Placement placement;
  };
  std::vector<Collapse> collapses;
  this->RemovedColumns.clear();
  for (std::size_t e = 0; e < edgeCount; ++e)
  {
    const int32_t a = chord.edges[e][0], b = chord.edges[e][1];
    this->SaveNodeState(this->SavedNodes[2 * e], a);
    this->SaveNodeState(this->SavedNodes[2 * e + 1], b);
    const bool pinnedA = this->Pinned(a), pinnedB = this->Pinned(b);
    const bool boundaryA = m.IsBoundaryNode(a), boundaryB = m.IsBoundaryNode(b);
    const bool end = !chord.closed && (e == 0 || e + 1 == edgeCount);
    if ((pinnedA && pinnedB) || (pinnedA && boundaryB && !boundaryA) || (pinnedB && boundaryA && !boundaryB) ||
      (boundaryA && boundaryB && !end))
    {
      // Two pinned nodes cannot merge, a boundary node must not be pulled inside, and an
      // inner edge between two boundary nodes would join two stretches of the boundary.
      ++this->Stats.rejectedTopology;
      this->SavedNodes.resize(2 * e + 2);
      return false;
    }
    if (pinnedA || pinnedB)
    {
      collapses.push_back({ pinnedA ? a : b, pinnedA ? b : a, AtSurvivor });
    }
    else if (boundaryA && boundaryB)
    {
      collapses.push_back({ a, b, AlongBoundary });
    }
    else if (boundaryA || boundaryB)
    {
      collapses.push_back({ boundaryA ? a : b, boundaryA ? b : a, AtSurvivor });
    }
    else
    {
      collapses.push_back({ a, b, Smoothed });
    }
  }
  this->RemovedColumns.assign(chord.columns.begin(), chord.columns.end());
  for (int32_t c : chord.columns)
  {
    m.ColumnAlive[c] = 0;
    --m.AliveColumnCount;
    for (int32_t node : m.Corners[c])
    {
      auto& list = m.ColumnsOfNode[node];
      list.erase(std::remove(list.begin(), list.end(), c), list.end());
    }
  }
  for (const Collapse& collapse : collapses)
  {
    this->MergeNode(collapse.other, collapse.survivor);
  }
  for (const Collapse& collapse : collapses)
  {
    if (m.ColumnsOfNode[collapse.survivor].empty() || !this->TopologyValidAt(collapse.survivor))
    {
      ++this->Stats.rejectedTopology;
      return false;
    }
  }
  // Placement: the midpoints first, then the boundary ends at whichever of their midpoint
  // and nodes costs least, then the interior survivors smoothed together a few times.
  this->Scratch.clear();
  for (std::size_t e = 0; e < edgeCount; ++e)
  {
    const Collapse& collapse = collapses[e];
    if (collapse.placement == AtSurvivor)
    {
      continue;
    }
    const NodeState* pair[2] = { &this->SavedNodes[2 * e], &this->SavedNodes[2 * e + 1] };
    this->PlaceAtAverage(collapse.survivor, pair, 2);
    this->Scratch.push_back(collapse.survivor);
    if (collapse.placement == AlongBoundary)
    {
      const MovedNode middle = this->SaveNode(collapse.survivor);
      double best = this->NodeError(collapse.survivor);
      const NodeState* bestAt = nullptr;
      for (const NodeState* at : pair)
      {
        std::copy(at->positions.begin(), at->positions.end(),
          m.Positions.begin() + static_cast<std::size_t>(collapse.survivor) * (m.LayerCount + 1) * 3);
        const double error = this->NodeError(collapse.survivor);
        if (error < best)
        {
          best = error;
          bestAt = at;
        }
      }
      this->RestoreNode(middle);
      if (bestAt)
      {
        std::copy(bestAt->positions.begin(), bestAt->positions.end(),
          m.Positions.begin() + static_cast<std::size_t>(collapse.survivor) * (m.LayerCount + 1) * 3);
        m.Topology[collapse.survivor] = bestAt->topology;
      }
    }
  }
  for (int sweep = 0; sweep < 3; ++sweep)
  {
    for (const Collapse& collapse : collapses)
    {
      if (collapse.placement == Smoothed)
      {
        this->Smooth(collapse.survivor);
      }
    }
  }
  if (ring)
  {
    this->SmoothRing(true);
  }
  cost = 0;
  for (int32_t node : this->Scratch)
  {
    cost = std::max(cost, this->NodeError(node));
  }
  for (const Collapse& collapse : collapses)
  {
    if (collapse.placement == AtSurvivor)
    {
      cost = std::max(cost, this->NodeError(collapse.survivor));
      this->Scratch.push_back(collapse.survivor);
    }
  }
  return this->ShapeKeptAround(this->Scratch);
}

int64_t ColumnCollapse::PerformChord(const ChordPath& chord)
{
  double cost = 0, ringCost = 0;
  const bool plain = this->ApplyChord(chord, false, cost);
  this->Undo();
  const bool ringed = this->ApplyChord(chord, true, ringCost);
  this->Undo();
  if (!plain && !ringed)
  {
    return 0;
  }
  if (!this->ApplyChord(chord, ringed && (!plain || ringCost < cost), cost))
  {
    this->Undo(); // not reached: the same chord was valid a moment ago
    return 0;
  }
  std::vector<int32_t> survivors = this->Scratch;
  const int64_t removed = static_cast<int64_t>(this->RemovedColumns.size());
  this->Commit();
  ++this->Stats.collapses;
  ++this->Stats.operatorCounts[Chord];
  this->Stats.maxError = std::max(this->Stats.maxError, cost);
  this->RemoveDoublets(std::move(survivors));
  return removed;
}

int64_t ColumnCollapse::CollapseChord(int32_t column, int axis)
{
  ChordPath chord;
  if (column < 0 || column >= this->Mesh.ColumnSlots() || !this->Mesh.IsColumnAlive(column) ||
    !this->TraceChord(column, axis & 1, chord, nullptr))
  {
    return 0;
  }
  return this->PerformChord(chord);
}

int64_t ColumnCollapse::CollapseChords(int64_t targetColumns)
{
  // Every chord once (the visited flags), weighed by the cheaper of its two ways.
  ColumnMesh& m = this->Mesh;
  struct Candidate
  {
    double cost;
    int32_t column;
    int axis;
    bool operator<(const Candidate& other) const
    {
      return this->cost != other.cost ? this->cost < other.cost : this->column < other.column;
    }
  };
  std::vector<Candidate> candidates;
  std::vector<uint8_t> visited(static_cast<std::size_t>(m.ColumnSlots()) * 2, 0);
  ChordPath chord;
  for (int32_t column : this->AliveList)
  {
    for (int axis = 0; axis < 2; ++axis)
    {
      if (visited[static_cast<std::size_t>(column) * 2 + axis] || !this->TraceChord(column, axis, chord, &visited))
      {
        continue;
      }
      double cost = 0, ringCost = 0;
      const bool plain = this->ApplyChord(chord, false, cost);
      this->Undo();
      const bool ringed = this->ApplyChord(chord, true, ringCost);
      this->Undo();
      if (plain || ringed)
      {
        candidates.push_back({ plain && ringed ? std::min(cost, ringCost) : (plain ? cost : ringCost), column, axis });
      }
    }
  }
  std::sort(candidates.begin(), candidates.end());
  // Chords cost more than column collapses do: a few go, then collapses resume around them.
  const int64_t budget = std::max<int64_t>(1, (m.AliveColumns() - targetColumns) / 4);
  int64_t removed = 0;
  for (const Candidate& candidate : candidates)
  {
    if (m.AliveColumns() <= targetColumns || removed >= budget)
    {
      break;
    }
    // Earlier chords changed the mesh: trace again; one longer than what is left to remove
    // goes only if nothing else did.
    if (!m.IsColumnAlive(candidate.column) || !this->TraceChord(candidate.column, candidate.axis, chord, nullptr) ||
      (removed > 0 && static_cast<int64_t>(chord.columns.size()) > m.AliveColumns() - targetColumns))
    {
      continue;
    }
    removed += this->PerformChord(chord);
  }
  return removed;
}

SimplifyReport ColumnCollapse::Finish(int64_t targetColumns, const std::function<void(double)>& progress)
{
  this->Stats.columnsAfter = this->Mesh.AliveColumns();
  this->Stats.reachedTarget = this->Mesh.AliveColumns() <= targetColumns;
  if (progress)
  {
    progress(1.0);
  }
  return this->Stats;
}

bool ColumnCollapse::Unblock(int64_t& relaxedAt, int64_t targetColumns)
{
  if (this->Mesh.AliveColumns() == relaxedAt)
  {
    // Rotations and smoothing freed nothing last time: boundary slivers in pairs, chords.
    const int64_t merged = this->MergeAlongBoundaries(targetColumns);
    return merged + (this->Mesh.AliveColumns() > targetColumns ? this->CollapseChords(targetColumns) : 0) > 0;
  }
  relaxedAt = this->Mesh.AliveColumns();
  ++this->Stats.relaxations;
  this->Stalled = true;
  this->RotateEdges();
  for (int pass = 0; pass < 3; ++pass)
  {
    this->Relax(this->Stats.maxError);
  }
  this->MergeAlongBoundaries(targetColumns);
  return true;
}

int64_t ColumnCollapse::SweepCollapses(int64_t targetColumns)
{
  std::vector<std::pair<double, int32_t>> valid;
  for (int32_t column : this->AliveList)
  {
    Plan plan;
    if (this->PlanColumn(column, plan))
    {
      valid.emplace_back(plan.cost, column);
    }
  }
  std::sort(valid.begin(), valid.end());
  int64_t performed = 0;
  for (const auto& entry : valid)
  {
    Plan plan;
    if (this->Mesh.AliveColumns() <= targetColumns)
    {
      break;
    }
    if (this->PlanColumn(entry.second, plan)) // again: the collapses before changed the mesh
    {
      this->Perform(plan);
      ++performed;
    }
  }
  return performed;
}

void ColumnCollapse::RepairInvertedColumns(int64_t targetColumns)
{
  if (this->Mesh.AliveColumns() > targetColumns) // a mesh left as it is stays as it came
  {
    this->StraightenReflexCorners();
    this->CollapseInvertedColumns(targetColumns);
  }
}

int64_t ColumnCollapse::StraightenReflexCorners()
{
  // A corner-point grid can bound its outline with columns whose outer corner turns inward a
  // little (a staircase along an oblique limit: Brugge, Emerald), inverting every cell of the
  // column. When that corner's node belongs to this column alone, it moves out past the
  // chord of its two neighbours at each interface where it turns inward: the outline moves
  // by that node's distance to the chord plus a margin, and nothing else changes. The margin
  // grows (to 5% of the chord) until the cells are valid: pillars that lean make a corner
  // that is barely convex seen from above still invert.
  ColumnMesh& m = this->Mesh;
  const double sign = m.OrientationSign;
  int64_t straightened = 0;
  std::vector<MovedNode> saved;
  for (int32_t column : this->AliveList)
  {
    if (!this->InvertsCells(column))
    {
      continue;
    }
    const auto q = m.Corners[column];
    saved.clear();
    for (int i = 0; i < 4; ++i)
    {
      if (m.ColumnsOfNode[q[i]].size() == 1 && !this->Pinned(q[i]))
      {
        saved.push_back(this->SaveNode(q[i]));
      }
    }
    if (saved.empty())
    {
      continue;
    }
    bool valid = false;
    for (const double margin : { 1e-4, 1e-3, 1e-2, 2e-2, 5e-2 })
    {
      for (const MovedNode& original : saved)
      {
        this->RestoreNode(original);
        const int i = static_cast<int>(std::find(q.begin(), q.end(), original.node) - q.begin());
        for (int32_t k = 0; k <= m.LayerCount; ++k)
        {
          const glm::dvec3 a = m.Position(q[(i + 3) % 4], k), b = m.Position(original.node, k),
                           c = m.Position(q[(i + 1) % 4], k);
          const double turn = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
          const glm::dvec2 chord(c.x - a.x, c.y - a.y);
          const double length2 = glm::dot(chord, chord);
          if (turn * sign >= 0 || !(length2 > 0))
          {
            continue;
          }
          const double t = std::clamp(glm::dot(glm::dvec2(b.x - a.x, b.y - a.y), chord) / length2, 0.0, 1.0);
          const glm::dvec2 foot = glm::dvec2(a.x, a.y) + t * chord;
          // Outward: across the chord from b, away from the column's interior.
          const glm::dvec2 normal = sign * glm::dvec2(chord.y, -chord.x) / std::sqrt(length2);
          const glm::dvec2 placed = foot + normal * (margin * std::sqrt(length2));
          m.SetPosition(original.node, k, glm::dvec3(placed.x, placed.y, b.z));
        }
      }
      if (!this->InvertsCells(column) && !this->FoldsOver(column))
      {
        valid = true;
        break;
      }
    }
    if (!valid)
    {
      for (const MovedNode& original : saved)
      {
        this->RestoreNode(original);
      }
      continue;
    }
    for (const MovedNode& original : saved)
    {
      for (int32_t k = 0; k <= m.LayerCount; ++k)
      {
        const double* was = &original.positions[3 * static_cast<std::size_t>(k)];
        const glm::dvec3 now = m.Position(original.node, k);
        this->Stats.straightenedMove =
          std::max(this->Stats.straightenedMove, std::hypot(now.x - was[0], now.y - was[1]));
      }
    }
    ++straightened;
  }
  this->Stats.straightenedColumns += straightened;
  return straightened;
}

int64_t ColumnCollapse::CollapseInvertedColumns(int64_t targetColumns)
{
  // Collapses never create an inverted cell, and a collapse next to a column that is
  // inverted already is rejected too (its nodes cannot move without judging that column), so
  // such columns would stay to the end and keep their neighbours. Remove them first, each by
  // its cheapest valid plan; a column that has none yet is tried again after the others.
  std::vector<int32_t> pending;
  for (int32_t column : this->AliveList)
  {
    if (this->InvertsCells(column))
    {
      pending.push_back(column);
    }
  }
  int64_t removed = 0;
  const bool stalled = this->Stalled;
  this->Stalled = true; // ring plans too: these columns' neighbours are often slivers
  // Inverted columns come in chains (a staircase boundary of reflex corners): a collapse may
  // leave another column of the chain as it found it, inverted, for its own turn will come.
  this->Exempt.assign(static_cast<std::size_t>(this->Mesh.ColumnSlots()), 0);
  for (int32_t column : pending)
  {
    this->Exempt[column] = 1;
  }
  for (bool progressed = true; progressed && !pending.empty();)
  {
    progressed = false;
    std::vector<int32_t> left;
    for (int32_t column : pending)
    {
      if (this->Mesh.AliveColumns() <= targetColumns)
      {
        break;
      }
      this->Exempt[column] = 0;
      if (!this->Mesh.IsColumnAlive(column) || !this->InvertsCells(column))
      {
        continue;
      }
      Plan plan;
      if (this->PlanColumn(column, plan))
      {
        const int64_t before = this->Mesh.AliveColumns();
        this->Perform(plan);
        removed += before - this->Mesh.AliveColumns();
        progressed = true;
        // A column this collapse mended is judged like any other from now on.
        for (int32_t other : pending)
        {
          if (this->Exempt[other] && this->Mesh.IsColumnAlive(other) && !this->InvertsCells(other))
          {
            this->Exempt[other] = 0;
          }
        }
      }
      else
      {
        this->Exempt[column] = 1;
        left.push_back(column);
      }
    }
    pending.swap(left);
  }
  this->Stalled = stalled;
  this->Exempt.clear();
  this->Stats.invertedColumnsCollapsed += removed;
  return removed;
}

SimplifyReport ColumnCollapse::Simplify(int64_t targetColumns, const std::function<void(double)>& progress)
{
  ColumnMesh& m = this->Mesh;
  this->Stats.columnsBefore = m.AliveColumns();
  this->RepairInvertedColumns(targetColumns);
  const int64_t toRemove = std::max<int64_t>(1, m.AliveColumns() - targetColumns);
  int64_t failures = 0;
  int64_t sinceProgress = 0;
  int64_t relaxedAt = -1;
  while (m.AliveColumns() > targetColumns && !this->AliveList.empty())
  {
    Plan best;
    bool found = false;
    for (int candidate = 0; candidate < this->Candidates; ++candidate)
    {
      const auto pick = static_cast<std::size_t>(this->RandomUnit() * static_cast<double>(this->AliveList.size()));
      Plan plan;
      if (this->PlanColumn(this->AliveList[std::min(pick, this->AliveList.size() - 1)], plan) &&
        (!found || plan.cost < best.cost))
      {
        best = plan;
        found = true;
      }
    }
    if (!found)
    {
      // Nothing valid among these candidates. Sixteen times in a row: valid collapses have
      // become rare, and drawing at random until every column has had its chances would
      // cost eight plans a column. Plan each column once instead and perform what is valid;
      // when nothing is, unblock, and give up when that frees nothing.
      if (++failures >= 16)
      {
        failures = 0;
        if (this->SweepCollapses(targetColumns) == 0 && !this->Unblock(relaxedAt, targetColumns))
        {
          break;
        }
      }
      continue;
    }
    failures = 0;
    this->Perform(best);
    if (progress && ++sinceProgress >= 256)
    {
      sinceProgress = 0;
      progress(std::min(
        1.0, static_cast<double>(this->Stats.columnsBefore - m.AliveColumns()) / static_cast<double>(toRemove)));
    }
  }
  return this->Finish(targetColumns, progress);
}

SimplifyReport ColumnCollapse::SimplifyGreedy(int64_t targetColumns, const std::function<void(double)>& progress)
{
  ColumnMesh& m = this->Mesh;
  this->Stats.columnsBefore = m.AliveColumns();
  this->RepairInvertedColumns(targetColumns);
  const int64_t toRemove = std::max<int64_t>(1, m.AliveColumns() - targetColumns);
  struct Entry
  {
    double cost;
    int32_t column;
    uint32_t stamp;
    bool operator<(const Entry& other) const
    {
      // std::priority_queue keeps the largest on top: invert for the cheapest, ties by column.
      return this->cost != other.cost ? this->cost > other.cost : this->column > other.column;
    }
  };
  std::priority_queue<Entry> queue;
  std::vector<uint32_t> stamps(static_cast<std::size_t>(m.ColumnSlots()), 0);
  auto plan = [&](int32_t column) {
    Plan found;
    ++stamps[column];
    if (this->PlanColumn(column, found))
    {
      queue.push({ found.cost, column, stamps[column] });
    }
  };
  for (int32_t column : this->AliveList)
  {
    plan(column);
  }
  std::vector<int32_t> neighbours, touched;
  std::vector<uint8_t> boundary;
  int64_t sinceProgress = 0;
  int64_t relaxedAt = -1;
  for (;;)
  {
    while (m.AliveColumns() > targetColumns && !queue.empty())
    {
      const Entry top = queue.top();
      queue.pop();
      if (top.stamp != stamps[top.column] || !m.IsColumnAlive(top.column))
      {
        continue; // superseded
      }
      Plan fresh;
      ++stamps[top.column];
      if (!this->PlanColumn(top.column, fresh))
      {
        continue; // planned again when a neighbour changes
      }
      if (!queue.empty() && fresh.cost > queue.top().cost)
      {
        queue.push({ fresh.cost, top.column, stamps[top.column] });
        continue;
      }
      // Columns whose plans may change: those within two edges of the nodes this collapse
      // merges or smooths (a plan smooths its kept nodes over their neighbours).
      touched.clear();
      std::vector<int32_t> ring(m.Corners[top.column].begin(), m.Corners[top.column].end());
      for (int step = 0; step < 2; ++step)
      {
        const std::size_t count = ring.size();
        for (std::size_t i = 0; i < count; ++i)
        {
          m.Neighbours(ring[i], neighbours, boundary);
          ring.insert(ring.end(), neighbours.begin(), neighbours.end());
        }
        std::sort(ring.begin(), ring.end());
        ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
      }
      for (int32_t node : ring)
      {
        touched.insert(touched.end(), m.ColumnsOfNode[node].begin(), m.ColumnsOfNode[node].end());
      }
      this->Perform(fresh);
      std::sort(touched.begin(), touched.end());
      touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
      for (int32_t column : touched)
      {
        if (m.IsColumnAlive(column) && !m.IsLocked(column))
        {
          plan(column);
        }
      }
      if (progress && ++sinceProgress >= 256)
      {
        sinceProgress = 0;
        progress(std::min(
          1.0, static_cast<double>(this->Stats.columnsBefore - m.AliveColumns()) / static_cast<double>(toRemove)));
      }
    }
    // Nothing valid is left in the queue: unblock as Simplify does, and plan every column again.
    if (m.AliveColumns() <= targetColumns || !this->Unblock(relaxedAt, targetColumns))
    {
      break;
    }
    for (int32_t column : this->AliveList)
    {
      plan(column);
    }
  }
  return this->Finish(targetColumns, progress);
}

} // namespace resmr
