#include "vtkMultiresolutionSurfaceRepresentation.h"

#include "vtkMultiresolutionExtractSubset.h"
#include "vtkMultiresolutionReader.h"
#include "vtkMultiresolutionSurfaceMapper.h"
#include "vtkMultiresolutionThreshold.h"

#include "MultiresolutionFile.h"

#include "vtkActor.h"
#include "vtkAlgorithmOutput.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkPVRenderView.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkScalarsToColors.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <exception>
#include <string>

vtkStandardNewMacro(vtkMultiresolutionSurfaceRepresentation);

vtkMultiresolutionSurfaceRepresentation::vtkMultiresolutionSurfaceRepresentation()
{
  this->Actor->SetMapper(this->Mapper);
  this->Actor->SetVisibility(0);
  this->Actor->SetPickable(0); // the descriptor has no cells a pick could name
}

vtkMultiresolutionSurfaceRepresentation::~vtkMultiresolutionSurfaceRepresentation() = default;

int vtkMultiresolutionSurfaceRepresentation::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1); // the client's copy has no input
  return 1;
}

int vtkMultiresolutionSurfaceRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->Delivered = vtkSmartPointer<vtkPolyData>::New();
  this->Error.clear();
  if (inputVector[0]->GetNumberOfInformationObjects() == 1)
  {
    vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
    // The reader upstream (past ParaView's post filter) names the files; the step is the one
    // the descriptor was made for, so the animation cache keeps the right step with it.
    vtkMultiresolutionReader* reader = nullptr;
    vtkAlgorithm* upstream = this->GetNumberOfInputConnections(0) ? this->GetInputAlgorithm(0, 0) : nullptr;
    for (int depth = 0; upstream && !reader && depth < 8; ++depth)
    {
      reader = vtkMultiresolutionReader::SafeDownCast(upstream);
      upstream = upstream->GetNumberOfInputPorts() > 0 && upstream->GetNumberOfInputConnections(0) > 0
        ? upstream->GetInputAlgorithm(0, 0)
        : nullptr;
    }
    if (!reader)
    {
      this->Error = "Multiresolution Surface needs a .resmr file (a Multiresolution Reservoir source) as input";
      vtkErrorMacro(<< this->Error);
    }
    else if (input && input->GetNumberOfPoints() > 0)
    {
      this->Delivered->ShallowCopy(input);
      this->Delivered->SetFieldData(vtkNew<vtkFieldData>()); // the input's stays as it is
      int step = 0;
      if (input->GetInformation()->Has(vtkDataObject::DATA_TIME_STEP()))
      {
        step = reader->GetStepNumber(input->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()));
      }
      vtkNew<vtkStringArray> source;
      source->SetName(vtkMultiresolutionSurfaceMapper::SourceArrayName());
      source->InsertNextValue(reader->GetFileName() ? reader->GetFileName() : "");
      source->InsertNextValue(reader->GetResolvedPropertyFileName());
      source->InsertNextValue(std::to_string(step));
      source->InsertNextValue(reader->GetApplyMapAxes() ? "1" : "0");
      source->InsertNextValue(reader->GetPropertyFileStamp());
      // An I/J/K range set upstream (Multiresolution Extract Subset), as "I0 I1 J0 J1 K0 K1".
      vtkIntArray* range = vtkIntArray::SafeDownCast(
        input->GetFieldData()->GetAbstractArray(vtkMultiresolutionExtractSubset::RangeArrayName()));
      std::string rangeText;
      for (vtkIdType n = 0; range && range->GetNumberOfValues() == 6 && n < 6; ++n)
      {
        rangeText += (n ? " " : "") + std::to_string(range->GetValue(n));
      }
      // Boxes left out (Exclude), a line "exclude I0 I1 J0 J1 K0 K1" each.
      vtkIntArray* excluded = vtkIntArray::SafeDownCast(
        input->GetFieldData()->GetAbstractArray(vtkMultiresolutionExtractSubset::ExcludedArrayName()));
      for (vtkIdType n = 0; excluded && n + 6 <= excluded->GetNumberOfValues(); n += 6)
      {
        rangeText += "\nexclude";
        for (vtkIdType v = 0; v < 6; ++v)
        {
          rangeText += " " + std::to_string(excluded->GetValue(n + v));
        }
      }
      source->InsertNextValue(rangeText);
      // Property filters set upstream (Multiresolution Threshold), "low high name" a line.
      vtkStringArray* filters = vtkStringArray::SafeDownCast(
        input->GetFieldData()->GetAbstractArray(vtkMultiresolutionThreshold::FilterArrayName()));
      source->InsertNextValue(filters && filters->GetNumberOfValues() == 1 ? filters->GetValue(0) : std::string());
      this->Delivered->GetFieldData()->AddArray(source);
      // The Layer property's range: the header is read once a file (the mapper opens it again
      // where it draws, which may be another process).
      const std::string path = reader->GetFileName() ? reader->GetFileName() : "";
      if (path != this->LayerRangeFile)
      {
        this->LayerRangeFile = path;
        this->LayerRange[1] = 0;
        try
        {
          this->LayerRange[1] = static_cast<int>(resmr::MultiresolutionFile(path).Header().dims[2]);
        }
        catch (const std::exception&)
        {
          // the reader reports a file it cannot open
        }
      }
    }
  }
  return this->Superclass::RequestData(request, inputVector, outputVector);
}

int vtkMultiresolutionSurfaceRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* request, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(request, inInfo, outInfo))
  {
    return 0;
  }
  if (request == vtkPVView::REQUEST_UPDATE())
  {
    vtkPVRenderView::SetPiece(inInfo, this, this->Delivered);
    if (this->Delivered && this->Delivered->GetNumberOfPoints() > 0)
    {
      double bounds[6];
      this->Delivered->GetBounds(bounds);
      vtkNew<vtkMatrix4x4> matrix;
      this->Actor->GetMatrix(matrix);
      vtkPVRenderView::SetGeometryBounds(inInfo, this, bounds, matrix);
    }
    // Draw where the file is: the server's ranks, never a copy on the client.
    vtkPVRenderView::SetRequiresDistributedRendering(inInfo, this, true);
    outInfo->Set(vtkPVRenderView::NEED_ORDERED_COMPOSITING(), 0);
  }
  else if (request == vtkPVView::REQUEST_UPDATE_LOD())
  {
    vtkPVRenderView::SetRequiresDistributedRenderingLOD(inInfo, this, true);
  }
  else if (request == vtkPVView::REQUEST_RENDER())
  {
    this->Mapper->SetInputDataObject(vtkPVView::GetDeliveredPiece(inInfo, this));
  }
  return 1;
}

bool vtkMultiresolutionSurfaceRepresentation::AddToView(vtkView* view)
{
  vtkPVRenderView* renderView = vtkPVRenderView::SafeDownCast(view);
  if (renderView)
  {
    renderView->GetRenderer()->AddActor(this->Actor);
    return this->Superclass::AddToView(view);
  }
  return false;
}

bool vtkMultiresolutionSurfaceRepresentation::RemoveFromView(vtkView* view)
{
  vtkPVRenderView* renderView = vtkPVRenderView::SafeDownCast(view);
  if (renderView)
  {
    this->Mapper->ForgetLastFrame();
    renderView->GetRenderer()->RemoveActor(this->Actor);
    return this->Superclass::RemoveFromView(view);
  }
  return false;
}

void vtkMultiresolutionSurfaceRepresentation::SetVisibility(bool visible)
{
  this->Superclass::SetVisibility(visible);
  this->Actor->SetVisibility(visible ? 1 : 0);
}

void vtkMultiresolutionSurfaceRepresentation::SetInputArrayToProcess(
  int index, int port, int connection, int fieldAssociation, const char* name)
{
  this->Superclass::SetInputArrayToProcess(index, port, connection, fieldAssociation, name);
  // Any association: the descriptor's arrays stand for the file's properties.
  this->Mapper->SetArrayName(name ? name : "");
  this->Mapper->SetScalarVisibility(name && *name ? 1 : 0);
  this->Mapper->Modified();
}

void vtkMultiresolutionSurfaceRepresentation::SetLookupTable(vtkScalarsToColors* table)
{
  this->Mapper->SetLookupTable(table);
}

void vtkMultiresolutionSurfaceRepresentation::SetDiffuseColor(double r, double g, double b)
{
  this->Actor->GetProperty()->SetDiffuseColor(r, g, b);
}
void vtkMultiresolutionSurfaceRepresentation::SetAmbientColor(double r, double g, double b)
{
  this->Actor->GetProperty()->SetAmbientColor(r, g, b);
}
void vtkMultiresolutionSurfaceRepresentation::SetSpecularColor(double r, double g, double b)
{
  this->Actor->GetProperty()->SetSpecularColor(r, g, b);
}
void vtkMultiresolutionSurfaceRepresentation::SetAmbient(double value)
{
  this->Actor->GetProperty()->SetAmbient(value);
}
void vtkMultiresolutionSurfaceRepresentation::SetDiffuse(double value)
{
  this->Actor->GetProperty()->SetDiffuse(value);
}
void vtkMultiresolutionSurfaceRepresentation::SetSpecular(double value)
{
  this->Actor->GetProperty()->SetSpecular(value);
}
void vtkMultiresolutionSurfaceRepresentation::SetSpecularPower(double value)
{
  this->Actor->GetProperty()->SetSpecularPower(value);
}
void vtkMultiresolutionSurfaceRepresentation::SetPosition(double x, double y, double z)
{
  this->Actor->SetPosition(x, y, z);
}
void vtkMultiresolutionSurfaceRepresentation::SetScale(double x, double y, double z)
{
  this->Actor->SetScale(x, y, z);
}
void vtkMultiresolutionSurfaceRepresentation::SetOrientation(double x, double y, double z)
{
  this->Actor->SetOrientation(x, y, z);
}
void vtkMultiresolutionSurfaceRepresentation::SetOrigin(double x, double y, double z)
{
  this->Actor->SetOrigin(x, y, z);
}

void vtkMultiresolutionSurfaceRepresentation::SetColorMode(int mode)
{
  this->Mapper->SetColorMode(mode);
}
void vtkMultiresolutionSurfaceRepresentation::SetPixelTolerance(double pixels)
{
  this->Mapper->SetPixelTolerance(pixels);
}
void vtkMultiresolutionSurfaceRepresentation::SetTargetFrameRate(double fps)
{
  this->Mapper->SetTargetFrameRate(fps);
}
void vtkMultiresolutionSurfaceRepresentation::SetMaximumPixelTolerance(double pixels)
{
  this->Mapper->SetMaximumPixelTolerance(pixels);
}
void vtkMultiresolutionSurfaceRepresentation::SetMaximumEstimatedError(double pixels)
{
  this->Mapper->SetMaximumEstimatedError(pixels);
}
void vtkMultiresolutionSurfaceRepresentation::SetMovingResolutionFloor(double fraction)
{
  this->Mapper->SetMovingResolutionFloor(fraction);
}
void vtkMultiresolutionSurfaceRepresentation::SetMemoryBudgetMB(int megabytes)
{
  this->Mapper->SetMemoryBudgetMB(megabytes);
}
void vtkMultiresolutionSurfaceRepresentation::SetGridLines(bool show)
{
  this->Mapper->SetGridLines(show);
}
void vtkMultiresolutionSurfaceRepresentation::SetGridLineWidth(double pixels)
{
  this->Mapper->SetGridLineWidth(pixels);
}
void vtkMultiresolutionSurfaceRepresentation::SetGridLineColor(double r, double g, double b)
{
  this->Mapper->SetGridLineColor(r, g, b);
}
void vtkMultiresolutionSurfaceRepresentation::SetWaitForDetailMs(int milliseconds)
{
  this->Mapper->SetWaitForDetailMs(milliseconds);
}
void vtkMultiresolutionSurfaceRepresentation::SetLayer(int layer)
{
  this->Mapper->SetLayer(layer);
}
double vtkMultiresolutionSurfaceRepresentation::GetCurrentTolerance()
{
  return this->Mapper->GetCurrentTolerance();
}
double vtkMultiresolutionSurfaceRepresentation::GetCurrentEstimatedError()
{
  return this->Mapper->GetCurrentEstimatedError();
}
int vtkMultiresolutionSurfaceRepresentation::GetCurrentFrameControlled()
{
  return this->Mapper->GetCurrentFrameControlled() ? 1 : 0;
}
double vtkMultiresolutionSurfaceRepresentation::GetCurrentRenderScale()
{
  return this->Mapper->GetCurrentRenderScale();
}
double vtkMultiresolutionSurfaceRepresentation::GetResidentMB()
{
  return this->Mapper->GetResidentMB();
}
double vtkMultiresolutionSurfaceRepresentation::GetTrianglesDrawn()
{
  return static_cast<double>(this->Mapper->GetTrianglesDrawn());
}
int vtkMultiresolutionSurfaceRepresentation::GetRegionsDrawn()
{
  return this->Mapper->GetRegionsDrawn();
}
int vtkMultiresolutionSurfaceRepresentation::GetRegionsSubstituted()
{
  return this->Mapper->GetRegionsSubstituted();
}
double vtkMultiresolutionSurfaceRepresentation::GetLastFrameMs()
{
  return this->Mapper->GetLastFrameMs();
}
int vtkMultiresolutionSurfaceRepresentation::GetLoadsPending()
{
  return this->Mapper->GetLoadsPending() ? 1 : 0;
}
double vtkMultiresolutionSurfaceRepresentation::GetRefreshWaitMs()
{
  return this->Mapper->GetRefreshWaitMs();
}
const char* vtkMultiresolutionSurfaceRepresentation::GetLastError()
{
  return this->Error.empty() ? this->Mapper->GetLastError() : this->Error.c_str();
}

void vtkMultiresolutionSurfaceRepresentation::PickAt(double x, double y)
{
  this->Mapper->PickAt(x, y);
}
void vtkMultiresolutionSurfaceRepresentation::InspectCell(int i, int j, int k)
{
  this->Mapper->InspectCell(i, j, k);
}
int vtkMultiresolutionSurfaceRepresentation::GetPicksDone()
{
  return this->Mapper->GetPicksDone();
}
int* vtkMultiresolutionSurfaceRepresentation::GetPickedCell()
{
  std::copy(this->Mapper->GetPickedCell(), this->Mapper->GetPickedCell() + 3, this->PickedCell);
  return this->PickedCell;
}
int vtkMultiresolutionSurfaceRepresentation::GetPickedActive()
{
  return this->Mapper->GetPickedActive();
}
double* vtkMultiresolutionSurfaceRepresentation::GetPickedPoint()
{
  std::copy(this->Mapper->GetPickedPoint(), this->Mapper->GetPickedPoint() + 3, this->PickedPoint);
  return this->PickedPoint;
}
double* vtkMultiresolutionSurfaceRepresentation::GetPickedCorners()
{
  std::copy(this->Mapper->GetPickedCorners(), this->Mapper->GetPickedCorners() + 24, this->PickedCorners);
  return this->PickedCorners;
}
const char* vtkMultiresolutionSurfaceRepresentation::GetPickedValues()
{
  return this->Mapper->GetPickedValues();
}

void vtkMultiresolutionSurfaceRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Mapper: " << this->Mapper << "\n";
  os << indent << "LayerRange: " << this->LayerRange[0] << " " << this->LayerRange[1] << "\n";
}
