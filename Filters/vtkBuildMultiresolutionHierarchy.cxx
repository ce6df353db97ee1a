#include "vtkBuildMultiresolutionHierarchy.h"

#include "HierarchyBuilder.h"
#include "LayerSource.h"

#include "vtkDoubleArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTable.h"

#include <stdexcept>

vtkStandardNewMacro(vtkBuildMultiresolutionHierarchy);

vtkBuildMultiresolutionHierarchy::vtkBuildMultiresolutionHierarchy()
{
  this->SetNumberOfInputPorts(0);
}

void vtkBuildMultiresolutionHierarchy::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Input: " << this->Input << "\n";
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "Scratch: " << this->Scratch << "\n";
  os << indent << "Cmax: " << this->Cmax << "\n";
  os << indent << "Threads: " << this->Threads << "\n";
  os << indent << "MemoryMiB: " << this->MemoryMiB << "\n";
  os << indent << "Resume: " << this->Resume << "\n";
}

int vtkBuildMultiresolutionHierarchy::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // Every rank must run RequestData (the build is collective), not only piece 0.
  outputVector->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

int vtkBuildMultiresolutionHierarchy::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkTable* output = vtkTable::GetData(outputVector, 0);
  this->LastError.clear();
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  resmr::HierarchyOptions options;
  options.cmax = this->Cmax;
  options.threads = this->Threads;
  options.memoryBytes = static_cast<int64_t>(this->MemoryMiB) << 20;
  options.scratch = this->Scratch;
  options.resume = this->Resume;
  if (controller && controller->GetNumberOfProcesses() > 1)
  {
    options.rank = controller->GetLocalProcessId();
    options.ranks = controller->GetNumberOfProcesses();
    options.barrier = [controller] { controller->Barrier(); };
  }
  try
  {
    if (this->Input.empty() || this->FileName.empty())
    {
      throw std::invalid_argument("Input and FileName are both needed");
    }
    // Only rank 0 streams the input (the others read its partition), but every rank needs
    // its size: each opens it (an EGRID's header; a deck is parsed, its grid spooled to
    // unique unlinked files in the shared scratch folder, so ranks never collide).
    std::unique_ptr<resmr::LayerSource> source =
      resmr::OpenLayerSource(this->Input, resmr::ScratchFolder(this->FileName, options));
    const resmr::HierarchyReport report =
      resmr::BuildHierarchy(*source, this->FileName, options, [this](const char* phase, double fraction) {
        this->SetProgressText(phase);
        this->UpdateProgress(fraction);
      });
    const std::pair<const char*, double> values[] = { { "Cells", double(report.cells) },
      { "ActiveCells", double(report.activeCells) }, { "Columns", double(report.columns) },
      { "Levels", double(report.leafLevel + 1) }, { "Regions", double(report.regions) },
      { "FileBytes", double(report.fileBytes) }, { "Seconds", report.totalSeconds },
      { "ResumedFromLevel", double(report.resumedFromLevel) }, { "HashedCells", double(report.hashedCells) },
      { "Ranks", double(options.ranks) } };
    for (const auto& value : values)
    {
      vtkNew<vtkDoubleArray> column;
      column->SetName(value.first);
      column->InsertNextValue(value.second);
      output->AddColumn(column);
    }
  }
  catch (const std::exception& error)
  {
    this->LastError = error.what();
    vtkErrorMacro("BuildMultiresolutionHierarchy: " << error.what());
    return 0;
  }
  return 1;
}
