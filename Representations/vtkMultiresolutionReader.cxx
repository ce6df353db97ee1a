#include "vtkMultiresolutionReader.h"

#include "CornerPointGeometry.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <sys/stat.h>

vtkStandardNewMacro(vtkMultiresolutionReader);

namespace
{
bool IsFile(const std::string& path)
{
  struct stat status;
  return !path.empty() && stat(path.c_str(), &status) == 0 && S_ISREG(status.st_mode);
}

/// Changes whenever the file is rewritten (a new file renamed into place has a new inode).
std::string FileStamp(const std::string& path)
{
  struct stat status;
  if (path.empty() || stat(path.c_str(), &status) != 0)
  {
    return {};
  }
  return std::to_string(status.st_ino) + ":" + std::to_string(status.st_size) + ":" +
    std::to_string(status.st_mtim.tv_sec) + "." + std::to_string(status.st_mtim.tv_nsec);
}
} // namespace

vtkMultiresolutionReader::vtkMultiresolutionReader()
{
  this->SetNumberOfInputPorts(0);
}

vtkMultiresolutionReader::~vtkMultiresolutionReader() = default;

std::string vtkMultiresolutionReader::PropertyPathFor() const
{
  if (!this->PropertyFileName.empty())
  {
    return this->PropertyFileName;
  }
  const std::string& name = this->FileName;
  const std::size_t dot = name.find_last_of('.');
  const std::string stem =
    dot != std::string::npos && name.find('/', dot) == std::string::npos ? name.substr(0, dot) : name;
  const std::string beside = stem + ".resmrp";
  return IsFile(beside) ? beside : std::string();
}

int vtkMultiresolutionReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  this->StepDays.clear();
  this->StepNumbers.clear();
  this->LastError.clear();
  this->InformationFailed.clear();
  std::fill(this->Dimensions, this->Dimensions + 3, 0);
  if (this->FileName.empty())
  {
    this->InformationFailed = "no FileName: a .resmr file is needed";
    return this->Fail(this->InformationFailed);
  }
  try
  {
    const resmr::MultiresolutionFile geometry(this->FileName); // checks header, index and trailer
    for (int a = 0; a < 3; ++a)
    {
      this->Dimensions[a] = static_cast<int>(geometry.Header().dims[a]);
    }
    this->WarnOfUnreachableRegions(geometry);
    this->ResolvedPropertyFile = this->PropertyPathFor();
    this->PropertyFileStamp = FileStamp(this->ResolvedPropertyFile);
    if (this->ResolvedPropertyFile.empty())
    {
      return 1;
    }
    const resmr::PropertyFile properties(this->ResolvedPropertyFile);
    properties.CheckGeometry(geometry);
    std::map<int32_t, double> steps;
    for (const resmr::PropertyTable& table : properties.Tables())
    {
      if (table.step >= 0)
      {
        steps[table.step] = table.days;
      }
    }
    for (const auto& step : steps)
    {
      this->StepNumbers.push_back(step.first);
      this->StepDays.push_back(step.second);
    }
    if (!this->StepDays.empty())
    {
      outInfo->Set(
        vtkStreamingDemandDrivenPipeline::TIME_STEPS(), this->StepDays.data(), static_cast<int>(this->StepDays.size()));
      const double range[2] = { this->StepDays.front(), this->StepDays.back() };
      outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    }
  }
  catch (const std::exception& error)
  {
    this->InformationFailed = error.what();
    return this->Fail(this->InformationFailed);
  }
  return 1;
}

int vtkMultiresolutionReader::RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkPolyData* output = vtkPolyData::GetData(outInfo);
  if (!this->InformationFailed.empty())
  {
    return this->Fail(this->InformationFailed); // the file did not open: the message stands
  }
  this->LastError.clear();
  // One piece: the descriptor is tiny, and the view reads the file wherever it renders.
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) &&
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) > 0)
  {
    return 1;
  }
  try
  {
    const resmr::MultiresolutionFile geometry(this->FileName);
    // The model's box: the union of the roots' bounding volumes (x, y, depth), z = -depth.
    double low[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
      std::numeric_limits<double>::max() };
    double high[3] = { std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest(),
      std::numeric_limits<double>::lowest() };
    for (const resmr::RegionRecord& region : geometry.Regions())
    {
      if (region.level != 0)
      {
        continue;
      }
      for (int axis = 0; axis < 3; ++axis)
      {
        low[axis] = std::min(low[axis], double(region.bounds[axis]));
        high[axis] = std::max(high[axis], double(region.bounds[axis + 3]));
      }
    }
    if (low[0] > high[0])
    {
      return this->Fail(this->FileName + ": no root region in the file");
    }
    // The box's corners in map coordinates (MAPAXES), as the grid readers place the grid.
    std::array<double, 6> transform;
    const bool mapAxes =
      this->ApplyMapAxes && resmr::CornerPointGeometry::PlacementTransform(geometry.Header().map, transform);
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    for (int corner = 0; corner < 8; ++corner)
    {
      const double depth = (corner & 4) ? high[2] : low[2];
      double x = (corner & 1) ? high[0] : low[0], y = (corner & 2) ? high[1] : low[1];
      if (mapAxes)
      {
        resmr::CornerPointGeometry::ApplyMapTransform(transform, x, y);
      }
      points->InsertNextPoint(x, y, -depth);
    }
    vtkNew<vtkCellArray> edges;
    for (int a = 0; a < 8; ++a)
    {
      for (int bit = 1; bit < 8; bit <<= 1)
      {
        if (!(a & bit))
        {
          const vtkIdType edge[2] = { a, a | bit };
          edges->InsertNextCell(2, edge);
        }
      }
    }
    output->SetPoints(points);
    output->SetLines(edges);
    int32_t step = 0;

    if (!this->ResolvedPropertyFile.empty())
    {
      const resmr::PropertyFile properties(this->ResolvedPropertyFile);
      properties.CheckGeometry(geometry);
      // The step shown: the last whose time is not after the requested one.
      if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()) && !this->StepDays.empty())
      {
        const double time = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
        step = this->GetStepNumber(time);
        output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), this->StepDays[this->StepIndex(time)]);
      }
      // Each property's range at that step (static ones at every step): what Color By lists
      // and Rescale reads. Names without a table at this step get NaN.
      std::map<std::string, std::pair<float, float>> ranges;
      const float none = std::numeric_limits<float>::quiet_NaN();
      for (const resmr::PropertyTable& table : properties.Tables())
      {
        auto& range = ranges.emplace(table.name, std::make_pair(none, none)).first->second;
        if (table.step < 0 || table.step == step)
        {
          range = { table.minimum, table.maximum };
        }
      }
      const vtkIdType cells = output->GetNumberOfCells();
      for (const auto& entry : ranges)
      {
        vtkNew<vtkFloatArray> values;
        values->SetName(entry.first.c_str());
        values->SetNumberOfTuples(cells);
        for (vtkIdType c = 0; c < cells; ++c)
        {
          values->SetValue(c, c == 0 ? entry.second.first : entry.second.second);
        }
        output->GetCellData()->AddArray(values);
      }
    }
  }
  catch (const std::exception& error)
  {
    return this->Fail(error.what());
  }
  return 1;
}

std::size_t vtkMultiresolutionReader::StepIndex(double time) const
{
  const auto after = std::upper_bound(this->StepDays.begin(), this->StepDays.end(), time);
  return static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (after - this->StepDays.begin()) - 1));
}

int vtkMultiresolutionReader::GetStepNumber(double time) const
{
  return this->StepNumbers.empty() ? 0 : this->StepNumbers[this->StepIndex(time)];
}

void vtkMultiresolutionReader::WarnOfUnreachableRegions(const resmr::MultiresolutionFile& geometry)
{
  const std::vector<std::size_t> unreachable = resmr::UnreachableRegions(geometry);
  if (unreachable.empty())
  {
    return;
  }
  int64_t cells = 0;
  for (std::size_t r : unreachable)
  {
    cells += geometry.Regions()[r].activeCells;
  }
  vtkWarningMacro(<< this->FileName << ": " << unreachable.size() << " region(s) of the hierarchy (" << cells
                  << " active cells) have no parent region and are never drawn, so the view shows holes "
                     "there; the file was built by an earlier resmr: build it again (resmr build)");
}

int vtkMultiresolutionReader::Fail(const std::string& message)
{
  this->LastError = message;
  vtkErrorMacro(<< message);
  return 0;
}

void vtkMultiresolutionReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "PropertyFileName: " << this->PropertyFileName << "\n";
  os << indent << "ApplyMapAxes: " << this->ApplyMapAxes << "\n";
}
