//VTK::System::Dec
// A quad over the viewport, as vtkOpenGLRenderUtilities::RenderQuad binds its corners and
// texture coordinates: the stretching and the shading passes draw one.

in vec4 vertexMC;
in vec2 tcoordMC;
out vec2 tcoordVC;

void main()
{
  tcoordVC = tcoordMC;
  gl_Position = vertexMC;
}
