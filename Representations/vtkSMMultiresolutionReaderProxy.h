/**
 * @class   vtkSMMultiresolutionReaderProxy
 * @brief   Proxy of the .resmr reader that warns when a stock filter is applied to it.
 *
 * The reader's output is a descriptor of the model (its box's 8 corner points), not its
 * cells, so stock Slice, Clip, Threshold, Contour or Extract Subset applied downstream would
 * silently cut or threshold that box. When such a filter is registered with this reader
 * upstream (GUI, pvpython, client/server alike: proxies live on the client), one warning
 * names the filter and the file and says what to use instead.
 */
#ifndef vtkSMMultiresolutionReaderProxy_h
#define vtkSMMultiresolutionReaderProxy_h

#include "ResMRRepresentationsModule.h"
#include "vtkSMSourceProxy.h"
#include "vtkWeakPointer.h"

#include <string>

class RESMRREPRESENTATIONS_EXPORT vtkSMMultiresolutionReaderProxy : public vtkSMSourceProxy
{
public:
  static vtkSMMultiresolutionReaderProxy* New();
  vtkTypeMacro(vtkSMMultiresolutionReaderProxy, vtkSMSourceProxy);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The warning for a stock filter `xmlName` (Cut, Clip, Threshold, Contour, ExtractSubset,
  /// ClipClosedSurface) applied to the descriptor of `file`; empty for any other proxy.
  static std::string StockFilterWarning(const char* xmlName, const std::string& file);

protected:
  vtkSMMultiresolutionReaderProxy();
  ~vtkSMMultiresolutionReaderProxy() override;

  void CreateVTKObjects() override;

private:
  vtkSMMultiresolutionReaderProxy(const vtkSMMultiresolutionReaderProxy&) = delete;
  void operator=(const vtkSMMultiresolutionReaderProxy&) = delete;

  /// Warns if the proxy just registered is a stock filter with this reader upstream.
  void OnRegister(vtkObject* caller, unsigned long event, void* data);
  unsigned long ObserverTag = 0;
  vtkWeakPointer<vtkObject> Observed; ///< the session's proxy manager
};

#endif
