#include "vtkMultiresolutionShaderVariants.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkShaderProgram.h"

#include "MultiresolutionSurfaceFS.h"
#include "MultiresolutionSurfaceVS.h"

std::string vtkMultiresolutionShaderVariants::FragmentSource(const Painting& painting)
{
  const std::string source = MultiresolutionSurfaceFS;
  const std::string versionLine = "//VTK::System::Dec\n";
  const std::size_t at = source.find(versionLine);
  const auto flag = [](bool on) { return std::to_string(on ? 1 : 0); };
  const std::string defines = "#define COLOR_MODE " + std::to_string(painting.colorMode) + "\n#define LAYER_VIEW " +
    flag(painting.layerView) + "\n#define LOG_SCALE " + flag(painting.logScale) + "\n#define GRID_LINES " +
    flag(painting.gridLines) + "\n#define SPECULAR " + flag(painting.specular) + "\n";
  return at == std::string::npos
    ? source
    : source.substr(0, at + versionLine.size()) + defines + source.substr(at + versionLine.size());
}

vtkShaderProgram* vtkMultiresolutionShaderVariants::Ready(vtkOpenGLRenderWindow* window, const Painting& painting)
{
  const int key = painting.colorMode | (painting.layerView ? 4 : 0) | (painting.logScale ? 8 : 0) |
    (painting.gridLines ? 16 : 0) | (painting.specular ? 32 : 0);
  auto found = this->Sources.find(key);
  if (found == this->Sources.end())
  {
    found = this->Sources.emplace(key, FragmentSource(painting)).first;
  }
  return window->GetShaderCache()->ReadyShaderProgram(MultiresolutionSurfaceVS, found->second.c_str(), "");
}
