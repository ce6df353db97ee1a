// What one interactive frame may spend, paper Sec. 6.3 (a frame rate held by adjusting the
// cut) with Sec. 6.1's streaming: loaded meshes and the model's tables reach the GPU a bounded
// amount a frame, so a burst of loads or a large table never stalls one frame. Ours: the
// per-frame byte and time allowances, tables copied a slab of slices at a time, meshes copied
// a piece at a time (NextDrawPiece), the admission rule for a piece, and the frame time the
// frame-rate controller is told.
#pragma once

#include "FrameRateController.h"
#include "RegionCache.h"
#include "UploadPacer.h"
#include "ViewSelection.h"

#include <cstddef>
#include <cstdint>

namespace resmr
{

/// Most bytes copied to the GPU in one interactive frame, and the part of it the model's
/// tables may take while they are being copied.
constexpr std::size_t UploadBytesPerFrame = std::size_t(8) << 20;
constexpr std::size_t TableBytesPerFrame = std::size_t(4) << 20;
/// Most bytes of one GPU piece of a region's mesh: a leaf region's mesh on a large model is
/// tens of MB, and copied whole it holds one frame far past its budget; in pieces the pacer
/// admits a frame's copies a piece at a time.
constexpr std::size_t PieceBytes = std::size_t(1) << 20;
/// The time an interactive frame may spend copying meshes (see UploadPacer): a tenth of the
/// target frame time; at a fixed tolerance UploadMsAtFixedTolerance, or a share of the previous
/// frame's time when that is more (ours: a software rasterizer draws a million triangles in a
/// few hundred ms, and 10 ms of copies behind such frames kept a filtered 100M-cell view
/// waiting seconds for meshes already loaded; a frame then takes at most about twice its
/// drawing).
constexpr double UploadShareOfFrame = 0.1;
constexpr double UploadMsAtFixedTolerance = 10.0;
constexpr double UploadShareOfPreviousFrame = 0.5;

/// Milliseconds of copying a frame may spend at `targetFramesPerSecond` (0: fixed tolerance),
/// after a frame of `previousFrameMs`.
double UploadBudgetMs(double targetFramesPerSecond, double previousFrameMs = 0);
/// Bytes a frame may copy in `budgetMs`: UploadBytesPerFrame of meshes and TableBytesPerFrame
/// of tables, more in proportion for a budget above UploadMsAtFixedTolerance (a property's
/// table of the 100M model, 96 MB, took 24 frames at 4 MB behind llvmpipe's 500 ms frames).
std::size_t UploadByteCap(double budgetMs);
std::size_t TableByteCap(double budgetMs);

/// Slices of a 3D table (`slicesLeft` still to copy, `sliceBytes` each) to copy now: whole
/// slices while `budget` lasts, at least one if any budget is left, or all when `unbounded`;
/// 0 when none may go. Takes what they cost from `budget` (never below 0).
uint32_t SlicesThisFrame(uint32_t slicesLeft, std::size_t sliceBytes, std::size_t& budget, bool unbounded);

/// A region's draw buffers walked a piece at a time (NextDrawPiece, at most `maxBytes` each),
/// each piece measured once. The buffers must outlive the cursor.
class DrawPieceCursor
{
public:
  explicit DrawPieceCursor(const RegionDrawBuffers& buffers, std::size_t maxBytes = PieceBytes);
  /// Every index has been passed.
  bool Done() const { return this->Copied >= this->Buffers->indices.size(); }
  /// The next piece (Done() must be false).
  const DrawPiece& Next();
  /// Passes the next piece; its bytes.
  std::size_t Advance();

private:
  const RegionDrawBuffers* Buffers;
  std::size_t MaxBytes;
  std::size_t Copied = 0; ///< indices passed so far
  DrawPiece Piece{ ~std::size_t(0) };
};

/// Whether the next piece (`pieceBytes`) of a region's mesh may be copied this frame:
/// interactive frames (`bounded`) copy the roots whatever it takes (they stand in for
/// everything) and other regions only as `pacer` admits; the GPU's share of the memory budget
/// (`gpuShare`, `gpuBytes` used) is never passed.
bool MayCopyPiece(bool bounded, bool root, const UploadPacer& pacer, std::size_t pieceBytes, std::size_t gpuBytes,
  std::size_t gpuShare);

/// Tolerance (pixels) the frame-rate controller starts from when a frame rate is first
/// targeted: coarse, refined a step a frame, so the first frames after the roots do not draw
/// whatever detail has loaded before the controller catches up.
constexpr double ControllerStartPixels = 64.0;
/// The controller's starting tolerance for a user tolerance of `pixelTolerance`.
double ControllerStartTolerance(double pixelTolerance);

/// Most selections of one frame held within the estimated-error floor (SelectWithinFloor).
constexpr int FloorPasses = 3;
/// Selects a moving frame under a target frame rate (ours): while the ideal cut at the view's
/// tolerance (the controller's) is past the controller's estimated-error floor, the controller
/// lowers the tolerance (FrameRateController::HoldEstimateFloor) and the view is selected
/// again, FloorPasses times at most, since the estimate follows the bound only roughly.
/// `view.tolerancePixels` becomes the tolerance selected at.
ViewSelection SelectWithinFloor(const ViewSelector& selector, FrameRateController& controller, ViewParameters& view,
  const std::function<bool(std::size_t)>& resident);

/// The wait (ms) between a still view's refreshes while work is pending (ours; the GUI's
/// refresh and scripts follow it, readout RefreshWaitMs): while the loaders read, as long as
/// the last frame took (`lastFrameMs`), within [RefreshWaitFloorMs, RefreshWaitCeilingMs]: a
/// software rasterizer's frame of a million triangles takes a few hundred ms of every core,
/// and such frames back to back left the loaders (below the render thread's priority) almost
/// nothing. When the loaders are idle (`loadersBusy` false) and only copies to the GPU remain,
/// which happen in frames, the floor: waiting then only delays the picture.
constexpr double RefreshWaitFloorMs = 30.0;
constexpr double RefreshWaitCeilingMs = 1000.0;
double RefreshWaitMs(double lastFrameMs, bool loadersBusy);

/// The frame time (ms) the frame-rate controller is told. The whole frame is what the user
/// waits for: the frame's own time (`frameMs`), the renderer's time for it (`rendererMs`) and,
/// while frames come back to back (an interval under 3 target frame times), the interval
/// between frames, which also holds compositing, buffer swaps and the application's work. A
/// frame after one that allocated a table texture (`afterAllocation`) counts its own time
/// only, since the renderer's time and the interval still hold that allocation.
double MeasuredFrameMs(
  double frameMs, double rendererMs, double intervalMs, double targetFramesPerSecond, bool afterAllocation);

} // namespace resmr
