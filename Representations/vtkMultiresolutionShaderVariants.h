// The Multiresolution Surface's shader programs, one a painting state (paper Sec. 5): the
// fragment shader (MultiresolutionSurfaceFS.glsl) is compiled with the state's switches
// defined, so a frame's shader carries no branches for what it does not paint. Sources are
// kept by state; VTK's shader cache keeps the compiled programs. Private to the
// Multiresolution Surface mapper.
#ifndef vtkMultiresolutionShaderVariants_h
#define vtkMultiresolutionShaderVariants_h

#include <map>
#include <string>

class vtkOpenGLRenderWindow;
class vtkShaderProgram;

class vtkMultiresolutionShaderVariants
{
public:
  /// A painting state: the switches of the fragment shader.
  struct Painting
  {
    int colorMode = 0; ///< vtkMultiresolutionSurfaceMapper::ColorModes
    bool layerView = false;
    bool logScale = false;
    bool gridLines = false;
    bool specular = false;
    bool tableNormals = false; ///< tops and bottoms only, lit by the normal table
    bool wallDepths = false;   ///< side fragments find their layer in the wall depth table
    bool cellFilter = false;   ///< an I/J/K range or property filter: cut planes, face values
    int lighting = 0;          ///< vtkOpenGLRenderer's lighting complexity (0: unlit)
    int lightCount = 0;        ///< the renderer's lights switched on
  };

  /// The fragment shader's source for `painting`: its switches defined after the version line
  /// VTK puts in, the renderer's light uniforms (`lightUniforms`, as
  /// vtkOpenGLRenderer::GetLightingUniforms declares them) and one term a light.
  static std::string FragmentSource(const Painting& painting, const std::string& lightUniforms);

  /// The program for `painting` in `window`'s shader cache, compiled the first time and bound;
  /// null when it does not compile.
  vtkShaderProgram* Ready(vtkOpenGLRenderWindow* window, const Painting& painting, const char* lightUniforms);

private:
  std::map<long, std::string> Sources; ///< by the state's switches as bits
};

#endif
