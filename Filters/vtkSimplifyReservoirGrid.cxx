#include "vtkSimplifyReservoirGrid.h"

#include "ResMRFieldData.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellType.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkExplicitStructuredGrid.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include "ResMRExplicitGrid.h"

#include "ColumnCollapse.h"
#include "ColumnMesh.h"
#include "HexMesh.h"

#include <cmath>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(vtkSimplifyReservoirGrid);

vtkSimplifyReservoirGrid::vtkSimplifyReservoirGrid() = default;

void vtkSimplifyReservoirGrid::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TargetFraction: " << this->TargetFraction << "\n";
  os << indent << "TargetColumns: " << this->TargetColumns << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "Candidates: " << this->Candidates << "\n";
}

int vtkSimplifyReservoirGrid::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkExplicitStructuredGrid");
  return 1;
}

using resmr_filters::AddValue;

int vtkSimplifyReservoirGrid::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->LastError.clear();
  vtkExplicitStructuredGrid* input = vtkExplicitStructuredGrid::GetData(inputVector[0], 0);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
  auto fail = [&](const std::string& message) {
    this->LastError = "SimplifyReservoirGrid: " + message;
    vtkErrorMacro(<< this->LastError);
    return 0;
  };
  if (!input || input->GetNumberOfCells() == 0 || !input->GetPoints())
  {
    return fail("the input grid is empty");
  }
  int dims[3];
  input->GetCellDims(dims);
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  const int64_t cells = nx * ny * nz;
  vtkCellData* cellData = input->GetCellData();
  vtkDataArray* iArray = cellData->GetArray("I");
  vtkDataArray* jArray = cellData->GetArray("J");
  vtkDataArray* kArray = cellData->GetArray("K");
  if (!iArray || !jArray || !kArray || cells != input->GetNumberOfCells())
  {
    return fail("the input needs the cell arrays I, J and K of a reservoir grid (GRDECLReader, "
                "EGRIDReader or SyntheticReservoir)");
  }
  vtkUnsignedCharArray* ghosts = input->GetCellGhostArray();

  // ECLIPSE cell index -> VTK cell, and which cells are shown (active).
  std::vector<vtkIdType> cellOf(static_cast<std::size_t>(cells), -1);
  std::vector<bool> active(static_cast<std::size_t>(cells), false);
  bool mirrored = false;
  for (vtkIdType id = 0; id < input->GetNumberOfCells(); ++id)
  {
    const int64_t i = static_cast<int64_t>(iArray->GetTuple1(id)) - 1;
    const int64_t j = static_cast<int64_t>(jArray->GetTuple1(id)) - 1;
    const int64_t k = static_cast<int64_t>(kArray->GetTuple1(id)) - 1;
    if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz)
    {
      return fail("cell " + std::to_string(id) + " has I, J, K outside the grid");
    }
    const int64_t index = (k * ny + j) * nx + i;
    cellOf[index] = id;
    mirrored = mirrored || (id != index);
    active[index] = !ghosts || !(ghosts->GetValue(id) & vtkDataSetAttributes::HIDDENCELL);
  }
  // Mirrored (left-handed) grids store the layers upside down: VTK points 0-3 are deeper.
  vtkPoints* points = input->GetPoints();
  vtkCellArray* hexahedra = input->GetCells();
  const auto corners = [&](int64_t i, int64_t j, int64_t k, double out[8][3]) {
    const vtkIdType id = cellOf[(k * ny + j) * nx + i];
    vtkIdType count = 0;
    const vtkIdType* ids = nullptr;
    hexahedra->GetCellAtId(id, count, ids);
    for (int v = 0; v < 8; ++v)
    {
      const int corner = resmr_readers::EclipseCornerOfVTKPoint[v] ^ (mirrored ? 4 : 0);
      double p[3];
      points->GetPoint(ids[v], p);
      out[corner][0] = p[0];
      out[corner][1] = p[1];
      out[corner][2] = -p[2]; // depth
    }
  };
  try
  {
    resmr::ColumnMesh mesh = resmr::ColumnMesh::FromCells({ nx, ny, nz }, corners, active, 0, nx, 0, ny);
    const int64_t before = mesh.AliveColumns();
    const int64_t target = this->TargetColumns > 0
      ? this->TargetColumns
      : static_cast<int64_t>(std::llround(this->TargetFraction * static_cast<double>(before)));
    resmr::ColumnCollapse collapse(mesh, static_cast<uint64_t>(this->Seed));
    collapse.SetCandidates(this->Candidates);
    const resmr::SimplifyReport report =
      collapse.Simplify(target, [this](double done) { this->UpdateProgress(0.9 * done); });
    const resmr::HexMesh hex = resmr::ToHexMesh(mesh);

    vtkNew<vtkPoints> outPoints;
    outPoints->SetDataTypeToDouble();
    outPoints->SetNumberOfPoints(hex.PointCount());
    vtkNew<vtkDoubleArray> topology;
    topology->SetName("TopologicalCoordinates");
    topology->SetNumberOfComponents(3);
    topology->SetNumberOfTuples(hex.PointCount());
    for (int64_t p = 0; p < hex.PointCount(); ++p)
    {
      outPoints->SetPoint(p, hex.points[3 * p], hex.points[3 * p + 1], -hex.points[3 * p + 2]);
      topology->SetTuple(p, &hex.topology[3 * p]);
    }
    // Deeper face first, counter-clockwise seen from above: positive volumes in z up.
    static const int forward[8] = { 4, 5, 6, 7, 0, 1, 2, 3 };
    static const int backward[8] = { 4, 7, 6, 5, 0, 3, 2, 1 };
    const int* order = mesh.Orientation() > 0 ? forward : backward;
    vtkNew<vtkCellArray> outCells;
    outCells->AllocateExact(hex.CellCount(), 8 * hex.CellCount());
    vtkNew<vtkUnsignedCharArray> activeArray, ghostArray;
    activeArray->SetName("Active");
    ghostArray->SetName(vtkDataSetAttributes::GhostArrayName());
    vtkNew<vtkIntArray> layer;
    layer->SetName("ColumnLayer");
    for (int64_t c = 0; c < hex.CellCount(); ++c)
    {
      vtkIdType ids[8];
      for (int v = 0; v < 8; ++v)
      {
        ids[v] = static_cast<vtkIdType>(hex.cells[c][order[v]]);
      }
      outCells->InsertNextCell(8, ids);
      activeArray->InsertNextValue(hex.active[c]);
      ghostArray->InsertNextValue(hex.active[c] ? 0 : vtkDataSetAttributes::HIDDENCELL);
      layer->InsertNextValue(static_cast<int>(c % hex.layers) + 1);
    }
    output->SetPoints(outPoints);
    output->SetCells(VTK_HEXAHEDRON, outCells);
    output->GetPointData()->AddArray(topology);
    output->GetCellData()->AddArray(activeArray);
    output->GetCellData()->AddArray(layer);
    output->GetCellData()->AddArray(ghostArray);
    vtkFieldData* field = output->GetFieldData();
    AddValue(field, "ColumnsBefore", static_cast<double>(before));
    AddValue(field, "ColumnsAfter", static_cast<double>(mesh.AliveColumns()));
    AddValue(field, "Collapses", static_cast<double>(report.collapses));
    AddValue(field, "Doublets", static_cast<double>(report.doublets));
    AddValue(field, "MaxQuadricError", report.maxError);
    AddValue(field, "ReachedTarget", report.reachedTarget ? 1 : 0);
  }
  catch (const std::exception& error)
  {
    return fail(error.what());
  }
  this->UpdateProgress(1.0);
  return 1;
}
