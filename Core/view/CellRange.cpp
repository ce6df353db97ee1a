// I/J/K range filter (ours, see CellRange.h): region classification and the masking of a
// region's hexahedral mesh that ExtractSurfaces then closes.
#include "CellRange.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

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

/// Where a footprint lies against the (i, j) rectangle [lo, hi] of cells: sides on the grid's
/// limits cut nothing. Inside needs `insideMargin` cells to spare on each side, Outside
/// `outsideMargin` cells between them.
RangeClass AgainstRectangle(const std::array<float, 4>& footprint, const std::array<int64_t, 2>& lo,
  const std::array<int64_t, 2>& hi, const std::array<int64_t, 3>& dims, float insideMargin, float outsideMargin = 0)
{
  bool inside = true;
  for (int a = 0; a < 2; ++a)
  {
    // The sides as topological coordinates; on the grid's own limits, no side at all.
    const double low = lo[a] <= 0 ? -HUGE_VAL : double(lo[a]);
    const double high = hi[a] >= dims[a] - 1 ? HUGE_VAL : double(hi[a] + 1);
    const double from = footprint[2 * a], to = footprint[2 * a + 1];
    if (to <= low - outsideMargin || from >= high + outsideMargin)
    {
      return RangeClass::Outside;
    }
    inside = inside && from >= low + insideMargin && to <= high - insideMargin;
  }
  return inside ? RangeClass::Inside : RangeClass::Crossed;
}

/// Whether excluded box `e` holds every layer the range keeps.
bool HoldsEveryLayer(const CellBoxBounds& e, const CellRange& range, const std::array<int64_t, 3>& dims)
{
  return e[4] <= std::max<int64_t>(range.lo[2], 0) && e[5] >= std::min(range.hi[2], dims[2] - 1);
}

/// Whether excluded box `e` leaves out a layer the range keeps.
bool MeetsLayers(const CellBoxBounds& e, const CellRange& range, const std::array<int64_t, 3>& dims)
{
  return e[4] <= std::min(range.hi[2], dims[2] - 1) && e[5] >= std::max<int64_t>(range.lo[2], 0);
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
  // An excluded box that holds the whole box leaves nothing.
  for (const CellBoxBounds& e : this->excluded)
  {
    bool holds = true;
    for (int a = 0; a < 3; ++a)
    {
      holds =
        holds && e[2 * a] <= std::max<int64_t>(this->lo[a], 0) && e[2 * a + 1] >= std::min(this->hi[a], dims[a] - 1);
    }
    if (holds)
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
  for (const CellBoxBounds& e : this->excluded)
  {
    bool meets = true;
    for (int a = 0; a < 3; ++a)
    {
      meets =
        meets && e[2 * a] <= std::min(this->hi[a], dims[a] - 1) && e[2 * a + 1] >= std::max<int64_t>(this->lo[a], 0);
    }
    if (meets)
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
  for (const CellBoxBounds& e : this->excluded)
  {
    out += " without";
    for (int a = 0; a < 3; ++a)
    {
      out += (a ? ", " : " ") + std::string(names[a]) + " " + std::to_string(e[2 * a] + 1) + "-" +
        std::to_string(e[2 * a + 1] + 1);
    }
  }
  return out;
}

bool ParseCellRange(const std::string& text, const std::array<int64_t, 3>& dims, CellRange& range)
{
  CellRange parsed;
  parsed.lo = { 0, 0, 0 };
  parsed.hi = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
  bool boxed = false;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
  {
    std::istringstream in(line);
    std::string first;
    if (!(in >> first))
    {
      continue; // blank
    }
    const bool exclude = first == "exclude";
    if (!exclude)
    {
      in.clear();
      in.str(line);
    }
    std::array<long long, 6> v{};
    for (auto& value : v)
    {
      if (!(in >> value))
      {
        return false;
      }
    }
    std::string rest;
    if (in >> rest || (!exclude && boxed))
    {
      return false; // more on the line, or a second box
    }
    CellBoxBounds box{};
    for (int n = 0; n < 6; ++n)
    {
      box[static_cast<std::size_t>(n)] = v[static_cast<std::size_t>(n)] - 1;
    }
    if (exclude)
    {
      parsed.excluded.push_back(box);
      continue;
    }
    boxed = true;
    parsed.lo = { box[0], box[2], box[4] };
    parsed.hi = { box[1], box[3], box[5] };
  }
  range = std::move(parsed);
  return true;
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
  RangeClass inBox =
    AgainstRectangle(footprint, { range.lo[0], range.lo[1] }, { range.hi[0], range.hi[1] }, dims, insideMargin);
  for (const CellBoxBounds& e : range.excluded)
  {
    if (inBox == RangeClass::Outside || !MeetsLayers(e, range, dims))
    {
      continue;
    }
    // Clear of it with a cell to spare, the region keeps its cells and its borders' neighbours;
    // held whole (a cell to spare), it keeps none of its cells when the box holds every layer
    // of the range and is masked by layer otherwise (exact); else a side may pass through.
    const RangeClass against =
      AgainstRectangle(footprint, { e[0], e[2] }, { e[1], e[3] }, dims, insideMargin, insideMargin);
    if (against == RangeClass::Inside && HoldsEveryLayer(e, range, dims))
    {
      return RangeClass::Outside;
    }
    if (against == RangeClass::Crossed)
    {
      inBox = RangeClass::Crossed;
    }
  }
  return inBox;
}

bool ExclusionExposes(const std::array<float, 4>& footprint, const CellRange& range, const std::array<int64_t, 3>& dims)
{
  for (const CellBoxBounds& e : range.excluded)
  {
    if (MeetsLayers(e, range, dims) &&
      AgainstRectangle(footprint, { e[0], e[2] }, { e[1], e[3] }, dims, 0) != RangeClass::Outside)
    {
      return true;
    }
  }
  return false;
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
      const int64_t layer = mesh.firstLayer + int64_t(k); // the model's
      active = active && keep(centre, layer, c);
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
        if (!keep(across, layer, AcrossCutEdge))
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
    return InRangeIJ(range, centre) && k >= range.lo[2] && k <= range.hi[2] &&
      !range.Excluded(static_cast<int64_t>(std::floor(centre[0])), static_cast<int64_t>(std::floor(centre[1])), k);
  });
}

} // namespace resmr
