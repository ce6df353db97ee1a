// Shared by the Eclipse readers and the synthetic reservoir source: turns a Core corner-point grid into the plugin's
// vtkExplicitStructuredGrid contract (paper Sec. 3): z up, corners shared where ECLIPSE
// connects cells, I/J/K from 1, ACTNUM, HIDDENCELL for inactive cells, face connectivity
// flags; and maps per-cell arrays from ECLIPSE cell order to VTK cell order.
#ifndef ResMRExplicitGrid_h
#define ResMRExplicitGrid_h

#include "vtkDataArray.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include "LargeArrays.h"        // for resmr::AdviseHugePages
#include "ResMRReadersModule.h" // for export macro

#include <cstdint>
#include <vector>

class vtkExplicitStructuredGrid;
namespace resmr
{
class CornerPointGeometry;
}

namespace resmr_readers
{

/// ECLIPSE corner (di + 2 dj + 4 dk) of each point of the grid's VTK hexahedra; mirrored
/// (left-handed) grids swap top and bottom: corner ^ 4.
constexpr int EclipseCornerOfVTKPoint[8] = { 0, 1, 3, 2, 4, 5, 7, 6 };

/// Modification time of a file in nanoseconds, -1 if it cannot be read: readers reopen a
/// file when it changes.
RESMRREADERS_EXPORT long long FileModificationTime(const char* path);

/// VTK cell id of an ECLIPSE cell index (i fastest, k down). Left-handed grids are stored
/// with the structured k index running up so every hexahedron has a positive volume.
struct CellOrder
{
  int64_t nx = 0, ny = 0, nz = 0;
  bool mirrorK = false;
  vtkIdType operator()(int64_t eclipseCell) const
  {
    if (!this->mirrorK)
    {
      return static_cast<vtkIdType>(eclipseCell);
    }
    const int64_t layer = this->nx * this->ny;
    const int64_t k = eclipseCell / layer;
    return static_cast<vtkIdType>((this->nz - 1 - k) * layer + eclipseCell % layer);
  }
};

/// Builds points, hexahedra, connectivity flags and the I, J, K and ACTNUM cell arrays.
/// `actnum` holds ACTNUM as given (one per cell, ECLIPSE order), `active` which cells are
/// shown; inactive cells get HIDDENCELL unless showInactive. Throws std::bad_alloc.
RESMRREADERS_EXPORT CellOrder BuildExplicitGrid(const resmr::CornerPointGeometry& geometry,
  const std::vector<int32_t>& actnum, const std::vector<bool>& active, bool showInactive,
  vtkExplicitStructuredGrid* grid);

/// A new array of `cells` tuples named `name`, VTKArray (vtkFloatArray, vtkIntArray ...);
/// `fill(pointer)` writes values in ECLIPSE cell order into the pointer, which is the
/// array's own storage unless the grid is mirrored (then a scratch buffer, permuted after).
template<typename VTKArray, typename Fill>
vtkSmartPointer<VTKArray> MakeCellArray(const char* name, const CellOrder& order, Fill&& fill)
{
  using Value = typename VTKArray::ValueType;
  const int64_t cells = order.nx * order.ny * order.nz;
  auto array = vtkSmartPointer<VTKArray>::New();
  array->SetName(name);
  array->SetNumberOfValues(static_cast<vtkIdType>(cells));
  Value* out = array->GetPointer(0);
  resmr::AdviseHugePages(out, static_cast<std::size_t>(cells) * sizeof(Value));
  if (!order.mirrorK)
  {
    fill(out);
    return array;
  }
  std::vector<Value> scratch(static_cast<std::size_t>(cells));
  fill(scratch.data());
  for (int64_t cell = 0; cell < cells; ++cell)
  {
    out[order(cell)] = scratch[static_cast<std::size_t>(cell)];
  }
  return array;
}

} // namespace resmr_readers

#endif
