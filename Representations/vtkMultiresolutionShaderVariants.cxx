#include "vtkMultiresolutionShaderVariants.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkShaderProgram.h"

#include "MultiresolutionSurfaceFS.h"
#include "MultiresolutionSurfaceVS.h"

namespace
{
void ReplaceTag(std::string& source, const std::string& tag, const std::string& text)
{
  const std::size_t at = source.find(tag);
  if (at != std::string::npos)
  {
    source.replace(at, tag.size(), text);
  }
}

// One call a light, by the names vtkOpenGLRenderer gives its uniforms (lightColor0, ...).
std::string LightTerms(int lighting, int lightCount)
{
  std::string terms;
  for (int i = 0; lighting > 1 && i < lightCount; ++i)
  {
    const std::string n = std::to_string(i);
    terms += lighting == 2
      ? "AddLight(normal, toEye, -lightDirectionVC" + n + ", lightColor" + n + ", 1.0, diffuseSum, specularSum);\n"
      : "AddAnyLight(normal, toEye, viewPosition, lightColor" + n + ", lightDirectionVC" + n + ", lightPositionVC" + n +
        ", lightAttenuation" + n + ", lightConeAngle" + n + ", lightExponent" + n + ", lightPositional" + n +
        ", diffuseSum, specularSum);\n";
  }
  return terms;
}
} // namespace

std::string vtkMultiresolutionShaderVariants::FragmentSource(const Painting& painting, const std::string& lightUniforms)
{
  std::string source = MultiresolutionSurfaceFS;
  const auto flag = [](bool on) { return std::to_string(on ? 1 : 0); };
  const std::string defines = "#define COLOR_MODE " + std::to_string(painting.colorMode) + "\n#define LAYER_VIEW " +
    flag(painting.layerView) + "\n#define LOG_SCALE " + flag(painting.logScale) + "\n#define GRID_LINES " +
    flag(painting.gridLines) + "\n#define SPECULAR " + flag(painting.specular) + "\n#define TABLE_NORMALS " +
    flag(painting.tableNormals) + "\n#define WALL_DEPTHS " + flag(painting.wallDepths) + "\n#define LIGHTING " +
    std::to_string(painting.lighting) + "\n#define CELL_FILTER " + flag(painting.cellFilter) + "\n";
  ReplaceTag(source, "//RESMR::LightUniforms\n", painting.lighting > 0 ? lightUniforms + "\n" : "");
  ReplaceTag(source, "//RESMR::Lights\n", LightTerms(painting.lighting, painting.lightCount));
  const std::string versionLine = "//VTK::System::Dec\n";
  ReplaceTag(source, versionLine, versionLine + defines);
  return source;
}

vtkShaderProgram* vtkMultiresolutionShaderVariants::Ready(
  vtkOpenGLRenderWindow* window, const Painting& painting, const char* lightUniforms)
{
  const long key = painting.colorMode | (painting.layerView ? 4 : 0) | (painting.logScale ? 8 : 0) |
    (painting.gridLines ? 16 : 0) | (painting.specular ? 32 : 0) | (long(painting.lighting) << 6) |
    (long(painting.lightCount) << 8) | (painting.tableNormals ? 1L << 40 : 0) | (painting.wallDepths ? 1L << 41 : 0) |
    (painting.cellFilter ? 1L << 42 : 0);
  auto found = this->Sources.find(key);
  if (found == this->Sources.end())
  {
    found = this->Sources.emplace(key, FragmentSource(painting, lightUniforms ? lightUniforms : "")).first;
  }
  return window->GetShaderCache()->ReadyShaderProgram(MultiresolutionSurfaceVS, found->second.c_str(), "");
}
