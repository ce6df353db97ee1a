// View-dependent selection of region meshes for one frame, paper Sec. 6.2: a stateless
// top-down traversal of the diamond hierarchy that splits a diamond while its projected error
// (Lindstrom's bound) exceeds a pixel tolerance, culls regions outside the view frustum, culls
// top and bottom surfaces facing away by their normal cones, and draws a region whose
// children are not resident yet with the region itself (never a hole, never a crack).
//
// Contract:
// - World coordinates are VTK's: (x, y, z) with z = -depth (z up). The file's bounds are
//   (x, y, depth); the selection converts them.
// - Projected error of a diamond: its model-space error e (RegionRecord::error, the same for
//   both triangles, never smaller than a descendant's) seen as a sphere of radius e at the
//   point of the diamond's bounding box nearest the eye: pixels = e * PixelsPerUnit / d,
//   d = that distance but at least nearDistance, since nothing nearer than the near plane is
//   drawn (perspective; infinite when both are 0), or e * PixelsPerUnit (parallel).
// - Estimated error of a region (ours): the bound is a poor guide to what the picture shows
//   (it takes the largest error at the box's nearest point; a 64 px frame still puts 96% of its
//   pixels within 8 px of the exact one), so each drawn region also gets its typical error
//   (RegionRecord::typicalError; its own error in files that lack it) seen at the box's centre
//   (no nearer than its nearest point or the near plane). The frame's estimate is their mean
//   weighted by the share of the view each region's box covers (so a coarse region far off
//   counts for the little it shows); the frame-rate controller steers by it
//   (FrameRateController.h).
// - Conformity: a diamond is split only when every triangle of it is in the cut and all of
//   their children (absent regions are empty and count as resident) are resident. Bounding
//   boxes enclose every descendant, so projected errors never grow down the tree and the cut
//   of an all-resident hierarchy is the ideal one.
// - A root region that is not resident is not drawn (the caller loads the roots first).
// - `drawn` is ordered nearest first, so early depth rejection spares hidden fragments.
// - `wanted` lists the regions of the ideal cut (as if everything were resident) and the
//   ancestors leading to them, coarse before fine and near before far: the loading order.
// - Range view (ours): see Select; the forced splits set neither refineBelowPixels nor
//   coarsenAtPixels, which no tolerance changes.
// - `ideal` (ours): the figures below of that ideal cut, what the frame will show once its
//   wanted meshes are in; a frame still loading can tell from them whether its tolerance is
//   fine enough.
#pragma once

#include "CellRange.h"
#include "MultiresolutionFile.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace resmr
{

struct ViewParameters
{
  /// World to clip coordinates, row-major (clip = M * (x, y, z, 1)); OpenGL clip space.
  std::array<double, 16> worldToClip{};
  std::array<double, 3> eye{};       ///< camera position, world
  std::array<double, 3> direction{}; ///< unit view direction, world (parallel projection)
  bool parallel = false;
  /// Pixels one world unit covers at distance 1 (perspective: viewport height / (2 tan(fovy/2)))
  /// or anywhere (parallel: viewport height / (2 parallel scale)).
  double pixelsPerUnit = 1;
  double tolerancePixels = 1;
  double nearDistance = 0; ///< near clipping plane's distance from the eye (world units)
};

struct DrawnRegion
{
  std::size_t region = 0;                      ///< index into MultiresolutionFile::Regions()
  bool top = true, bottom = true, side = true; ///< surfaces not culled by their normal cones
  double projectedError = 0;                   ///< the region's error in pixels this frame (Lindstrom's bound)
  double estimatedError = 0;                   ///< the region's estimated error in pixels (see the contract)
  double screenShare = 0;                      ///< share of the viewport its box's screen rectangle covers
};

struct ViewSelection
{
  std::vector<DrawnRegion> drawn;  ///< what to draw this frame (resident regions only), nearest first
  std::vector<std::size_t> wanted; ///< the loading order (see the contract)
  /// Largest projected error (pixels) of a drawn region's diamond; what the tolerance holds
  /// once everything wanted is resident.
  double largestProjectedError = 0;
  /// The picture's estimated real error (pixels): the drawn regions' estimates, weighted by the
  /// share of the view they cover (see the contract).
  double estimatedErrorPixels = 0;
  /// The tolerances between which this frame's cut stays the same, for the frame-rate
  /// controller: a tolerance below `refineBelowPixels` splits a diamond drawn whole now (0:
  /// none can split, being leaves or waiting on loads), one at or above `coarsenAtPixels`
  /// draws a diamond split now whole (infinity: none is split).
  double refineBelowPixels = 0;
  double coarsenAtPixels = std::numeric_limits<double>::infinity();
  /// Drawn regions standing in for wanted descendants that are not resident.
  std::size_t substituted = 0;
  /// The same figures of the ideal cut (every region resident): largest projected error,
  /// estimated error and refineBelowPixels.
  struct Ideal
  {
    double largestProjectedError = 0;
    double estimatedErrorPixels = 0;
    double refineBelowPixels = 0;
  } ideal;
  /// The model's surface is closed and faces outward, so seen from outside its back faces are
  /// hidden and the renderer may cull them: true when the eye (perspective) is farther from the
  /// box of every region than twice the near plane (which then cuts no part of the model at
  /// a field of view below 120 degrees). Seen from inside, or through a near plane cutting the
  /// model, the back faces are what shows. Parallel projections are never culled.
  bool backFacesHidden = false;
};

/// The diamond tree of one file, built once: children and diamond partners of every region.
class ViewSelector
{
public:
  explicit ViewSelector(const MultiresolutionFile& file);

  /// Selects for `view`; `resident(region)` says whether a region's mesh is ready to draw.
  ViewSelection Select(const ViewParameters& view, const std::function<bool(std::size_t)>& resident) const;

  /// The I/J/K range view (CellRange.h): `ranged(classes)` fills, per region (the vector comes
  /// sized to the regions, every one Unknown), where the range lies against the regions known
  /// so far. Regions Outside are culled; a region Crossed is split whatever its error, down to
  /// the leaves, and so are the diamonds that must split for it to be in the cut (its parent,
  /// its partner's parent, and theirs in turn); a region Unknown (not decoded yet) is decided
  /// by its error until it is known. Empty: the whole model.
  using RangeClassifier = std::function<void(std::vector<RangeClass>& classes)>;
  void SetRangeClassifier(RangeClassifier ranged) { this->Ranged = std::move(ranged); }

  /// Property filters (PropertyFilter.h): `errors(widths)` fills, per region (the vector comes
  /// sized to the regions, every one 0), the width (model units) within which a filter that
  /// crosses it may draw cells that do not pass while it is drawn coarse. A region splits while
  /// that width projects above the tolerance, as while its error does, and so do the diamonds
  /// its split needs (its partner and parent take its width; culled ones split too, as for a
  /// range). Empty: none.
  using FilterErrorSource = std::function<void(std::vector<float>& widths)>;
  void SetFilterErrors(FilterErrorSource errors) { this->FilterErrors = std::move(errors); }

  /// The root regions (level 0), which the caller keeps resident.
  const std::vector<std::size_t>& Roots() const { return this->RootRegions; }

private:
  struct Node
  {
    std::array<int64_t, 2> children{ -1, -1 }; ///< region indices, -1: absent (empty)
    int64_t partner = -1;                      ///< the other triangle of its diamond, -1: none
    int64_t parent = -1;                       ///< -1: a root
  };
  /// Makes filter widths monotone over what a split needs (a region's diamond partner and
  /// parent take its width), as regions' errors are (see SetFilterErrors).
  void PropagateFilterErrors(std::vector<float>& widths) const;
  /// Per region, whether the range forces it to split (see SetRangeClassifier).
  std::vector<uint8_t> ForcedSplits(const std::vector<RangeClass>& classes) const;
  const MultiresolutionFile* File = nullptr;
  std::vector<Node> Nodes;
  std::vector<std::size_t> RootRegions;
  std::array<double, 6> ModelBox{}; ///< every region's box: xmin, xmax, ymin, ymax, zmin, zmax (z up)
  RangeClassifier Ranged;
  FilterErrorSource FilterErrors;
};

/// Whether a surface of `region` whose normals lie in `cone` (RegionSurface::cone; cosine -2:
/// empty) need not be drawn: empty, or facing away from the eye from every point of the
/// region's bounding volume. Select culls the stored top and bottom with it; the single-layer
/// view, whose faces are not those surfaces, culls its layer's top and bottom the same way.
bool SurfaceCulled(const std::array<float, 4>& cone, const RegionRecord& region, const ViewParameters& view);

/// A region's error in pixels seen from `view` (Lindstrom's bound, as Select splits by it).
double ProjectedErrorPixels(const RegionRecord& region, const ViewParameters& view);

/// A region's estimated error in pixels seen from `view` (see the contract).
double EstimatedErrorPixels(const RegionRecord& region, const ViewParameters& view);

/// Where the camera will probably be a frame ahead: the last two views extrapolated linearly
/// (eye and clip matrix), for loading ahead of need.
ViewParameters PredictNextView(const ViewParameters& previous, const ViewParameters& current);

} // namespace resmr
