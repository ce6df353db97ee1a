#include "vtkSMMultiresolutionSurfaceRepresentationProxy.h"

#include "vtkObjectFactory.h"
#include "vtkPVSession.h"
#include "vtkSMMessage.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyIterator.h"
#include "vtkSMSession.h"
#include "vtkSmartPointer.h"

vtkStandardNewMacro(vtkSMMultiresolutionSurfaceRepresentationProxy);

vtkSMMultiresolutionSurfaceRepresentationProxy::vtkSMMultiresolutionSurfaceRepresentationProxy() = default;
vtkSMMultiresolutionSurfaceRepresentationProxy::~vtkSMMultiresolutionSurfaceRepresentationProxy() = default;

void vtkSMMultiresolutionSurfaceRepresentationProxy::UpdatePropertyInformationInternal(vtkSMProperty* property)
{
  this->CreateVTKObjects();
  vtkSMSession* session = this->GetSession();
  if (!this->ObjectsCreated || !session)
  {
    return;
  }

  // The same pull request vtkSMProxy makes, addressed to the render server's root.
  vtkSMMessage message;
  Variant* names = message.AddExtension(PullRequest::arguments);
  names->set_type(Variant::STRING);
  if (property)
  {
    if (property->GetInformationOnly())
    {
      names->add_txt(property->GetXMLName());
    }
  }
  else
  {
    vtkSmartPointer<vtkSMPropertyIterator> it;
    it.TakeReference(this->NewPropertyIterator());
    it->SetTraverseSubProxies(0);
    for (it->Begin(); !it->IsAtEnd(); it->Next())
    {
      if (it->GetProperty()->GetInformationOnly())
      {
        names->add_txt(it->GetKey());
      }
    }
  }
  if (names->txt_size() == 0)
  {
    return;
  }
  message.set_global_id(this->GetGlobalID());
  message.set_location(vtkPVSession::RENDER_SERVER_ROOT);
  session->PullState(&message);
  this->LoadState(&message, session->GetProxyLocator());
}

void vtkSMMultiresolutionSurfaceRepresentationProxy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
