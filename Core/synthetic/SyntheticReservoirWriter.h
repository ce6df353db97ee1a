// Writes a SyntheticReservoir as simulator files, streamed layer by layer (paper Sec. 3 input
// at the sizes of Sec. 7): EGRID + INIT (+ UNRST when the model has report steps), or one
// ASCII GRDECL deck.
//
// Contract:
// - Memory O(nx * ny): every keyword is written by its own pass over the layer stream (the
//   generator is cheap next to the disk), so nothing per cell is ever held.
// - ECLIPSE keyword headers hold a 32-bit count: an EGRID holds at most 268,435,455 cells
//   (ZCORN has 8 values a cell). Larger models are refused before anything is written;
//   they are streamed straight from SyntheticLayerStream instead.
// - All files are written under temporary names and renamed only when every one of them is
//   complete; on any error (disk full, unwritable folder) none is left under its final name.
//   Errors throw InputError naming the file and keyword.
#pragma once

#include "SyntheticReservoir.h"

#include <functional>
#include <string>
#include <vector>

namespace resmr
{

/// The largest model one EGRID can hold: ZCORN's 8 values a cell in a 32-bit count.
constexpr int64_t MaxEgridCells = 268435455;

struct SyntheticOutput
{
  std::vector<std::string> files;   ///< written, in order
  std::vector<std::string> removed; ///< stale companions of an older model, removed
  SyntheticStatistics statistics;
  int64_t bytes = 0;
};

/// One cell array of the INIT WriteSyntheticEclipse writes.
struct SyntheticInitArray
{
  const char* name;
  bool everyCell; ///< written for every cell (PORV); the others for active cells only
};

/// The INIT's cell arrays in file order: PORV, DEPTH, DX, DY, DZ, PORO, PERMX, PERMY, PERMZ,
/// NTG.
const std::vector<SyntheticInitArray>& SyntheticInitArrays();

/// Array `index` of SyntheticInitArrays() for every cell of `layer` (nx ny values, i fastest,
/// inactive cells included): the values the INIT holds for its active cells, bit for bit.
void FillSyntheticInitArray(
  const SyntheticReservoir& model, std::size_t index, const SyntheticLayer& layer, float* values);

/// Called with the fraction done, 0 to 1.
using SyntheticProgress = std::function<void(double)>;

/// EGRID (+ INIT + UNRST beside it, same base name, extension case following the EGRID's).
SyntheticOutput WriteSyntheticEclipse(
  const SyntheticReservoir& model, const std::string& egridPath, const SyntheticProgress& progress = {});

/// One ASCII GRDECL deck: SPECGRID, COORD, ZCORN, ACTNUM, PORO, PERMX, PERMY, PERMZ, NTG.
SyntheticOutput WriteSyntheticGrdecl(
  const SyntheticReservoir& model, const std::string& path, const SyntheticProgress& progress = {});

} // namespace resmr
