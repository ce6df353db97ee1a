// Eclipse grid deck parser: ASCII GRDECL/DATA with INCLUDE, and binary GRDECL (paper Sec. 3).
//
// Contract:
// - Streams every file; holds only the arrays it returns, never the text.
// - Follows INCLUDE (nested, quoted or bare, relative to the including file or the deck),
//   IMPORT (binary GRDECL), BOX/ENDBOX, FAULTS and the array edits EQUALS, MULTIPLY, ADD,
//   COPY, MINVALUE, MAXVALUE, COPYBOX, OPERATE, OPERATER, EQUALREG, MULTIREG, ADDREG, COPYREG.
// - Skips RUNSPEC/SUMMARY/SCHEDULE content and unknown keywords without choking; any
//   numeric keyword with one value per cell becomes a cell array (a viewer array, see
//   GrdeclEdits.h, also when given for a BOX only).
// - What the viewer does not build is skipped with a warning (CornerPointModel::warnings) naming
//   the file, line, keyword and array: edits of simulator and unknown arrays, flow-only
//   keywords (MULTFLT, NNC, AQUNUM, PINCH, ...), local grids (CARFIN ... ENDFIN), a missing
//   INCLUDE. An error then caused by a missing INCLUDE names it.
// - Validates dimensions before allocating and every array's value count.
// - On bad input throws InputError naming the file, the line and the keyword; a deck
//   object is only returned complete.
#pragma once

#include "CornerPointModel.h"
#include "SpoolFile.h"

#include <cstdint>
#include <memory>
#include <string>

namespace resmr
{

struct GrdeclParseOptions
{
  /// Largest nx*ny*nz accepted; 0 means "what this machine's memory can hold".
  int64_t maxCells = 0;
  /// Stop at the first SCHEDULE keyword (grid and properties are all defined before it).
  bool stopAtSchedule = true;
  /// Warn (CornerPointModel::warnings) instead of failing when an INCLUDE file is missing.
  bool skipMissingIncludes = true;
};

/// Parses an ASCII deck (.grdecl, .DATA, .inc ...) or a binary GRDECL (.bgrdecl), chosen by
/// content. Throws InputError.
CornerPointModel ParseGrdeclFile(const std::string& path, const GrdeclParseOptions& options = {});

/// The grid arrays of a deck parsed with bounded memory (ParseGrdeclGrid), in temporary files
/// rather than in the deck. Destroying it frees the files.
struct GrdeclGridSpool
{
  /// ZCORN: 8 nx ny nz float32 depths, ECLIPSE order (the double values rounded to float, as
  /// the layer sources hand them on); null when the deck has none.
  std::unique_ptr<SpoolFile> zcorn;
  /// ACTNUM, DX, DY, DZ, TOPS: one float64 a cell, ECLIPSE order, NaN where not given (ACTNUM
  /// after the parse: 1 there, as ParseGrdeclFile does); null when the deck has none.
  std::unique_ptr<SpoolFile> actnum, dx, dy, dz, tops;

  /// The array of that name (ACTNUM, DX, DY, DZ, TOPS), or nullptr.
  SpoolFile* Find(const std::string& name) const;
};

/// Bounded-memory parse for building a hierarchy from a deck (paper Sec. 4.2: the model is
/// streamed): as ParseGrdeclFile, but ZCORN and the grid's cell arrays (ACTNUM, DX, DY, DZ,
/// TOPS) go to temporary files in `spoolFolder` (`spool`), and every other cell array is read,
/// checked and dropped. EQUALS, MULTIPLY, ADD and COPY (BOX-limited or not) edit the spooled
/// arrays in their files; COPY from a dropped array into a spooled one throws InputError
/// naming the file, line and keyword. The deck returned holds dims, COORD, DXV/DYV/DZV, map
/// axes, units, faults, files and warnings: no zcorn and no cell arrays. Memory: COORD and
/// buffers of a few hundred KiB, whatever the grid's size; maxCells 0 means no limit here.
CornerPointModel ParseGrdeclGrid(
  const std::string& path, const std::string& spoolFolder, GrdeclGridSpool& spool, GrdeclParseOptions options = {});

/// Cheap check for file dialogs: binary GRDECL, or text with an ECLIPSE keyword in column 1
/// within its first 64 KiB.
bool LooksLikeGrdeclFile(const std::string& path);

/// Checks dims and returns nx*ny*nz; throws InputError (file, line, keyword) when a dim is
/// not positive, the product overflows, or exceeds maxCells.
int64_t CheckedCellCount(const std::array<int64_t, 3>& dims, int64_t maxCells, const std::string& file, int64_t line,
  const std::string& keyword);

} // namespace resmr
