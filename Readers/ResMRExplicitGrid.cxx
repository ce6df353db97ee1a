// Corner-point grid -> vtkExplicitStructuredGrid (paper Sec. 3), shared by the readers.
#include "ResMRExplicitGrid.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkExplicitStructuredGrid.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"

#include "CornerPointGeometry.h"

#include <sys/stat.h>

namespace resmr_readers
{
long long FileModificationTime(const char* path)
{
  struct stat info;
  if (stat(path, &info) != 0)
  {
    return -1;
  }
  return static_cast<long long>(info.st_mtim.tv_sec) * 1000000000LL + info.st_mtim.tv_nsec;
}

CellOrder BuildExplicitGrid(const resmr::CornerPointGeometry& geometry, const std::vector<int32_t>& actnum,
  const std::vector<bool>& active, bool showInactive, vtkExplicitStructuredGrid* grid)
{
  CellOrder order;
  order.nx = geometry.Dims()[0];
  order.ny = geometry.Dims()[1];
  order.nz = geometry.Dims()[2];
  order.mirrorK = geometry.IsLeftHanded();
  const int64_t nx = order.nx, ny = order.ny, nz = order.nz;
  const vtkIdType cellCount = static_cast<vtkIdType>(nx * ny * nz);

  resmr::CornerPointGeometry::SharedCorners shared = geometry.BuildSharedCorners();
  const vtkIdType pointCount = static_cast<vtkIdType>(shared.points.size() / 3);
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(pointCount);
  double* xyz = coordinates->GetPointer(0);
  for (vtkIdType p = 0; p < pointCount; ++p)
  {
    xyz[3 * p] = shared.points[3 * p];
    xyz[3 * p + 1] = shared.points[3 * p + 1];
    xyz[3 * p + 2] = -shared.points[3 * p + 2]; // elevation: z up
  }
  shared.points = std::vector<double>();
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);

  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfValues(8 * cellCount);
  vtkIdType* ids = connectivity->GetPointer(0);
  for (int64_t cell = 0; cell < cellCount; ++cell)
  {
    vtkIdType* out = ids + 8 * order(cell);
    const int64_t* in = &shared.cellPoints[static_cast<std::size_t>(8 * cell)];
    for (int v = 0; v < 8; ++v)
    {
      // Mirrored: VTK points 0-3 take the bottom (deeper) face.
      const int corner = EclipseCornerOfVTKPoint[v] ^ (order.mirrorK ? 4 : 0);
      out[v] = static_cast<vtkIdType>(in[corner]);
    }
  }
  shared.cellPoints = std::vector<int64_t>();
  vtkNew<vtkCellArray> cells;
  cells->SetData(8, connectivity);

  grid->SetExtent(0, static_cast<int>(nx), 0, static_cast<int>(ny), 0, static_cast<int>(nz));
  grid->SetPoints(points);
  grid->SetCells(cells);

  vtkNew<vtkIntArray> iArray, jArray, kArray, actnumArray;
  iArray->SetName("I");
  jArray->SetName("J");
  kArray->SetName("K");
  actnumArray->SetName("ACTNUM");
  for (vtkIntArray* array : { iArray.Get(), jArray.Get(), kArray.Get(), actnumArray.Get() })
  {
    array->SetNumberOfValues(cellCount);
  }
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfValues(cellCount);
  bool anyHidden = false;
  for (int64_t cell = 0; cell < cellCount; ++cell)
  {
    const vtkIdType id = order(cell);
    iArray->SetValue(id, static_cast<int>(cell % nx + 1));
    jArray->SetValue(id, static_cast<int>((cell / nx) % ny + 1));
    kArray->SetValue(id, static_cast<int>(cell / (nx * ny) + 1));
    actnumArray->SetValue(id, actnum[static_cast<std::size_t>(cell)]);
    const bool hidden = !active[static_cast<std::size_t>(cell)] && !showInactive;
    ghosts->SetValue(id, hidden ? vtkDataSetAttributes::HIDDENCELL : 0);
    anyHidden |= hidden;
  }
  vtkCellData* cellData = grid->GetCellData();
  cellData->AddArray(iArray);
  cellData->AddArray(jArray);
  cellData->AddArray(kArray);
  cellData->AddArray(actnumArray);
  if (anyHidden)
  {
    cellData->AddArray(ghosts);
  }
  // After I, J, K: ParaView's hover and spreadsheet list a cell's arrays in this order, and an
  // engineer reads ECLIPSE's I, J, K first.
  grid->ComputeFacesConnectivityFlagsArray();
  return order;
}

} // namespace resmr_readers
