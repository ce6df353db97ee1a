#include "vtkSyntheticReservoirSource.h"

#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkExplicitStructuredGrid.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "ResMRExplicitGrid.h"

#include "CornerPointGeometry.h"
#include "CornerPointModel.h"
#include "MemoryBudget.h"
#include "SyntheticReservoir.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(vtkSyntheticReservoirSource);

struct vtkSyntheticReservoirSource::Internals
{
  std::unique_ptr<resmr::SyntheticReservoir> Model;
  vtkSmartPointer<vtkExplicitStructuredGrid> Base; ///< geometry and static arrays
  resmr_readers::CellOrder Order;
  std::vector<bool> Active;
  vtkMTimeType BuiltTime = 0;
};

vtkSyntheticReservoirSource::vtkSyntheticReservoirSource()
  : Internal(new Internals)
{
  this->SetNumberOfInputPorts(0);
}

vtkSyntheticReservoirSource::~vtkSyntheticReservoirSource() = default;

void vtkSyntheticReservoirSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " " << this->Dimensions[2]
     << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "Faults: " << this->Faults << "\n";
  os << indent << "Throw: " << this->Throw << "\n";
  os << indent << "Dip: " << this->Dip << "\n";
  os << indent << "PinchedFraction: " << this->PinchedFraction << "\n";
  os << indent << "WaterFraction: " << this->WaterFraction << "\n";
  os << indent << "OutsideFraction: " << this->OutsideFraction << "\n";
  os << indent << "Steps: " << this->Steps << "\n";
  os << indent << "MemoryLimitMB: " << this->MemoryLimitMB << "\n";
}

void vtkSyntheticReservoirSource::ReportError(const std::string& message)
{
  this->LastError = message;
  vtkErrorMacro(<< message);
}

namespace
{
resmr::SyntheticParameters ParametersOf(const int dims[3], int seed, int faults, double maxThrow, double dip,
  double pinched, double water, double outside, int steps)
{
  resmr::SyntheticParameters p;
  p.nx = dims[0];
  p.ny = dims[1];
  p.nz = dims[2];
  p.seed = static_cast<uint64_t>(seed);
  p.faults = faults;
  p.maxThrow = maxThrow;
  p.dipDegrees = dip;
  p.pinchedFraction = pinched;
  p.waterFraction = water;
  p.outsideFraction = outside;
  p.steps = steps;
  return p;
}

/// A float cell array in VTK order from values in ECLIPSE order, NaN in inactive cells.
vtkSmartPointer<vtkFloatArray> CellArray(
  const char* name, const resmr_readers::CellOrder& order, const std::vector<float>& values)
{
  return resmr_readers::MakeCellArray<vtkFloatArray>(
    name, order, [&](float* out) { std::copy(values.begin(), values.end(), out); });
}
} // namespace

int vtkSyntheticReservoirSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  info->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  const resmr::SyntheticParameters p = ParametersOf(this->Dimensions, this->Seed, this->Faults, this->Throw, this->Dip,
    this->PinchedFraction, this->WaterFraction, this->OutsideFraction, this->Steps);
  try
  {
    p.Validate();
  }
  catch (const std::exception& error)
  {
    this->ReportError(std::string("SyntheticReservoir: ") + error.what());
    return 0;
  }
  if (p.steps > 0)
  {
    std::vector<double> days;
    for (int s = 1; s <= p.steps; ++s)
    {
      days.push_back(static_cast<double>((3650LL * s) / p.steps)); // SyntheticReservoir::StepDays
    }
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_STEPS(), days.data(), static_cast<int>(days.size()));
    const double range[2] = { days.front(), days.back() };
    info->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

bool vtkSyntheticReservoirSource::BuildModelIfNeeded()
{
  Internals& internal = *this->Internal;
  if (internal.Base && internal.BuiltTime >= this->GetMTime())
  {
    return true;
  }
  internal.Base = nullptr;
  internal.Model.reset();
  const resmr::SyntheticParameters p = ParametersOf(this->Dimensions, this->Seed, this->Faults, this->Throw, this->Dip,
    this->PinchedFraction, this->WaterFraction, this->OutsideFraction, this->Steps);
  try
  {
    p.Validate();
    const int64_t limit = resmr::MaxFullResolutionCells(int64_t(this->MemoryLimitMB) << 20);
    if (p.CellCount() > limit)
    {
      throw std::invalid_argument(std::to_string(p.nx) + " x " + std::to_string(p.ny) + " x " + std::to_string(p.nz) +
        " cells are more than fit in memory at full resolution (limit " + std::to_string(limit) +
        " cells); write the model with `resmr synth " + std::to_string(p.nx) + " " + std::to_string(p.ny) + " " +
        std::to_string(p.nz) + " -o MODEL.EGRID` and " + resmr::MultiresolutionAdvice("MODEL.EGRID"));
    }
    internal.Model = std::make_unique<resmr::SyntheticReservoir>(p);
    const resmr::SyntheticReservoir& model = *internal.Model;
    const int64_t cells = p.CellCount(), columns = p.nx * p.ny;
    resmr::CornerPointModel deck;
    deck.dims = { p.nx, p.ny, p.nz };
    deck.coord = model.Coord();
    for (double& value : deck.coord)
    {
      value = static_cast<float>(value); // as an EGRID stores it: the same grid as resmr synth's
    }
    deck.zcornSingle.resize(static_cast<std::size_t>(8 * cells));
    std::vector<int32_t> actnum(static_cast<std::size_t>(cells));
    internal.Active.assign(static_cast<std::size_t>(cells), false);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> poro(actnum.size(), nan), permx(actnum.size(), nan), permz(actnum.size(), nan),
      ntg(actnum.size(), nan), porv(actnum.size(), 0.0f);
    resmr::SyntheticLayerStream stream(model);
    resmr::SyntheticLayer layer;
    while (stream.Next(layer))
    {
      std::copy(layer.zcorn.begin(), layer.zcorn.end(), deck.zcornSingle.begin() + 8 * columns * layer.k);
      for (int64_t c = 0; c < columns; ++c)
      {
        const int64_t cell = layer.k * columns + c;
        const bool active = layer.state[c] == resmr::SyntheticCellState::Active;
        actnum[cell] = active ? 1 : 0;
        internal.Active[cell] = active;
        if (active)
        {
          poro[cell] = layer.poro[c];
          permx[cell] = layer.permx[c];
          permz[cell] = layer.permx[c] * 0.1f; // as written to INIT
          ntg[cell] = layer.ntg[c];
          porv[cell] = layer.poreVolume[c];
        }
      }
      this->UpdateProgress(0.8 * static_cast<double>(layer.k + 1) / static_cast<double>(p.nz));
    }
    const resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(deck, false);
    auto base = vtkSmartPointer<vtkExplicitStructuredGrid>::New();
    internal.Order = resmr_readers::BuildExplicitGrid(geometry, actnum, internal.Active, false, base);
    vtkCellData* data = base->GetCellData();
    data->AddArray(CellArray("PORV", internal.Order, porv));
    data->AddArray(CellArray("PORO", internal.Order, poro));
    data->AddArray(CellArray("PERMX", internal.Order, permx));
    data->AddArray(CellArray("PERMY", internal.Order, permx));
    data->AddArray(CellArray("PERMZ", internal.Order, permz));
    data->AddArray(CellArray("NTG", internal.Order, ntg));
    internal.Base = base;
  }
  catch (const std::bad_alloc&)
  {
    internal.Model.reset();
    this->ReportError("SyntheticReservoir: not enough memory for this model");
    return false;
  }
  catch (const std::exception& error)
  {
    internal.Model.reset();
    this->ReportError(std::string("SyntheticReservoir: ") + error.what());
    return false;
  }
  internal.BuiltTime = this->GetMTime();
  return true;
}

int vtkSyntheticReservoirSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  this->LastError.clear();
  vtkInformation* info = outputVector->GetInformationObject(0);
  vtkExplicitStructuredGrid* output = vtkExplicitStructuredGrid::GetData(info);
  if (!this->BuildModelIfNeeded())
  {
    return 0;
  }
  Internals& internal = *this->Internal;
  output->ShallowCopy(internal.Base);
  const resmr::SyntheticReservoir& model = *internal.Model;
  const resmr::SyntheticParameters& p = model.Parameters();
  if (p.steps > 0)
  {
    // The report step at or before the requested time (the first if earlier).
    int step = 1;
    if (info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
    {
      const double time = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
      for (int s = 1; s <= p.steps; ++s)
      {
        step = model.StepDays(s) <= time ? s : step;
      }
    }
    const int64_t columns = p.nx * p.ny;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> pressure(static_cast<std::size_t>(p.CellCount()), nan), swat(pressure.size(), nan);
    std::vector<float> layerPressure(static_cast<std::size_t>(columns)), layerSwat(layerPressure.size());
    resmr::SyntheticLayerStream stream(model);
    resmr::SyntheticLayer layer;
    while (stream.Next(layer))
    {
      model.FillStep(step, layer, layerPressure.data(), layerSwat.data());
      for (int64_t c = 0; c < columns; ++c)
      {
        if (layer.state[c] == resmr::SyntheticCellState::Active)
        {
          pressure[layer.k * columns + c] = layerPressure[c];
          swat[layer.k * columns + c] = layerSwat[c];
        }
      }
    }
    output->GetCellData()->AddArray(CellArray("PRESSURE", internal.Order, pressure));
    output->GetCellData()->AddArray(CellArray("SWAT", internal.Order, swat));
    const double days = model.StepDays(step);
    output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), days);
    auto reportStep = vtkSmartPointer<vtkIntArray>::New();
    reportStep->SetName("ReportStep");
    reportStep->InsertNextValue(step);
    auto dayArray = vtkSmartPointer<vtkDoubleArray>::New();
    dayArray->SetName("Days");
    dayArray->InsertNextValue(days);
    vtkNew<vtkFieldData> field;
    field->AddArray(reportStep);
    field->AddArray(dayArray);
    output->SetFieldData(field);
  }
  this->UpdateProgress(1.0);
  return 1;
}
