#include "vtkGRDECLReader.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArraySelection.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkExplicitStructuredGrid.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include "CornerPointGeometry.h"
#include "Errors.h"
#include "GrdeclParser.h"
#include "MemoryBudget.h"
#include "ResMRExplicitGrid.h"

#include <cmath>
#include <optional>

struct vtkGRDECLReader::Internals
{
  std::string ParsedFile;
  long long ParsedModificationTime = -1;
  std::string FailedFile; ///< last file that failed to parse, to report it once
  long long FailedModificationTime = -1;
  std::string FailedMessage;
  resmr::CornerPointModel Deck;
  std::optional<resmr::CornerPointGeometry> Geometry;
};

vtkStandardNewMacro(vtkGRDECLReader);

namespace
{
} // namespace

vtkGRDECLReader::vtkGRDECLReader()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(2);
}

vtkGRDECLReader::~vtkGRDECLReader()
{
  this->SetFileName(nullptr);
}

void vtkGRDECLReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "ShowInactiveCells: " << this->ShowInactiveCells << "\n";
  os << indent << "ApplyMapAxes: " << this->ApplyMapAxes << "\n";
}

int vtkGRDECLReader::FillOutputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkExplicitStructuredGrid" : "vtkPolyData");
  return 1;
}

int vtkGRDECLReader::CanReadFile(const char* fileName)
{
  return fileName && resmr::LooksLikeGrdeclFile(fileName) ? 1 : 0;
}

vtkDataArraySelection* vtkGRDECLReader::GetCellArraySelection()
{
  return this->CellArraySelection;
}
int vtkGRDECLReader::GetNumberOfCellArrays()
{
  return this->CellArraySelection->GetNumberOfArrays();
}
const char* vtkGRDECLReader::GetCellArrayName(int index)
{
  return this->CellArraySelection->GetArrayName(index);
}
int vtkGRDECLReader::GetCellArrayStatus(const char* name)
{
  return this->CellArraySelection->ArrayIsEnabled(name);
}
void vtkGRDECLReader::SetCellArrayStatus(const char* name, int status)
{
  if (this->CellArraySelection->ArrayIsEnabled(name) != (status != 0) || !this->CellArraySelection->ArrayExists(name))
  {
    this->CellArraySelection->SetArraySetting(name, status);
    this->Modified();
  }
}

vtkDataArraySelection* vtkGRDECLReader::GetFaultSelection()
{
  return this->FaultSelection;
}
int vtkGRDECLReader::GetNumberOfFaultArrays()
{
  return this->FaultSelection->GetNumberOfArrays();
}
const char* vtkGRDECLReader::GetFaultArrayName(int index)
{
  return this->FaultSelection->GetArrayName(index);
}
int vtkGRDECLReader::GetFaultArrayStatus(const char* name)
{
  return this->FaultSelection->ArrayIsEnabled(name);
}
void vtkGRDECLReader::SetFaultArrayStatus(const char* name, int status)
{
  if (this->FaultSelection->ArrayIsEnabled(name) != (status != 0) || !this->FaultSelection->ArrayExists(name))
  {
    this->FaultSelection->SetArraySetting(name, status);
    this->Modified();
  }
}

void vtkGRDECLReader::SetMemoryLimitMB(int megabytes)
{
  megabytes = megabytes < 0 ? 0 : megabytes;
  if (megabytes != this->MemoryLimitMB)
  {
    this->MemoryLimitMB = megabytes;
    // Parse again under the new limit: a refusal may no longer hold, or a deck may no
    // longer fit.
    this->Internal->Geometry.reset();
    this->Internal->Deck = resmr::CornerPointModel();
    this->Internal->ParsedFile.clear();
    this->Internal->FailedFile.clear();
    this->Modified();
  }
}

void vtkGRDECLReader::ReportError(const std::string& message)
{
  this->LastError = message;
  vtkErrorMacro(<< message);
}

bool vtkGRDECLReader::ParseIfNeeded()
{
  if (!this->FileName || !*this->FileName)
  {
    this->ReportError("no FileName set");
    return false;
  }
  const long long modified = resmr_readers::FileModificationTime(this->FileName);
  Internals& internal = *this->Internal;
  if (internal.Geometry && internal.ParsedFile == this->FileName && internal.ParsedModificationTime == modified)
  {
    return true;
  }
  if (internal.FailedFile == this->FileName && internal.FailedModificationTime == modified)
  {
    this->LastError = internal.FailedMessage; // already reported in RequestInformation
    return false;
  }
  internal.Geometry.reset();
  internal.Deck = resmr::CornerPointModel();
  internal.ParsedFile.clear();
  internal.FailedFile.clear();
  this->Warnings.clear();
  const auto fail = [&](const std::string& message) {
    internal.Deck = resmr::CornerPointModel();
    internal.Geometry.reset();
    internal.FailedFile = this->FileName;
    internal.FailedModificationTime = modified;
    internal.FailedMessage = message;
    this->ReportError(message);
  };
  try
  {
    resmr::GrdeclParseOptions options;
    options.maxCells = resmr::MaxFullResolutionCells(int64_t(this->MemoryLimitMB) << 20);
    internal.Deck = resmr::ParseGrdeclFile(this->FileName, options);
    internal.Geometry = resmr::CornerPointGeometry::FromDeck(internal.Deck, this->ApplyMapAxes);
  }
  catch (const std::bad_alloc&)
  {
    fail(std::string(this->FileName) + ": not enough memory to read this deck");
    return false;
  }
  catch (const std::exception& error)
  {
    fail(error.what());
    return false;
  }
  internal.ParsedFile = this->FileName;
  internal.ParsedModificationTime = modified;
  for (const std::string& warning : internal.Deck.warnings)
  {
    this->Warnings += warning + "\n";
    vtkWarningMacro(<< warning);
  }
  for (const resmr::CellArray& array : internal.Deck.arrays)
  {
    if (!resmr::IsGeometryArrayName(array.name) && !this->CellArraySelection->ArrayExists(array.name.c_str()))
    {
      this->CellArraySelection->AddArray(array.name.c_str(), true);
    }
  }
  for (const resmr::Fault& fault : internal.Deck.faults)
  {
    if (!this->FaultSelection->ArrayExists(fault.name.c_str()))
    {
      this->FaultSelection->AddArray(fault.name.c_str(), true);
    }
  }
  return true;
}

int vtkGRDECLReader::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  this->LastError.clear();
  if (!this->ParseIfNeeded())
  {
    // Let RequestData run and empty the outputs, so no stale data is shown.
    int empty[6] = { 0, -1, 0, -1, 0, -1 };
    outputVector->GetInformationObject(0)->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), empty, 6);
    return 1;
  }
  const auto& dims = this->Internal->Geometry->Dims();
  int extent[6] = { 0, static_cast<int>(dims[0]), 0, static_cast<int>(dims[1]), 0, static_cast<int>(dims[2]) };
  outputVector->GetInformationObject(0)->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  return 1;
}

int vtkGRDECLReader::RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkExplicitStructuredGrid* grid = vtkExplicitStructuredGrid::GetData(outputVector, 0);
  vtkPolyData* faults = vtkPolyData::GetData(outputVector, 1);
  grid->Initialize();
  faults->Initialize();
  this->LastError.clear();
  if (!this->ParseIfNeeded())
  {
    return 0;
  }
  const resmr::CornerPointModel& deck = this->Internal->Deck;
  resmr::CornerPointGeometry& geometry = *this->Internal->Geometry;
  geometry.SetMapAxesApplied(this->ApplyMapAxes);
  this->LeftHanded = geometry.IsLeftHanded();

  try
  {
    const int64_t cellCount = geometry.CellCount();
    std::vector<int32_t> actnum(static_cast<std::size_t>(cellCount), 1);
    std::vector<bool> active(static_cast<std::size_t>(cellCount), true);
    if (const resmr::CellArray* actnumArray = deck.FindArray("ACTNUM"))
    {
      for (int64_t cell = 0; cell < cellCount; ++cell)
      {
        const double value = actnumArray->values[static_cast<std::size_t>(cell)];
        actnum[static_cast<std::size_t>(cell)] = static_cast<int32_t>(value);
        active[static_cast<std::size_t>(cell)] = value > 0;
      }
    }
    const resmr_readers::CellOrder order =
      resmr_readers::BuildExplicitGrid(geometry, actnum, active, this->ShowInactiveCells, grid);
    vtkCellData* cellData = grid->GetCellData();

    for (const resmr::CellArray& property : deck.arrays)
    {
      if (resmr::IsGeometryArrayName(property.name) || !this->CellArraySelection->ArrayIsEnabled(property.name.c_str()))
      {
        continue;
      }
      const std::vector<double>& values = property.values;
      if (property.isInteger)
      {
        cellData->AddArray(resmr_readers::MakeCellArray<vtkIntArray>(property.name.c_str(), order, [&](int* out) {
          for (int64_t cell = 0; cell < cellCount; ++cell)
          {
            const double value = values[static_cast<std::size_t>(cell)];
            out[cell] = std::isfinite(value) ? static_cast<int>(value) : 0;
          }
        }));
      }
      else
      {
        cellData->AddArray(resmr_readers::MakeCellArray<vtkDoubleArray>(
          property.name.c_str(), order, [&](double* out) { std::copy(values.begin(), values.end(), out); }));
      }
    }

    // Faults: one quad per faulted cell face, corners taken from the cell itself.
    vtkNew<vtkPoints> faultPoints;
    faultPoints->SetDataTypeToDouble();
    vtkNew<vtkCellArray> faultQuads;
    vtkNew<vtkIntArray> faultIndex;
    faultIndex->SetName("FaultIndex");
    vtkNew<vtkStringArray> faultNames;
    faultNames->SetName("FaultNames");
    static const int faceCorners[6][4] = { { 0, 2, 6, 4 }, { 1, 5, 7, 3 }, { 0, 4, 5, 1 }, { 2, 3, 7, 6 },
      { 0, 1, 3, 2 }, { 4, 6, 7, 5 } };
    for (std::size_t f = 0; f < deck.faults.size(); ++f)
    {
      const resmr::Fault& fault = deck.faults[f];
      faultNames->InsertNextValue(fault.name);
      if (!this->FaultSelection->ArrayIsEnabled(fault.name.c_str()))
      {
        continue;
      }
      for (const resmr::FaultFace& face : fault.faces)
      {
        for (int64_t k = face.box[4]; k <= face.box[5]; ++k)
        {
          for (int64_t j = face.box[2]; j <= face.box[3]; ++j)
          {
            for (int64_t i = face.box[0]; i <= face.box[1]; ++i)
            {
              double corners[8][3];
              geometry.CellCorners(i, j, k, corners);
              vtkIdType quad[4];
              for (int c = 0; c < 4; ++c)
              {
                const double* p = corners[faceCorners[face.face][c]];
                quad[c] = faultPoints->InsertNextPoint(p[0], p[1], -p[2]);
              }
              faultQuads->InsertNextCell(4, quad);
              faultIndex->InsertNextValue(static_cast<int>(f));
            }
          }
        }
      }
    }
    faults->SetPoints(faultPoints);
    faults->SetPolys(faultQuads);
    faults->GetCellData()->AddArray(faultIndex);
    faults->GetFieldData()->AddArray(faultNames);
  }
  catch (const std::bad_alloc&)
  {
    grid->Initialize();
    faults->Initialize();
    this->ReportError(std::string(this->FileName) + ": not enough memory to build the grid");
    return 0;
  }
  return 1;
}
