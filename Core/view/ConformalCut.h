// Stateless top-down selection of regions from a .resmr file (paper Sec. 6.2, after Adaptive
// TetraPuzzles): a diamond is split when its model-space error exceeds the tolerance; since
// errors are equal within a diamond and never grow down the tree, the regions selected always
// form a conformal cut, so their meshes match without cracks.
#pragma once

#include "MultiresolutionFile.h"

#include <cstddef>
#include <vector>

namespace resmr
{

/// Regions (indices into file.Regions()) of the conformal cut for `tolerance` (model units):
/// the coarsest whose error is at most the tolerance, or leaves. A tolerance of 0 gives the
/// finest level.
std::vector<std::size_t> SelectByError(const MultiresolutionFile& file, double tolerance);

/// Every region of one level (0: the coarsest; levels past the finest give the finest).
std::vector<std::size_t> SelectLevel(const MultiresolutionFile& file, int level);

} // namespace resmr
