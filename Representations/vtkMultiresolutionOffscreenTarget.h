// Drawing into one of the Multiresolution Surface's own framebuffers (ours): the view's
// viewport, scissor and framebuffer bindings saved, the target bound and cleared to nothing
// drawn (colour 0, far depth), and all of it restored after. Shared by the reduced-resolution
// target and the pick target. Private to the Multiresolution Surface mapper.
#ifndef vtkMultiresolutionOffscreenTarget_h
#define vtkMultiresolutionOffscreenTarget_h

#include "vtkOpenGLState.h"
#include "vtk_glew.h"

#include <array>

struct vtkMultiresolutionOffscreenTarget
{
  std::array<int, 4> SavedViewport{}, SavedScissor{};

  /// Binds `framebuffer` (colour attachment 0) with `viewport` and `scissor` (x, y, w, h), cleared.
  void Bind(vtkOpenGLState* state, unsigned int framebuffer, const std::array<int, 4>& viewport,
    const std::array<int, 4>& scissor)
  {
    state->vtkglGetIntegerv(GL_VIEWPORT, this->SavedViewport.data());
    state->vtkglGetIntegerv(GL_SCISSOR_BOX, this->SavedScissor.data());
    state->PushFramebufferBindings();
    state->vtkglBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    const GLenum target = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &target);
    state->vtkglViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
    state->vtkglScissor(scissor[0], scissor[1], scissor[2], scissor[3]);
    state->vtkglClearColor(0, 0, 0, 0);
    state->vtkglClearDepth(1);
    state->vtkglDepthMask(GL_TRUE);
    state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    state->vtkglClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }

  /// The view's framebuffer, viewport and scissor again.
  void Restore(vtkOpenGLState* state)
  {
    state->PopFramebufferBindings();
    const auto& v = this->SavedViewport;
    const auto& c = this->SavedScissor;
    state->vtkglViewport(v[0], v[1], v[2], v[3]);
    state->vtkglScissor(c[0], c[1], c[2], c[3]);
  }
};

#endif
