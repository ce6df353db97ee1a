#include "pqMultiresolutionReadout.h"

#include "pqRepresentation.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <cstring>

vtkSMProxy* pqMultiresolutionReadout::Surface(pqRepresentation* representation, bool visibleOnly)
{
  vtkSMProxy* proxy = representation ? representation->getProxy() : nullptr;
  if (!proxy || !proxy->GetProperty("Representation") || (visibleOnly && !representation->isVisible()))
  {
    return nullptr;
  }
  const char* type = vtkSMPropertyHelper(proxy, "Representation").GetAsString();
  // The exposed readout property belongs to the surface sub-proxy (GetSubProxy is protected).
  vtkSMProperty* readout = proxy->GetProperty("TrianglesDrawn");
  vtkSMProxy* surface = readout ? readout->GetParent() : nullptr;
  if (!type || std::strcmp(type, "Multiresolution Surface") != 0 || !surface || !surface->GetXMLName() ||
    std::strcmp(surface->GetXMLName(), "ResMRSurfaceRepresentation") != 0)
  {
    return nullptr;
  }
  return surface;
}

pqMultiresolutionReadout pqMultiresolutionReadout::Pull(vtkSMProxy* surface)
{
  pqMultiresolutionReadout readout;
  surface->UpdatePropertyInformation();
  readout.Tolerance = vtkSMPropertyHelper(surface, "CurrentTolerance").GetAsDouble();
  readout.EstimatedError = vtkSMPropertyHelper(surface, "CurrentEstimatedError").GetAsDouble();
  readout.RenderScale = vtkSMPropertyHelper(surface, "CurrentRenderScale").GetAsDouble();
  readout.Moving = vtkSMPropertyHelper(surface, "CurrentFrameMoving").GetAsInt() != 0;
  readout.TargetFrameRate = vtkSMPropertyHelper(surface, "TargetFrameRate").GetAsDouble();
  readout.ResidentMB = vtkSMPropertyHelper(surface, "ResidentMB").GetAsDouble();
  readout.BudgetMB = vtkSMPropertyHelper(surface, "MemoryBudgetMB").GetAsInt();
  readout.Triangles = vtkSMPropertyHelper(surface, "TrianglesDrawn").GetAsDouble();
  readout.Regions = vtkSMPropertyHelper(surface, "RegionsDrawn").GetAsInt();
  readout.Substituted = vtkSMPropertyHelper(surface, "RegionsSubstituted").GetAsInt();
  readout.FrameMs = vtkSMPropertyHelper(surface, "LastFrameMs").GetAsDouble();
  readout.LoadsPending = vtkSMPropertyHelper(surface, "LoadsPending").GetAsInt() != 0;
  readout.RefreshWaitMs = vtkSMPropertyHelper(surface, "RefreshWaitMs").GetAsDouble();
  const char* error = vtkSMPropertyHelper(surface, "LastError").GetAsString();
  readout.Error = QString::fromUtf8(error ? error : "");
  return readout;
}
