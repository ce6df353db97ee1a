/**
 * @class   vtkBuildMultiresolutionHierarchy
 * @brief   Builds a .resmr multiresolution file from a reservoir model, out of core.
 *
 * The ParaView face of `resmr build` (Abraham & Celes 2019, Sec. 4.2, 4.3, 5.3-5.4, 6.1):
 * streams the model named by Input (a GRDECL/DATA deck, an EGRID, or
 * `synth:NIxNJxNK[:SEED]`) into the diamond hierarchy and writes FileName. Progress goes to
 * the usual progress events, the phase to the progress text.
 *
 * Under MPI (`mpirun -np N pvbatch --symmetric script.py`) every rank runs this filter with
 * the same properties: the ranks split the leaves and each level's diamonds through the
 * global vtkMultiProcessController, sharing the scratch folder (beside FileName, or Scratch),
 * and rank 0 writes the file. The result is the file a single process writes.
 *
 * A killed build resumes from its last finished level when run again with the same
 * properties (Resume, on by default).
 *
 * Output: a one-row vtkTable of the build report (cells, levels, regions, bytes, seconds,
 * the level resumed from, hashed cells). A failed build leaves no file, an empty table and
 * the reason in GetLastError().
 */
#ifndef vtkBuildMultiresolutionHierarchy_h
#define vtkBuildMultiresolutionHierarchy_h

#include "ResMRFiltersModule.h" // for export macro
#include "vtkTableAlgorithm.h"

#include <string>

class RESMRFILTERS_EXPORT vtkBuildMultiresolutionHierarchy : public vtkTableAlgorithm
{
public:
  static vtkBuildMultiresolutionHierarchy* New();
  vtkTypeMacro(vtkBuildMultiresolutionHierarchy, vtkTableAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The model: a GRDECL/DATA deck, an EGRID, or synth:NIxNJxNK[:SEED].
  vtkSetStdStringFromCharMacro(Input);
  vtkGetCharFromStdStringMacro(Input);
  ///@}

  ///@{
  /// The .resmr file to write.
  vtkSetStdStringFromCharMacro(FileName);
  vtkGetCharFromStdStringMacro(FileName);
  ///@}

  ///@{
  /// Scratch folder shared by the ranks; empty: FileName + ".scratch".
  vtkSetStdStringFromCharMacro(Scratch);
  vtkGetCharFromStdStringMacro(Scratch);
  ///@}

  ///@{
  /// Columns a region holds at most; 0 (default): chosen from the model.
  vtkSetClampMacro(Cmax, int, 0, 1 << 20);
  vtkGetMacro(Cmax, int);
  ///@}

  ///@{
  /// Worker threads a rank; 0 (default): every core.
  vtkSetClampMacro(Threads, int, 0, 1024);
  vtkGetMacro(Threads, int);
  ///@}

  ///@{
  /// Memory budget of a rank in MiB; 0 (default): half the available memory.
  vtkSetClampMacro(MemoryMiB, int, 0, 1 << 30);
  vtkGetMacro(MemoryMiB, int);
  ///@}

  ///@{
  /// Continue a killed build of the same input and options (default on).
  vtkSetMacro(Resume, bool);
  vtkGetMacro(Resume, bool);
  vtkBooleanMacro(Resume, bool);
  ///@}

  /// Why the last update failed, empty if it did not.
  const char* GetLastError() { return this->LastError.c_str(); }

protected:
  vtkBuildMultiresolutionHierarchy();
  ~vtkBuildMultiresolutionHierarchy() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkBuildMultiresolutionHierarchy(const vtkBuildMultiresolutionHierarchy&) = delete;
  void operator=(const vtkBuildMultiresolutionHierarchy&) = delete;

  std::string Input;
  std::string FileName;
  std::string Scratch;
  int Cmax = 0;
  int Threads = 0;
  int MemoryMiB = 0;
  bool Resume = true;
  std::string LastError;
};

#endif
