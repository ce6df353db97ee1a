#include "vtkMultiresolutionOffscreenTarget.h"

#include "MultiresolutionQuadVS.h"
#include "MultiresolutionStretchFS.h"

#include "vtkObject.h" // vtkOpenGLError.h's macros need it (VTK 9.3)
#include "vtkOpenGLError.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkOpenGLVertexArrayObject.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureUnitManager.h"
#include "vtk_glew.h"

#include <algorithm>
#include <cmath>

namespace
{
/// A 2D texture of `width` x `height` texels, sampled with `filter`; the unit's binding kept.
unsigned int MakeTexture(int width, int height, int internalFormat, unsigned int format, unsigned int type, int filter)
{
  GLint bound = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &bound);
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexImage2D(GL_TEXTURE_2D, 0, internalFormat, width, height, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(bound));
  return texture;
}
} // namespace

vtkMultiresolutionOffscreenTarget::vtkMultiresolutionOffscreenTarget() = default;
vtkMultiresolutionOffscreenTarget::~vtkMultiresolutionOffscreenTarget() = default;

namespace
{
/// A framebuffer with `color` and `depth` (0: none) attached; 0 if incomplete.
unsigned int MakeFramebuffer(vtkOpenGLRenderWindow* window, unsigned int color, unsigned int depth)
{
  GLuint framebuffer = 0;
  glGenFramebuffers(1, &framebuffer);
  vtkOpenGLState* state = window->GetState();
  state->PushFramebufferBindings();
  state->vtkglBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color, 0);
  if (depth)
  {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
  }
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  state->PopFramebufferBindings();
  if (!complete)
  {
    glDeleteFramebuffers(1, &framebuffer);
    return 0;
  }
  return framebuffer;
}
} // namespace

bool vtkMultiresolutionOffscreenTarget::Allocate(vtkOpenGLRenderWindow* window, int width, int height)
{
  // Raw GL objects, freed by glDelete* alone: VTK's framebuffer and texture objects make their
  // window current to free themselves, which fails while a view is being torn down.
  this->ReleaseGraphicsResources(window);
  this->Color = MakeTexture(width, height, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, GL_LINEAR);
  this->Depth = MakeTexture(width, height, GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, GL_NEAREST);
  this->ColorFramebuffer = MakeFramebuffer(window, this->Color, this->Depth);
  if (!this->ColorFramebuffer)
  {
    this->ReleaseGraphicsResources(window);
    return false;
  }
  this->Size = { width, height };
  return true;
}

bool vtkMultiresolutionOffscreenTarget::AllocateVisibility(vtkOpenGLRenderWindow* window)
{
  if (!this->VisibilityFramebuffer)
  {
    this->CellData =
      MakeTexture(this->Size[0], this->Size[1], GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT, GL_NEAREST);
    this->VisibilityFramebuffer = MakeFramebuffer(window, this->CellData, this->Depth);
    this->ShadingFramebuffer = MakeFramebuffer(window, this->Color, 0);
  }
  return this->VisibilityFramebuffer && this->ShadingFramebuffer;
}

bool vtkMultiresolutionOffscreenTarget::Ready(
  vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale, bool visibility)
{
  int width = 0, height = 0, x = 0, y = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x, &y);
  if (width < 2 || height < 2)
  {
    return false;
  }
  if ((!this->ColorFramebuffer || this->Size[0] != width || this->Size[1] != height) &&
    !this->Allocate(window, width, height))
  {
    return false;
  }
  if (visibility && !this->AllocateVisibility(window))
  {
    return false;
  }
  this->Drawn = { std::max(1, static_cast<int>(std::lround(width * scale))),
    std::max(1, static_cast<int>(std::lround(height * scale))) };
  this->Reduced = scale < 1;
  vtkOpenGLState* state = window->GetState();
  state->vtkglGetIntegerv(GL_VIEWPORT, this->SavedViewport.data());
  state->vtkglGetIntegerv(GL_SCISSOR_BOX, this->SavedScissor.data());
  state->PushFramebufferBindings();
  this->ViewBound = false;
  this->BindAndClear(window, visibility ? this->VisibilityFramebuffer : this->ColorFramebuffer, true);
  return true;
}

void vtkMultiresolutionOffscreenTarget::BindAndClear(
  vtkOpenGLRenderWindow* window, unsigned int framebuffer, bool depth)
{
  vtkOpenGLState* state = window->GetState();
  state->vtkglBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  const GLenum target = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &target);
  state->vtkglViewport(0, 0, this->Drawn[0], this->Drawn[1]);
  state->vtkglScissor(0, 0, this->Drawn[0], this->Drawn[1]);
  state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  if (framebuffer == this->VisibilityFramebuffer)
  {
    const GLuint none[4] = { 0, 0, 0, 0 };
    glClearBufferuiv(GL_COLOR, 0, none);
  }
  else
  {
    state->vtkglClearColor(0, 0, 0, 0);
    state->vtkglClear(GL_COLOR_BUFFER_BIT);
  }
  if (depth)
  {
    state->vtkglClearDepth(1);
    state->vtkglDepthMask(GL_TRUE);
    state->vtkglClear(GL_DEPTH_BUFFER_BIT);
  }
}

bool vtkMultiresolutionOffscreenTarget::BeginReduced(vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale)
{
  return scale < 1 && this->Ready(window, renderer, scale, false);
}

bool vtkMultiresolutionOffscreenTarget::BeginVisibility(
  vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale)
{
  return this->Ready(window, renderer, std::min(scale, 1.0), true);
}

void vtkMultiresolutionOffscreenTarget::Shade(vtkOpenGLRenderWindow* window, vtkShaderProgram* program)
{
  vtkOpenGLState* state = window->GetState();
  if (this->Reduced)
  {
    // Onto the reduced colour target, stretched by End with the visibility pass's depth.
    this->BindAndClear(window, this->ShadingFramebuffer, false);
    state->vtkglDisable(GL_DEPTH_TEST);
  }
  else
  {
    // Onto the view, with the surface's depth, so the view's other actors hide it and it them.
    this->RestoreView(window);
    state->vtkglEnable(GL_DEPTH_TEST);
    state->vtkglDepthFunc(GL_LEQUAL);
    state->vtkglDepthMask(GL_TRUE);
  }
  state->vtkglDisable(GL_BLEND);
  state->vtkglDisable(GL_CULL_FACE);
  vtkTextureUnitManager* units = window->GetTextureUnitManager();
  const int dataUnit = units->Allocate(), depthUnit = units->Allocate();
  if (dataUnit >= 0 && depthUnit >= 0)
  {
    state->vtkglActiveTexture(GL_TEXTURE0 + dataUnit);
    glBindTexture(GL_TEXTURE_2D, this->CellData);
    state->vtkglActiveTexture(GL_TEXTURE0 + depthUnit);
    glBindTexture(GL_TEXTURE_2D, this->Depth);
    program->SetUniformi("surfaceData", dataUnit);
    program->SetUniformi("surfaceDepth", depthUnit);
    const float drawn[2] = { float(this->Drawn[0]), float(this->Drawn[1]) };
    program->SetUniform2f("drawnSize", drawn);
    this->DrawQuad(program);
    glBindTexture(GL_TEXTURE_2D, 0);
    state->vtkglActiveTexture(GL_TEXTURE0 + dataUnit);
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  if (dataUnit >= 0)
  {
    units->Free(dataUnit);
  }
  if (depthUnit >= 0)
  {
    units->Free(depthUnit);
  }
  vtkOpenGLStaticCheckErrorMacro("after shading the multiresolution surface");
}

void vtkMultiresolutionOffscreenTarget::RestoreView(vtkOpenGLRenderWindow* window)
{
  if (this->ViewBound)
  {
    return;
  }
  vtkOpenGLState* state = window->GetState();
  state->PopFramebufferBindings();
  const auto& v = this->SavedViewport;
  const auto& c = this->SavedScissor;
  state->vtkglViewport(v[0], v[1], v[2], v[3]);
  state->vtkglScissor(c[0], c[1], c[2], c[3]);
  this->ViewBound = true;
}

void vtkMultiresolutionOffscreenTarget::End(vtkOpenGLRenderWindow* window)
{
  this->RestoreView(window);
  if (this->Reduced)
  {
    this->Stretch(window);
  }
}

void vtkMultiresolutionOffscreenTarget::DrawQuad(vtkShaderProgram* program)
{
  // The programs are the shader cache's (the window frees them); the quad's buffers are made
  // for each draw, so only the vertex array is ours, laid out again for each program.
  if (!this->Quad)
  {
    this->Quad = vtkSmartPointer<vtkOpenGLVertexArrayObject>::New();
  }
  this->Quad->ShaderProgramChanged();
  float corners[12] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 };
  float coordinates[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };
  vtkOpenGLRenderUtilities::RenderQuad(corners, coordinates, program, this->Quad);
}

void vtkMultiresolutionOffscreenTarget::Stretch(vtkOpenGLRenderWindow* window)
{
  vtkOpenGLState* state = window->GetState();
  vtkShaderProgram* program =
    window->GetShaderCache()->ReadyShaderProgram(MultiresolutionQuadVS, MultiresolutionStretchFS, "");
  if (!program)
  {
    return;
  }
  vtkTextureUnitManager* units = window->GetTextureUnitManager();
  const int colorUnit = units->Allocate(), depthUnit = units->Allocate();
  if (colorUnit < 0 || depthUnit < 0)
  {
    units->Free(std::max(colorUnit, depthUnit));
    return;
  }
  state->vtkglActiveTexture(GL_TEXTURE0 + colorUnit);
  glBindTexture(GL_TEXTURE_2D, this->Color);
  state->vtkglActiveTexture(GL_TEXTURE0 + depthUnit);
  glBindTexture(GL_TEXTURE_2D, this->Depth);
  program->SetUniformi("colorTexture", colorUnit);
  program->SetUniformi("depthTexture", depthUnit);
  const float fraction[2] = { float(this->Drawn[0]) / float(this->Size[0]),
    float(this->Drawn[1]) / float(this->Size[1]) };
  const float half[2] = { 0.5f / float(this->Size[0]), 0.5f / float(this->Size[1]) };
  program->SetUniform2f("drawnFraction", fraction);
  program->SetUniform2f("halfTexel", half);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_LEQUAL);
  state->vtkglDepthMask(GL_TRUE);
  state->vtkglDisable(GL_BLEND);
  state->vtkglDisable(GL_CULL_FACE);
  this->DrawQuad(program);
  glBindTexture(GL_TEXTURE_2D, 0);
  state->vtkglActiveTexture(GL_TEXTURE0 + colorUnit);
  glBindTexture(GL_TEXTURE_2D, 0);
  units->Free(depthUnit);
  units->Free(colorUnit);
  vtkOpenGLStaticCheckErrorMacro("after stretching the reduced multiresolution surface");
}

void vtkMultiresolutionOffscreenTarget::ReleaseGraphicsResources(vtkWindow*)
{
  if (this->Quad)
  {
    this->Quad->ReleaseGraphicsResources();
    this->Quad = nullptr;
  }
  const GLuint framebuffers[3] = { this->ColorFramebuffer, this->VisibilityFramebuffer, this->ShadingFramebuffer };
  glDeleteFramebuffers(3, framebuffers); // zeros are ignored
  const GLuint textures[3] = { this->Color, this->Depth, this->CellData };
  glDeleteTextures(3, textures);
  this->ColorFramebuffer = this->VisibilityFramebuffer = this->ShadingFramebuffer = 0;
  this->Color = this->Depth = this->CellData = 0;
  this->Size = { 0, 0 };
}
