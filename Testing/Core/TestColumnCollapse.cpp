// Unit tests of the column-collapse simplification (paper Sec. 4.1): quadrics; each operator
// on small hand-built meshes (resulting topology, quadrics, topological coordinates); faults
// splitting nodes; invariants after random simplification of a real model (hexahedral
// columns of nk cells, no inverted cell, no doublet, coordinates inside the original ranges);
// determinism for a seed; bad input.
#include "ColumnCollapse.h"
#include "ColumnMesh.h"
#include "CoreTesting.h"
#include "CornerPointGeometry.h"
#include "CornerPointModel.h"
#include "EclipseGrid.h"
#include "FaultWelding.h"
#include "MeshQuality.h"
#include "SyntheticReservoir.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
std::string DataDirectory;

/// An n x m grid of columns, `layers` flat layers of thickness 1 (depth k), unit cells in
/// x and y; every cell active.
resmr::ColumnMesh Grid(int n, int m, int layers)
{
  std::vector<double> positions;
  std::vector<std::array<double, 2>> topology;
  for (int j = 0; j <= m; ++j)
  {
    for (int i = 0; i <= n; ++i)
    {
      topology.push_back({ double(i), double(j) });
      for (int k = 0; k <= layers; ++k)
      {
        positions.insert(positions.end(), { double(i), double(j), double(k) });
      }
    }
  }
  std::vector<std::array<int32_t, 4>> corners;
  for (int j = 0; j < m; ++j)
  {
    for (int i = 0; i < n; ++i)
    {
      const int32_t p = j * (n + 1) + i;
      corners.push_back({ p, p + 1, p + n + 2, p + n + 1 });
    }
  }
  return resmr::ColumnMesh::FromParts(
    layers, positions, topology, corners, std::vector<uint8_t>(corners.size() * layers, 1));
}

void TestQuadric()
{
  // The plane z = 5 (normal (0,0,1), d = -5) weighted 3: error 3 d^2; optimal z 5.
  const resmr::Quadric q = resmr::Quadric::FromPlane({ 0, 0, 1 }, -5, 3);
  CHECK(std::fabs(q.Error({ 1, 2, 7 }) - 12) < 1e-12);
  CHECK(std::fabs(q.OptimalZ(4, -3, 0) - 5) < 1e-12);
  resmr::Quadric sum = q;
  sum += resmr::Quadric::FromPlane({ 0, 0, 1 }, -7, 1);
  CHECK(std::fabs(sum.OptimalZ(0, 0, 0) - 5.5) < 1e-12); // weighted mean of 5 (x3) and 7
  // No plane constrains z: the fallback.
  CHECK(resmr::Quadric::FromPlane({ 1, 0, 0 }, 0, 1).OptimalZ(0, 0, 42) == 42);
  glm::dvec3 normal;
  double d;
  CHECK(!resmr::Quadric::PlaneOfQuad({ 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 }, normal, d));
}

void TestQuadricsOfFaces()
{
  // One flat layer: a corner node of the 2x2 grid lies on the top plane (weight 1), the two
  // grid-limit side planes (type 4, weight 10,000): its quadric is 0 at its own position and
  // grows 10,000 x d^2 moving sideways, 1 x d^2 (per top face) moving up.
  resmr::ColumnMesh mesh = Grid(2, 2, 1);
  const resmr::Quadric& corner = mesh.NodeQuadric(0, 0);
  CHECK(corner.Error({ 0, 0, 0 }) < 1e-9);
  CHECK(std::fabs(corner.Error({ -1, 0, 0 }) - 10000) < 1e-6);
  CHECK(std::fabs(corner.Error({ 0, 0, -1 }) - 1) < 1e-9);
  // The centre node touches four top faces and no side face.
  const resmr::Quadric& centre = mesh.NodeQuadric(4, 0);
  CHECK(std::fabs(centre.Error({ 1, 1, -1 }) - 4) < 1e-9);
  CHECK(centre.Error({ 5, 5, 0 }) < 1e-9);
  // An inactive cell beside an active one makes their shared side face external (type 2):
  // in a 2 x 1 row whose right cell is inactive, the middle nodes get the side plane x = 1.
  resmr::ColumnMesh row = resmr::ColumnMesh::FromParts(1,
    { 0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 2, 0, 0, 2, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 0, 1, 1, 1, 2, 1, 0, 2, 1, 1 },
    { { 0, 0 }, { 1, 0 }, { 2, 0 }, { 0, 1 }, { 1, 1 }, { 2, 1 } }, { { 0, 1, 4, 3 }, { 1, 2, 5, 4 } }, { 1, 0 });
  CHECK(std::fabs(row.NodeQuadric(1, 0).Error({ 1.5, 0, 0 }) - 0.25 * 10000) < 1e-6);
  CHECK(row.NodeQuadric(2, 0).Error({ 5, 5, 5 }) == 0); // touches only the inactive cell
  CHECK(mesh.IsBoundaryNode(0) && !mesh.IsBoundaryNode(4));
  CHECK(mesh.LateralValence(4) == 4 && mesh.LateralValence(0) == 2 && mesh.LateralValence(1) == 3);
}

void TestInternalCollapse()
{
  // 3x3 columns, 2 layers: the centre column is internal. Its diagonal with the lowest
  // valence (all 4 here, tie; new valences tie too) is merged; the two other corners stay
  // and lose one edge each.
  resmr::ColumnMesh mesh = Grid(3, 3, 2);
  resmr::ColumnCollapse collapse(mesh, 7);
  resmr::ColumnCollapse::Plan plan;
  CHECK(collapse.PlanColumn(4, plan));
  CHECK(plan.op == resmr::ColumnCollapse::Internal);
  CHECK(plan.mergedCount == 2 && plan.keptCount == 2);
  const int32_t a = plan.merged[0], b = plan.merged[1];
  const resmr::Quadric qa = mesh.NodeQuadric(a, 1), qb = mesh.NodeQuadric(b, 1);
  const int valenceKept = mesh.LateralValence(plan.kept[0]);
  collapse.Perform(plan);
  CHECK(mesh.AliveColumns() == 8);
  CHECK(!mesh.IsColumnAlive(4));
  const int32_t survivor = mesh.IsNodeAlive(a) ? a : b;
  CHECK(mesh.IsNodeAlive(a) != mesh.IsNodeAlive(b));
  CHECK(mesh.LateralValence(plan.kept[0]) == valenceKept - 1);
  CHECK(mesh.LateralValence(survivor) == 4 + 4 - 2);
  // Quadrics add.
  resmr::Quadric sum = qa;
  sum += qb;
  for (int i = 0; i < 10; ++i)
  {
    CHECK(std::fabs(mesh.NodeQuadric(survivor, 1).q[i] - sum.q[i]) < 1e-9);
  }
  // Smoothed to the centre of its neighbours, on the flat layers, with the matching
  // topological coordinate.
  const glm::dvec3 p = mesh.Position(survivor, 1);
  CHECK(std::fabs(p.x - 1.5) < 1e-9 && std::fabs(p.y - 1.5) < 1e-9 && std::fabs(p.z - 1) < 1e-9);
  const auto& t = mesh.TopologicalCoordinate(survivor);
  CHECK(std::fabs(t[0] - 1.5) < 1e-9 && std::fabs(t[1] - 1.5) < 1e-9);
  CHECK(collapse.Report().operatorCounts[resmr::ColumnCollapse::Internal] == 1);
}

void TestBoundaryCornerAndFourBoundary()
{
  // Boundary collapse: the middle column of the bottom row has one boundary edge; the
  // survivor sits on the boundary node, so the outline does not move.
  {
    resmr::ColumnMesh mesh = Grid(3, 3, 1);
    resmr::ColumnCollapse collapse(mesh, 1);
    resmr::ColumnCollapse::Plan plan;
    CHECK(collapse.PlanColumn(1, plan));
    CHECK(plan.op == resmr::ColumnCollapse::Boundary);
    CHECK(plan.placeAt >= 0 && mesh.IsBoundaryNode(plan.placeAt));
    const glm::dvec3 before = mesh.Position(plan.placeAt, 0);
    collapse.Perform(plan);
    CHECK(mesh.AliveColumns() == 8);
    CHECK(glm::length(mesh.Position(plan.placeAt, 0) - before) == 0);
    CHECK(mesh.IsBoundaryNode(plan.placeAt));
  }
  // Corner collapse: the three nodes on the two boundary edges become one, at the position
  // of least error among them; the inner node stays.
  {
    resmr::ColumnMesh mesh = Grid(3, 3, 1);
    resmr::ColumnCollapse collapse(mesh, 1);
    resmr::ColumnCollapse::Plan plan;
    CHECK(collapse.PlanColumn(0, plan));
    CHECK(plan.op == resmr::ColumnCollapse::Corner);
    CHECK(plan.mergedCount == 3 && plan.keptCount == 1 && plan.kept[0] == 5);
    collapse.Perform(plan);
    CHECK(mesh.AliveColumns() == 8);
    int alive = 0;
    for (int i = 0; i < 3; ++i)
    {
      alive += mesh.IsNodeAlive(plan.merged[i]);
    }
    CHECK(alive == 1);
  }
  // Four boundary nodes, one internal edge: the end column of a 3 x 1 row.
  {
    resmr::ColumnMesh mesh = Grid(3, 1, 2);
    resmr::ColumnCollapse collapse(mesh, 1);
    resmr::ColumnCollapse::Plan plan;
    CHECK(collapse.PlanColumn(0, plan));
    CHECK(plan.op == resmr::ColumnCollapse::FourBoundary);
    CHECK(plan.mergedCount == 3 && plan.keptCount == 1);
    CHECK(plan.kept[0] == 1 || plan.kept[0] == 5); // a node of the internal edge stays
    collapse.Perform(plan);
    CHECK(mesh.AliveColumns() == 2);
    // The middle column of the row has two opposite boundary edges, which none of the
    // paper's operators removes: the strip collapse turns each boundary edge into one of its
    // nodes, left where it was, and the end columns become neighbours.
    resmr::ColumnMesh row = Grid(3, 1, 1);
    resmr::ColumnCollapse rowCollapse(row, 1);
    CHECK(rowCollapse.PlanColumn(1, plan));
    CHECK(plan.op == resmr::ColumnCollapse::Strip && plan.keptCount == 0);
    const glm::dvec3 first = row.Position(plan.placeAt, 1), second = row.Position(plan.placeSecondAt, 1);
    rowCollapse.Perform(plan);
    CHECK(row.AliveColumns() == 2 && !row.IsColumnAlive(1));
    CHECK(row.Position(plan.placeAt, 1) == first && row.Position(plan.placeSecondAt, 1) == second);
    CHECK(!row.IsBoundaryEdge(0, 1) && !row.IsBoundaryEdge(2, 3)); // the ends now share an edge
    CHECK(rowCollapse.Report().operatorCounts[resmr::ColumnCollapse::Strip] == 1);
    CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(row), row.Orientation()).inverted == 0);
  }
  // A single column cannot collapse; simplification leaves it unchanged.
  {
    resmr::ColumnMesh mesh = Grid(1, 1, 3);
    resmr::ColumnCollapse collapse(mesh, 1);
    const resmr::SimplifyReport report = collapse.Simplify(0);
    CHECK(mesh.AliveColumns() == 1 && !report.reachedTarget && report.collapses == 0);
  }
}

void TestRandomSimplificationInvariants()
{
  // A 12 x 10 grid with 3 layers, simplified to a quarter: counts, no doublet left, every
  // column four distinct nodes, valid cells, coordinates in range.
  resmr::ColumnMesh mesh = Grid(12, 10, 3);
  resmr::ColumnCollapse collapse(mesh, 3);
  const resmr::SimplifyReport report = collapse.Simplify(30);
  CHECK(report.reachedTarget);
  CHECK(mesh.AliveColumns() <= 30);
  CHECK(report.collapses + report.doublets == 120 - mesh.AliveColumns());
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    if (mesh.IsNodeAlive(node) && !mesh.NodeColumns(node).empty() && !mesh.IsBoundaryNode(node))
    {
      CHECK(mesh.LateralValence(node) >= 3);
    }
  }
  const resmr::HexMesh hex = resmr::ToHexMesh(mesh);
  CHECK(hex.CellCount() == mesh.AliveColumns() * 3);
  CHECK(resmr::MeasureHexahedra(hex, mesh.Orientation()).inverted == 0);
  for (std::size_t p = 0; p < hex.topology.size(); p += 3)
  {
    CHECK(hex.topology[p] >= 0 && hex.topology[p] <= 12 && hex.topology[p + 1] >= 0 && hex.topology[p + 1] <= 10);
  }
}

/// Sum of the quadrics of the live nodes at an interface: collapses only add quadrics
/// together, so it never changes.
resmr::Quadric TotalQuadric(const resmr::ColumnMesh& mesh, int32_t interface)
{
  resmr::Quadric sum;
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    if (mesh.IsNodeAlive(node) && !mesh.NodeColumns(node).empty())
    {
      sum += mesh.NodeQuadric(node, interface);
    }
  }
  return sum;
}

bool SameQuadric(const resmr::Quadric& a, const resmr::Quadric& b)
{
  for (int i = 0; i < 10; ++i)
  {
    if (std::fabs(a.q[i] - b.q[i]) > 1e-9 * (1 + std::fabs(a.q[i])))
    {
      return false;
    }
  }
  return true;
}

void TestDoubletCascade()
{
  // A 6 x 6 grid (node (i, j) = 7j + i, column (i, j) = 6j + i). Three internal collapses,
  // each keeping node A = (2, 2), bring it and its neighbour B = (3, 2) down to lateral
  // valence 2 and 3; the third leaves A between two columns sharing two consecutive edges
  // (Fig. 7). Its removal takes one valence from B, a second doublet, removed in turn.
  resmr::ColumnMesh mesh = Grid(6, 6, 2);
  const resmr::Quadric total0 = TotalQuadric(mesh, 0), total2 = TotalQuadric(mesh, 2);
  resmr::ColumnCollapse collapse(mesh, 1);
  auto node = [](int i, int j) { return 7 * j + i; };
  auto internal = [&](int column, int32_t a, int32_t b, int32_t keepA, int32_t keepB) {
    resmr::ColumnCollapse::Plan plan;
    plan.column = column;
    plan.op = resmr::ColumnCollapse::Internal;
    plan.mergedCount = 2;
    plan.merged[0] = a;
    plan.merged[1] = b;
    plan.keptCount = 2;
    plan.kept[0] = keepA;
    plan.kept[1] = keepB;
    const int64_t before = mesh.AliveColumns();
    collapse.Perform(plan);
    CHECK(mesh.AliveColumns() < before);
  };
  const int32_t A = node(2, 2), B = node(3, 2);
  internal(6 * 1 + 3, node(3, 1), node(4, 2), B, node(4, 1)); // B: valence 3
  CHECK(mesh.LateralValence(B) == 3 && collapse.Report().doublets == 0);
  internal(6 * 1 + 1, node(2, 1), node(1, 2), A, node(1, 1)); // A: valence 3
  CHECK(mesh.LateralValence(A) == 3 && collapse.Report().doublets == 0);
  internal(6 * 2 + 1, node(2, 1), node(2, 3), A, node(1, 3)); // A: a doublet, then B
  const resmr::SimplifyReport& report = collapse.Report();
  CHECK(report.collapses == 3);
  std::printf("doublet test: %lld doublets, %lld fold-over, %lld inverted, %lld topology rejections\n",
    (long long)report.doublets, (long long)report.rejectedFoldOver, (long long)report.rejectedInverted,
    (long long)report.rejectedTopology);
  CHECK(report.doublets >= 2);
  CHECK(report.operatorCounts[resmr::ColumnCollapse::Doublet] == report.doublets);
  CHECK(mesh.AliveColumns() == 36 - 3 - report.doublets);
  CHECK(!mesh.IsNodeAlive(A) || mesh.NodeColumns(A).empty());
  CHECK(!mesh.IsNodeAlive(B) || mesh.NodeColumns(B).empty());
  // No doublet is left, every column still has four distinct nodes, and no quadric was lost
  // (a doublet's node adds its quadric to the one it moves onto).
  for (int32_t n = 0; n < mesh.NodeCount(); ++n)
  {
    if (mesh.IsNodeAlive(n) && !mesh.NodeColumns(n).empty() && !mesh.IsBoundaryNode(n))
    {
      CHECK(mesh.LateralValence(n) >= 3);
    }
  }
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (mesh.IsColumnAlive(c))
    {
      auto q = mesh.ColumnCorners(c);
      std::sort(q.begin(), q.end());
      CHECK(std::adjacent_find(q.begin(), q.end()) == q.end());
    }
  }
  CHECK(SameQuadric(TotalQuadric(mesh, 0), total0) && SameQuadric(TotalQuadric(mesh, 2), total2));
  // Topological coordinates of the live nodes stay inside the grid.
  for (int32_t n = 0; n < mesh.NodeCount(); ++n)
  {
    if (mesh.IsNodeAlive(n) && !mesh.NodeColumns(n).empty())
    {
      const auto& t = mesh.TopologicalCoordinate(n);
      CHECK(t[0] >= 0 && t[0] <= 6 && t[1] >= 0 && t[1] <= 6);
    }
  }
  CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation()).inverted == 0);
}

void TestFault()
{
  // A 4 x 3 x 2 grid of 10 m cells whose columns i >= 2 are thrown down 5 m: the pillars at
  // i = 2 carry two nodes each (one a side), the fault edges are boundaries of both sides,
  // and fault nodes get the side planes (type 3) with the weight 10,000.
  const std::array<int64_t, 3> dims = { 4, 3, 2 };
  auto corners = [](int64_t i, int64_t j, int64_t k, double out[8][3]) {
    const double throwDown = i >= 2 ? 5.0 : 0.0;
    for (int c = 0; c < 8; ++c)
    {
      out[c][0] = 10.0 * static_cast<double>(i + (c & 1));
      out[c][1] = 10.0 * static_cast<double>(j + ((c >> 1) & 1));
      out[c][2] = 1000.0 + throwDown + static_cast<double>(k + (c >> 2));
    }
  };
  resmr::ColumnMesh mesh = resmr::ColumnMesh::FromCells(dims, corners, std::vector<bool>(24, true), 0, 4, 0, 3);
  CHECK(mesh.AliveColumns() == 12);
  CHECK(mesh.NodeCount() == 5 * 4 + 4); // the four fault pillars split
  // Column (1, 1) = 5 has the fault on its edge from corner 1 to corner 2; column (2, 1) = 6
  // across it shares no node with it.
  const auto& left = mesh.ColumnCorners(5);
  const auto& right = mesh.ColumnCorners(6);
  for (int32_t a : left)
  {
    CHECK(std::find(right.begin(), right.end(), a) == right.end());
  }
  CHECK(mesh.IsBoundaryEdge(5, 1) && mesh.IsBoundaryEdge(6, 3) && !mesh.IsBoundaryEdge(5, 0));
  CHECK(mesh.IsBoundaryNode(left[1]) && mesh.IsBoundaryNode(left[2]) && !mesh.IsBoundaryNode(left[0]));
  // The fault plane x = 20 is in the fault node's quadric, heavily weighted: 1 m off it
  // costs at least 10,000; 1 m up along it, a top face's weight.
  const glm::dvec3 onFault = mesh.Position(left[2], 1);
  CHECK(std::fabs(onFault.x - 20) < 1e-12 && std::fabs(onFault.z - 1001) < 1e-12);
  CHECK(mesh.NodeQuadric(left[2], 1).Error(onFault) < 1e-9);
  CHECK(mesh.NodeQuadric(left[2], 1).Error(onFault + glm::dvec3(1, 0, 0)) >= 10000 - 1e-6);
  CHECK(mesh.NodeQuadric(left[2], 1).Error(onFault + glm::dvec3(0, 0, 1)) < 10);
  // The collapse of column (1, 1) is a boundary collapse against the fault: the survivor is
  // a fault node, which stays where it was, and the other side is untouched.
  std::vector<glm::dvec3> rightSide;
  for (int32_t a : right)
  {
    rightSide.push_back(mesh.Position(a, 1));
  }
  resmr::ColumnCollapse collapse(mesh, 5);
  resmr::ColumnCollapse::Plan plan;
  CHECK(collapse.PlanColumn(5, plan));
  CHECK(plan.op == resmr::ColumnCollapse::Boundary);
  CHECK(plan.placeAt == left[1] || plan.placeAt == left[2]);
  const glm::dvec3 kept = mesh.Position(plan.placeAt, 2);
  collapse.Perform(plan);
  CHECK(mesh.AliveColumns() == 11 && !mesh.IsColumnAlive(5));
  CHECK(glm::length(mesh.Position(plan.placeAt, 2) - kept) == 0);
  CHECK(mesh.IsBoundaryNode(plan.placeAt));
  for (int i = 0; i < 4; ++i)
  {
    CHECK(mesh.Position(right[i], 1) == rightSide[i]);
  }
  // Simplified to 4 columns: still no node shared across the fault (x < 20 on one side,
  // >= 20 on the other, depths 5 m apart), and no inverted cell.
  collapse.Simplify(4);
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (!mesh.IsColumnAlive(c))
    {
      continue;
    }
    bool west = false, east = false;
    for (int32_t a : mesh.ColumnCorners(c))
    {
      const glm::dvec3 p = mesh.Position(a, 0);
      west = west || p.x < 20 - 1e-9;
      east = east || p.x > 20 + 1e-9;
    }
    CHECK(!(west && east));
  }
  CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation()).inverted == 0);
}

/// TestFault's grid: 4 x 3 x 2 cells of 10 m, columns i >= 2 thrown down 5 m.
resmr::ColumnMesh ThrownGrid()
{
  auto corners = [](int64_t i, int64_t j, int64_t k, double out[8][3]) {
    for (int c = 0; c < 8; ++c)
    {
      out[c][0] = 10.0 * static_cast<double>(i + (c & 1));
      out[c][1] = 10.0 * static_cast<double>(j + ((c >> 1) & 1));
      out[c][2] = 1000.0 + (i >= 2 ? 5.0 : 0.0) + static_cast<double>(k + (c >> 2));
    }
  };
  return resmr::ColumnMesh::FromCells({ 4, 3, 2 }, corners, std::vector<bool>(24, true), 0, 4, 0, 3);
}

void TestWeldFaults()
{
  // Welded: the four split pillars become one node each, at the mean of the two sides (2.5 m
  // from each), and the columns across the fault become neighbours.
  resmr::ColumnMesh mesh = ThrownGrid();
  const int32_t fault = mesh.ColumnCorners(5)[2]; // (1, 1)'s corner on pillar (2, 2), west side
  const glm::dvec3 west = mesh.Position(fault, 1);
  const resmr::FaultWeld weld = resmr::WeldFaults(mesh);
  CHECK(weld.edges == 3 && weld.nodes == 4);
  CHECK(std::fabs(weld.largestMove - 2.5) < 1e-9);
  CHECK(!mesh.IsBoundaryEdge(5, 1) && !mesh.IsBoundaryEdge(6, 3));
  CHECK(mesh.ColumnCorners(5)[1] == mesh.ColumnCorners(6)[0] && mesh.ColumnCorners(5)[2] == mesh.ColumnCorners(6)[3]);
  const int32_t joined = mesh.ColumnCorners(5)[2];
  CHECK(glm::length(mesh.Position(joined, 1) - (west + glm::dvec3(0, 0, 2.5))) < 1e-9);
  CHECK(mesh.NodeColumns(joined).size() == 4);
  CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation()).inverted == 0);
  int64_t boundaryNodes = 0;
  for (int32_t n = 0; n < mesh.NodeCount(); ++n)
  {
    boundaryNodes += mesh.IsNodeAlive(n) && mesh.IsBoundaryNode(n);
  }
  CHECK(boundaryNodes == 14); // the outline of a 4 x 3 grid only
  // A locked column keeps its nodes: the fault edges touching it stay apart, and so does a
  // pillar both of whose welded edges touch one.
  resmr::ColumnMesh locked = ThrownGrid();
  locked.SetLocked(1, true); // (1, 0), on pillars (2, 0) and (2, 1)
  const resmr::FaultWeld partial = resmr::WeldFaults(locked);
  CHECK(partial.edges == 1 && partial.nodes == 2);
  CHECK(locked.IsBoundaryEdge(1, 1) && locked.IsBoundaryEdge(5, 1) && !locked.IsBoundaryEdge(9, 1));
  // MergeNodes refuses, changing nothing, what would break the mesh.
  resmr::ColumnMesh grid = Grid(2, 1, 1);
  std::vector<int32_t> into(static_cast<std::size_t>(grid.NodeCount()));
  for (int32_t n = 0; n < grid.NodeCount(); ++n)
  {
    into[n] = n;
  }
  into[1] = 0; // two corners of column 0
  resmr_testing::ExpectError<std::logic_error>(
    "merge within a column", [&] { grid.MergeNodes(into); }, { "one node twice" });
  CHECK(grid.ColumnCorners(0)[1] == 1 && grid.IsNodeAlive(1));
  into[1] = 1;
  into[2] = 0; // nodes of columns 1 and 0 only, but column 1 is locked
  grid.SetLocked(1, true);
  resmr_testing::ExpectError<std::logic_error>(
    "merge into a locked column", [&] { grid.MergeNodes(into); }, { "locked" });
}

resmr::ColumnMesh Reek(std::vector<bool>& active, resmr::CornerPointGeometry*& geometryOut)
{
  static resmr::EclipseGrid grid =
    resmr::ReadEclipseGrid(DataDirectory + "/reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID");
  static resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(grid.deck, false);
  active.resize(static_cast<std::size_t>(geometry.CellCount()));
  for (int64_t c = 0; c < geometry.CellCount(); ++c)
  {
    active[c] = grid.IsActive(c);
  }
  geometryOut = &geometry;
  return resmr::ColumnMesh::FromCornerPoints(geometry, active);
}

void TestRealModel()
{
  std::vector<bool> active;
  resmr::CornerPointGeometry* geometry = nullptr;
  resmr::ColumnMesh mesh = Reek(active, geometry);
  const int64_t nx = geometry->Dims()[0], ny = geometry->Dims()[1], nz = geometry->Dims()[2];
  // Columns with an active cell, completed (Fig. 3).
  int64_t expected = 0;
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      bool any = false;
      for (int64_t k = 0; k < nz; ++k)
      {
        any = any || active[(k * ny + j) * nx + i];
      }
      expected += any;
    }
  }
  CHECK(mesh.AliveColumns() == expected);
  CHECK(mesh.Layers() == nz);
  // Faults split nodes: more nodes than pillars touched, and boundary edges inside the grid.
  CHECK(mesh.NodeCount() > (nx + 1) * (ny + 1) / 2);
  const resmr::HexMesh original = resmr::ToHexMesh(mesh);
  CHECK(resmr::MeasureHexahedra(original, mesh.Orientation()).inverted == 0);

  const int64_t before = mesh.AliveColumns();
  resmr::ColumnCollapse collapse(mesh, 11);
  const resmr::SimplifyReport report = collapse.Simplify(before / 2);
  std::printf(
    "Reek: %lld -> %lld columns, %lld collapses, %lld doublets, ops %lld/%lld/%lld/%lld, %lld fold-overs rejected\n",
    static_cast<long long>(before), static_cast<long long>(mesh.AliveColumns()),
    static_cast<long long>(report.collapses), static_cast<long long>(report.doublets),
    static_cast<long long>(report.operatorCounts[0]), static_cast<long long>(report.operatorCounts[1]),
    static_cast<long long>(report.operatorCounts[2]), static_cast<long long>(report.operatorCounts[3]),
    static_cast<long long>(report.rejectedFoldOver));
  CHECK(report.reachedTarget);
  const resmr::HexMesh simplified = resmr::ToHexMesh(mesh);
  const resmr::HexQuality quality = resmr::MeasureHexahedra(simplified, mesh.Orientation());
  CHECK(quality.inverted == 0);
  CHECK(simplified.CellCount() == mesh.AliveColumns() * nz);
  // Coordinates inside the original ranges; tk is the interface.
  for (int64_t p = 0; p < simplified.PointCount(); ++p)
  {
    const double* t = &simplified.topology[p * 3];
    CHECK(t[0] >= 0 && t[0] <= nx && t[1] >= 0 && t[1] <= ny && t[2] >= 0 && t[2] <= nz);
  }
  for (const auto& cell : simplified.cells)
  {
    for (int i = 0; i < 4; ++i)
    {
      CHECK(simplified.topology[cell[i + 4] * 3 + 2] == simplified.topology[cell[i] * 3 + 2] + 1);
    }
  }
  const resmr::BoundaryDistance distance = resmr::MeasureBoundaryDistance(original, simplified);
  std::printf("Reek at 50%%: min scaled Jacobian %.3f, boundary Hausdorff %.1f m (%.4f of the diagonal)\n",
    quality.minScaledJacobian, distance.hausdorff, distance.relative);
  CHECK(distance.relative < 0.05);
  CHECK(resmr::MeasureBoundaryDistance(original, original).hausdorff < 1e-6);

  // Deterministic for a seed; another seed, another mesh.
  auto run = [&](uint64_t seed) {
    std::vector<bool> flags;
    resmr::CornerPointGeometry* g = nullptr;
    resmr::ColumnMesh again = Reek(flags, g);
    resmr::ColumnCollapse c(again, seed);
    c.Simplify(before / 2);
    return resmr::ToHexMesh(again).points;
  };
  CHECK(run(11) == simplified.points);
  CHECK(run(12) != simplified.points);

  // Down to 1% of the columns: the paper's operators alone stall near 9% (slivers fanned
  // around fault nodes); rotations and smoothing must carry it through, still valid.
  std::vector<bool> flags;
  resmr::CornerPointGeometry* g = nullptr;
  resmr::ColumnMesh small = Reek(flags, g);
  resmr::ColumnCollapse down(small, 1);
  const resmr::SimplifyReport smallReport = down.Simplify(before / 100);
  std::printf("Reek at 1%%: %lld columns, %lld rotations, %lld relaxations\n",
    static_cast<long long>(small.AliveColumns()), static_cast<long long>(smallReport.rotations),
    static_cast<long long>(smallReport.relaxations));
  CHECK(smallReport.reachedTarget);
  CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(small), small.Orientation()).inverted == 0);
  // The greedy selection unblocks the same way.
  resmr::ColumnMesh greedyMesh = Reek(flags, g);
  resmr::ColumnCollapse greedy(greedyMesh, 1);
  CHECK(greedy.SimplifyGreedy(before / 100).reachedTarget);
  CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(greedyMesh), greedyMesh.Orientation()).inverted == 0);
}

void TestLockedColumns()
{
  // Locked columns survive with their nodes where they were, however far the rest goes.
  resmr::ColumnMesh mesh = Grid(8, 8, 2);
  std::vector<int32_t> locked;
  for (int32_t c = 0; c < 8; ++c)
  {
    locked.push_back(c);         // the bottom row
    locked.push_back(8 * 4 + c); // a row across the middle
  }
  for (int32_t c : locked)
  {
    mesh.SetLocked(c, true);
  }
  std::vector<std::array<int32_t, 4>> corners;
  std::vector<glm::dvec3> positions;
  for (int32_t c : locked)
  {
    corners.push_back(mesh.ColumnCorners(c));
    for (int32_t node : mesh.ColumnCorners(c))
    {
      for (int32_t k = 0; k <= 2; ++k)
      {
        positions.push_back(mesh.Position(node, k));
      }
    }
  }
  resmr::ColumnCollapse collapse(mesh, 5);
  const resmr::SimplifyReport report = collapse.Simplify(20);
  CHECK(mesh.AliveColumns() < 40);
  CHECK(report.collapses > 20);
  std::size_t at = 0;
  for (std::size_t i = 0; i < locked.size(); ++i)
  {
    CHECK(mesh.IsColumnAlive(locked[i]));
    CHECK(mesh.ColumnCorners(locked[i]) == corners[i]);
    for (int32_t node : corners[i])
    {
      for (int32_t k = 0; k <= 2; ++k)
      {
        CHECK(mesh.Position(node, k) == positions[at++]);
      }
    }
  }
  CHECK(resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation()).inverted == 0);
}

void TestEdgeRotation()
{
  // Two columns splitting a hexagon along v0-v3, with corners of 14 degrees (a scaled
  // Jacobian of 0.24); split along v1-v4 no corner is under 59 degrees (0.86), and along
  // v2-v5 it would stay 0.24.
  const double hexagon[6][2] = { { 3, 1 }, { 2, 2 }, { -1, 3 }, { -3, -1 }, { 1, -2 }, { 2, -2 } };
  std::vector<double> positions;
  std::vector<std::array<double, 2>> topology;
  for (const auto& p : hexagon)
  {
    topology.push_back({ p[0], p[1] });
    positions.insert(positions.end(), { p[0], p[1], 0.0, p[0], p[1], 1.0 });
  }
  resmr::ColumnMesh mesh =
    resmr::ColumnMesh::FromParts(1, positions, topology, { { 0, 1, 2, 3 }, { 3, 4, 5, 0 } }, { 1, 0 });
  const double before = resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation()).minScaledJacobian;
  CHECK(mesh.LateralValence(0) == 3 && mesh.LateralValence(3) == 3);
  resmr::ColumnCollapse collapse(mesh, 1);
  CHECK(collapse.RotateEdges() == 1);
  CHECK(collapse.RotateEdges() == 0); // turning back would be worse
  // v0 and v3 no longer share an edge; the new diagonal's ends gained one.
  CHECK(mesh.LateralValence(0) == 2 && mesh.LateralValence(3) == 2);
  CHECK(mesh.LateralValence(1) == 3 && mesh.LateralValence(4) == 3);
  for (int32_t c = 0; c < 2; ++c)
  {
    auto q = mesh.ColumnCorners(c);
    std::sort(q.begin(), q.end());
    CHECK(std::adjacent_find(q.begin(), q.end()) == q.end());
    CHECK(mesh.IsCellActive(c, 0)); // active where either column was
  }
  for (int32_t node = 0; node < 6; ++node)
  {
    CHECK(mesh.Position(node, 0) == glm::dvec3(hexagon[node][0], hexagon[node][1], 0.0));
  }
  const resmr::HexQuality after = resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation());
  std::printf("Edge rotation: min scaled Jacobian %.3f -> %.3f\n", before, after.minScaledJacobian);
  CHECK(std::fabs(before - 0.2425) < 1e-3);
  CHECK(after.inverted == 0 && std::fabs(after.minScaledJacobian - 0.8575) < 1e-3);
}

/// Alive nodes (with columns) at y = `y` in interface 0.
int NodesAtY(const resmr::ColumnMesh& mesh, double y)
{
  int count = 0;
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    count += mesh.IsNodeAlive(node) && !mesh.NodeColumns(node).empty() && mesh.Position(node, 0).y == y ? 1 : 0;
  }
  return count;
}

bool AllColumnsValid(const resmr::ColumnMesh& mesh)
{
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (!mesh.IsColumnAlive(c))
    {
      continue;
    }
    auto q = mesh.ColumnCorners(c);
    for (int32_t node : q)
    {
      const auto& columns = mesh.NodeColumns(node);
      if (!mesh.IsNodeAlive(node) || std::find(columns.begin(), columns.end(), c) == columns.end())
      {
        return false;
      }
    }
    std::sort(q.begin(), q.end());
    if (std::adjacent_find(q.begin(), q.end()) != q.end())
    {
      return false;
    }
  }
  return resmr::MeasureHexahedra(resmr::ToHexMesh(mesh), mesh.Orientation()).inverted == 0;
}

void TestChordCollapse()
{
  // 4 x 3 columns: the chord through column (1, 1) across its bottom and top edges is the
  // column of cells i = 1, from the boundary at y = 0 to the boundary at y = 3.
  resmr::ColumnMesh mesh = Grid(4, 3, 1);
  const resmr::Quadric bottomLeft = mesh.NodeQuadric(1, 0), bottomRight = mesh.NodeQuadric(2, 0);
  resmr::ColumnCollapse collapse(mesh, 1);
  CHECK(collapse.CollapseChord(5, 0) == 3);
  CHECK(mesh.AliveColumns() == 9);
  CHECK(!mesh.IsColumnAlive(1) && !mesh.IsColumnAlive(5) && !mesh.IsColumnAlive(9));
  CHECK(collapse.Report().operatorCounts[resmr::ColumnCollapse::Chord] == 1);
  CHECK(mesh.ConnectedParts() == 1);
  CHECK(AllColumnsValid(mesh));
  // Each crossed edge is one node now: 4 of the 20 nodes are gone, 5 - 1 left on each row.
  CHECK(NodesAtY(mesh, 0) == 4 && NodesAtY(mesh, 3) == 4);
  // The boundary ends stay on the boundary, halfway (every position costs nothing there and
  // the midpoint keeps the cells even), with the merged quadric and the mean topological
  // coordinate; columns (0, 0) and (2, 0) are neighbours now.
  const int32_t end = mesh.IsNodeAlive(1) ? 1 : 2;
  CHECK(!mesh.IsNodeAlive(end == 1 ? 2 : 1));
  CHECK(mesh.Position(end, 0) == glm::dvec3(1.5, 0, 0));
  CHECK(mesh.TopologicalCoordinate(end)[0] == 1.5 && mesh.TopologicalCoordinate(end)[1] == 0);
  resmr::Quadric sum = bottomLeft;
  sum += bottomRight;
  CHECK(SameQuadric(mesh.NodeQuadric(end, 0), sum));
  const auto& left = mesh.ColumnCorners(0);
  const auto& right = mesh.ColumnCorners(2);
  CHECK(std::count_if(left.begin(), left.end(),
          [&](int32_t n) { return std::find(right.begin(), right.end(), n) != right.end(); }) == 2);

  // Refused: a chord along a strip one column wide (it would vanish), and one through a
  // locked column. Across the strip, the chord is one column (as a strip collapse).
  resmr::ColumnMesh strip = Grid(1, 3, 1);
  resmr::ColumnCollapse stripCollapse(strip, 1);
  CHECK(stripCollapse.CollapseChord(1, 0) == 0 && strip.AliveColumns() == 3);
  CHECK(stripCollapse.CollapseChord(1, 1) == 1 && strip.AliveColumns() == 2 && strip.ConnectedParts() == 1);
  CHECK(AllColumnsValid(strip));
  resmr::ColumnMesh locked = Grid(4, 3, 1);
  locked.SetLocked(9, true);
  resmr::ColumnCollapse lockedCollapse(locked, 1);
  CHECK(lockedCollapse.CollapseChord(5, 0) == 0 && locked.AliveColumns() == 12);
  CHECK(lockedCollapse.CollapseChord(6, 1) == 4 && locked.AliveColumns() == 8 && AllColumnsValid(locked));
}

void TestMergeAlongBoundary()
{
  // 4 x 2 columns: the bottom row stands on the straight boundary y = 0 with 5 nodes. One
  // merge turns two of its columns into one and takes two nodes off that boundary.
  resmr::ColumnMesh mesh = Grid(4, 2, 1);
  resmr::ColumnCollapse collapse(mesh, 1);
  CHECK(collapse.MergeAlongBoundaries(7) == 1);
  CHECK(mesh.AliveColumns() == 7);
  CHECK(NodesAtY(mesh, 0) == 3 && NodesAtY(mesh, 1) == 5 && NodesAtY(mesh, 2) == 5);
  CHECK(collapse.Report().operatorCounts[resmr::ColumnCollapse::Corner] == 1);
  CHECK(AllColumnsValid(mesh));
  CHECK(mesh.ConnectedParts() == 1);
  // Nothing is left to merge once no boundary stretch holds three nodes in a row.
  resmr::ColumnMesh square = Grid(1, 1, 1);
  resmr::ColumnCollapse squareCollapse(square, 1);
  CHECK(squareCollapse.MergeAlongBoundaries(0) == 0);
}

void TestRepairInvertedColumns()
{
  // 4 x 3 unit columns. The outline corner (4, 0) belongs to column 3 alone; moved in to
  // (3.4, 0.6) it turns inward and inverts the column. It moves out past the chord from
  // (3, 0) to (4, 1), to its foot (3.5, 0.5) and a hair beyond; nothing else moves.
  resmr::ColumnMesh outline = Grid(4, 3, 1);
  const int32_t corner = 4;
  for (int k = 0; k <= 1; ++k)
  {
    outline.SetPosition(corner, k, glm::dvec3(3.4, 0.6, k));
  }
  CHECK(!AllColumnsValid(outline));
  resmr::ColumnCollapse straighten(outline, 1);
  straighten.RepairInvertedColumns(11);
  CHECK(straighten.Report().straightenedColumns == 1 && straighten.Report().invertedColumnsCollapsed == 0);
  CHECK(outline.AliveColumns() == 12 && AllColumnsValid(outline));
  for (int k = 0; k <= 1; ++k)
  {
    const glm::dvec3 p = outline.Position(corner, k);
    CHECK(std::abs(p.x - 3.5) < 1e-3 && std::abs(p.y - 0.5) < 1e-3 && p.x > 3.5 && p.y < 0.5 && p.z == k);
  }
  CHECK(outline.TopologicalCoordinate(corner)[0] == 4 && outline.TopologicalCoordinate(corner)[1] == 0);

  // The interior node (2, 1), moved to (1.4, 0.4), turns inward in column 1 only; four
  // columns share it, so it cannot move out: column 1 is collapsed first, before any other.
  resmr::ColumnMesh inside = Grid(4, 3, 1);
  const int32_t interior = 1 * 5 + 2;
  for (int k = 0; k <= 1; ++k)
  {
    inside.SetPosition(interior, k, glm::dvec3(1.4, 0.4, k));
  }
  CHECK(!AllColumnsValid(inside));
  resmr::ColumnCollapse collapse(inside, 1);
  CHECK(collapse.Simplify(11).reachedTarget);
  CHECK(collapse.Report().straightenedColumns == 0 && collapse.Report().invertedColumnsCollapsed == 1);
  CHECK(!inside.IsColumnAlive(1) && inside.AliveColumns() == 11 && AllColumnsValid(inside));

  // Nothing to remove: the mesh stays as it came, inverted column included.
  resmr::ColumnMesh kept = Grid(4, 3, 1);
  kept.SetPosition(corner, 0, glm::dvec3(3.4, 0.6, 0));
  resmr::ColumnCollapse keep(kept, 1);
  keep.RepairInvertedColumns(12);
  CHECK(kept.Position(corner, 0) == glm::dvec3(3.4, 0.6, 0) && keep.Report().straightenedColumns == 0);
}

void TestSyntheticEndGame()
{
  // The faulted synthetic model of the benchmark (1M cells, 7264 columns in 17 parts) down to
  // 1% of its columns. Its straight faults and pinched-out layers stalled every operator near
  // 190 columns: slivers fanned on the faults fold whatever collapses next to them, and where
  // a layer pinches out, interfaces placed one by one leaned across the thickness left and
  // inverted the cell (now limited once collapses run out).
  resmr::SyntheticParameters parameters;
  parameters.nx = parameters.ny = parameters.nz = 100;
  parameters.seed = 1;
  const resmr::SyntheticReservoir reservoir(parameters);
  resmr::CornerPointModel deck;
  deck.dims = { parameters.nx, parameters.ny, parameters.nz };
  deck.coord = reservoir.Coord();
  deck.zcornSingle.resize(static_cast<std::size_t>(8 * parameters.CellCount()));
  std::vector<bool> active(static_cast<std::size_t>(parameters.CellCount()));
  resmr::SyntheticLayerStream stream(reservoir);
  resmr::SyntheticLayer layer;
  const int64_t columns = parameters.nx * parameters.ny;
  while (stream.Next(layer))
  {
    std::copy(layer.zcorn.begin(), layer.zcorn.end(), deck.zcornSingle.begin() + 8 * columns * layer.k);
    for (int64_t c = 0; c < columns; ++c)
    {
      active[layer.k * columns + c] = layer.state[c] == resmr::SyntheticCellState::Active;
    }
  }
  const resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(deck, false);
  resmr::ColumnMesh mesh = resmr::ColumnMesh::FromCornerPoints(geometry, active);
  CHECK(mesh.AliveColumns() == 7264 && mesh.ConnectedParts() == 17);
  resmr::ColumnCollapse collapse(mesh, 1);
  const resmr::SimplifyReport report = collapse.Simplify(73);
  std::printf("Synthetic 1M at 1%%: %lld columns, %lld rotations, %lld relaxations\n",
    static_cast<long long>(mesh.AliveColumns()), static_cast<long long>(report.rotations),
    static_cast<long long>(report.relaxations));
  CHECK(report.reachedTarget && mesh.AliveColumns() <= 73);
  CHECK(mesh.ConnectedParts() == 17);
  CHECK(AllColumnsValid(mesh));
}

void TestConnectedParts()
{
  CHECK(Grid(4, 3, 1).ConnectedParts() == 1);
  // Two unit columns touching at one corner only, and a third far away: three parts.
  std::vector<double> positions;
  std::vector<std::array<double, 2>> topology;
  const double xy[11][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 }, { 2, 1 }, { 2, 2 }, { 1, 2 }, { 5, 5 }, { 6, 5 },
    { 6, 6 }, { 5, 6 } };
  for (const auto& p : xy)
  {
    topology.push_back({ p[0], p[1] });
    positions.insert(positions.end(), { p[0], p[1], 0.0, p[0], p[1], 1.0 });
  }
  const resmr::ColumnMesh mesh = resmr::ColumnMesh::FromParts(
    1, positions, topology, { { 0, 1, 2, 3 }, { 2, 4, 5, 6 }, { 7, 8, 9, 10 } }, { 1, 1, 1 });
  CHECK(mesh.ConnectedParts() == 3);
}

void TestBadInput()
{
  using resmr_testing::ExpectError;
  std::vector<bool> active;
  resmr::CornerPointGeometry* geometry = nullptr;
  Reek(active, geometry);
  ExpectError<std::invalid_argument>("empty box",
    [&] { resmr::ColumnMesh::FromCornerPoints(*geometry, active, 5, 5, 0, 10); }, { "empty or out-of-grid box" });
  ExpectError<std::invalid_argument>("box outside",
    [&] { resmr::ColumnMesh::FromCornerPoints(*geometry, active, 0, 1000, 0, 10); }, { "out-of-grid box" });
  const std::vector<bool> none(active.size(), false);
  ExpectError<std::invalid_argument>(
    "all inactive", [&] { resmr::ColumnMesh::FromCornerPoints(*geometry, none); }, { "no active cell" });
  ExpectError<std::invalid_argument>("wrong flags",
    [&] { resmr::ColumnMesh::FromCornerPoints(*geometry, std::vector<bool>(3, true)); }, { "3 active flags" });
  ExpectError<std::invalid_argument>("bad parts",
    [&] {
      resmr::ColumnMesh::FromParts(1, { 0, 0, 0 }, { { 0, 0 } }, { { 0, 0, 0, 9 } }, { 1 });
    },
    { "inconsistent parts" });
  // Zero-thickness layers: degenerate cells are not measured, and simplification keeps them.
  resmr::ColumnMesh flat = Grid(6, 6, 2);
  for (int32_t node = 0; node < flat.NodeCount(); ++node)
  {
    flat.SetPosition(node, 1, flat.Position(node, 0));
  }
  resmr::ColumnCollapse collapse(flat, 1);
  collapse.Simplify(18);
  const resmr::HexQuality quality = resmr::MeasureHexahedra(resmr::ToHexMesh(flat), flat.Orientation());
  CHECK(quality.inverted == 0 && quality.degenerate == flat.AliveColumns());
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: TestColumnCollapse DATA_DIR\n");
    return 2;
  }
  DataDirectory = argv[1];
  TestQuadric();
  TestQuadricsOfFaces();
  TestInternalCollapse();
  TestBoundaryCornerAndFourBoundary();
  TestRandomSimplificationInvariants();
  TestDoubletCascade();
  TestFault();
  TestWeldFaults();
  TestRealModel();
  TestLockedColumns();
  TestEdgeRotation();
  TestChordCollapse();
  TestMergeAlongBoundary();
  TestRepairInvertedColumns();
  TestSyntheticEndGame();
  TestConnectedParts();
  TestBadInput();
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d check(s) failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("all column collapse checks passed\n");
  return 0;
}
