// EGRID files (paper Sec. 3: the corner-point model as simulators write it): the global
// grid's dimensions, pillars, corner depths, ACTNUM and map axes, handed on as a GrdeclDeck
// so the grid is built by the same code as a deck's (CornerPointGeometry).
//
// Contract:
// - Reads FILEHEAD, GRIDHEAD, MAPUNITS, MAPAXES, GRIDUNIT, COORD, ZCORN, ACTNUM and ENDGRID
//   of the global grid, unformatted (.EGRID) or formatted (.FEGRID).
// - Local grid refinements and non-neighbour connections are not read: their names and
//   counts are returned so callers can say what is not shown.
// - Dual-porosity grids (ACTNUM 1 matrix, 2 fracture, 3 both): the matrix grid is the one
//   returned; `activeCells` counts matrix cells, `fractureCells` the fracture ones.
// - Old-style .GRID files and non-corner-point grids are rejected with GrdeclError, as is
//   every inconsistency (array sizes, dims, non-finite coordinates).
#pragma once

#include "GrdeclDeck.h"

#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

struct EclipseGrid
{
  /// dims, coord, zcorn, map axes and units (no cell arrays: ACTNUM is below).
  GrdeclDeck deck;
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
    const int32_t value = this->actnum[static_cast<std::size_t>(cell)];
    return this->dualPorosity ? (value & 1) != 0 : value > 0;
  }
};

/// Cheap check for file dialogs: the file starts with an EGRID's FILEHEAD or GRIDHEAD
/// record, unformatted or formatted.
bool LooksLikeEclipseGridFile(const std::string& path);

/// Reads an EGRID or FEGRID file; maxCells 0 means "what this machine can hold".
EclipseGrid ReadEclipseGrid(const std::string& path, int64_t maxCells = 0);

} // namespace resmr
