// The pick pass's target (ours): one pixel of float colour and depth, into which the
// Multiresolution Surface mapper draws its frame's cut through a matrix that blows the picked
// pixel up to the whole viewport, each fragment painting its cell's (i, j, k)
// (resmr::CellFromPickPixel). A pick costs one draw of the cut into one pixel and adds a few
// bytes of GPU memory. Private to the Multiresolution Surface mapper.
#ifndef vtkMultiresolutionCellPicker_h
#define vtkMultiresolutionCellPicker_h

#include <array>

class vtkOpenGLRenderWindow;
class vtkWindow;

class vtkMultiresolutionCellPicker
{
public:
  vtkMultiresolutionCellPicker() = default;
  ~vtkMultiresolutionCellPicker() = default;

  /// Binds the one-pixel target, cleared to nothing drawn (alpha 0, far depth); false (the
  /// view's framebuffer still bound) where it cannot be made.
  bool Begin(vtkOpenGLRenderWindow* window);
  /// Reads the pixel (RGBA, and depth in [0, 1]) and rebinds the view's framebuffer and
  /// viewport.
  void End(vtkOpenGLRenderWindow* window, std::array<float, 4>& rgba, float& depth);
  void ReleaseGraphicsResources(vtkWindow* window);

private:
  unsigned int Framebuffer = 0, Color = 0, Depth = 0; ///< GL names (renderbuffers), 0: none
  std::array<int, 4> SavedViewport{}, SavedScissor{};
};

#endif
