// Holding a target frame rate by the projected error tolerance, paper Sec. 6.3: the primitive
// count, and so the frame time, falls as the tolerance grows, so the tolerance is scaled by
// the ratio of measured to target frame time, a little each frame.
//
// Contract:
// - Update(frameSeconds) takes the last frame's measured time and gives the tolerance (pixels)
//   for the next frame. Frames over HighFraction of the target raise the tolerance at once in
//   proportion (the 99th percentile matters more than the mean); frames under LowFraction
//   lower it gently; in between it stays, so the tolerance does not oscillate and the
//   frame-to-frame jitter (a fifth under llvmpipe) stays within the target.
// - The tolerance stays within [MinimumPixels, MaximumPixels]. The maximum is far above any
//   picture one wants: the bound projects each region's largest error at its box's point
//   nearest the eye, so in a low flight the roots' bound is thousands of pixels, and a
//   smaller cap (256 px once) left the controller stuck with a million triangles in view.
// - A frame that drew ancestors in place of meshes still loading (complete = false) does not
//   lower the tolerance: its time says nothing of the detail wanted, and refining on it ran the
//   tolerance down to the minimum while a model's first meshes loaded, then the arriving
//   meshes slowed a dozen frames past the target. Slow incomplete frames still raise it.
// - Tolerance grows as frame time to the power 1/2: triangles drawn go as about 1 / tol^2
//   for surfaces (screen-space error bounds a linear size).
// - Steps act on the cut, not on a number: the selection reports the range of tolerances
//   that give the frame's cut (CutRange), and any tolerance in it draws the same thing. A
//   step to refine starts from the range's low end, one to coarsen from its high end, so
//   every step changes what is drawn. Without it a tolerance raised far above the view's
//   errors (a slow frame at the roots, or near leaves of a low flight that no tolerance
//   short of thousands of pixels coarsens) took dozens of frames to mean anything again:
//   dozens of frames too coarse, or too slow. A refining step still lowers the tolerance by
//   at most MaxRefineStep a frame, since the range is this view's and the next may differ.
// - Detail is traded last (ours, not the paper's): a slow frame while the camera moves first
//   lowers the render scale (the fraction of the view's width and height the surface is drawn
//   at, then stretched to the view), down to ScaleFloor, and only then coarsens the geometry;
//   with headroom the geometry refines first and the scale comes back only once nothing is
//   left to refine. A fill-bound frame (a software rasterizer, a laptop, a remote desktop)
//   costs about its pixel count, which no tolerance lowers: at the roots a 1280x720 frame of
//   a billion-cell model still took 120 ms on llvmpipe. Still frames (the camera did not
//   move) neither use nor change the scale: they are drawn at full resolution.
// - The quality floor (ours): the tolerance never rises above Ceiling (SetMaximumPixels), the
//   coarsest picture the user accepts while moving; a frame still too slow there is late
//   rather than wrong. MaximumPixels as the ceiling lets the controller go as far as it likes.
// - Steered by the estimated error (ours): the bound overstates the picture's real error, and
//   by how much depends on the view (a low flight's bound is its nearest box corner's, far
//   below what is seen), so the floor is also set on the frame's estimated error
//   (ViewSelection::estimatedErrorPixels, SetMaximumEstimatedPixels). Taking the estimate as
//   proportional to the cut's bound, the tolerance may not rise past the one whose estimate
//   would be EstimateAim of that floor, and a complete frame whose estimate is past the floor
//   refines to it (a quarter at most a frame) whatever its time: late rather than wrong. The
//   aim below the floor keeps a cut's steps from flipping the frames between two cuts. The
//   estimate does not grow smoothly with the tolerance (merging a diamond of a coarse level
//   can double it), so a step that took the estimate past the floor also blocks coarsening
//   from where the cut before it began to change (its CutRange::coarsenAt); without it the
//   frames flipped between the two cuts every other frame. The block rises by BlockRelease a
//   frame, as the view moves on. Ceiling still holds, so the bound limits what an estimate can
//   let through.
// - The floor before the frame (ours): HoldEstimateFloor takes the frame's ideal cut (what it
//   will draw once its wanted meshes are in, ViewSelection::ideal) before it is drawn, and
//   refines past the floor at once, with no quarter-a-frame limit, since the view is the one
//   about to be drawn. Without it a frame still loading kept its tolerance, so while a large
//   model's first meshes came in (seconds) the loader fetched a cut already known to be too
//   coarse, and the controller's starting tolerance stayed what the frames were drawn at.
#pragma once

#include <limits>

namespace resmr
{

/// The tolerances (pixels) that draw the same cut as the last frame's: a tolerance below
/// `refineBelow` splits a diamond drawn whole (0: nothing can split now), one at or above
/// `coarsenAt` merges a split diamond (infinity: nothing is split). The defaults say nothing.
struct CutRange
{
  double refineBelow = std::numeric_limits<double>::infinity();
  double coarsenAt = 0;
  /// The cut's largest projected error and its estimated error (ViewSelection), pixels; an
  /// estimate of 0 or less says nothing.
  double bound = 0;
  double estimate = 0;
};

class FrameRateController
{
public:
  static constexpr double MinimumPixels = 0.5;
  static constexpr double MaximumPixels = 65536;
  /// The band of frame times, as fractions of the target, the tolerance is held in, and the
  /// time each correction aims at.
  static constexpr double LowFraction = 0.6, HighFraction = 0.85, AimFraction = 0.7;
  /// The most one frame lowers the tolerance by, as a factor (see CutRange).
  static constexpr double MaxRefineStep = 0.25;
  /// Where, as a fraction of the estimated-error floor, steps steered by the estimate aim.
  static constexpr double EstimateAim = 0.8;
  /// How fast, as a factor a frame, a block on coarsening set by the estimate lifts.
  static constexpr double BlockRelease = 1.02;

  /// The default ScaleFloor: half the width and height, a quarter of the pixels, where a
  /// cell of two pixels and a grid line of one still show.
  static constexpr double DefaultScaleFloor = 0.5;
  /// The most one frame raises the scale by, as a factor.
  static constexpr double MaxScaleStep = 1.25;

  void SetTargetFramesPerSecond(double fps) { this->TargetSeconds = fps > 0 ? 1.0 / fps : 0.1; }
  /// The lowest render scale moving frames may use, in (0, 1]; 1: always full resolution.
  void SetScaleFloor(double floor);
  /// The coarsest tolerance moving frames may use, in [MinimumPixels, MaximumPixels].
  void SetMaximumPixels(double pixels);
  double MaximumTolerance() const { return this->Ceiling; }
  /// The coarsest estimated error (pixels) moving frames may have; infinity: no such floor.
  void SetMaximumEstimatedPixels(double pixels);
  /// The render scale for the next moving frame (1 until a slow moving frame lowers it).
  double Scale() const { return this->RenderScale; }
  double TargetFramesPerSecond() const { return 1.0 / this->TargetSeconds; }
  void Reset(double tolerancePixels);
  double Tolerance() const { return this->Pixels; }
  /// The tolerance for the next frame, from the time the last one took, whether it drew all
  /// the detail the tolerance selected, the tolerances that draw the same cut, and whether the
  /// camera moved since the frame before (only moving frames change the scale).
  double Update(double frameSeconds, bool complete = true, const CutRange& same = CutRange(), bool moving = false);
  /// The tolerance for the frame about to be drawn, given its ideal cut at the current one
  /// (see the contract): lower when that cut's estimate is past the floor, else unchanged.
  double HoldEstimateFloor(const CutRange& ideal);

private:
  double Coarsen(double factor, const CutRange& same);
  /// A complete frame past the estimated-error floor: refine to it, whatever the frame's time.
  double RefineToEstimateFloor(const CutRange& same, double ratio, bool moving);
  /// The tolerance within the estimated-error floor from `cut`, lowering by at most the factor
  /// `step` (0: no limit); blocks coarsening back to the cut that broke it.
  double FloorTolerance(const CutRange& cut, double step);
  /// The largest tolerance the estimated-error floor allows, from the frame's cut.
  double EstimateLimit(const CutRange& same) const;
  double Refine(double factor, const CutRange& same);

  double TargetSeconds = 0.1;
  double Pixels = 1;
  double Ceiling = MaximumPixels;
  double EstimateCeiling = std::numeric_limits<double>::infinity();
  double EstimateBlock = MaximumPixels; ///< coarsening stays below it (see the contract)
  double LastGoodCoarsenAt = 0;         ///< coarsenAt of the last complete cut within the floor
  double Floor = DefaultScaleFloor;
  double RenderScale = 1;
};

} // namespace resmr
