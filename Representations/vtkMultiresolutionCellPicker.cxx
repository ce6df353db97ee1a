#include "vtkMultiresolutionCellPicker.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtk_glew.h"

bool vtkMultiresolutionCellPicker::Begin(vtkOpenGLRenderWindow* window, int x, int y, int width, int height)
{
  vtkOpenGLState* state = window->GetState();
  if (!this->Framebuffer)
  {
    // Raw GL objects, freed by glDelete* alone (as the reduced-resolution target's).
    glGenRenderbuffers(1, &this->Color);
    glBindRenderbuffer(GL_RENDERBUFFER, this->Color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, 1, 1);
    glGenRenderbuffers(1, &this->Depth);
    glBindRenderbuffer(GL_RENDERBUFFER, this->Depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, 1, 1);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glGenFramebuffers(1, &this->Framebuffer);
    state->PushFramebufferBindings();
    state->vtkglBindFramebuffer(GL_FRAMEBUFFER, this->Framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, this->Color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, this->Depth);
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    state->PopFramebufferBindings();
    if (!complete)
    {
      this->ReleaseGraphicsResources(window);
      return false;
    }
  }
  this->Target.Bind(state, this->Framebuffer, { -x, -y, width, height }, { 0, 0, 1, 1 });
  return true;
}

void vtkMultiresolutionCellPicker::End(vtkOpenGLRenderWindow* window, std::array<float, 4>& rgba, float& depth)
{
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, rgba.data());
  glReadPixels(0, 0, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &depth);
  this->Target.Restore(window->GetState());
}

void vtkMultiresolutionCellPicker::ReleaseGraphicsResources(vtkWindow*)
{
  if (this->Framebuffer)
  {
    glDeleteFramebuffers(1, &this->Framebuffer);
    glDeleteRenderbuffers(1, &this->Color);
    glDeleteRenderbuffers(1, &this->Depth);
  }
  this->Framebuffer = this->Color = this->Depth = 0;
}
