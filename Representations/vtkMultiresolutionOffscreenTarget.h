// Where the Multiresolution Surface is drawn before it reaches the view (ours, not the
// paper's). Private to the Multiresolution Surface mapper.
//
// - Two passes (the default for lit and property colours): the visibility pass draws the
//   meshes into a target of cell coordinates, face kinds, grid line strengths and facet
//   normals with the depth; the shading pass then reads the tables, lights and lines each
//   covered pixel once, onto the view or onto the reduced colour target. A software
//   rasterizer shades small triangles in whole blocks of pixels, so a one-pass frame runs its
//   table reads and lights many times a pixel; two passes run them once.
// - Reduced resolution (moving frames, the frame-rate controller's render scale): the surface
//   is drawn through a viewport of that fraction of an offscreen target the size of the view,
//   then stretched onto the view with its depth.
//
// Contract: Begin* binds a target (false: nothing bound, draw straight to the view); every
// successful Begin* is closed by End, which leaves the view's framebuffer, viewport and
// scissor as they were. The textures are sized to the view once, so a changing scale
// allocates nothing.
#ifndef vtkMultiresolutionOffscreenTarget_h
#define vtkMultiresolutionOffscreenTarget_h

#include "vtkSmartPointer.h"

#include <array>

class vtkOpenGLVertexArrayObject;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkShaderProgram;
class vtkWindow;

class vtkMultiresolutionOffscreenTarget
{
public:
  vtkMultiresolutionOffscreenTarget();
  ~vtkMultiresolutionOffscreenTarget();

  /// One pass at a reduced resolution: binds the colour target, cleared, with a viewport of
  /// `scale` (< 1) of the renderer's.
  bool BeginReduced(vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale);
  /// Two passes: binds the visibility target, cleared, with a viewport of `scale` (1: the
  /// renderer's whole size) of the renderer's.
  bool BeginVisibility(vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale);
  /// Draws the shading pass with `program` (bound, its own uniforms set): onto the view at
  /// full scale, with the surface's depth, else onto the reduced colour target.
  void Shade(vtkOpenGLRenderWindow* window, vtkShaderProgram* program);
  /// Rebinds the view's framebuffer, viewport and scissor, and stretches a reduced drawing
  /// onto them.
  void End(vtkOpenGLRenderWindow* window);
  /// Frees the targets and the quad (the window is going away or changing).
  void ReleaseGraphicsResources(vtkWindow* window);

private:
  bool Ready(vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale, bool visibility);
  bool Allocate(vtkOpenGLRenderWindow* window, int width, int height);
  bool AllocateVisibility(vtkOpenGLRenderWindow* window);
  void BindAndClear(vtkOpenGLRenderWindow* window, unsigned int framebuffer, bool depth);
  void RestoreView(vtkOpenGLRenderWindow* window);
  void DrawQuad(vtkShaderProgram* program);
  void Stretch(vtkOpenGLRenderWindow* window);

  // GL names, 0: none. Colour and depth serve one reduced pass; cell data and depth the
  // visibility pass; colour alone the reduced shading pass.
  unsigned int ColorFramebuffer = 0, VisibilityFramebuffer = 0, ShadingFramebuffer = 0;
  unsigned int Color = 0, Depth = 0, CellData = 0;
  std::array<int, 2> Size{}; ///< of the textures: the view's
  vtkSmartPointer<vtkOpenGLVertexArrayObject> Quad;
  std::array<int, 2> Drawn{};                         ///< the drawn viewport's width and height
  bool Reduced = false;                               ///< drawn at a fraction of the view (stretched by End)
  bool ViewBound = true;                              ///< the view's framebuffer is bound again
  std::array<int, 4> SavedViewport{}, SavedScissor{}; ///< the view's, restored by End
};

#endif
