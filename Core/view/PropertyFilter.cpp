// Property filter (ours, see PropertyFilter.h): region classification from block ranges,
// the masking of a region's cells by their values, and the values its faces carry.
#include "PropertyFilter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace resmr
{

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

bool ValueFilterSet::BlockMayPass(int64_t i, int64_t j) const
{
  const auto counts = this->Properties->BlockCounts();
  for (std::size_t f = 0; f < this->Wanted.size(); ++f)
  {
    if (this->Blocks[f].empty())
    {
      continue;
    }
    const ValueRange& b = this->Blocks[f][static_cast<std::size_t>(i / ColumnBlockSide + counts[0] * (j / ColumnBlockSide))];
    if (!(b.low <= b.high && b.high >= this->Wanted[f].low && b.low <= this->Wanted[f].high))
    {
      return false;
    }
  }
  return true;
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
  box.lo[2] = 0;
  box.hi[2] = dims[2] - 1;
  const PropertyFile& file = filter.values->File();
  for (const int table : filter.values->Tables())
  {
    box.tables.push_back(file.ReadBox(static_cast<std::size_t>(table), box.lo, box.hi));
  }
  if (filter.paintTable >= 0)
  {
    const auto& tables = filter.values->Tables();
    const auto same = std::find(tables.begin(), tables.end(), filter.paintTable);
    box.tables.push_back(same != tables.end() ? box.tables[static_cast<std::size_t>(same - tables.begin())]
                                              : file.ReadBox(static_cast<std::size_t>(filter.paintTable), box.lo, box.hi));
  }
  return box;
}

void MaskToFilter(RegionMesh& mesh, const CellFilter& filter, const CellBox* box)
{
  const CellRange& range = filter.range;
  const ValueFilterSet* values = filter.HasValues() ? filter.values.get() : nullptr;
  MaskCells(mesh, [&](const std::array<double, 2>& at, int64_t k) {
    const double fi = std::floor(at[0]), fj = std::floor(at[1]);
    if (!range.Contains(int64_t(fi), int64_t(fj), k) || fi != fi || fj != fj)
    {
      return false;
    }
    if (!values)
    {
      return true;
    }
    const auto& dims = values->File().Dimensions();
    if (fi < 0 || fj < 0 || fi >= double(dims[0]) || fj >= double(dims[1]))
    {
      return false;
    }
    const int64_t i = int64_t(fi), j = int64_t(fj);
    if (!box)
    {
      return values->BlockMayPass(i, j);
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

std::vector<float> FaceValues(const std::vector<float>& vertices, const std::vector<uint32_t>& indices, const CellBox& box)
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
