// EGRID files (paper Sec. 3: the corner-point model as simulators write it): the global
// grid's dimensions, pillars, corner depths, ACTNUM and map axes, handed on as a CornerPointModel
// so the grid is built by the same code as a deck's (CornerPointGeometry).
//
// Contract:
// - Reads FILEHEAD, GRIDHEAD, MAPUNITS, MAPAXES, GRIDUNIT, COORD, ZCORN, ACTNUM and ENDGRID
//   of the global grid, unformatted (.EGRID) or formatted (.FEGRID).
// - Local grid refinements and non-neighbour connections are not read: their names and
//   counts are returned so callers can say what is not shown.
// - Dual-porosity grids (ACTNUM 1 matrix, 2 fracture, 3 both): the matrix grid is the one
//   returned; `activeCells` counts matrix cells, `fractureCells` the fracture ones.
// - Old-style .GRID files and non-corner-point grids are rejected with InputError, as is
//   every inconsistency (array sizes, dims, non-finite coordinates).
// - LocateEclipseGrid does the same checks of the records' names, types and counts without
//   reading COORD, ZCORN or ACTNUM: a layer-by-layer reader then reads what it needs.
#pragma once

#include "CornerPointModel.h"

#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

class EclipseKeywordFile;
struct EclipseRecord;

/// Active flag of an ACTNUM value: the matrix value in dual porosity (1 or 3), > 0 else.
inline bool ActiveCellValue(int32_t value, bool dualPorosity)
{
  return dualPorosity ? (value & 1) != 0 : value > 0;
}

struct EclipseGrid
{
  /// dims, coord, zcorn, map axes and units (no cell arrays: ACTNUM is below).
  CornerPointModel deck;
  /// ACTNUM as written (0..3), one per cell; all 1 when the file has none.
  std::vector<int32_t> actnum;
  int64_t activeCells = 0;   ///< cells with a matrix (or single-porosity) value
  int64_t fractureCells = 0; ///< dual porosity: cells with a fracture value
  bool dualPorosity = false;
  std::vector<std::string> localGridNames; ///< LGRs in the file (not shown)
  int64_t nonNeighbourConnections = 0;     ///< NNC pairs of the global grid (not shown)
  std::string units;                       ///< GRIDUNIT's length unit: METRES, FEET, ...

  bool IsActive(int64_t cell) const
  {
    return ActiveCellValue(this->actnum[static_cast<std::size_t>(cell)], this->dualPorosity);
  }
};

/// The global grid of an EGRID, its records located and checked (GRIDHEAD, dims, the counts
/// and types of COORD/ZCORN/ACTNUM) but COORD, ZCORN and ACTNUM not read.
struct EclipseGridLayout
{
  /// dims, map axes and units; no coord, zcorn or cell arrays.
  CornerPointModel deck;
  /// The global grid's records (the last of each name, as ReadEclipseGrid keeps), pointing
  /// into the file's index; `actnum` is null when the file has none.
  const EclipseRecord* coord = nullptr;
  const EclipseRecord* zcorn = nullptr;
  const EclipseRecord* actnum = nullptr;
  bool dualPorosityHeader = false; ///< FILEHEAD says dual porosity (ACTNUM 2/3 says so too)
  std::vector<std::string> localGridNames;
  int64_t nonNeighbourConnections = 0;
  std::string units;
};

/// Locates the global grid of an open EGRID/FEGRID; maxCells as ReadEclipseGrid's. Throws
/// InputError as ReadEclipseGrid does for everything but the values of COORD, ZCORN and
/// ACTNUM.
EclipseGridLayout LocateEclipseGrid(const EclipseKeywordFile& file, int64_t maxCells);

/// Cheap check for file dialogs: the file starts with an EGRID's FILEHEAD or GRIDHEAD
/// record, unformatted or formatted.
bool LooksLikeEclipseGridFile(const std::string& path);

/// What ReadEclipseGrid reads: everything, or only what maps results to cells (dims and
/// ACTNUM; deck.coord and the depths left empty), a ninth of the memory for callers that
/// draw nothing (resmr add-properties).
enum class EclipseGridParts
{
  Everything,
  ActiveCellsOnly
};

/// Reads an EGRID or FEGRID file; maxCells 0 means "what this machine can hold".
EclipseGrid ReadEclipseGrid(
  const std::string& path, int64_t maxCells = 0, EclipseGridParts parts = EclipseGridParts::Everything);

} // namespace resmr
