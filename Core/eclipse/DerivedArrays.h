// Arrays engineers expect that a simulator may not write, derived from those it did (paper
// Sec. 3: the cell properties shown). Ours: the paper shows stored arrays only. Defined here
// once, so the EGRID reader and `resmr add-properties` offer the same arrays.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

class EclipseResults;

/// SOIL = 1 - SWAT - SGAS: OPM Flow and many ECLIPSE runs write SWAT and SGAS only.
constexpr const char* DerivedOilName = "SOIL";

/// Whether arrays `names` (a run's or a step's dynamic arrays) call for a derived SOIL: they
/// hold SWAT and no SOIL.
bool NeedsDerivedOil(const std::vector<std::string>& names);

/// Fills cellValues[0, cellCount) with 1 - SWAT - SGAS of report step `step` (index into
/// results.Steps()); SGAS counts as 0 in a run without gas, a cell without SWAT gets NaN.
/// False if the step has no SWAT.
bool ReadDerivedOil(const EclipseResults& results, std::size_t step, float* cellValues, int64_t cellCount);

} // namespace resmr
