#include "CellInspection.h"

#include "DiamondHierarchy.h"
#include "RegionMesh.h"
#include "ThreadGroup.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <future>
#include <limits>
#include <stdexcept>
#include <thread>

#ifdef __GLIBC__
#include <malloc.h>
#endif

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

/// Squared distance from p to the triangle (0 inside): leaves hold the columns whose centres
/// their triangles hold (Sec. 4.2), so the column under a point is in the triangle holding it or
/// in one beside it, where the leaves' boxes (a diamond's, both triangles) overlap by half.
double DistanceToTriangle(const DiamondHierarchy::Triangle& t, const std::array<double, 2>& p)
{
  const DiamondHierarchy::Point* v[3] = { &t.apex, &t.left, &t.right };
  double nearest = std::numeric_limits<double>::max();
  int sides = 0;
  for (int e = 0; e < 3; ++e)
  {
    const auto& a = *v[e];
    const auto& b = *v[(e + 1) % 3];
    const double ex = b[0] - a[0], ey = b[1] - a[1], px = p[0] - a[0], py = p[1] - a[1];
    const double length = ex * ex + ey * ey;
    const double s = length > 0 ? std::clamp((px * ex + py * ey) / length, 0.0, 1.0) : 0.0;
    const double dx = px - s * ex, dy = py - s * ey;
    nearest = std::min(nearest, dx * dx + dy * dy);
    sides += ex * py - ey * px >= 0 ? 1 : -1;
  }
  return sides == 3 || sides == -3 ? 0.0 : nearest;
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
  std::vector<std::size_t> tables;
  for (int pass = 0; pass < 2; ++pass)
  {
    for (std::size_t t = 0; t < properties.Tables().size(); ++t)
    {
      const int32_t tableStep = properties.Tables()[t].step;
      if (pass == 0 ? tableStep < 0 : tableStep == step)
      {
        tables.push_back(t);
      }
    }
  }
  // One band a table, each checked whole (CRC) and decoded up to the cell: the tables on every
  // core, so a pick answers while the cursor rests; a cold file's bands asked of the disk
  // together first.
  for (std::size_t t : tables)
  {
    properties.PrefetchCell(t, cell);
  }
  std::vector<CellValue> values(tables.size());
  std::vector<std::string> errors(tables.size());
  std::atomic<std::size_t> next{ 0 };
  RunOnThreads(
    static_cast<int>(std::min<std::size_t>(tables.size(), std::max(1u, std::thread::hardware_concurrency()))), [&] {
      for (std::size_t n = next++; n < tables.size(); n = next++)
      {
        const PropertyTable& table = properties.Tables()[tables[n]];
        values[n] = { table.name, table.step, 0 };
        try
        {
          values[n].value = properties.ReadCell(tables[n], cell);
        }
        catch (const std::exception& error)
        {
          errors[n] = error.what();
        }
      }
    });
  for (const std::string& error : errors)
  {
    if (!error.empty())
    {
      throw FileFormatError(error);
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
  // Leaves by how far their triangles lie from the place: the column is in one of the nearest.
  const MultiresolutionHeader& header = file.Header();
  const DiamondHierarchy tree(header.box[0], header.box[1], header.box[2], header.box[3], header.leafLevel);
  const auto& regions = file.Regions();
  std::vector<std::pair<double, std::size_t>> leaves;
  for (std::size_t r = 0; r < regions.size(); ++r)
  {
    if (regions[r].level == header.leafLevel)
    {
      leaves.emplace_back(DistanceToTriangle(tree.ModelTriangle(regions[r].level, regions[r].index), place), r);
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

CellReport InspectCell(const MultiresolutionFile& file, const PropertyFile* properties,
  const std::array<int64_t, 3>& cell, int32_t step, const std::array<double, 3>* near)
{
  CellReport report;
  {
    std::future<std::vector<CellValue>> values;
    if (properties)
    {
      values = std::async(std::launch::async, [&] { return CellValues(*properties, cell, step); });
    }
    report.geometry = InspectCellGeometry(file, cell, near); // the future joins if this throws
    if (values.valid())
    {
      report.values = values.get();
    }
  }
#ifdef __GLIBC__
  // A layer chunk decoded is megabytes; freed, glibc keeps it in the threads' arenas.
  malloc_trim(0);
#endif
  return report;
}

bool BoxMayCoverPixel(const std::array<double, 3>& low, const std::array<double, 3>& high,
  const std::array<double, 16>& toClip, double x, double y, double width, double height)
{
  double least[2] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max() };
  double most[2] = { std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest() };
  for (int corner = 0; corner < 8; ++corner)
  {
    const double p[4] = { corner & 1 ? high[0] : low[0], corner & 2 ? high[1] : low[1], corner & 4 ? high[2] : low[2],
      1 };
    double clip[4];
    for (int r = 0; r < 4; ++r)
    {
      clip[r] = toClip[4 * r] * p[0] + toClip[4 * r + 1] * p[1] + toClip[4 * r + 2] * p[2] + toClip[4 * r + 3] * p[3];
    }
    if (!(clip[3] > 0))
    {
      return true; // behind the eye: its projection wraps
    }
    const double window[2] = { (clip[0] / clip[3] + 1) * width / 2, (clip[1] / clip[3] + 1) * height / 2 };
    for (int a = 0; a < 2; ++a)
    {
      least[a] = std::min(least[a], window[a]);
      most[a] = std::max(most[a], window[a]);
    }
  }
  // A pixel of margin: the rasterizer's snapping and the box's float corners.
  return x >= least[0] - 1 && x <= most[0] + 1 && y >= least[1] - 1 && y <= most[1] + 1;
}

bool RegionMayCoverPixel(const std::array<float, 6>& bounds, const std::array<double, 16>& modelToClip, double x,
  double y, double width, double height)
{
  // z up: the box's z runs from -(deepest) to -(shallowest).
  return BoxMayCoverPixel({ bounds[0], bounds[1], -double(bounds[5]) }, { bounds[3], bounds[4], -double(bounds[2]) },
    modelToClip, x, y, width, height);
}

std::vector<std::array<float, 6>> TriangleChunkBoxes(const RegionDrawBuffers& buffers)
{
  const std::size_t chunkIndices = std::size_t(PickChunkTriangles) * 3;
  const std::size_t vertexCount = buffers.vertices.size() / 6;
  std::vector<std::array<float, 6>> boxes((buffers.indices.size() + chunkIndices - 1) / chunkIndices);
  for (std::size_t c = 0; c < boxes.size(); ++c)
  {
    std::array<float, 6> box{ std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
      std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest(), std::numeric_limits<float>::lowest(),
      std::numeric_limits<float>::lowest() };
    const std::size_t end = std::min(buffers.indices.size(), (c + 1) * chunkIndices);
    for (std::size_t n = c * chunkIndices; n < end; ++n)
    {
      const uint32_t v = buffers.indices[n];
      if (v >= vertexCount)
      {
        continue;
      }
      const float* p = &buffers.vertices[std::size_t(v) * 6];
      for (std::size_t a = 0; a < 3; ++a)
      {
        box[a] = std::min(box[a], p[a]);
        box[3 + a] = std::max(box[3 + a], p[a]);
      }
    }
    boxes[c] = box;
  }
  return boxes;
}

std::vector<std::pair<uint32_t, uint32_t>> IndexRunsCoveringPixel(const std::vector<std::array<float, 6>>& boxes,
  uint32_t first, uint32_t count, const std::array<double, 16>& toClip, double x, double y, double width, double height)
{
  std::vector<std::pair<uint32_t, uint32_t>> runs;
  const uint32_t chunkIndices = PickChunkTriangles * 3, end = first + count;
  for (uint32_t at = first; at < end;)
  {
    const std::size_t chunk = at / chunkIndices;
    const uint32_t chunkEnd = std::min(end, static_cast<uint32_t>((chunk + 1) * chunkIndices));
    const bool covers = chunk >= boxes.size() ||
      BoxMayCoverPixel({ boxes[chunk][0], boxes[chunk][1], boxes[chunk][2] },
        { boxes[chunk][3], boxes[chunk][4], boxes[chunk][5] }, toClip, x, y, width, height);
    if (covers)
    {
      if (!runs.empty() && runs.back().first + runs.back().second == at)
      {
        runs.back().second += chunkEnd - at;
      }
      else
      {
        runs.emplace_back(at, chunkEnd - at);
      }
    }
    at = chunkEnd;
  }
  return runs;
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
