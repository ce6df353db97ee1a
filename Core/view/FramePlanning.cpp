// Per-frame upload and timing plan (paper Sec. 6.1, 6.3); see FramePlanning.h.
#include "FramePlanning.h"

#include <algorithm>
#include <cmath>

namespace resmr
{

double UploadBudgetMs(double targetFramesPerSecond, double previousFrameMs)
{
  if (targetFramesPerSecond > 0)
  {
    return UploadShareOfFrame * 1000 / targetFramesPerSecond;
  }
  const double previous = std::isfinite(previousFrameMs) ? previousFrameMs : 0.0;
  return std::max(UploadMsAtFixedTolerance, UploadShareOfPreviousFrame * previous);
}

namespace
{
double CapScale(double budgetMs)
{
  return std::isfinite(budgetMs) ? std::max(1.0, budgetMs / UploadMsAtFixedTolerance) : 1.0;
}
} // namespace

double RefreshWaitMs(double lastFrameMs, bool loadersBusy)
{
  const double frame = std::isfinite(lastFrameMs) ? lastFrameMs : 0.0;
  return loadersBusy ? std::clamp(frame, RefreshWaitFloorMs, RefreshWaitCeilingMs) : RefreshWaitFloorMs;
}

std::size_t UploadByteCap(double budgetMs)
{
  return static_cast<std::size_t>(CapScale(budgetMs) * static_cast<double>(UploadBytesPerFrame));
}

std::size_t TableByteCap(double budgetMs)
{
  return static_cast<std::size_t>(CapScale(budgetMs) * static_cast<double>(TableBytesPerFrame));
}

uint32_t SlicesThisFrame(uint32_t slicesLeft, std::size_t sliceBytes, std::size_t& budget, bool unbounded)
{
  if (slicesLeft == 0 || (!unbounded && budget == 0))
  {
    return 0;
  }
  uint32_t slices = slicesLeft;
  if (!unbounded && sliceBytes > 0)
  {
    slices = static_cast<uint32_t>(std::min<std::size_t>(std::max<std::size_t>(budget / sliceBytes, 1), slicesLeft));
  }
  budget -= std::min(budget, slices * sliceBytes);
  return slices;
}

DrawPieceCursor::DrawPieceCursor(const RegionDrawBuffers& buffers, std::size_t maxBytes)
  : Buffers(&buffers)
  , MaxBytes(maxBytes)
{
}

const DrawPiece& DrawPieceCursor::Next()
{
  if (!this->Done() && this->Piece.first != this->Copied)
  {
    this->Piece = NextDrawPiece(*this->Buffers, this->Copied, this->MaxBytes);
  }
  return this->Piece;
}

std::size_t DrawPieceCursor::Advance()
{
  const DrawPiece& piece = this->Next();
  this->Copied = piece.end;
  return piece.bytes;
}

bool MayCopyPiece(
  bool bounded, bool root, const UploadPacer& pacer, std::size_t pieceBytes, std::size_t gpuBytes, std::size_t gpuShare)
{
  return !(bounded && !root && !pacer.Admit(pieceBytes)) && gpuBytes + pieceBytes <= gpuShare;
}

double ControllerStartTolerance(double pixelTolerance)
{
  return std::max(pixelTolerance, ControllerStartPixels);
}

ViewSelection SelectWithinFloor(const ViewSelector& selector, FrameRateController& controller, ViewParameters& view,
  const std::function<bool(std::size_t)>& resident)
{
  ViewSelection selection = selector.Select(view, resident);
  for (int pass = 0; pass < FloorPasses; ++pass)
  {
    CutRange ideal;
    ideal.refineBelow = selection.ideal.refineBelowPixels;
    ideal.bound = selection.ideal.largestProjectedError;
    ideal.estimate = selection.ideal.estimatedErrorPixels;
    const double tolerance = controller.HoldEstimateFloor(ideal);
    if (!(tolerance < view.tolerancePixels))
    {
      break;
    }
    view.tolerancePixels = tolerance;
    selection = selector.Select(view, resident);
  }
  return selection;
}

double MeasuredFrameMs(
  double frameMs, double rendererMs, double intervalMs, double targetFramesPerSecond, bool afterAllocation)
{
  double measured = afterAllocation ? frameMs : std::max(frameMs, rendererMs);
  if (intervalMs < 3000 / targetFramesPerSecond && !afterAllocation)
  {
    measured = std::max(measured, intervalMs);
  }
  return measured;
}

} // namespace resmr
