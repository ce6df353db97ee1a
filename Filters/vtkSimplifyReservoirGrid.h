/**
 * @class   vtkSimplifyReservoirGrid
 * @brief   Column-collapse simplification of a reservoir grid (Abraham & Celes 2019, Sec. 4.1).
 *
 * Input: the vtkExplicitStructuredGrid of GRDECLReader, EGRIDReader or SyntheticReservoir
 * (cell arrays I, J, K; hidden cells are inactive). Output: the simplified all-hexahedra mesh
 * as a vtkUnstructuredGrid: columns of nk cells (inactive ones hidden, as in the input),
 * z up, with the point array TopologicalCoordinates (ti, tj, tk: the pillar and interface,
 * 0-based, Sec. 5.1) carried through every collapse, and the cell arrays Active and
 * ColumnLayer (k + 1).
 *
 * Work is forwarded to resmr::ColumnMesh and resmr::ColumnCollapse (Core). The target is a
 * fraction of the columns (TargetFraction) or a column count (TargetColumns, if above 0).
 * Field data records what was done: columns before and after, collapses, doublets, the
 * largest quadric error, and whether the target was reached.
 */
#ifndef vtkSimplifyReservoirGrid_h
#define vtkSimplifyReservoirGrid_h

#include "ResMRFiltersModule.h" // for export macro
#include "vtkUnstructuredGridAlgorithm.h"

#include <string>

class RESMRFILTERS_EXPORT vtkSimplifyReservoirGrid : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkSimplifyReservoirGrid* New();
  vtkTypeMacro(vtkSimplifyReservoirGrid, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Fraction of the columns to keep (default 0.1), used when TargetColumns is 0.
  vtkSetClampMacro(TargetFraction, double, 0.0, 1.0);
  vtkGetMacro(TargetFraction, double);
  ///@}

  ///@{
  /// Columns to keep; 0 (the default) uses TargetFraction.
  vtkSetClampMacro(TargetColumns, int, 0, VTK_INT_MAX);
  vtkGetMacro(TargetColumns, int);
  ///@}

  ///@{
  /// Random seed of the candidate choice; the same seed gives the same mesh.
  vtkSetClampMacro(Seed, int, 0, VTK_INT_MAX);
  vtkGetMacro(Seed, int);
  ///@}

  ///@{
  /// Random candidates weighed before each collapse (default 8, as the paper).
  vtkSetClampMacro(Candidates, int, 1, 1024);
  vtkGetMacro(Candidates, int);
  ///@}

  /// Why the last update failed, empty if it did not.
  const char* GetLastError() { return this->LastError.c_str(); }

protected:
  vtkSimplifyReservoirGrid();
  ~vtkSimplifyReservoirGrid() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkSimplifyReservoirGrid(const vtkSimplifyReservoirGrid&) = delete;
  void operator=(const vtkSimplifyReservoirGrid&) = delete;

  double TargetFraction = 0.1;
  int TargetColumns = 0;
  int Seed = 1;
  int Candidates = 8;
  std::string LastError;
};

#endif
