/**
 * @class   vtkExtractMultiresolutionLevel
 * @brief   The hexahedral mesh of one level, or of one error tolerance, of a .resmr file.
 *
 * Reads a multiresolution file written by `resmr build` (Abraham & Celes 2019, Sec. 4.2, 6.1)
 * and gives the all-hexahedra mesh of a conformal cut of its diamond hierarchy as a
 * vtkUnstructuredGrid: every region of level Level (0 is the coarsest), or, when Level is -1,
 * the coarsest regions whose model-space error is at most ErrorTolerance (Sec. 6.2), which
 * match without cracks. Points are z up (z = -depth); the point array
 * TopologicalCoordinates holds (ti, tj, tk) of each vertex (Sec. 5.1, 0-based); the cell
 * arrays are Active (inactive cells are also hidden, as in the readers), ColumnLayer (k + 1),
 * Region and Level. Field data: Levels, SelectedRegions, MaxError (of the regions shown).
 *
 * Work is forwarded to resmr::MultiresolutionFile and resmr::SelectByError (Core). A damaged
 * file fails the update with the file and the place named (GetLastError()).
 */
#ifndef vtkExtractMultiresolutionLevel_h
#define vtkExtractMultiresolutionLevel_h

#include "ResMRFiltersModule.h" // for export macro
#include "vtkUnstructuredGridAlgorithm.h"

#include <string>

class RESMRFILTERS_EXPORT vtkExtractMultiresolutionLevel : public vtkUnstructuredGridAlgorithm
{
public:
  static vtkExtractMultiresolutionLevel* New();
  vtkTypeMacro(vtkExtractMultiresolutionLevel, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The .resmr file.
  vtkSetStdStringFromCharMacro(FileName);
  vtkGetCharFromStdStringMacro(FileName);
  ///@}

  ///@{
  /// Level to extract (0: the coarsest, past the finest: the finest); -1 (the default) selects
  /// by ErrorTolerance instead.
  vtkSetClampMacro(Level, int, -1, 64);
  vtkGetMacro(Level, int);
  ///@}

  ///@{
  /// Largest model-space error (model units) of the regions shown when Level is -1; 0 gives
  /// the finest level.
  vtkSetClampMacro(ErrorTolerance, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(ErrorTolerance, double);
  ///@}

  /// Why the last update failed, empty if it did not.
  const char* GetLastError() { return this->LastError.c_str(); }

protected:
  vtkExtractMultiresolutionLevel();
  ~vtkExtractMultiresolutionLevel() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkExtractMultiresolutionLevel(const vtkExtractMultiresolutionLevel&) = delete;
  void operator=(const vtkExtractMultiresolutionLevel&) = delete;

  std::string FileName;
  int Level = -1;
  double ErrorTolerance = 0.0;
  std::string LastError;
};

#endif
