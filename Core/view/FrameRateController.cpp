// Frame-rate control by projected error tolerance, paper Sec. 6.3.
#include "FrameRateController.h"

#include <algorithm>
#include <cmath>

namespace resmr
{

void FrameRateController::Reset(double tolerancePixels)
{
  this->Pixels = std::clamp(tolerancePixels, MinimumPixels, MaximumPixels);
}

double FrameRateController::Update(double frameSeconds, bool complete, const CutRange& same)
{
  if (!(frameSeconds > 0) || !std::isfinite(frameSeconds))
  {
    return this->Pixels;
  }
  // Frame times jitter from frame to frame (loads, uploads, the system), so the tolerance is
  // held in a band below the target, and the slow tail stays inside it.
  const double ratio = frameSeconds / this->TargetSeconds;
  double factor = 1;
  if (ratio > HighFraction)
  {
    factor = std::min(4.0, std::sqrt(ratio / AimFraction)); // near or over budget: back off now
  }
  else if (ratio < LowFraction && complete)
  {
    factor = std::max(0.8, std::sqrt(ratio / AimFraction)); // headroom: refine a step at a time
  }
  double from = this->Pixels;
  if (factor > 1 && same.coarsenAt > from && std::isfinite(same.coarsenAt))
  {
    from = same.coarsenAt; // every tolerance below it draws this frame again
  }
  else if (factor < 1 && same.refineBelow < from && same.refineBelow > 0)
  {
    from = same.refineBelow; // every tolerance above it does
  }
  double next = from * factor;
  if (factor < 1)
  {
    // At most a quarter a frame: the range is this view's, and the next may be another (a
    // cut in a camera path, from a close look where only a far diamond can still split, to
    // a low flight); refining straight to the far diamond's tolerance would start the flight
    // far over budget for many frames while the tolerance climbed back.
    next = std::max(next, this->Pixels * MaxRefineStep);
  }
  this->Pixels = std::clamp(next, MinimumPixels, MaximumPixels);
  return this->Pixels;
}

} // namespace resmr
