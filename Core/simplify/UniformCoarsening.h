// The naive alternative to paper Sec. 4.1's simplification, kept as the yardstick its
// benchmark must beat: merge blocks of b x b columns into one column, with no regard for
// faults, boundaries or errors.
#pragma once

#include "HexMesh.h"

#include <cstdint>
#include <vector>

namespace resmr
{

class CornerPointGeometry;

/// One coarse column per block of `block` x `block` columns holding an active cell; its
/// corners are the block's outer corner pillars as the block's corner columns see them; a
/// coarse cell is active if any cell of its block in that layer is.
HexMesh CoarsenUniformly(const CornerPointGeometry& geometry, const std::vector<bool>& active, int64_t block);

} // namespace resmr
