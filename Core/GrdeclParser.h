// Eclipse grid deck parser: ASCII GRDECL/DATA with INCLUDE, and binary GRDECL (paper Sec. 3).
//
// Contract:
// - Streams every file; holds only the arrays it returns, never the text.
// - Follows INCLUDE (nested, quoted or bare, relative to the including file or the deck),
//   IMPORT (binary GRDECL), BOX/ENDBOX, EQUALS, MULTIPLY, ADD, COPY and FAULTS.
// - Skips RUNSPEC/SUMMARY/SCHEDULE content and unknown keywords without choking; any
//   numeric keyword with one value per cell (or per BOX cell) becomes a cell array.
// - Validates dimensions before allocating and every array's value count.
// - On bad input throws GrdeclError naming the file, the line and the keyword; a deck
//   object is only returned complete.
#pragma once

#include "GrdeclDeck.h"

#include <cstdint>
#include <string>

namespace resmr
{

struct GrdeclParseOptions
{
  /// Largest nx*ny*nz accepted; 0 means "what this machine's memory can hold".
  int64_t maxCells = 0;
  /// Stop at the first SCHEDULE keyword (grid and properties are all defined before it).
  bool stopAtSchedule = true;
  /// Warn (GrdeclDeck::warnings) instead of failing when an INCLUDE file is missing.
  bool skipMissingIncludes = false;
};

/// Parses an ASCII deck (.grdecl, .DATA, .inc ...) or a binary GRDECL (.bgrdecl), chosen by
/// content. Throws GrdeclError.
GrdeclDeck ParseGrdeclFile(const std::string& path, const GrdeclParseOptions& options = {});

/// Cheap check for file dialogs: binary GRDECL, or text with an ECLIPSE keyword in column 1
/// within its first 64 KiB.
bool LooksLikeGrdeclFile(const std::string& path);

/// Largest cell count whose corner-point arrays fit in this machine's physical memory.
int64_t MaxCellsForThisMachine();

/// Checks dims and returns nx*ny*nz; throws GrdeclError (file, line, keyword) when a dim is
/// not positive, the product overflows, or exceeds maxCells.
int64_t CheckedCellCount(const std::array<int64_t, 3>& dims, int64_t maxCells,
  const std::string& file, int64_t line, const std::string& keyword);

} // namespace resmr
