// EGRID reader (paper Sec. 3: the corner-point model as simulators write it).
#include "EclipseGrid.h"

#include "EclipseKeywordFile.h"
#include "Errors.h"
#include "GrdeclParser.h"
#include "LargeArrays.h"
#include "MemoryBudget.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <type_traits>

namespace resmr
{

bool LooksLikeEclipseGridFile(const std::string& path)
{
  const std::string text = EclipseKeywordFile::FileHead(path, 63);
  const char* head = text.c_str();
  const std::size_t got = text.size();
  const char* name = nullptr;
  if (EclipseKeywordFile::LooksLikeUnformatted(path))
  {
    name = head + 4;
  }
  else if (EclipseKeywordFile::LooksLikeFormatted(path))
  {
    name = std::strchr(head, '\'') + 1;
  }
  return name && name + 8 <= head + got &&
    (std::strncmp(name, "FILEHEAD", 8) == 0 || std::strncmp(name, "GRIDHEAD", 8) == 0);
}

namespace
{
/// True if no value is NaN or infinite: an exponent of all ones, tested on the bits so the
/// loop vectorizes (a floating-point sum would be a serial dependency chain).
template<typename Real>
bool AllFinite(const Real* values, std::size_t count)
{
  using Bits = std::conditional_t<sizeof(Real) == 4, uint32_t, uint64_t>;
  const Bits exponent = sizeof(Real) == 4 ? Bits(0x7f800000u) : Bits(0x7ff0000000000000ull);
  Bits special = 0;
  for (std::size_t v = 0; v < count; ++v)
  {
    Bits bits;
    std::memcpy(&bits, values + v, sizeof(Real));
    special |= Bits((bits & exponent) == exponent);
  }
  return special == 0;
}
} // namespace

EclipseGridLayout LocateEclipseGrid(const EclipseKeywordFile& file, int64_t maxCells)
{
  const std::string& path = file.Path();
  const auto fail = [&](const EclipseRecord* record, const std::string& what) -> void {
    file.Fail(record, record ? record->headerOffset : 0, what);
  };
  const auto& records = file.Records();

  // Old-style GRID files carry DIMENS + COORDS/CORNERS per cell instead of GRIDHEAD.
  if (!file.Find("GRIDHEAD"))
  {
    if (file.Find("COORDS") || file.Find("CORNERS") || file.Find("DIMENS"))
    {
      fail(nullptr,
        "old-style GRID file (COORDS/CORNERS per cell) is not supported; ask the simulator "
        "for an EGRID file (GRIDFILE 0 1 in the GRID section)");
    }
    fail(nullptr, "no GRIDHEAD keyword: not an EGRID file");
  }

  EclipseGridLayout layout;
  CornerPointModel& deck = layout.deck;
  deck.files.push_back(path);
  std::vector<double> numbers;
  std::vector<int32_t> integers;
  bool global = true; // records before the first ENDGRID (or LGR) belong to the global grid
  bool sawGridHead = false;
  bool globalConnections = false;
  for (std::size_t r = 0; r < records.size(); ++r)
  {
    const EclipseRecord& record = records[r];
    const std::string& name = record.name;
    if (name == "LGR")
    {
      global = false;
      const std::vector<std::string> names = file.ReadStrings(record);
      layout.localGridNames.push_back(names.empty() ? std::string("?") : names.front());
      continue;
    }
    if (name == "NNCHEAD" && record.IsNumeric() && record.count >= 2)
    {
      integers.resize(static_cast<std::size_t>(record.count));
      file.Read(record, integers.data());
      globalConnections = integers[1] == 0; // NNCHEAD(2): 0 for the global grid
      continue;
    }
    if (name == "NNC1")
    {
      layout.nonNeighbourConnections += globalConnections ? record.count : 0;
      continue;
    }
    if (name == "ENDGRID")
    {
      global = false;
      continue;
    }
    if (!global)
    {
      continue;
    }
    if (name == "FILEHEAD" && record.IsNumeric() && record.count >= 7)
    {
      integers.resize(static_cast<std::size_t>(record.count));
      file.Read(record, integers.data());
      layout.dualPorosityHeader = integers[5] != 0;
    }
    else if (name == "GRIDHEAD")
    {
      if (!record.IsNumeric() || record.count < 4)
      {
        fail(&record, "needs at least 4 integers (type, nx, ny, nz)");
      }
      if (sawGridHead)
      {
        fail(&record, "the global grid has a second GRIDHEAD");
      }
      integers.resize(static_cast<std::size_t>(record.count));
      file.Read(record, integers.data());
      if (integers[0] != 1)
      {
        fail(&record,
          "grid type " + std::to_string(integers[0]) + " is not a corner-point grid (only type 1 is supported)");
      }
      const std::array<int64_t, 3> dims{ integers[1], integers[2], integers[3] };
      CheckedCellCount(dims, maxCells, path, 0, "GRIDHEAD");
      deck.dims = dims;
      sawGridHead = true;
    }
    else if (name == "MAPAXES")
    {
      if (!record.IsNumeric() || record.count != 6)
      {
        fail(&record, "needs 6 numbers");
      }
      file.ReadNumbers(record, numbers);
      deck.hasMapAxes = true;
      deck.mapAxes.yAxisPoint = { numbers[0], numbers[1] };
      deck.mapAxes.origin = { numbers[2], numbers[3] };
      deck.mapAxes.xAxisPoint = { numbers[4], numbers[5] };
    }
    else if (name == "MAPUNITS" && record.type == EclipseDataType::Character)
    {
      const auto values = file.ReadStrings(record);
      deck.mapUnits = values.empty() ? "" : values.front();
    }
    else if (name == "GRIDUNIT" && record.type == EclipseDataType::Character)
    {
      const auto values = file.ReadStrings(record);
      deck.gridUnit = values.empty() ? "" : values.front();
      layout.units = deck.gridUnit;
      deck.gridUnitIsMap = values.size() > 1 && values[1] == "MAP";
    }
    else if (name == "COORD" || name == "ZCORN" || name == "ACTNUM")
    {
      if (!sawGridHead)
      {
        fail(&record, "appears before GRIDHEAD");
      }
      const int64_t nx = deck.dims[0], ny = deck.dims[1], nz = deck.dims[2];
      const int64_t expected = name == "COORD" ? 6 * (nx + 1) * (ny + 1)
        : name == "ZCORN"                      ? 8 * nx * ny * nz
                                               : nx * ny * nz;
      if (!record.IsNumeric() || record.count != expected)
      {
        fail(&record,
          "expected " + std::to_string(expected) + " numbers for a " + std::to_string(nx) + " x " + std::to_string(ny) +
            " x " + std::to_string(nz) + " grid, file has " + std::to_string(record.count) + " of type " +
            record.typeName);
      }
      (name == "COORD" ? layout.coord : name == "ZCORN" ? layout.zcorn : layout.actnum) = &record;
    }
  }
  if (!sawGridHead || !layout.coord || !layout.zcorn)
  {
    fail(nullptr,
      std::string("the global grid lacks ") +
        (!sawGridHead       ? "GRIDHEAD"
            : !layout.coord ? "COORD"
                            : "ZCORN"));
  }
  return layout;
}

namespace
{
/// Reads a COORD or ZCORN record whole into `target`; every value must be finite.
template<typename Real>
void ReadFiniteRecord(const EclipseKeywordFile& file, const EclipseRecord& record, std::vector<Real>& target)
{
  target.clear();
  ResizeLarge(target, static_cast<std::size_t>(record.count));
  file.Read(record, target.data());
  if (!AllFinite(target.data(), target.size()))
  {
    for (std::size_t v = 0; v < target.size(); ++v)
    {
      if (!std::isfinite(target[v]))
      {
        file.Fail(&record, record.headerOffset, "value " + std::to_string(v + 1) + " is not finite");
      }
    }
  }
}
} // namespace

EclipseGrid ReadEclipseGrid(const std::string& path, int64_t maxCells, EclipseGridParts parts)
{
  if (maxCells <= 0)
  {
    maxCells = MaxParsableCells();
  }
  const EclipseKeywordFile file(path);
  EclipseGridLayout layout = LocateEclipseGrid(file, maxCells);
  EclipseGrid grid;
  CornerPointModel& deck = grid.deck;
  deck = std::move(layout.deck);
  grid.dualPorosity = layout.dualPorosityHeader;
  grid.localGridNames = std::move(layout.localGridNames);
  grid.nonNeighbourConnections = layout.nonNeighbourConnections;
  grid.units = std::move(layout.units);
  if (parts == EclipseGridParts::Everything)
  {
    ReadFiniteRecord(file, *layout.coord, deck.coord);
    if (layout.zcorn->type == EclipseDataType::Real)
    {
      ReadFiniteRecord(file, *layout.zcorn, deck.zcornSingle); // EGRID's float32 depths, kept as they are
    }
    else
    {
      ReadFiniteRecord(file, *layout.zcorn, deck.zcorn);
    }
  }
  if (layout.actnum)
  {
    ResizeLarge(grid.actnum, static_cast<std::size_t>(layout.actnum->count));
    file.Read(*layout.actnum, grid.actnum.data());
  }
  const int64_t cells = deck.CellCount();
  if (grid.actnum.empty())
  {
    grid.actnum.assign(static_cast<std::size_t>(cells), 1);
  }
  for (const int32_t value : grid.actnum)
  {
    grid.dualPorosity |= value > 1; // FILEHEAD missing or silent: ACTNUM 2/3 says dual porosity
  }
  for (const int32_t value : grid.actnum)
  {
    // Branch-free per cell (vectorized): matrix = ACTNUM 1 or 3 in dual porosity, > 0 else.
    grid.activeCells += grid.dualPorosity ? (value & 1) : (value > 0);
    grid.fractureCells += grid.dualPorosity ? ((value >> 1) & 1) : 0;
  }
  if (grid.dualPorosity)
  {
    deck.warnings.push_back(path + ": dual-porosity grid: showing the matrix grid (" +
      std::to_string(grid.activeCells) + " matrix cells; " + std::to_string(grid.fractureCells) +
      " fracture cells not shown)");
  }
  if (!grid.localGridNames.empty())
  {
    std::string names;
    for (const std::string& lgr : grid.localGridNames)
    {
      names += (names.empty() ? "" : ", ") + lgr;
    }
    deck.warnings.push_back(path + ": " + std::to_string(grid.localGridNames.size()) +
      " local grid refinement(s) not shown, only the global grid: " + names);
  }
  return grid;
}

} // namespace resmr
