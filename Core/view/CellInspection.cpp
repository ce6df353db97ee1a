#include "CellInspection.h"

#include "RegionMesh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace resmr
{

std::array<double, 3> CellGeometry::Centre() const
{
  std::array<double, 3> centre{ 0, 0, 0 };
  for (const auto& corner : this->corners)
  {
    for (int a = 0; a < 3; ++a)
    {
      centre[a] += corner[a] / 8;
    }
  }
  return centre;
}

namespace
{
void CheckCell(const std::array<int64_t, 3>& dims, const std::array<int64_t, 3>& cell)
{
  for (int a = 0; a < 3; ++a)
  {
    if (cell[a] < 0 || cell[a] >= dims[a])
    {
      throw std::out_of_range("cell (" + std::to_string(cell[0] + 1) + ", " + std::to_string(cell[1] + 1) + ", " +
        std::to_string(cell[2] + 1) + ") is outside the grid of " + std::to_string(dims[0]) + " x " +
        std::to_string(dims[1]) + " x " + std::to_string(dims[2]) + " cells");
    }
  }
}

/// The column of `mesh` whose corners' topological box holds the centre of column (i, j), or
/// -1. Leaves' columns are the original ones; a coarse column covers several.
int64_t ColumnCovering(const RegionMesh& mesh, int64_t i, int64_t j)
{
  const double ci = static_cast<double>(i) + 0.5, cj = static_cast<double>(j) + 0.5;
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    float low[2] = { std::numeric_limits<float>::max(), std::numeric_limits<float>::max() };
    float high[2] = { std::numeric_limits<float>::lowest(), std::numeric_limits<float>::lowest() };
    for (uint32_t node : mesh.corners[c])
    {
      for (int a = 0; a < 2; ++a)
      {
        low[a] = std::min(low[a], mesh.topology[node][a]);
        high[a] = std::max(high[a], mesh.topology[node][a]);
      }
    }
    if (ci > low[0] && ci < high[0] && cj > low[1] && cj < high[1])
    {
      return static_cast<int64_t>(c);
    }
  }
  return -1;
}

/// The mean of a column's four corners on its top interface (x, y).
std::array<double, 2> ColumnPlace(const RegionMesh& mesh, int64_t column)
{
  std::array<double, 2> place{ 0, 0 };
  for (uint32_t node : mesh.corners[static_cast<std::size_t>(column)])
  {
    const double* p = &mesh.positions[std::size_t(mesh.Vertex(node, 0)) * 3];
    place[0] += p[0] / 4;
    place[1] += p[1] / 4;
  }
  return place;
}

/// Where column (i, j) stands, from the first root region that covers it.
bool PlaceFromRoots(const MultiresolutionFile& file, int64_t i, int64_t j, std::array<double, 2>& place)
{
  const auto& regions = file.Regions();
  for (std::size_t r = 0; r < regions.size(); ++r)
  {
    if (regions[r].level != 0)
    {
      continue;
    }
    const RegionMesh mesh = file.ReadRegion(r);
    const int64_t column = ColumnCovering(mesh, i, j);
    if (column >= 0)
    {
      place = ColumnPlace(mesh, column);
      return true;
    }
  }
  return false;
}

/// The cell's corners and activity from leaf `mesh`'s column (i, j); false if it has none.
bool ReadCell(const RegionMesh& mesh, const std::array<int64_t, 3>& cell, CellGeometry& out)
{
  const int64_t column = ColumnCovering(mesh, cell[0], cell[1]);
  if (column < 0 || cell[2] >= mesh.layers)
  {
    return false;
  }
  const auto& q = mesh.corners[static_cast<std::size_t>(column)];
  for (uint32_t node : q)
  {
    // ECLIPSE's corner order: i fastest, then j, top before bottom.
    const int di = mesh.topology[node][0] > static_cast<float>(cell[0]) + 0.5f ? 1 : 0;
    const int dj = mesh.topology[node][1] > static_cast<float>(cell[1]) + 0.5f ? 1 : 0;
    for (int bottom = 0; bottom < 2; ++bottom)
    {
      const double* p = &mesh.positions[std::size_t(mesh.Vertex(node, static_cast<int32_t>(cell[2]) + bottom)) * 3];
      out.corners[static_cast<std::size_t>(4 * bottom + 2 * dj + di)] = { p[0], p[1], -p[2] };
    }
  }
  out.active = mesh.active[static_cast<std::size_t>(column) * static_cast<std::size_t>(mesh.layers) +
                 static_cast<std::size_t>(cell[2])] != 0;
  out.found = true;
  return true;
}
} // namespace

std::vector<CellValue> CellValues(const PropertyFile& properties, const std::array<int64_t, 3>& cell, int32_t step)
{
  CheckCell(properties.Dimensions(), cell);
  const std::size_t at = static_cast<std::size_t>(cell[0] + properties.Dimensions()[0] * cell[1]);
  std::vector<CellValue> values;
  for (int pass = 0; pass < 2; ++pass)
  {
    for (std::size_t t = 0; t < properties.Tables().size(); ++t)
    {
      const PropertyTable& table = properties.Tables()[t];
      if (pass == 0 ? table.step >= 0 : table.step != step)
      {
        continue;
      }
      values.push_back({ table.name, table.step, properties.ReadLayer(t, cell[2])[at] });
    }
  }
  return values;
}

CellGeometry InspectCellGeometry(
  const MultiresolutionFile& file, const std::array<int64_t, 3>& cell, const std::array<double, 3>* near)
{
  CheckCell(file.Header().dims, cell);
  CellGeometry out;
  std::array<double, 2> place{ 0, 0 };
  if (near)
  {
    place = { (*near)[0], (*near)[1] };
  }
  else if (!PlaceFromRoots(file, cell[0], cell[1], place))
  {
    return out; // no region covers the column: it holds no active cell
  }
  // Leaves by how far their boxes lie from the place: the column is in one of the nearest.
  const auto& regions = file.Regions();
  std::vector<std::pair<double, std::size_t>> leaves;
  for (std::size_t r = 0; r < regions.size(); ++r)
  {
    if (regions[r].level == file.Header().leafLevel)
    {
      const auto& b = regions[r].bounds;
      const double dx = std::max({ double(b[0]) - place[0], 0.0, place[0] - double(b[3]) });
      const double dy = std::max({ double(b[1]) - place[1], 0.0, place[1] - double(b[4]) });
      leaves.emplace_back(dx * dx + dy * dy, r);
    }
  }
  const std::size_t tries = std::min<std::size_t>(leaves.size(), MaxLeavesSearched);
  std::partial_sort(leaves.begin(), leaves.begin() + static_cast<std::ptrdiff_t>(tries), leaves.end());
  for (std::size_t n = 0; n < tries; ++n)
  {
    if (ReadCell(file.ReadRegion(leaves[n].second), cell, out))
    {
      out.leafRegion = leaves[n].second;
      return out;
    }
  }
  return out;
}

bool CellFromPickPixel(
  const std::array<float, 4>& rgba, const std::array<int64_t, 3>& dims, std::array<int64_t, 3>& cell)
{
  if (!(rgba[3] > 0.5f))
  {
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    const float v = rgba[static_cast<std::size_t>(a)];
    if (!(v >= 0) || v >= static_cast<float>(dims[static_cast<std::size_t>(a)]))
    {
      return false;
    }
    cell[static_cast<std::size_t>(a)] = static_cast<int64_t>(v);
  }
  return true;
}

} // namespace resmr
