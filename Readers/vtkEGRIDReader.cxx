#include "vtkEGRIDReader.h"

#include "vtkCellData.h"
#include "vtkDataArraySelection.h"
#include "vtkDoubleArray.h"
#include "vtkExplicitStructuredGrid.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include "CornerPointGeometry.h"
#include "DerivedArrays.h"
#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseResults.h"
#include "Errors.h"
#include "MemoryBudget.h"
#include "ResMRExplicitGrid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

namespace
{
/// An array the user can select: INIT (static) or restart (dynamic); the shown name differs
/// from the file's only when both files hold the same keyword.
struct SelectableArray
{
  std::string shownName;
  std::string keyword;
  bool dynamic = false;
  resmr::EclipseResultArray info;
  bool derivedOil = false; ///< SOIL = 1 - SWAT - SGAS, for restarts that do not hold SOIL
};

bool IsCommonArray(const std::string& name)
{
  static const std::set<std::string> names = { "PORO", "PERMX", "PERMY", "PERMZ", "NTG", "PORV", "SATNUM", "PVTNUM",
    "EQLNUM", "FIPNUM", "PRESSURE", "SWAT", "SGAS", "SOIL", "RS", "RV" };
  return names.count(name) > 0;
}
} // namespace

struct vtkEGRIDReader::Internals
{
  std::string OpenedFile;
  long long OpenedModificationTime = -1;
  std::string FailedFile; ///< last file that failed to open, reported once
  long long FailedModificationTime = -1;
  std::string FailedMessage;

  std::optional<resmr::EclipseGrid> Grid;
  std::optional<resmr::CornerPointGeometry> Geometry;
  std::unique_ptr<resmr::EclipseResults> Results;
  std::vector<SelectableArray> Arrays;
  std::vector<double> Times;     ///< one per report step, strictly increasing
  bool RescanCompanions = false; ///< Reload(): index INIT and restarts again, keep the grid

  /// Geometry, I/J/K/ACTNUM and the selected static arrays, shared by every step's output.
  vtkSmartPointer<vtkExplicitStructuredGrid> Base;
  resmr_readers::CellOrder Order;
  bool BaseShowInactive = false;
  bool BaseApplyMapAxes = true;
  std::set<std::string> BaseStaticArrays;

  void Reset()
  {
    this->Base = nullptr;
    this->BaseStaticArrays.clear();
    this->Results.reset();
    this->Geometry.reset();
    this->Grid.reset();
    this->Arrays.clear();
    this->Times.clear();
    this->OpenedFile.clear();
    this->RescanCompanions = false; // a full open indexes them anyway
  }
};

vtkStandardNewMacro(vtkEGRIDReader);

vtkEGRIDReader::vtkEGRIDReader()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
}

vtkEGRIDReader::~vtkEGRIDReader()
{
  this->SetFileName(nullptr);
}

void vtkEGRIDReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "ShowInactiveCells: " << this->ShowInactiveCells << "\n";
  os << indent << "ApplyMapAxes: " << this->ApplyMapAxes << "\n";
  os << indent << "CurrentStep: " << this->CurrentStep << "\n";
}

int vtkEGRIDReader::CanReadFile(const char* fileName)
{
  // Any keyword file: old-style GRID files are then refused with a message saying why.
  return fileName &&
      (resmr::EclipseKeywordFile::LooksLikeUnformatted(fileName) ||
        resmr::EclipseKeywordFile::LooksLikeFormatted(fileName))
    ? 1
    : 0;
}

vtkDataArraySelection* vtkEGRIDReader::GetCellArraySelection()
{
  return this->CellArraySelection;
}
int vtkEGRIDReader::GetNumberOfCellArrays()
{
  return this->CellArraySelection->GetNumberOfArrays();
}
const char* vtkEGRIDReader::GetCellArrayName(int index)
{
  return this->CellArraySelection->GetArrayName(index);
}
int vtkEGRIDReader::GetCellArrayStatus(const char* name)
{
  return this->CellArraySelection->ArrayIsEnabled(name);
}
void vtkEGRIDReader::SetCellArrayStatus(const char* name, int status)
{
  if (this->CellArraySelection->ArrayIsEnabled(name) != (status != 0) || !this->CellArraySelection->ArrayExists(name))
  {
    this->CellArraySelection->SetArraySetting(name, status);
    this->Modified();
  }
}

int vtkEGRIDReader::GetNumberOfReportSteps()
{
  return static_cast<int>(this->Internal->Times.size());
}

void vtkEGRIDReader::SetMemoryLimitMB(int megabytes)
{
  megabytes = megabytes < 0 ? 0 : megabytes;
  if (megabytes != this->MemoryLimitMB)
  {
    this->MemoryLimitMB = megabytes;
    // Open again under the new limit: a refusal may no longer hold, or a grid may no
    // longer fit.
    this->Internal->Reset();
    this->Internal->FailedFile.clear();
    this->Modified();
  }
}

void vtkEGRIDReader::ReportError(const std::string& message)
{
  this->LastError = message;
  vtkErrorMacro(<< message);
}

bool vtkEGRIDReader::OpenIfNeeded()
{
  if (!this->FileName || !*this->FileName)
  {
    this->ReportError("no FileName set");
    return false;
  }
  const long long modified = resmr_readers::FileModificationTime(this->FileName);
  Internals& internal = *this->Internal;
  if (internal.Results && internal.OpenedFile == this->FileName && internal.OpenedModificationTime == modified)
  {
    return !internal.RescanCompanions || this->RescanCompanions();
  }
  if (internal.FailedFile == this->FileName && internal.FailedModificationTime == modified)
  {
    this->LastError = internal.FailedMessage; // already reported
    return false;
  }
  internal.Reset();
  internal.FailedFile.clear();
  this->Warnings.clear();
  try
  {
    internal.Grid =
      resmr::ReadEclipseGrid(this->FileName, resmr::MaxFullResolutionCells(int64_t(this->MemoryLimitMB) << 20));
    internal.Results = std::make_unique<resmr::EclipseResults>(this->FileName, *internal.Grid);
    internal.Geometry = resmr::CornerPointGeometry::FromDeck(internal.Grid->deck, this->ApplyMapAxes);
  }
  catch (const std::exception& error)
  {
    const bool memory = dynamic_cast<const std::bad_alloc*>(&error) != nullptr;
    const std::string message =
      memory ? std::string(this->FileName) + ": not enough memory to read this grid" : std::string(error.what());
    internal.Reset();
    internal.FailedFile = this->FileName;
    internal.FailedModificationTime = modified;
    internal.FailedMessage = message;
    this->ReportError(message);
    return false;
  }
  internal.OpenedFile = this->FileName;
  internal.OpenedModificationTime = modified;
  this->ListArraysAndTimes();
  return true;
}

bool vtkEGRIDReader::RescanCompanions()
{
  Internals& internal = *this->Internal;
  internal.RescanCompanions = false;
  try
  {
    internal.Results = std::make_unique<resmr::EclipseResults>(this->FileName, *internal.Grid);
  }
  catch (const std::exception& error)
  {
    internal.Reset();
    this->ReportError(error.what());
    return false;
  }
  // The INIT may have changed too: static arrays are read again when next shown.
  if (internal.Base)
  {
    for (const std::string& name : internal.BaseStaticArrays)
    {
      internal.Base->GetCellData()->RemoveArray(name.c_str());
    }
  }
  internal.BaseStaticArrays.clear();
  internal.Arrays.clear();
  internal.Times.clear();
  this->Warnings.clear();
  this->ListArraysAndTimes();
  return true;
}

void vtkEGRIDReader::Reload()
{
  // Only the companions: the grid of a run being written does not change.
  this->Internal->RescanCompanions = true;
  this->Internal->FailedFile.clear();
  this->Modified();
}

void vtkEGRIDReader::ListArraysAndTimes()
{
  Internals& internal = *this->Internal;
  std::vector<std::string> warnings = internal.Grid->deck.warnings;
  warnings.insert(warnings.end(), internal.Results->Warnings().begin(), internal.Results->Warnings().end());

  // Selectable arrays: restart arrays keep their names; an INIT array of the same name is
  // shown as NAME_INIT.
  const auto& dynamicArrays = internal.Results->DynamicArrays();
  for (const resmr::EclipseResultArray& array : internal.Results->StaticArrays())
  {
    const bool clash = std::any_of(dynamicArrays.begin(), dynamicArrays.end(),
      [&](const resmr::EclipseResultArray& other) { return other.name == array.name; });
    internal.Arrays.push_back({ clash ? array.name + "_INIT" : array.name, array.name, false, array });
  }
  std::vector<std::string> dynamicNames;
  for (const resmr::EclipseResultArray& array : dynamicArrays)
  {
    internal.Arrays.push_back({ array.name, array.name, true, array });
    dynamicNames.push_back(array.name);
  }
  if (resmr::NeedsDerivedOil(dynamicNames))
  {
    SelectableArray oil{ resmr::DerivedOilName, resmr::DerivedOilName, true,
      { resmr::DerivedOilName, resmr::EclipseDataType::Real } };
    oil.derivedOil = true;
    internal.Arrays.push_back(oil);
  }
  const bool all = internal.Grid->deck.CellCount() <= DefaultAllArraysCellLimit;
  for (const SelectableArray& array : internal.Arrays)
  {
    if (!this->CellArraySelection->ArrayExists(array.shownName.c_str()))
    {
      this->CellArraySelection->AddArray(array.shownName.c_str(), all || IsCommonArray(array.keyword));
    }
  }

  // ParaView needs strictly increasing times; restarts written twice at one date (or with
  // no usable time) are shown by step index instead.
  for (const resmr::EclipseReportStep& step : internal.Results->Steps())
  {
    internal.Times.push_back(step.days);
  }
  for (std::size_t s = 1; s < internal.Times.size(); ++s)
  {
    if (!(internal.Times[s] > internal.Times[s - 1]))
    {
      warnings.push_back(std::string(this->FileName) +
        ": report step times are not increasing; time steps are numbered by report index");
      for (std::size_t t = 0; t < internal.Times.size(); ++t)
      {
        internal.Times[t] = static_cast<double>(t);
      }
      break;
    }
  }
  for (const std::string& warning : warnings)
  {
    this->AddWarning(warning);
  }
}

void vtkEGRIDReader::AddWarning(const std::string& warning)
{
  this->Warnings += warning + "\n";
  vtkWarningMacro(<< warning);
}

bool vtkEGRIDReader::BuildBaseIfNeeded()
{
  Internals& internal = *this->Internal;
  if (internal.Base && internal.BaseShowInactive == this->ShowInactiveCells &&
    internal.BaseApplyMapAxes == this->ApplyMapAxes)
  {
    return true;
  }
  internal.Base = nullptr;
  internal.BaseStaticArrays.clear();
  try
  {
    internal.Geometry->SetMapAxesApplied(this->ApplyMapAxes);
    std::vector<bool> active(static_cast<std::size_t>(internal.Geometry->CellCount()));
    for (std::size_t cell = 0; cell < active.size(); ++cell)
    {
      active[cell] = internal.Grid->IsActive(static_cast<int64_t>(cell));
    }
    auto base = vtkSmartPointer<vtkExplicitStructuredGrid>::New();
    internal.Order = resmr_readers::BuildExplicitGrid(
      *internal.Geometry, internal.Grid->actnum, active, this->ShowInactiveCells, base);
    internal.Base = base;
  }
  catch (const std::bad_alloc&)
  {
    this->ReportError(std::string(this->FileName) + ": not enough memory to build the grid");
    return false;
  }
  internal.BaseShowInactive = this->ShowInactiveCells;
  internal.BaseApplyMapAxes = this->ApplyMapAxes;
  return true;
}

namespace
{
/// Reads one INIT or restart array into a new VTK array of the matching type; nullptr if the
/// step lacks it.
vtkSmartPointer<vtkDataArray> ReadCellArray(const resmr::EclipseResults& results, const SelectableArray& array,
  std::size_t step, const resmr_readers::CellOrder& order)
{
  if (array.derivedOil)
  {
    bool found = true;
    auto oil = resmr_readers::MakeCellArray<vtkFloatArray>(resmr::DerivedOilName, order,
      [&](float* out) { found = resmr::ReadDerivedOil(results, step, out, int64_t(order.nx) * order.ny * order.nz); });
    return found ? oil : nullptr;
  }
  bool found = true;
  const auto read = [&](auto* out, auto fill) {
    found = array.dynamic ? results.ReadDynamic(step, array.keyword, out, fill)
                          : results.ReadStatic(array.keyword, out, fill);
  };
  vtkSmartPointer<vtkDataArray> result;
  if (array.info.IsInteger())
  {
    result = resmr_readers::MakeCellArray<vtkIntArray>(
      array.shownName.c_str(), order, [&](int* out) { read(out, int32_t(0)); });
  }
  else if (array.info.type == resmr::EclipseDataType::Double)
  {
    result = resmr_readers::MakeCellArray<vtkDoubleArray>(
      array.shownName.c_str(), order, [&](double* out) { read(out, std::numeric_limits<double>::quiet_NaN()); });
  }
  else
  {
    result = resmr_readers::MakeCellArray<vtkFloatArray>(
      array.shownName.c_str(), order, [&](float* out) { read(out, std::numeric_limits<float>::quiet_NaN()); });
  }
  return found ? result : nullptr;
}
/// ReadCellArray, with a record whose blocks turn out damaged costing that array only:
/// nullptr, and `why` says what was left out.
vtkSmartPointer<vtkDataArray> ReadCellArrayOrExplain(const resmr::EclipseResults& results, const SelectableArray& array,
  std::size_t step, const resmr_readers::CellOrder& order, std::string& why)
{
  try
  {
    return ReadCellArray(results, array, step, order);
  }
  catch (const resmr::InputError& error)
  {
    why = std::string(error.what()) + "; " + array.shownName + " is not shown";
    return nullptr;
  }
}
} // namespace

void vtkEGRIDReader::WarnOnce(const std::string& warning)
{
  if (!warning.empty() && this->Warnings.find(warning) == std::string::npos)
  {
    this->AddWarning(warning);
  }
}

void vtkEGRIDReader::UpdateStaticArrays()
{
  Internals& internal = *this->Internal;
  vtkCellData* cellData = internal.Base->GetCellData();
  for (const SelectableArray& array : internal.Arrays)
  {
    if (array.dynamic)
    {
      continue;
    }
    const bool wanted = this->CellArraySelection->ArrayIsEnabled(array.shownName.c_str()) != 0;
    const bool present = internal.BaseStaticArrays.count(array.shownName) > 0;
    if (wanted && !present)
    {
      std::string why;
      auto values = ReadCellArrayOrExplain(*internal.Results, array, 0, internal.Order, why);
      this->WarnOnce(why);
      if (values)
      {
        cellData->AddArray(values);
        internal.BaseStaticArrays.insert(array.shownName);
      }
    }
    else if (!wanted && present)
    {
      cellData->RemoveArray(array.shownName.c_str());
      internal.BaseStaticArrays.erase(array.shownName);
    }
  }
}

int vtkEGRIDReader::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  this->LastError.clear();
  vtkInformation* info = outputVector->GetInformationObject(0);
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (!this->OpenIfNeeded())
  {
    // Let RequestData run and empty the output, so no stale data is shown.
    int empty[6] = { 0, -1, 0, -1, 0, -1 };
    info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), empty, 6);
    return 1;
  }
  const auto& dims = this->Internal->Grid->deck.dims;
  int extent[6] = { 0, static_cast<int>(dims[0]), 0, static_cast<int>(dims[1]), 0, static_cast<int>(dims[2]) };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  const std::vector<double>& times = this->Internal->Times;
  if (!times.empty())
  {
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
    const double range[2] = { times.front(), times.back() };
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

int vtkEGRIDReader::RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  vtkExplicitStructuredGrid* output = vtkExplicitStructuredGrid::GetData(outputVector, 0);
  output->Initialize();
  this->LastError.clear();
  this->CurrentStep = -1;
  if (!this->OpenIfNeeded() || !this->BuildBaseIfNeeded())
  {
    return 0;
  }
  Internals& internal = *this->Internal;

  // The report step at or before the requested time (the first one before any).
  const std::vector<double>& times = internal.Times;
  std::size_t step = 0;
  if (!times.empty() && info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    const double requested = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    const auto after = std::upper_bound(times.begin(), times.end(), requested + 1e-9);
    step = after == times.begin() ? 0 : static_cast<std::size_t>(after - times.begin() - 1);
  }

  try
  {
    this->UpdateStaticArrays();
    output->ShallowCopy(internal.Base);
    vtkCellData* cellData = output->GetCellData();
    // What the grid holds but the output does not show, for scripts and the Information tab.
    vtkNew<vtkIntArray> connections;
    connections->SetName("NonNeighbourConnections");
    connections->InsertNextValue(static_cast<int>(internal.Grid->nonNeighbourConnections));
    output->GetFieldData()->AddArray(connections);
    vtkNew<vtkStringArray> localGrids;
    localGrids->SetName("LocalGridRefinements");
    for (const std::string& name : internal.Grid->localGridNames)
    {
      localGrids->InsertNextValue(name);
    }
    output->GetFieldData()->AddArray(localGrids);
    if (!times.empty())
    {
      this->CurrentStep = static_cast<int>(step);
      for (const SelectableArray& array : internal.Arrays)
      {
        if (array.dynamic && this->CellArraySelection->ArrayIsEnabled(array.shownName.c_str()))
        {
          std::string why;
          auto values = ReadCellArrayOrExplain(*internal.Results, array, step, internal.Order, why);
          this->WarnOnce(why);
          if (values)
          {
            cellData->AddArray(values);
          }
        }
      }
      const resmr::EclipseReportStep& report = internal.Results->Steps()[step];
      vtkNew<vtkIntArray> reportStep;
      reportStep->SetName("ReportStep");
      reportStep->InsertNextValue(report.reportNumber);
      vtkNew<vtkDoubleArray> days;
      days->SetName("Days");
      days->InsertNextValue(report.days);
      vtkNew<vtkStringArray> date;
      date->SetName("Date");
      char text[32];
      std::snprintf(text, sizeof(text), "%04d-%02d-%02d", report.date[0], report.date[1], report.date[2]);
      date->InsertNextValue(text);
      output->GetFieldData()->AddArray(reportStep);
      output->GetFieldData()->AddArray(days);
      output->GetFieldData()->AddArray(date);
      output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), times[step]);
    }
  }
  catch (const std::bad_alloc&)
  {
    output->Initialize();
    this->ReportError(std::string(this->FileName) + ": not enough memory for the selected arrays");
    return 0;
  }
  catch (const std::exception& error)
  {
    output->Initialize();
    this->ReportError(error.what());
    return 0;
  }
  return 1;
}
