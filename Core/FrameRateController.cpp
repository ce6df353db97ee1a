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

double FrameRateController::Update(double frameSeconds)
{
  if (!(frameSeconds > 0) || !std::isfinite(frameSeconds))
  {
    return this->Pixels;
  }
  const double ratio = frameSeconds / this->TargetSeconds;
  double factor = 1;
  if (ratio > 1)
  {
    factor = std::min(4.0, std::sqrt(ratio) * 1.1); // over budget: back off now, with margin
  }
  else if (ratio < 0.8)
  {
    factor = std::max(0.8, std::sqrt(ratio / 0.8)); // headroom: refine a step at a time
  }
  this->Pixels = std::clamp(this->Pixels * factor, MinimumPixels, MaximumPixels);
  return this->Pixels;
}

} // namespace resmr
