// Drawing the Multiresolution Surface at a fraction of the view's resolution while the camera
// moves (the frame-rate controller's render scale): an offscreen target the size of the view
// is drawn into through a viewport of that fraction, then stretched onto the view with its
// depth. Per-pixel work (the hash fetches, lighting, grid lines) falls as the square of the
// scale, which fill-bound renderers (llvmpipe, remote desktops) need; the still frame is
// drawn straight to the view at full resolution. Private to the Multiresolution Surface
// mapper.
#ifndef vtkMultiresolutionReducedResolution_h
#define vtkMultiresolutionReducedResolution_h

#include "vtkMultiresolutionOffscreenTarget.h"
#include "vtkSmartPointer.h"

#include <array>

class vtkOpenGLVertexArrayObject;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkWindow;

class vtkMultiresolutionReducedResolution
{
public:
  vtkMultiresolutionReducedResolution();
  ~vtkMultiresolutionReducedResolution();

  /// Binds the offscreen target, cleared, with a viewport of `scale` of the renderer's; false
  /// (the view's framebuffer still bound) where the target cannot be made.
  bool Begin(vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale);
  /// Rebinds the view's framebuffer and viewport and stretches the target onto them.
  void End(vtkOpenGLRenderWindow* window);
  /// Frees the target and the stretching program (the window is going away or changing).
  void ReleaseGraphicsResources(vtkWindow* window);

private:
  bool Allocate(vtkOpenGLRenderWindow* window, int width, int height);

  unsigned int Framebuffer = 0, Color = 0, Depth = 0; ///< GL names, 0: none
  std::array<int, 2> Size{};                          ///< of the textures: the view's
  vtkSmartPointer<vtkOpenGLVertexArrayObject> Quad;
  std::array<int, 2> Drawn{};               ///< the reduced viewport's width and height
  vtkMultiresolutionOffscreenTarget Target; ///< the view's bindings, restored by End
};

#endif
