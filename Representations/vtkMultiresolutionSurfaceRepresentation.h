/**
 * @class   vtkMultiresolutionSurfaceRepresentation
 * @brief   The "Multiresolution Surface" representation of a .resmr file (paper Sec. 5, 6).
 *
 * Takes the descriptor of vtkMultiresolutionReader, finds the reader upstream for its files
 * and the step shown, and delivers a copy of the descriptor naming them to the processes
 * that render, where vtkMultiresolutionSurfaceMapper reads meshes from the file as the
 * camera asks. Rendering is always distributed: the file is read where the image is made
 * (the server in client/server mode), never shipped to the client. Colouring follows
 * ParaView's colour-by (the property name) and lookup table (colours and range).
 */
#ifndef vtkMultiresolutionSurfaceRepresentation_h
#define vtkMultiresolutionSurfaceRepresentation_h

#include "ResMRRepresentationsModule.h"
#include "vtkNew.h"
#include "vtkPVDataRepresentation.h"
#include "vtkSmartPointer.h"

class vtkActor;
class vtkMultiresolutionSurfaceMapper;
class vtkPolyData;
class vtkScalarsToColors;

class RESMRREPRESENTATIONS_EXPORT vtkMultiresolutionSurfaceRepresentation : public vtkPVDataRepresentation
{
public:
  static vtkMultiresolutionSurfaceRepresentation* New();
  vtkTypeMacro(vtkMultiresolutionSurfaceRepresentation, vtkPVDataRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  int ProcessViewRequest(vtkInformationRequestKey* request, vtkInformation* inInfo, vtkInformation* outInfo) override;
  void SetVisibility(bool visible) override;

  ///@{
  /// Colouring (ColorArrayName, LookupTable): a point or cell array name picks the property.
  void SetInputArrayToProcess(int index, int port, int connection, int fieldAssociation, const char* name) override;
  void SetInputArrayToProcess(
    int index, int port, int connection, int fieldAssociation, int fieldAttributeType) override
  {
    this->Superclass::SetInputArrayToProcess(index, port, connection, fieldAssociation, fieldAttributeType);
  }
  void SetInputArrayToProcess(int index, vtkInformation* info) override
  {
    this->Superclass::SetInputArrayToProcess(index, info);
  }
  void SetInputArrayToProcess(
    int index, int port, int connection, const char* fieldAssociation, const char* attributeTypeOrName) override
  {
    this->Superclass::SetInputArrayToProcess(index, port, connection, fieldAssociation, attributeTypeOrName);
  }
  void SetLookupTable(vtkScalarsToColors* table);
  ///@}

  ///@{
  /// Appearance, forwarded to the actor's property.
  void SetDiffuseColor(double r, double g, double b);
  void SetAmbientColor(double r, double g, double b);
  void SetSpecularColor(double r, double g, double b);
  void SetAmbient(double value);
  void SetDiffuse(double value);
  void SetSpecular(double value);
  void SetSpecularPower(double value);
  void SetInterpolation(int) {} ///< lighting is per fragment always
  void SetOpacity(double) {}    ///< opaque only
  void SetPosition(double x, double y, double z);
  void SetScale(double x, double y, double z);
  void SetOrientation(double x, double y, double z);
  void SetOrigin(double x, double y, double z);
  ///@}

  ///@{
  /// Forwarded to vtkMultiresolutionSurfaceMapper.
  void SetColorMode(int mode);
  void SetPixelTolerance(double pixels);
  void SetTargetFrameRate(double fps);
  void SetMaximumPixelTolerance(double pixels);
  void SetMaximumEstimatedError(double pixels);
  void SetMovingResolutionFloor(double fraction);
  void SetMemoryBudgetMB(int megabytes);
  void SetGridLines(bool show);
  void SetGridLineWidth(double pixels);
  void SetGridLineColor(double r, double g, double b);
  void SetWaitForDetailMs(int milliseconds);
  void SetLayer(int layer);
  double GetCurrentTolerance();
  double GetCurrentEstimatedError();
  double GetCurrentRenderScale();
  int GetCurrentFrameControlled();
  double GetResidentMB();
  double GetTrianglesDrawn();
  int GetRegionsDrawn();
  int GetRegionsSubstituted();
  double GetLastFrameMs();
  int GetLoadsPending();
  double GetRefreshWaitMs();
  const char* GetLastError();
  /// Picking: display pixel (x, y) picked at the next render (see the mapper), and what the
  /// last pick found. The copies are the representation's, so the server's pull reads them.
  void PickAt(double x, double y);
  void InspectCell(int i, int j, int k);
  int GetPicksDone();
  int* GetPickedCell() VTK_SIZEHINT(3);
  int GetPickedActive();
  double* GetPickedPoint() VTK_SIZEHINT(3);
  double* GetPickedCorners() VTK_SIZEHINT(24);
  const char* GetPickedValues();
  ///@}

  vtkMultiresolutionSurfaceMapper* GetMapper() { return this->Mapper; }

  /// 0 and the model's layer count nk: the range of Layer (0 the whole model), read from the
  /// file's header when the input names a file; 0 0 before, and where the representation has
  /// no input (the client's copy in client/server mode).
  vtkGetVector2Macro(LayerRange, int);

protected:
  vtkMultiresolutionSurfaceRepresentation();
  ~vtkMultiresolutionSurfaceRepresentation() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(
    vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector) override;
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

private:
  vtkMultiresolutionSurfaceRepresentation(const vtkMultiresolutionSurfaceRepresentation&) = delete;
  void operator=(const vtkMultiresolutionSurfaceRepresentation&) = delete;

  vtkNew<vtkMultiresolutionSurfaceMapper> Mapper;
  vtkNew<vtkActor> Actor;
  vtkSmartPointer<vtkPolyData> Delivered;
  std::string Error;
  int LayerRange[2] = { 0, 0 };
  std::string LayerRangeFile; ///< the file LayerRange was read from
  int PickedCell[3] = { 0, 0, 0 };
  double PickedPoint[3] = { 0, 0, 0 };
  double PickedCorners[24] = {};
};

#endif
