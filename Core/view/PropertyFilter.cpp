// Property filter (ours, see PropertyFilter.h): region classification from block ranges,
// the masking of a region's cells by their values, and the values its faces carry.
#include "PropertyFilter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace resmr
{

bool ParseValueFilters(const std::string& text, std::vector<ValueFilter>& filters)
{
  std::vector<ValueFilter> parsed;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line))
  {
    if (line.find_first_not_of(" \t\r") == std::string::npos)
    {
      continue;
    }
    std::istringstream in(line);
    double low = 0, high = 0;
    std::string name;
    if (!(in >> low >> high) || !std::getline(in, name))
    {
      return false;
    }
    const std::size_t first = name.find_first_not_of(" \t");
    const std::size_t last = name.find_last_not_of(" \t\r");
    if (first == std::string::npos || name[0] != ' ')
    {
      return false; // no name, or one run into the number
    }
    ValueFilter filter;
    filter.name = name.substr(first, last - first + 1);
    filter.low = static_cast<float>(low);
    filter.high = static_cast<float>(high);
    parsed.push_back(filter);
  }
  filters.insert(filters.end(), parsed.begin(), parsed.end());
  return true;
}

int FindFilterTable(const PropertyFile& file, const std::string& name, int32_t step)
{
  const int at = file.Find(name, step);
  return at >= 0 ? at : file.Find(name, -1);
}

ValueFilterSet::ValueFilterSet(std::shared_ptr<const PropertyFile> file, std::vector<ValueFilter> filters, int32_t step)
  : Properties(std::move(file))
  , Wanted(std::move(filters))
  , AtStep(step)
{
  for (const ValueFilter& filter : this->Wanted)
  {
    const int table = FindFilterTable(*this->Properties, filter.name, step);
    if (table < 0)
    {
      throw std::invalid_argument(this->Properties->Path() + ": no array '" + filter.name + "' at step " +
        std::to_string(step) + " to filter by");
    }
    this->TableIndices.push_back(table);
    this->Blocks.push_back(this->Properties->ReadBlockRanges(static_cast<std::size_t>(table)));
    this->LayerBlocks.push_back(this->Properties->ReadLayerBlocks(static_cast<std::size_t>(table)));
  }
}

RangeClass ValueFilterSet::Classify(const std::array<float, 4>& footprint, float margin) const
{
  if (footprint[1] < footprint[0])
  {
    return RangeClass::Outside;
  }
  const auto& dims = this->Properties->Dimensions();
  const auto counts = this->Properties->BlockCounts();
  // Blocks under the footprint's cells, widened by the margin, within the grid.
  std::array<int64_t, 4> cells{};
  for (int a = 0; a < 2; ++a)
  {
    const double from = std::floor(double(footprint[2 * a]) - margin);
    const double to = std::ceil(double(footprint[2 * a + 1]) + margin) - 1;
    cells[2 * a] = static_cast<int64_t>(std::clamp<double>(from, 0, double(dims[a] - 1)));
    cells[2 * a + 1] = static_cast<int64_t>(std::clamp<double>(to, 0, double(dims[a] - 1)));
  }
  bool inside = true;
  for (std::size_t f = 0; f < this->Wanted.size(); ++f)
  {
    if (this->Blocks[f].empty())
    {
      return RangeClass::Crossed;
    }
    bool anyMay = false, allPass = true;
    for (int64_t bj = cells[2] / ColumnBlockSide; bj <= cells[3] / ColumnBlockSide; ++bj)
    {
      for (int64_t bi = cells[0] / ColumnBlockSide; bi <= cells[1] / ColumnBlockSide; ++bi)
      {
        const ValueRange& b = this->Blocks[f][static_cast<std::size_t>(bi + counts[0] * bj)];
        if (b.low > b.high)
        {
          continue; // no active cell: nothing to show, nothing to hide
        }
        anyMay = anyMay || (b.high >= this->Wanted[f].low && b.low <= this->Wanted[f].high);
        allPass = allPass && b.low >= this->Wanted[f].low && b.high <= this->Wanted[f].high;
      }
    }
    if (!anyMay)
    {
      return RangeClass::Outside;
    }
    inside = inside && allPass;
  }
  return inside ? RangeClass::Inside : RangeClass::Crossed;
}

bool ValueFilterSet::LayerBlocksMayPass(
  const std::array<int64_t, 2>& lo, const std::array<int64_t, 2>& hi, int64_t k) const
{
  const auto counts = this->Properties->LayerBlockCounts();
  for (std::size_t f = 0; f < this->Wanted.size(); ++f)
  {
    if (this->LayerBlocks[f].empty())
    {
      continue;
    }
    bool may = false;
    for (int64_t bj = lo[1] / LayerBlockSide; bj <= hi[1] / LayerBlockSide && !may; ++bj)
    {
      for (int64_t bi = lo[0] / LayerBlockSide; bi <= hi[0] / LayerBlockSide && !may; ++bi)
      {
        const BlockSummary& b = this->LayerBlocks[f][static_cast<std::size_t>(bi + counts[0] * (bj + counts[1] * k))];
        may = b.low <= b.high && b.high >= this->Wanted[f].low && b.low <= this->Wanted[f].high;
      }
    }
    if (!may)
    {
      return false;
    }
  }
  return true;
}

float FilterError(const RegionRecord& region, const std::array<float, 4>& footprint)
{
  const double cells = std::max(double(footprint[1] - footprint[0]) * double(footprint[3] - footprint[2]), 1.0);
  const auto& b = region.bounds;
  const double area = std::max(double(b[3] - b[0]) * double(b[4] - b[1]), 0.0);
  const double columnWidth = 2 * std::sqrt(cells / double(std::max<int64_t>(region.columns, 1)));
  return static_cast<float>(std::max(columnWidth, double(LayerBlockSide)) * std::sqrt(area / cells));
}

std::array<int32_t, 2> FilterLayers(
  const CellFilter& filter, const std::vector<std::array<float, 2>>& topology, const std::array<int64_t, 3>& dims)
{
  const int64_t first = std::clamp<int64_t>(filter.range.lo[2], 0, dims[2] - 1);
  const int64_t last = std::clamp<int64_t>(filter.range.hi[2], first, dims[2] - 1);
  if (!filter.HasValues() || topology.empty())
  {
    return { int32_t(first), int32_t(last) };
  }
  // The region's cells: the box of its nodes, within the grid.
  std::array<float, 4> box{ topology[0][0], topology[0][0], topology[0][1], topology[0][1] };
  for (const auto& t : topology)
  {
    box = { std::min(box[0], t[0]), std::max(box[1], t[0]), std::min(box[2], t[1]), std::max(box[3], t[1]) };
  }
  std::array<int64_t, 2> lo{}, hi{};
  for (int a = 0; a < 2; ++a)
  {
    lo[a] = std::clamp<int64_t>(static_cast<int64_t>(std::floor(box[2 * a])), 0, dims[a] - 1);
    hi[a] = std::clamp<int64_t>(static_cast<int64_t>(std::ceil(box[2 * a + 1])) - 1, lo[a], dims[a] - 1);
  }
  int64_t low = last + 1, high = first - 1;
  for (int64_t k = first; k <= last; ++k)
  {
    if (filter.values->LayerBlocksMayPass(lo, hi, k))
    {
      low = std::min(low, k);
      high = k;
    }
  }
  return low <= high ? std::array<int32_t, 2>{ int32_t(low), int32_t(high) }
                     : std::array<int32_t, 2>{ int32_t(first), int32_t(first) };
}

CellBox ReadCellBox(const RegionMesh& mesh, const CellFilter& filter, const std::array<int64_t, 3>& dims)
{
  CellBox box;
  const std::array<float, 4> topology = TopologyBox(mesh);
  if (topology[1] < topology[0] || !filter.values)
  {
    return box;
  }
  for (int a = 0; a < 2; ++a)
  {
    box.lo[a] = std::clamp<int64_t>(static_cast<int64_t>(std::floor(topology[2 * a])) - 1, 0, dims[a] - 1);
    box.hi[a] = std::clamp<int64_t>(static_cast<int64_t>(std::ceil(topology[2 * a + 1])), 0, dims[a] - 1);
  }
  // The mesh's layers (a window of the model's when a range keeps some; MaskToFilter asks
  // for no layer outside the range).
  box.lo[2] = std::clamp<int64_t>(std::max<int64_t>(mesh.firstLayer, filter.range.lo[2]), 0, dims[2] - 1);
  box.hi[2] =
    std::clamp<int64_t>(std::min<int64_t>(mesh.firstLayer + mesh.layers - 1, filter.range.hi[2]), 0, dims[2] - 1);
  if (box.hi[2] < box.lo[2])
  {
    return CellBox{};
  }
  const PropertyFile& file = filter.values->File();
  for (const int table : filter.values->Tables())
  {
    box.tables.push_back(file.ReadBox(static_cast<std::size_t>(table), box.lo, box.hi));
  }
  if (filter.paintTable >= 0)
  {
    const auto& tables = filter.values->Tables();
    const auto same = std::find(tables.begin(), tables.end(), filter.paintTable);
    box.tables.push_back(same != tables.end()
        ? box.tables[static_cast<std::size_t>(same - tables.begin())]
        : file.ReadBox(static_cast<std::size_t>(filter.paintTable), box.lo, box.hi));
  }
  return box;
}

void MaskToFilter(RegionMesh& mesh, const CellFilter& filter, const CellBox* box)
{
  const CellRange& range = filter.range;
  const ValueFilterSet* values = filter.HasValues() ? filter.values.get() : nullptr;
  // A coarse column's cells: the box of its nodes' topology, within the grid.
  const auto& dims = filter.values ? filter.values->File().Dimensions() : std::array<int64_t, 3>{};
  std::vector<std::array<int64_t, 4>> columnCells;
  for (std::size_t c = 0; values && !box && c < mesh.corners.size(); ++c)
  {
    const std::array<float, 4> column = ColumnTopologyBox(mesh, c);
    const auto cell = [&](float t, int a) {
      return std::clamp<int64_t>(static_cast<int64_t>(std::floor(t)), 0, dims[a] - 1);
    };
    columnCells.push_back(
      { cell(column[0], 0), cell(std::ceil(column[1]) - 1, 0), cell(column[2], 1), cell(std::ceil(column[3]) - 1, 1) });
  }
  MaskCells(mesh, [&](const std::array<double, 2>& at, int64_t k, std::size_t column) {
    const double fi = std::floor(at[0]), fj = std::floor(at[1]);
    if (!range.Contains(int64_t(fi), int64_t(fj), k) || fi != fi || fj != fj)
    {
      return false;
    }
    if (!values)
    {
      return true;
    }
    if (fi < 0 || fj < 0 || fi >= double(dims[0]) || fj >= double(dims[1]))
    {
      return false;
    }
    const int64_t i = int64_t(fi), j = int64_t(fj);
    if (!box)
    {
      const std::array<int64_t, 4> cells =
        column == AcrossCutEdge ? std::array<int64_t, 4>{ i, i, j, j } : columnCells[column];
      return values->LayerBlocksMayPass({ cells[0], cells[2] }, { cells[1], cells[3] }, k);
    }
    const int64_t ci = std::clamp(i, box->lo[0], box->hi[0]), cj = std::clamp(j, box->lo[1], box->hi[1]);
    for (std::size_t f = 0; f < values->Filters().size(); ++f)
    {
      if (!values->Filters()[f].Passes(box->At(f, ci, cj, k)))
      {
        return false;
      }
    }
    return true;
  });
}

std::vector<float> FaceMeans(const std::vector<float>& vertices, const std::vector<uint32_t>& indices,
  const std::vector<BlockSummary>& blocks, const std::array<int64_t, 3>& dims)
{
  std::vector<float> out(indices.size() / 3, std::numeric_limits<float>::quiet_NaN());
  const int64_t bx = (dims[0] + LayerBlockSide - 1) / LayerBlockSide,
                by = (dims[1] + LayerBlockSide - 1) / LayerBlockSide;
  if (blocks.size() != static_cast<std::size_t>(bx * by * dims[2]))
  {
    return out;
  }
  for (std::size_t t = 0; t < out.size(); ++t)
  {
    std::array<double, 3> c{ 0, 0, 0 };
    for (int v = 0; v < 3; ++v)
    {
      for (int a = 0; a < 3; ++a)
      {
        c[a] += vertices[std::size_t(indices[3 * t + v]) * 6 + 3 + a] / 3.0;
      }
    }
    std::array<int64_t, 3> cell{};
    for (int a = 0; a < 3; ++a)
    {
      cell[a] = std::clamp<int64_t>(static_cast<int64_t>(std::floor(c[a])), 0, dims[a] - 1);
    }
    out[t] =
      blocks[static_cast<std::size_t>(cell[0] / LayerBlockSide + bx * (cell[1] / LayerBlockSide + by * cell[2]))].mean;
  }
  return out;
}

std::vector<float> FaceValues(
  const std::vector<float>& vertices, const std::vector<uint32_t>& indices, const CellBox& box)
{
  std::vector<float> out(indices.size() / 3, std::numeric_limits<float>::quiet_NaN());
  if (box.tables.empty())
  {
    return out;
  }
  const std::size_t painted = box.tables.size() - 1;
  for (std::size_t t = 0; t < out.size(); ++t)
  {
    std::array<double, 3> c{ 0, 0, 0 };
    for (int v = 0; v < 3; ++v)
    {
      const float* vertex = &vertices[std::size_t(indices[3 * t + v]) * 6];
      for (int a = 0; a < 3; ++a)
      {
        c[a] += vertex[3 + a] / 3.0;
      }
    }
    std::array<int64_t, 3> cell{};
    bool in = true;
    for (int a = 0; a < 3; ++a)
    {
      cell[a] = static_cast<int64_t>(std::floor(c[a]));
      in = in && cell[a] >= box.lo[a] && cell[a] <= box.hi[a];
    }
    if (in)
    {
      out[t] = box.At(painted, cell[0], cell[1], cell[2]);
    }
  }
  return out;
}

} // namespace resmr
