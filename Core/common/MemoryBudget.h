// The project's one memory policy: how much memory each path may take on this machine.
// Full-resolution grids cost about 300 bytes a cell in ParaView (paper Sec. 1 and 7: stock
// tools stop near 50-60 million cells); bigger models go through the multiresolution path,
// which loads only what the view needs (Sec. 6). The hierarchy build (Sec. 7) takes half
// the available memory unless told otherwise.
#pragma once

#include <cstdint>
#include <string>

namespace resmr
{

/// Bytes a cell of a full-resolution vtkExplicitStructuredGrid costs while it is read and
/// shown: the grid itself (points, hexahedra, I/J/K, ACTNUM), the reader's peak above it, a
/// few arrays and ParaView's surface for rendering (bench/results/egrid_load.md).
constexpr int64_t FullResolutionBytesPerCell = 300;

/// Memory the system can give without swapping (MemAvailable), else physical memory.
int64_t AvailableMemoryBytes();

/// Physical memory of the machine.
int64_t PhysicalMemoryBytes();

/// Most cells a deck or EGRID may declare before parsing stops: ZCORN alone holds 8 doubles
/// a cell, so a bigger grid cannot be read into this machine's memory at all.
int64_t MaxParsableCells();

/// The hierarchy build's memory when the user gives none: half the available memory.
int64_t DefaultBuildMemoryBytes();

/// Cells of a full-resolution grid that fit in `limitBytes` (0: the available memory).
int64_t MaxFullResolutionCells(int64_t limitBytes = 0);

/// The advice given with a refusal: where the multiresolution path starts.
std::string MultiresolutionAdvice(const std::string& path);

} // namespace resmr
