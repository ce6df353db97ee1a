// The pick pass's target (ours): one pixel of float colour and depth, into which the
// Multiresolution Surface mapper draws its frame's cut through the view's own viewport moved so
// that the picked pixel is the target's one, each fragment painting its cell's (i, j, k)
// (resmr::CellFromPickPixel). The geometry is placed and snapped exactly as in the frame (an
// offset of whole pixels), so the pixel names the cell the frame shows there, edges included.
// A pick costs one draw of the cut into one pixel and adds a few bytes of GPU memory. Private
// to the Multiresolution Surface mapper.
#ifndef vtkMultiresolutionCellPicker_h
#define vtkMultiresolutionCellPicker_h

#include "vtkMultiresolutionOffscreenTarget.h"

#include <array>

class vtkOpenGLRenderWindow;
class vtkWindow;

class vtkMultiresolutionCellPicker
{
public:
  vtkMultiresolutionCellPicker() = default;
  ~vtkMultiresolutionCellPicker() = default;

  /// Binds the one-pixel target, cleared to nothing drawn (alpha 0, far depth), with a
  /// viewport of `width` x `height` whose pixel (x, y) is the target's; false (the view's
  /// framebuffer still bound) where it cannot be made.
  bool Begin(vtkOpenGLRenderWindow* window, int x, int y, int width, int height);
  /// Reads the pixel (RGBA, and depth in [0, 1]) and rebinds the view's framebuffer and
  /// viewport.
  void End(vtkOpenGLRenderWindow* window, std::array<float, 4>& rgba, float& depth);
  void ReleaseGraphicsResources(vtkWindow* window);

private:
  unsigned int Framebuffer = 0, Color = 0, Depth = 0; ///< GL names (renderbuffers), 0: none
  vtkMultiresolutionOffscreenTarget Target;
};

#endif
