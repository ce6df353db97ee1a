// What stays resident and what stands in, paper Sec. 6.2: one memory budget holds the meshes
// in main memory (the loader, RegionCache) and their GPU mirror together, and data not
// resident yet is replaced by what is (an ancestor for a region, an earlier time step for a
// property table). Ours: the split of the budget, which GPU copies go when the mirror would
// pass its share, which property table is asked for and which is drawn, and which parts of a
// region's buffers are drawn (its simplified side, Sec. 4.3, past a few pixels of error).
#pragma once

#include "PropertyFile.h"
#include "RegionCache.h"
#include "ViewSelection.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace resmr
{

/// The loader's share of a budget of `budgetMB` MB: the GPU mirrors at most what is resident,
/// so half each keeps both together within the budget.
std::size_t MainMemoryShare(int budgetMB);
/// The GPU mirror's share: the rest of the budget.
std::size_t GpuShare(int budgetMB);

/// GPU copies to release, in order, before a piece of `pieceBytes` of the region at
/// `position` in `order` (the frame's regions, most needed first) can be copied, until
/// `gpuBytes` plus the piece fit `gpuShare`: copies of regions not in `order` (the cache still
/// has them), taken from `mirrored` (region, bytes on the GPU) in its order; then copies of
/// regions after `position`, the last first, so that a coarse region the cut needs is never
/// kept out by finer ones copied before it. The result may not be enough: then uploads wait.
std::vector<std::size_t> CopiesToRelease(const std::vector<std::pair<std::size_t, std::size_t>>& mirrored,
  const std::vector<std::size_t>& order, std::size_t position, std::size_t gpuBytes, std::size_t pieceBytes,
  std::size_t gpuShare);

/// The property table a frame asks for.
struct PropertyRequest
{
  bool wanted = false; ///< the property exists (at `step` or as a static table)
  std::string name;
  int32_t step = -1; ///< the table's step: the frame's, or -1 for a static property
  int32_t layer = -1;
};

/// The table for property `name` at `step` in the single-layer `layer` (-1: whole model): a
/// static property has one table, step -1, for every step. Not wanted when `properties` is
/// null, `name` empty or the file has no such table.
PropertyRequest RequestFor(const PropertyFile* properties, const std::string& name, int32_t step, int32_t layer);

/// Whether `table` is the one `request` asks for.
bool IsRequested(const PropertyTableData* table, const PropertyRequest& request);

/// Whether `table` (the one on the GPU) may be drawn for `request`: the requested table, or an
/// earlier time step of the same property and layer standing in until it arrives. Another
/// property is never drawn through this one's colour map.
bool MayStandIn(const PropertyTableData* table, const PropertyRequest& request);

/// Projected error (pixels) past which a region draws its simplified side in place of its exact
/// one, whatever the file's version (see DrawsSimplifiedSide).
constexpr double CoarseSidePixels = 2.0;

/// Whether a region whose error projects to `projectedError` pixels in a frame of `view` draws
/// its simplified side (Sec. 4.3) rather than its exact one: past CoarseSidePixels, where the
/// geometry is no closer anyway. From SidesInPlaceVersion on, the simplified side paints every
/// layer and column within the region's own error of where the exact side paints it, so in a
/// frame whose tolerance is past CoarseSidePixels (a moving frame, mostly) it is also drawn
/// wherever twice the region's error projects within the tolerance, the leaves included: a
/// fifth fewer triangles for the same picture on models of many layers. Frames of a finer
/// tolerance (a still frame at 1 px) keep the exact side of every region within
/// CoarseSidePixels. Older files' simplified sides may paint a layer anywhere on a flat wall.
bool DrawsSimplifiedSide(uint32_t fileVersion, double projectedError, const ViewParameters& view);

/// The regions of `regions` that draw their simplified side seen from `view`
/// (DrawsSimplifiedSide): the cache need not hold their exact one (RegionCache::Request).
std::vector<std::size_t> RegionsWithSimplifiedSide(
  const MultiresolutionFile& file, const std::vector<std::size_t>& regions, const ViewParameters& view);

/// A run of a region's indices drawn as one kind of face (0 top, 1 bottom, 2 side).
struct DrawPart
{
  bool shown = false;
  uint32_t first = 0, count = 0;
  int kind = 0;
  bool oneLayer = false; ///< a side whose triangles each span one layer (the exact side)
  /// Whether the renderer may cull the run's back faces, where it culls at all (the eye
  /// outside the model: ViewSelection::backFacesHidden); see PartsToDraw.
  bool cullBackFaces = true;
};

/// The top, bottom and side index runs of `buffers` for a region drawn as `drawn`. The whole
/// model's top and bottom are culled by the selection (`drawn`); a layer's own top and bottom
/// (`layerView`) and a range's (RegionDrawBuffers::ranged) by their own cones against `region` and `view`. The
/// simplified side is drawn where DrawsSimplifiedSide says so (a file of `fileVersion`), when the region has one: on
/// models of many layers the exact side is most of the triangles. Buffers loaded without
/// their exact side draw the simplified one whatever the error.
/// The top seen from above (the eye not below the region's box) and the bottom seen from
/// below keep their back faces (cullBackFaces false): nearly every triangle of them faces the
/// eye, and those that do not are folds of the visible sheet seen edge-on, where a rasterizer
/// that decides a triangle's facing before snapping it to its sub-pixel grid (llvmpipe) can
/// cull a sliver its neighbours left the only cover of a sample: a pin-hole. The sides and the
/// surface facing away, most of the back faces, may be culled.
std::array<DrawPart, 3> PartsToDraw(const RegionDrawBuffers& buffers, const DrawnRegion& drawn, bool layerView,
  const RegionRecord& region, const ViewParameters& view, uint32_t fileVersion);

} // namespace resmr
