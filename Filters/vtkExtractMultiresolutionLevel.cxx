#include "vtkExtractMultiresolutionLevel.h"

#include "ResMRFieldData.h"

#include "ConformalCut.h"
#include "MultiresolutionFile.h"
#include "RegionMesh.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>

vtkStandardNewMacro(vtkExtractMultiresolutionLevel);

using resmr_filters::AddValue;

vtkExtractMultiresolutionLevel::vtkExtractMultiresolutionLevel()
{
  this->SetNumberOfInputPorts(0);
}

void vtkExtractMultiresolutionLevel::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << this->FileName << "\n";
  os << indent << "Level: " << this->Level << "\n";
  os << indent << "ErrorTolerance: " << this->ErrorTolerance << "\n";
}

int vtkExtractMultiresolutionLevel::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
  this->LastError.clear();
  try
  {
    if (this->FileName.empty())
    {
      throw std::runtime_error("no file name given");
    }
    const resmr::MultiresolutionFile file(this->FileName);
    const std::vector<std::size_t> regions =
      this->Level >= 0 ? resmr::SelectLevel(file, this->Level) : resmr::SelectByError(file, this->ErrorTolerance);
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    vtkNew<vtkDoubleArray> topology;
    topology->SetName("TopologicalCoordinates");
    topology->SetNumberOfComponents(3);
    vtkNew<vtkCellArray> cells;
    vtkNew<vtkUnsignedCharArray> active, ghosts;
    active->SetName("Active");
    ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
    vtkNew<vtkIntArray> layerArray, regionArray, levelArray;
    layerArray->SetName("ColumnLayer");
    regionArray->SetName("Region");
    levelArray->SetName("Level");
    double maxError = 0;
    // Deeper face first, counter-clockwise seen from above: positive volumes in z up.
    static const int forward[4] = { 0, 1, 2, 3 };
    static const int backward[4] = { 0, 3, 2, 1 };
    for (std::size_t n = 0; n < regions.size(); ++n)
    {
      const resmr::RegionRecord& record = file.Regions()[regions[n]];
      const resmr::RegionMesh mesh = file.ReadRegion(regions[n]);
      maxError = std::max<double>(maxError, record.error);
      const vtkIdType first = points->GetNumberOfPoints();
      const int32_t interfaces = mesh.layers + 1;
      for (int64_t v = 0; v < mesh.VertexCount(); ++v)
      {
        const double* p = &mesh.positions[static_cast<std::size_t>(v) * 3];
        points->InsertNextPoint(p[0], p[1], -p[2]);
        const auto& t = mesh.topology[static_cast<std::size_t>(v / interfaces)];
        topology->InsertNextTuple3(t[0], t[1], static_cast<double>(v % interfaces));
      }
      const int* order = resmr::RegionOrientation(mesh) > 0 ? forward : backward;
      for (int64_t c = 0; c < mesh.ColumnCount(); ++c)
      {
        const auto& q = mesh.corners[static_cast<std::size_t>(c)];
        for (int32_t k = 0; k < mesh.layers; ++k)
        {
          vtkIdType ids[8];
          for (int v = 0; v < 4; ++v)
          {
            ids[v] = first + mesh.Vertex(q[order[v]], k + 1);
            ids[v + 4] = first + mesh.Vertex(q[order[v]], k);
          }
          cells->InsertNextCell(8, ids);
          const bool on = mesh.active[static_cast<std::size_t>(c) * mesh.layers + k] != 0;
          active->InsertNextValue(on ? 1 : 0);
          ghosts->InsertNextValue(on ? 0 : vtkDataSetAttributes::HIDDENCELL);
          layerArray->InsertNextValue(k + 1);
          regionArray->InsertNextValue(static_cast<int>(record.index));
          levelArray->InsertNextValue(record.level);
        }
      }
      this->UpdateProgress(static_cast<double>(n + 1) / static_cast<double>(regions.size()));
    }
    output->SetPoints(points);
    output->SetCells(VTK_HEXAHEDRON, cells);
    output->GetPointData()->AddArray(topology);
    output->GetCellData()->AddArray(active);
    output->GetCellData()->AddArray(layerArray);
    output->GetCellData()->AddArray(regionArray);
    output->GetCellData()->AddArray(levelArray);
    output->GetCellData()->AddArray(ghosts);
    AddValue(output->GetFieldData(), "Levels", file.Header().leafLevel + 1);
    AddValue(output->GetFieldData(), "SelectedRegions", static_cast<double>(regions.size()));
    AddValue(output->GetFieldData(), "MaxError", maxError);
  }
  catch (const std::exception& error)
  {
    this->LastError = error.what();
    vtkErrorMacro(<< this->FileName << ": " << error.what());
    return 0;
  }
  return 1;
}
