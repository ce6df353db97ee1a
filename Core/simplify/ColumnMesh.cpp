// Column-structured hexahedral mesh of a reservoir region (paper Sec. 4.1, Figs. 3 and 4).
#include "ColumnMesh.h"

#include "CornerPointGeometry.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace resmr
{
namespace
{
/// Corner q of our columns ((i,j), (i+1,j), (i+1,j+1), (i,j+1)) as an ECLIPSE corner index.
constexpr int EclipseCorner[4] = { 0, 1, 3, 2 };

int Find(std::array<int, 4>& parent, int x)
{
  while (parent[x] != x)
  {
    x = parent[x] = parent[parent[x]];
  }
  return x;
}
} // namespace

ColumnMesh ColumnMesh::FromCornerPoints(const CornerPointGeometry& geometry, const std::vector<bool>& active)
{
  return FromCornerPoints(geometry, active, 0, geometry.Dims()[0], 0, geometry.Dims()[1]);
}

ColumnMesh ColumnMesh::FromCornerPoints(
  const CornerPointGeometry& geometry, const std::vector<bool>& active, int64_t i0, int64_t i1, int64_t j0, int64_t j1)
{
  return FromCells(
    geometry.Dims(),
    [&](int64_t i, int64_t j, int64_t k, double corners[8][3]) { geometry.CellCorners(i, j, k, corners); }, active, i0,
    i1, j0, j1);
}

namespace
{
/// FromCells' arguments checked: a non-empty box inside the grid, one active flag a cell, one
/// selection flag a column of the box.
void CheckCellBox(const std::array<int64_t, 3>& dims, const std::vector<bool>& active, int64_t i0, int64_t i1,
  int64_t j0, int64_t j1, const std::vector<uint8_t>* selected)
{
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  if (i0 < 0 || j0 < 0 || i1 > nx || j1 > ny || i0 >= i1 || j0 >= j1 || nz < 1)
  {
    throw std::invalid_argument("column mesh: empty or out-of-grid box [" + std::to_string(i0) + ", " +
      std::to_string(i1) + ") x [" + std::to_string(j0) + ", " + std::to_string(j1) + ") of a " + std::to_string(nx) +
      " x " + std::to_string(ny) + " x " + std::to_string(nz) + " grid");
  }
  if (static_cast<int64_t>(active.size()) != nx * ny * nz)
  {
    throw std::invalid_argument(
      "column mesh: " + std::to_string(active.size()) + " active flags for " + std::to_string(nx * ny * nz) + " cells");
  }
  const int64_t width = i1 - i0, height = j1 - j0;
  if (selected && static_cast<int64_t>(selected->size()) != width * height)
  {
    throw std::invalid_argument("column mesh: selection of " + std::to_string(selected->size()) +
      " flags for a box of " + std::to_string(width * height) + " columns");
  }
}
} // namespace

ColumnMesh ColumnMesh::FromCells(const std::array<int64_t, 3>& dims, const CellCornersFunction& cellCorners,
  const std::vector<bool>& active, int64_t i0, int64_t i1, int64_t j0, int64_t j1, const std::vector<uint8_t>* selected)
{
  CheckCellBox(dims, active, i0, i1, j0, j1, selected);
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  const int64_t width = i1 - i0, height = j1 - j0;
  ColumnMesh mesh;
  mesh.LayerCount = static_cast<int32_t>(nz);
  const int64_t interfaces = nz + 1;

  // Columns with at least one active cell (Fig. 3).
  std::vector<int32_t> columnOf(static_cast<std::size_t>(width * height), -1);
  for (int64_t j = j0; j < j1; ++j)
  {
    for (int64_t i = i0; i < i1; ++i)
    {
      if (selected && !(*selected)[static_cast<std::size_t>((j - j0) * width + (i - i0))])
      {
        continue;
      }
      bool any = false;
      for (int64_t k = 0; k < nz && !any; ++k)
      {
        any = active[static_cast<std::size_t>((k * ny + j) * nx + i)];
      }
      if (any)
      {
        columnOf[(j - j0) * width + (i - i0)] = static_cast<int32_t>(mesh.Corners.size());
        mesh.Corners.push_back({ -1, -1, -1, -1 });
        mesh.Origin.push_back({ static_cast<int32_t>(i), static_cast<int32_t>(j) });
        for (int64_t k = 0; k < nz; ++k)
        {
          mesh.ActiveCells.push_back(active[static_cast<std::size_t>((k * ny + j) * nx + i)] ? 1 : 0);
        }
      }
    }
  }
  if (mesh.Corners.empty())
  {
    throw std::invalid_argument("column mesh: no active cell in the box");
  }

  // Corner stacks of two rows of columns at a time: [row][i][corner][interface][xyz].
  const std::size_t stackSize = static_cast<std::size_t>(4 * interfaces * 3);
  std::vector<double> rows[2];
  rows[0].assign(static_cast<std::size_t>(width) * stackSize, 0.0);
  rows[1].assign(static_cast<std::size_t>(width) * stackSize, 0.0);
  auto fillRow = [&](std::vector<double>& row, int64_t j) {
    double corners[8][3];
    for (int64_t i = i0; i < i1; ++i)
    {
      if (columnOf[(j - j0) * width + (i - i0)] < 0)
      {
        continue;
      }
      double* stack = &row[static_cast<std::size_t>(i - i0) * stackSize];
      for (int64_t k = 0; k < nz; ++k)
      {
        cellCorners(i, j, k, corners);
        for (int q = 0; q < 4; ++q)
        {
          for (int d = 0; d < 3; ++d)
          {
            if (!std::isfinite(corners[EclipseCorner[q]][d]) || !std::isfinite(corners[EclipseCorner[q] + 4][d]))
            {
              throw std::invalid_argument("column mesh: cell (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) +
                ", " + std::to_string(k + 1) + ") has a non-finite corner");
            }
            stack[(q * interfaces + k) * 3 + d] = corners[EclipseCorner[q]][d];
            if (k == nz - 1)
            {
              stack[(q * interfaces + nz) * 3 + d] = corners[EclipseCorner[q] + 4][d];
            }
          }
        }
      }
    }
  };
  auto stackOf = [&](int64_t i, int64_t j, int q) -> const double* {
    const std::vector<double>& row = rows[(j - j0) & 1];
    return &row[static_cast<std::size_t>(i - i0) * stackSize + static_cast<std::size_t>(q * interfaces * 3)];
  };
  auto sameStack = [&](const double* a, const double* b) { return std::equal(a, a + interfaces * 3, b); };

  // Nodes, pillar by pillar: the (up to) four columns around a pillar share a node where
  // edge-adjacent columns agree at every interface.
  for (int64_t pj = j0; pj <= j1; ++pj)
  {
    if (pj < j1)
    {
      fillRow(rows[(pj - j0) & 1], pj);
    }
    for (int64_t pi = i0; pi <= i1; ++pi)
    {
      // Around the pillar: 0 (pi-1, pj-1), 1 (pi, pj-1), 2 (pi-1, pj), 3 (pi, pj); the corner
      // each touches the pillar with.
      const int64_t ci[4] = { pi - 1, pi, pi - 1, pi };
      const int64_t cj[4] = { pj - 1, pj - 1, pj, pj };
      const int cq[4] = { 2, 3, 1, 0 };
      int32_t column[4];
      for (int a = 0; a < 4; ++a)
      {
        const bool inside = ci[a] >= i0 && ci[a] < i1 && cj[a] >= j0 && cj[a] < j1;
        column[a] = inside ? columnOf[(cj[a] - j0) * width + (ci[a] - i0)] : -1;
      }
      std::array<int, 4> parent = { 0, 1, 2, 3 };
      const int pairs[4][2] = { { 0, 1 }, { 2, 3 }, { 0, 2 }, { 1, 3 } };
      for (const auto& pair : pairs)
      {
        const int a = pair[0], b = pair[1];
        if (column[a] >= 0 && column[b] >= 0 && sameStack(stackOf(ci[a], cj[a], cq[a]), stackOf(ci[b], cj[b], cq[b])))
        {
          parent[Find(parent, a)] = Find(parent, b);
        }
      }
      int32_t nodeOfRoot[4] = { -1, -1, -1, -1 };
      for (int a = 0; a < 4; ++a)
      {
        if (column[a] < 0)
        {
          continue;
        }
        const int root = Find(parent, a);
        if (nodeOfRoot[root] < 0)
        {
          nodeOfRoot[root] = static_cast<int32_t>(mesh.Topology.size());
          mesh.Topology.push_back({ static_cast<double>(pi), static_cast<double>(pj) });
          const double* stack = stackOf(ci[a], cj[a], cq[a]);
          mesh.Positions.insert(mesh.Positions.end(), stack, stack + interfaces * 3);
        }
        mesh.Corners[column[a]][cq[a]] = nodeOfRoot[root];
      }
    }
  }
  mesh.BuildAdjacencyAndQuadrics();
  return mesh;
}

ColumnMesh ColumnMesh::FromParts(int32_t layers, std::vector<double> positions,
  std::vector<std::array<double, 2>> topology, std::vector<std::array<int32_t, 4>> corners,
  std::vector<uint8_t> activeCells)
{
  if (layers < 1 || positions.size() != topology.size() * static_cast<std::size_t>(layers + 1) * 3 ||
    activeCells.size() != corners.size() * static_cast<std::size_t>(layers))
  {
    throw std::invalid_argument("column mesh: inconsistent parts");
  }
  ColumnMesh mesh;
  mesh.LayerCount = layers;
  mesh.Positions = std::move(positions);
  mesh.Topology = std::move(topology);
  mesh.Corners = std::move(corners);
  mesh.ActiveCells = std::move(activeCells);
  mesh.Origin.assign(mesh.Corners.size(), { -1, -1 });
  for (const auto& quad : mesh.Corners)
  {
    for (int32_t node : quad)
    {
      if (node < 0 || node >= static_cast<int32_t>(mesh.Topology.size()))
      {
        throw std::invalid_argument("column mesh: corner refers to a missing node");
      }
    }
  }
  mesh.BuildAdjacencyAndQuadrics();
  return mesh;
}

ColumnMesh ColumnMesh::FromData(ColumnMeshData data)
{
  const std::size_t nodes = data.topology.size();
  const std::size_t interfaces = static_cast<std::size_t>(data.layers) + 1;
  if (data.layers < 1 || data.positions.size() != nodes * interfaces * 3 ||
    data.quadrics.size() != nodes * interfaces ||
    data.activeCells.size() != data.corners.size() * static_cast<std::size_t>(data.layers) ||
    data.origin.size() != data.corners.size())
  {
    throw std::invalid_argument("column mesh: inconsistent saved arrays");
  }
  for (const auto& quad : data.corners)
  {
    for (int32_t node : quad)
    {
      if (node < 0 || static_cast<std::size_t>(node) >= nodes)
      {
        throw std::invalid_argument("column mesh: a saved column refers to a missing node");
      }
    }
  }
  ColumnMesh mesh;
  mesh.LayerCount = data.layers;
  mesh.Positions = std::move(data.positions);
  mesh.Topology = std::move(data.topology);
  mesh.Corners = std::move(data.corners);
  mesh.ActiveCells = std::move(data.activeCells);
  mesh.Origin = std::move(data.origin);
  mesh.BuildAdjacency();
  mesh.Quadrics = std::move(data.quadrics);
  mesh.ComputeOrientation();
  return mesh;
}

ColumnMeshData ColumnMesh::Export(const std::vector<uint8_t>* keepColumns, std::vector<int32_t>* nodeMap) const
{
  ColumnMeshData data;
  data.layers = this->LayerCount;
  const std::size_t interfaces = static_cast<std::size_t>(this->LayerCount) + 1;
  std::vector<int32_t> map(this->Topology.size(), -1);
  for (std::size_t c = 0; c < this->Corners.size(); ++c)
  {
    if (!this->ColumnAlive[c] || (keepColumns && !(*keepColumns)[c]))
    {
      continue;
    }
    std::array<int32_t, 4> quad;
    for (int q = 0; q < 4; ++q)
    {
      const int32_t node = this->Corners[c][q];
      if (map[node] < 0)
      {
        map[node] = static_cast<int32_t>(data.topology.size());
        data.topology.push_back(this->Topology[node]);
        const std::size_t first = static_cast<std::size_t>(node) * interfaces;
        data.positions.insert(data.positions.end(), this->Positions.begin() + first * 3,
          this->Positions.begin() + (first + interfaces) * 3);
        data.quadrics.insert(
          data.quadrics.end(), this->Quadrics.begin() + first, this->Quadrics.begin() + first + interfaces);
      }
      quad[q] = map[node];
    }
    data.corners.push_back(quad);
    data.origin.push_back(this->Origin[c]);
    const auto cells = this->ActiveCells.begin() + c * static_cast<std::size_t>(this->LayerCount);
    data.activeCells.insert(data.activeCells.end(), cells, cells + this->LayerCount);
  }
  if (nodeMap)
  {
    *nodeMap = std::move(map);
  }
  return data;
}

void ColumnMesh::BuildAdjacency()
{
  const std::size_t nodes = this->Topology.size();
  this->NodeAlive.assign(nodes, 1);
  this->ColumnAlive.assign(this->Corners.size(), 1);
  this->Locked.assign(this->Corners.size(), 0);
  this->AliveColumnCount = static_cast<int64_t>(this->Corners.size());
  this->ColumnsOfNode.assign(nodes, {});
  for (std::size_t c = 0; c < this->Corners.size(); ++c)
  {
    for (int32_t node : this->Corners[c])
    {
      this->ColumnsOfNode[node].push_back(static_cast<int32_t>(c));
    }
  }
}

void ColumnMesh::BuildAdjacencyAndQuadrics()
{
  const std::size_t nodes = this->Topology.size();
  const int32_t interfaces = this->LayerCount + 1;
  this->BuildAdjacency();
  this->Quadrics.assign(nodes * static_cast<std::size_t>(interfaces), Quadric());
  glm::dvec3 normal;
  double d;
  for (int32_t c = 0; c < static_cast<int32_t>(this->Corners.size()); ++c)
  {
    const auto& q = this->Corners[c];
    for (int32_t k = 0; k < this->LayerCount; ++k)
    {
      if (!this->IsCellActive(c, k))
      {
        continue;
      }
      // Type 1: top and bottom faces.
      for (int32_t level : { k, k + 1 })
      {
        if (Quadric::PlaneOfQuad(this->Position(q[0], level), this->Position(q[1], level), this->Position(q[2], level),
              this->Position(q[3], level), normal, d))
        {
          const Quadric plane = Quadric::FromPlane(normal, d, 1.0);
          for (int32_t node : q)
          {
            this->NodeQuadric(node, level) += plane;
          }
        }
      }
      // Types 2, 3, 4: external side faces, heavily weighted.
      for (int e = 0; e < 4; ++e)
      {
        const int32_t a = q[e], b = q[(e + 1) % 4];
        int32_t across = -1;
        for (int32_t other : this->ColumnsOfNode[a])
        {
          if (other == c)
          {
            continue;
          }
          const auto& o = this->Corners[other];
          for (int f = 0; f < 4; ++f)
          {
            if (o[f] == b && o[(f + 1) % 4] == a)
            {
              across = other;
            }
          }
        }
        if (across >= 0 && this->IsCellActive(across, k))
        {
          continue; // internal face
        }
        if (Quadric::PlaneOfQuad(this->Position(a, k), this->Position(b, k), this->Position(b, k + 1),
              this->Position(a, k + 1), normal, d))
        {
          const Quadric plane = Quadric::FromPlane(normal, d, SideWeight);
          this->NodeQuadric(a, k) += plane;
          this->NodeQuadric(b, k) += plane;
          this->NodeQuadric(a, k + 1) += plane;
          this->NodeQuadric(b, k + 1) += plane;
        }
      }
    }
  }
  (void)interfaces;
  this->ComputeOrientation();
}

double ColumnMesh::MergeNodes(const std::vector<int32_t>& into)
{
  const int32_t nodes = this->NodeCount();
  if (static_cast<int32_t>(into.size()) != nodes)
  {
    throw std::logic_error("column mesh: a merge map must name every node");
  }
  // Check first, so that a refused merge changes nothing.
  std::vector<std::vector<int32_t>> groups(static_cast<std::size_t>(nodes));
  for (int32_t n = 0; n < nodes; ++n)
  {
    const int32_t to = into[n];
    if (to == n)
    {
      continue;
    }
    if (to < 0 || to >= nodes || into[to] != to || !this->NodeAlive[n] || !this->NodeAlive[to])
    {
      throw std::logic_error("column mesh: a merge map must send live nodes to live nodes that stay");
    }
    for (int32_t node : { n, to })
    {
      for (int32_t column : this->ColumnsOfNode[node])
      {
        if (this->Locked[column])
        {
          throw std::logic_error("column mesh: a locked column's node cannot merge");
        }
      }
    }
    groups[to].push_back(n);
  }
  for (int32_t c = 0; c < this->ColumnSlots(); ++c)
  {
    const auto& q = this->Corners[c];
    for (int a = 0; this->ColumnAlive[c] && a < 4; ++a)
    {
      for (int b = a + 1; b < 4; ++b)
      {
        if (into[q[a]] == into[q[b]])
        {
          throw std::logic_error("column mesh: a merge would give a column one node twice");
        }
      }
    }
  }
  double largest = 0;
  for (int32_t to = 0; to < nodes; ++to)
  {
    std::vector<int32_t>& group = groups[to];
    if (group.empty())
    {
      continue;
    }
    group.push_back(to);
    for (int32_t k = 0; k <= this->LayerCount; ++k)
    {
      glm::dvec3 mean(0.0);
      for (int32_t n : group)
      {
        mean += this->Position(n, k) / static_cast<double>(group.size());
      }
      for (int32_t n : group)
      {
        largest = std::max(largest, glm::length(this->Position(n, k) - mean));
      }
      this->SetPosition(to, k, mean);
      for (int32_t n : group)
      {
        if (n != to)
        {
          this->NodeQuadric(to, k) += this->NodeQuadric(n, k);
        }
      }
    }
    for (int32_t n : group)
    {
      if (n != to)
      {
        this->NodeAlive[n] = 0;
        auto& columns = this->ColumnsOfNode[to];
        columns.insert(columns.end(), this->ColumnsOfNode[n].begin(), this->ColumnsOfNode[n].end());
        this->ColumnsOfNode[n].clear();
      }
    }
  }
  for (auto& q : this->Corners)
  {
    for (int32_t& node : q)
    {
      node = into[node];
    }
  }
  return largest;
}

void ColumnMesh::ComputeOrientation()
{
  double area = 0;
  for (std::size_t c = 0; c < this->Corners.size(); ++c)
  {
    const auto& q = this->Corners[c];
    for (int e = 0; e < 4; ++e)
    {
      const glm::dvec3 a = this->Position(q[e], 0), b = this->Position(q[(e + 1) % 4], 0);
      area += a.x * b.y - b.x * a.y;
    }
  }
  this->OrientationSign = area >= 0 ? 1 : -1;
}

void ColumnMesh::Neighbours(int32_t node, std::vector<int32_t>& nodes, std::vector<uint8_t>& boundary) const
{
  nodes.clear();
  boundary.clear();
  for (int32_t column : this->ColumnsOfNode[node])
  {
    const auto& q = this->Corners[column];
    const int at = static_cast<int>(std::find(q.begin(), q.end(), node) - q.begin());
    for (int32_t other : { q[(at + 1) % 4], q[(at + 3) % 4] })
    {
      const auto found = std::find(nodes.begin(), nodes.end(), other);
      if (found == nodes.end())
      {
        nodes.push_back(other);
        boundary.push_back(1);
      }
      else
      {
        boundary[found - nodes.begin()] = 0; // a second column on this edge
      }
    }
  }
}

int ColumnMesh::LateralValence(int32_t node) const
{
  // Distinct neighbours, counted without building lists (a node has few columns).
  const auto& columns = this->ColumnsOfNode[node];
  int valence = 0;
  for (std::size_t c = 0; c < columns.size(); ++c)
  {
    const auto& q = this->Corners[columns[c]];
    const int at = static_cast<int>(std::find(q.begin(), q.end(), node) - q.begin());
    for (int32_t other : { q[(at + 1) % 4], q[(at + 3) % 4] })
    {
      bool seen = false;
      for (std::size_t d = 0; d < c && !seen; ++d)
      {
        const auto& o = this->Corners[columns[d]];
        seen = std::find(o.begin(), o.end(), other) != o.end();
      }
      valence += seen ? 0 : 1;
    }
  }
  return valence;
}

bool ColumnMesh::IsBoundaryNode(int32_t node) const
{
  // A node is on the boundary when some edge at it lies in one column only. Its columns
  // are few: count each edge's columns in place rather than build the neighbour lists.
  const auto& columns = this->ColumnsOfNode[node];
  for (int32_t column : columns)
  {
    const auto& q = this->Corners[column];
    const int at = static_cast<int>(std::find(q.begin(), q.end(), node) - q.begin());
    for (int32_t other : { q[(at + 1) % 4], q[(at + 3) % 4] })
    {
      int shared = 0;
      for (int32_t second : columns)
      {
        const auto& o = this->Corners[second];
        shared += (o[0] == other) | (o[1] == other) | (o[2] == other) | (o[3] == other);
      }
      if (shared == 1)
      {
        return true;
      }
    }
  }
  return false;
}

int64_t ColumnMesh::ConnectedParts() const
{
  std::vector<int32_t> parent(this->Corners.size());
  for (std::size_t c = 0; c < parent.size(); ++c)
  {
    parent[c] = static_cast<int32_t>(c);
  }
  auto root = [&](int32_t c) {
    while (parent[c] != c)
    {
      c = parent[c] = parent[parent[c]];
    }
    return c;
  };
  for (std::size_t node = 0; node < this->ColumnsOfNode.size(); ++node)
  {
    const auto& columns = this->ColumnsOfNode[node];
    for (std::size_t a = 0; a < columns.size(); ++a)
    {
      for (std::size_t b = a + 1; b < columns.size(); ++b)
      {
        // Joined if they share an edge (two nodes), not where they only touch at a corner.
        const auto& qa = this->Corners[columns[a]];
        const auto& qb = this->Corners[columns[b]];
        int shared = 0;
        for (int32_t n : qa)
        {
          shared += std::find(qb.begin(), qb.end(), n) != qb.end() ? 1 : 0;
        }
        if (shared >= 2)
        {
          parent[root(columns[a])] = root(columns[b]);
        }
      }
    }
  }
  int64_t parts = 0;
  for (std::size_t c = 0; c < parent.size(); ++c)
  {
    parts += this->ColumnAlive[c] && root(static_cast<int32_t>(c)) == static_cast<int32_t>(c) ? 1 : 0;
  }
  return parts;
}

bool ColumnMesh::IsBoundaryEdge(int32_t column, int corner) const
{
  const auto& q = this->Corners[column];
  const int32_t a = q[corner], b = q[(corner + 1) % 4];
  for (int32_t other : this->ColumnsOfNode[a])
  {
    if (other == column)
    {
      continue;
    }
    const auto& o = this->Corners[other];
    for (int f = 0; f < 4; ++f)
    {
      if (o[f] == b && o[(f + 1) % 4] == a)
      {
        return false;
      }
    }
  }
  return true;
}

} // namespace resmr

namespace resmr
{

HexMesh ToHexMesh(const ColumnMesh& mesh)
{
  HexMesh out;
  const int32_t layers = mesh.Layers();
  const int32_t interfaces = layers + 1;
  out.layers = layers;
  std::vector<int64_t> firstPoint(static_cast<std::size_t>(mesh.NodeCount()), -1);
  int64_t points = 0;
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    if (mesh.IsNodeAlive(node) && !mesh.NodeColumns(node).empty())
    {
      firstPoint[node] = points;
      points += interfaces;
      for (int32_t k = 0; k < interfaces; ++k)
      {
        const glm::dvec3 p = mesh.Position(node, k);
        out.points.insert(out.points.end(), { p.x, p.y, p.z });
        const auto& t = mesh.TopologicalCoordinate(node);
        out.topology.insert(out.topology.end(), { t[0], t[1], static_cast<double>(k) });
      }
    }
  }
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (!mesh.IsColumnAlive(c))
    {
      continue;
    }
    const auto& q = mesh.ColumnCorners(c);
    for (int32_t k = 0; k < layers; ++k)
    {
      std::array<int64_t, 8> cell;
      for (int i = 0; i < 4; ++i)
      {
        cell[i] = firstPoint[q[i]] + k;
        cell[i + 4] = firstPoint[q[i]] + k + 1;
      }
      out.cells.push_back(cell);
      out.active.push_back(mesh.IsCellActive(c, k) ? 1 : 0);
    }
  }
  return out;
}

} // namespace resmr
