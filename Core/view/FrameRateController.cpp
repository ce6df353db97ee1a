// Frame-rate control by projected error tolerance, paper Sec. 6.3.
#include "FrameRateController.h"

#include <algorithm>
#include <cmath>

namespace resmr
{

void FrameRateController::Reset(double tolerancePixels)
{
  this->Pixels = std::clamp(tolerancePixels, MinimumPixels, this->Ceiling);
  this->RenderScale = 1;
  this->EstimateBlock = MaximumPixels;
  this->LastGoodCoarsenAt = 0;
}

void FrameRateController::SetMaximumPixels(double pixels)
{
  this->Ceiling = std::isfinite(pixels) ? std::clamp(pixels, MinimumPixels, MaximumPixels) : MaximumPixels;
  this->Pixels = std::min(this->Pixels, this->Ceiling);
}

void FrameRateController::SetMaximumEstimatedPixels(double pixels)
{
  this->EstimateCeiling = pixels > 0 ? pixels : std::numeric_limits<double>::infinity();
}

double FrameRateController::EstimateLimit(const CutRange& same) const
{
  if (!std::isfinite(this->EstimateCeiling))
  {
    return MaximumPixels;
  }
  // Strictly below the block: at it, the cut that broke the floor comes back.
  const double blocked = std::nextafter(this->EstimateBlock, 0.0);
  if (!(same.estimate > 0) || !(same.bound > 0))
  {
    return blocked;
  }
  return std::min(blocked, same.bound * EstimateAim * this->EstimateCeiling / same.estimate);
}

void FrameRateController::SetScaleFloor(double floor)
{
  this->Floor = std::isfinite(floor) ? std::clamp(floor, 0.05, 1.0) : 1.0;
  this->RenderScale = std::max(this->RenderScale, this->Floor);
}

double FrameRateController::Update(double frameSeconds, bool complete, const CutRange& same, bool moving)
{
  if (!(frameSeconds > 0) || !std::isfinite(frameSeconds))
  {
    return this->Pixels;
  }
  // Frame times jitter from frame to frame (loads, uploads, the system), so the tolerance is
  // held in a band below the target, and the slow tail stays inside it.
  const double ratio = frameSeconds / this->TargetSeconds;
  if (complete && same.estimate > this->EstimateCeiling && this->Pixels > MinimumPixels)
  {
    return this->RefineToEstimateFloor(same, ratio, moving);
  }
  if (complete && same.estimate <= this->EstimateCeiling)
  {
    this->LastGoodCoarsenAt = std::isfinite(same.coarsenAt) ? same.coarsenAt : 0;
  }
  // The block lifts slowly: the view moves on, and the cut it kept out may be fine there.
  this->EstimateBlock = std::min(MaximumPixels, this->EstimateBlock * BlockRelease);
  const double limit = this->EstimateLimit(same);
  if (ratio > HighFraction)
  {
    const double factor = std::min(4.0, std::sqrt(ratio / AimFraction)); // near or over budget: back off now
    if (moving && this->RenderScale > this->Floor)
    {
      // Pixels first: the fill part of a frame goes as the square of the scale.
      this->RenderScale = std::max(this->Floor, this->RenderScale / factor);
      return this->Pixels;
    }
    const double before = this->Pixels;
    this->Pixels = std::max(before, std::min(this->Coarsen(factor, same), limit));
    return this->Pixels;
  }
  if (ratio < LowFraction && complete)
  {
    const double factor = std::max(0.8, std::sqrt(ratio / AimFraction)); // headroom: refine a step at a time
    const bool finest = same.refineBelow <= 0 || this->Pixels <= MinimumPixels;
    if (finest && moving && this->RenderScale < 1)
    {
      this->RenderScale = std::min({ 1.0, this->RenderScale * MaxScaleStep, this->RenderScale / factor });
      return this->Pixels;
    }
    return this->Refine(factor, same);
  }
  return this->Pixels;
}

double FrameRateController::RefineToEstimateFloor(const CutRange& same, double ratio, bool moving)
{
  // Past the estimated-error floor (the view came closer to what this cut simplified, or a
  // step coarsened more than the estimate's proportion foretold): refine.
  this->Pixels = this->FloorTolerance(same, MaxRefineStep);
  if (ratio > HighFraction && moving)
  {
    // Slow as well: the pixels pay for the detail the floor wants.
    this->RenderScale = std::max(this->Floor, this->RenderScale / std::min(4.0, std::sqrt(ratio / AimFraction)));
  }
  return this->Pixels;
}

double FrameRateController::HoldEstimateFloor(const CutRange& ideal)
{
  if (ideal.estimate > this->EstimateCeiling && this->Pixels > MinimumPixels)
  {
    this->Pixels = this->FloorTolerance(ideal, 0);
  }
  return this->Pixels;
}

double FrameRateController::FloorTolerance(const CutRange& cut, double step)
{
  // Coarsen no more up to where the last cut within the floor began to change.
  this->EstimateBlock =
    this->LastGoodCoarsenAt > 0 && this->LastGoodCoarsenAt <= this->Pixels ? this->LastGoodCoarsenAt : this->Pixels;
  this->LastGoodCoarsenAt = 0;
  const double limit = this->EstimateLimit(cut);
  const double from = cut.refineBelow < this->Pixels && cut.refineBelow > 0 ? cut.refineBelow : this->Pixels;
  return std::clamp(std::max(std::min(from, limit), this->Pixels * step), MinimumPixels, this->Ceiling);
}

double FrameRateController::Coarsen(double factor, const CutRange& same)
{
  const double from = same.coarsenAt > this->Pixels && std::isfinite(same.coarsenAt)
    ? same.coarsenAt // every tolerance below it draws this frame again
    : this->Pixels;
  this->Pixels = std::clamp(from * factor, MinimumPixels, this->Ceiling);
  return this->Pixels;
}

double FrameRateController::Refine(double factor, const CutRange& same)
{
  const double from = same.refineBelow < this->Pixels && same.refineBelow > 0
    ? same.refineBelow // every tolerance above it draws this frame again
    : this->Pixels;
  // At most a quarter a frame: the range is this view's, and the next may be another (a cut in
  // a camera path, from a close look where only a far diamond can still split, to a low
  // flight); refining straight to the far diamond's tolerance would start the flight far over
  // budget for many frames while the tolerance climbed back.
  const double next = std::max(from * factor, this->Pixels * MaxRefineStep);
  this->Pixels = std::clamp(next, MinimumPixels, this->Ceiling);
  return this->Pixels;
}

} // namespace resmr
