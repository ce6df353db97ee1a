#include "vtkMultiresolutionReducedResolution.h"

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
// The quad's corners and texture coordinates as vtkOpenGLRenderUtilities::RenderQuad binds them.
const char* StretchVS = R"(//VTK::System::Dec
in vec4 vertexMC;
in vec2 tcoordMC;
out vec2 tcoordVC;
void main()
{
  tcoordVC = tcoordMC;
  gl_Position = vertexMC;
}
)";

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

vtkMultiresolutionReducedResolution::vtkMultiresolutionReducedResolution() = default;
vtkMultiresolutionReducedResolution::~vtkMultiresolutionReducedResolution() = default;

bool vtkMultiresolutionReducedResolution::Allocate(vtkOpenGLRenderWindow* window, int width, int height)
{
  // Raw GL objects, freed by glDelete* alone: VTK's framebuffer and texture objects make their
  // window current to free themselves, which fails while a view is being torn down.
  this->ReleaseGraphicsResources(window);
  this->Color = MakeTexture(width, height, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, GL_LINEAR);
  this->Depth = MakeTexture(width, height, GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, GL_NEAREST);
  glGenFramebuffers(1, &this->Framebuffer);
  vtkOpenGLState* state = window->GetState();
  state->PushFramebufferBindings();
  state->vtkglBindFramebuffer(GL_FRAMEBUFFER, this->Framebuffer);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->Color, 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, this->Depth, 0);
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  state->PopFramebufferBindings();
  if (!complete)
  {
    this->ReleaseGraphicsResources(window);
    return false;
  }
  this->Size = { width, height };
  return true;
}

bool vtkMultiresolutionReducedResolution::Begin(vtkOpenGLRenderWindow* window, vtkRenderer* renderer, double scale)
{
  int width = 0, height = 0, x = 0, y = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x, &y);
  if (width < 2 || height < 2)
  {
    return false;
  }
  // Sized to the view once (a fraction of it is drawn into), so a changing scale allocates
  // nothing.
  if ((!this->Framebuffer || this->Size[0] != width || this->Size[1] != height) &&
    !this->Allocate(window, width, height))
  {
    return false;
  }
  this->Drawn = { std::max(1, static_cast<int>(std::lround(width * scale))),
    std::max(1, static_cast<int>(std::lround(height * scale))) };
  this->Target.Bind(window->GetState(), this->Framebuffer, { 0, 0, this->Drawn[0], this->Drawn[1] },
    { 0, 0, this->Drawn[0], this->Drawn[1] });
  return true;
}

void vtkMultiresolutionReducedResolution::End(vtkOpenGLRenderWindow* window)
{
  vtkOpenGLState* state = window->GetState();
  this->Target.Restore(state);
  // The program is the shader cache's (the window frees it); the quad's buffers are made for
  // each draw, so only the vertex array is ours.
  vtkShaderProgram* program = window->GetShaderCache()->ReadyShaderProgram(StretchVS, MultiresolutionStretchFS, "");
  if (!program)
  {
    return;
  }
  if (!this->Quad)
  {
    this->Quad = vtkSmartPointer<vtkOpenGLVertexArrayObject>::New();
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
  float corners[12] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 };
  float coordinates[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };
  vtkOpenGLRenderUtilities::RenderQuad(corners, coordinates, program, this->Quad);
  glBindTexture(GL_TEXTURE_2D, 0);
  state->vtkglActiveTexture(GL_TEXTURE0 + colorUnit);
  glBindTexture(GL_TEXTURE_2D, 0);
  units->Free(depthUnit);
  units->Free(colorUnit);
  vtkOpenGLStaticCheckErrorMacro("after stretching the reduced multiresolution surface");
}

void vtkMultiresolutionReducedResolution::ReleaseGraphicsResources(vtkWindow*)
{
  if (this->Quad)
  {
    this->Quad->ReleaseGraphicsResources();
    this->Quad = nullptr;
  }
  if (this->Framebuffer)
  {
    glDeleteFramebuffers(1, &this->Framebuffer);
  }
  const GLuint textures[2] = { this->Color, this->Depth };
  if (this->Color || this->Depth)
  {
    glDeleteTextures(2, textures);
  }
  this->Framebuffer = this->Color = this->Depth = 0;
  this->Size = { 0, 0 };
}
