// I/J/K range filter (ours, see CellRange.h): region classification and the masking of a
// region's hexahedral mesh that ExtractSurfaces then closes.
#include "CellRange.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace resmr
{
namespace
{
std::array<double, 2> ColumnCentre(const RegionMesh& mesh, std::size_t column)
{
  std::array<double, 2> sum{ 0, 0 };
  for (const uint32_t node : mesh.corners[column])
  {
    sum[0] += mesh.topology[node][0];
    sum[1] += mesh.topology[node][1];
  }
  return { sum[0] / 4, sum[1] / 4 };
}

bool InRangeIJ(const CellRange& range, const std::array<double, 2>& centre)
{
  const double i = std::floor(centre[0]), j = std::floor(centre[1]);
  return i >= double(range.lo[0]) && i <= double(range.hi[0]) && j >= double(range.lo[1]) && j <= double(range.hi[1]);
}
} // namespace

bool CellRange::Empty(const std::array<int64_t, 3>& dims) const
{
  for (int a = 0; a < 3; ++a)
  {
    if (std::max<int64_t>(this->lo[a], 0) > std::min(this->hi[a], dims[a] - 1))
    {
      return true;
    }
  }
  return false;
}

bool CellRange::Whole(const std::array<int64_t, 3>& dims) const
{
  for (int a = 0; a < 3; ++a)
  {
    if (this->lo[a] > 0 || this->hi[a] < dims[a] - 1)
    {
      return false;
    }
  }
  return true;
}

std::string CellRange::Describe() const
{
  std::string out;
  const char* names[3] = { "I", "J", "K" };
  for (int a = 0; a < 3; ++a)
  {
    out += (a ? ", " : "") + std::string(names[a]) + " " + std::to_string(this->lo[a] + 1) + "-" +
      std::to_string(this->hi[a] + 1);
  }
  return out;
}

std::array<float, 4> RegionFootprint(const RegionMesh& mesh)
{
  const std::array<float, 4> box = TopologyBox(mesh);
  if (box[1] < box[0])
  {
    return box; // lies nowhere
  }
  float widest = 0;
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    const std::array<float, 4> column = ColumnTopologyBox(mesh, c);
    widest = std::max({ widest, column[1] - column[0], column[3] - column[2] });
  }
  const float margin = std::ceil(widest) + 1;
  return { box[0] - margin, box[1] + margin, box[2] - margin, box[3] + margin };
}

RangeClass ClassifyFootprint(
  const std::array<float, 4>& footprint, const CellRange& range, const std::array<int64_t, 3>& dims, float insideMargin)
{
  if (footprint[1] < footprint[0] || range.Empty(dims))
  {
    return RangeClass::Outside;
  }
  bool inside = true;
  for (int a = 0; a < 2; ++a)
  {
    // The range's sides as topological coordinates; on the grid's own limits, no side at all.
    const double low = range.lo[a] <= 0 ? -HUGE_VAL : double(range.lo[a]);
    const double high = range.hi[a] >= dims[a] - 1 ? HUGE_VAL : double(range.hi[a] + 1);
    const double from = footprint[2 * a], to = footprint[2 * a + 1];
    if (to <= low || from >= high)
    {
      return RangeClass::Outside;
    }
    inside = inside && from >= low + insideMargin && to <= high - insideMargin;
  }
  return inside ? RangeClass::Inside : RangeClass::Crossed;
}

std::array<float, 4> ColumnTopologyBox(const RegionMesh& mesh, std::size_t column)
{
  const auto& first = mesh.topology[mesh.corners[column][0]];
  std::array<float, 4> box{ first[0], first[0], first[1], first[1] };
  for (const uint32_t node : mesh.corners[column])
  {
    for (int a = 0; a < 2; ++a)
    {
      box[2 * a] = std::min(box[2 * a], mesh.topology[node][a]);
      box[2 * a + 1] = std::max(box[2 * a + 1], mesh.topology[node][a]);
    }
  }
  return box;
}

std::array<double, 2> ColumnCentreOf(const RegionMesh& mesh, std::size_t column)
{
  return ColumnCentre(mesh, column);
}

void MaskCells(RegionMesh& mesh, const std::function<bool(const std::array<double, 2>&, int64_t, std::size_t)>& keep)
{
  const std::size_t layers = static_cast<std::size_t>(mesh.layers);
  std::vector<uint8_t> cutOpen(mesh.active.size(), 0); // per cell, cut edges whose cell across goes
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    const std::array<double, 2> centre = ColumnCentre(mesh, c);
    for (std::size_t k = 0; k < layers; ++k)
    {
      uint8_t& active = mesh.active[c * layers + k];
      active = active && keep(centre, int64_t(k), c);
      for (int e = 0; active && e < 4; ++e)
      {
        if (!(mesh.cutEdges[c] & (1u << e)))
        {
          continue;
        }
        const auto& a = mesh.topology[mesh.corners[c][e]];
        const auto& b = mesh.topology[mesh.corners[c][(e + 1) % 4]];
        const std::array<double, 2> across{ double(a[0]) + double(b[0]) - centre[0],
          double(a[1]) + double(b[1]) - centre[1] };
        if (!keep(across, int64_t(k), AcrossCutEdge))
        {
          cutOpen[c * layers + k] |= static_cast<uint8_t>(1u << e);
        }
      }
    }
  }
  // Inside the region, from the masked cells; the cut edges keep what the file says of the
  // cell across, unless that cell goes.
  ComputeOpenSides(mesh);
  for (std::size_t n = 0; n < cutOpen.size(); ++n)
  {
    mesh.openSides[n] |= cutOpen[n];
  }
}

void MaskToRange(RegionMesh& mesh, const CellRange& range)
{
  MaskCells(mesh, [&](const std::array<double, 2>& centre, int64_t k, std::size_t) {
    return InRangeIJ(range, centre) && k >= range.lo[2] && k <= range.hi[2];
  });
}

} // namespace resmr
