/**
 * @class   vtkSMMultiresolutionSurfaceRepresentationProxy
 * @brief   Proxy of the Multiresolution Surface whose readout comes from where it renders.
 *
 * The surface always renders distributed: in client/server mode the server draws it and
 * the client's copy of vtkMultiresolutionSurfaceRepresentation never does, so its readout
 * stays 0. vtkSMProxy pulls information properties from the first process of the proxy's
 * location, the client here; this proxy pulls them from the render server's root instead
 * (the same process in builtin mode). Parallel servers report rank 0's frame.
 */
#ifndef vtkSMMultiresolutionSurfaceRepresentationProxy_h
#define vtkSMMultiresolutionSurfaceRepresentationProxy_h

#include "ResMRRepresentationsModule.h"
#include "vtkSMRepresentationProxy.h"

class RESMRREPRESENTATIONS_EXPORT vtkSMMultiresolutionSurfaceRepresentationProxy : public vtkSMRepresentationProxy
{
public:
  static vtkSMMultiresolutionSurfaceRepresentationProxy* New();
  vtkTypeMacro(vtkSMMultiresolutionSurfaceRepresentationProxy, vtkSMRepresentationProxy);
  void PrintSelf(ostream& os, vtkIndent indent) override;

protected:
  vtkSMMultiresolutionSurfaceRepresentationProxy();
  ~vtkSMMultiresolutionSurfaceRepresentationProxy() override;

  void UpdatePropertyInformationInternal(vtkSMProperty* property = nullptr) override;

private:
  vtkSMMultiresolutionSurfaceRepresentationProxy(const vtkSMMultiresolutionSurfaceRepresentationProxy&) = delete;
  void operator=(const vtkSMMultiresolutionSurfaceRepresentationProxy&) = delete;
};

#endif
