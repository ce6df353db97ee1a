#include "vtkSMMultiresolutionReaderProxy.h"

#include "vtkCommand.h"
#include "vtkObjectFactory.h"
#include "vtkSMInputProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxyManager.h"
#include "vtkSMSessionProxyManager.h"

#include <cstring>
#include <string>

vtkStandardNewMacro(vtkSMMultiresolutionReaderProxy);

vtkSMMultiresolutionReaderProxy::vtkSMMultiresolutionReaderProxy() = default;

vtkSMMultiresolutionReaderProxy::~vtkSMMultiresolutionReaderProxy()
{
  if (this->Observed)
  {
    this->Observed->RemoveObserver(this->ObserverTag);
  }
}

void vtkSMMultiresolutionReaderProxy::CreateVTKObjects()
{
  if (this->ObjectsCreated)
  {
    return;
  }
  this->Superclass::CreateVTKObjects();
  vtkSMSessionProxyManager* proxies = this->GetSessionProxyManager();
  if (proxies && !this->Observed)
  {
    this->Observed = proxies;
    this->ObserverTag =
      proxies->AddObserver(vtkCommand::RegisterEvent, this, &vtkSMMultiresolutionReaderProxy::OnRegister);
  }
}

std::string vtkSMMultiresolutionReaderProxy::StockFilterWarning(const char* xmlName, const std::string& file)
{
  const char* stock[][2] = { { "Cut", "Slice" }, { "Clip", "Clip" }, { "Threshold", "Threshold" },
    { "Contour", "Contour" }, { "ExtractSubset", "Extract Subset" }, { "ClipClosedSurface", "Clip Closed Surface" } };
  for (const auto& filter : stock)
  {
    if (xmlName && std::strcmp(xmlName, filter[0]) == 0)
    {
      return std::string(filter[1]) + " on " + file +
        " acts on the multiresolution descriptor's 8 corner points, not on the model's cells: use "
        "Filters > Multiresolution > Multiresolution Extract Subset (MultiresolutionExtractSubset in pvpython) "
        "for I, J, K boxes and slices of the model, and Multiresolution Threshold "
        "(MultiresolutionThreshold) to keep the cells whose property value lies in a range.";
    }
  }
  return std::string();
}

void vtkSMMultiresolutionReaderProxy::OnRegister(vtkObject*, unsigned long, void* data)
{
  auto* info = static_cast<vtkSMProxyManager::RegisteredProxyInformation*>(data);
  if (!info || info->Type != vtkSMProxyManager::RegisteredProxyInformation::PROXY || !info->Proxy || !info->GroupName ||
    std::strcmp(info->GroupName, "sources") != 0)
  {
    return;
  }
  const std::string file = vtkSMPropertyHelper(this, "FileName").GetAsString();
  const std::string warning = StockFilterWarning(info->Proxy->GetXMLName(), file);
  if (warning.empty())
  {
    return;
  }
  // This reader upstream of the new filter, through any filters between.
  vtkSMProxy* upstream = info->Proxy;
  for (int depth = 0; upstream && depth < 32; ++depth)
  {
    auto* input = vtkSMInputProperty::SafeDownCast(upstream->GetProperty("Input"));
    upstream = input && input->GetNumberOfProxies() > 0 ? input->GetProxy(0) : nullptr;
    if (upstream == this)
    {
      vtkWarningMacro(<< warning);
      return;
    }
  }
}

void vtkSMMultiresolutionReaderProxy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
