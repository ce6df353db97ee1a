/**
 * @class   vtkEGRIDReader
 * @brief   Reads simulator output: an EGRID (or FEGRID) grid with its INIT static arrays and
 *          restart report steps (UNRST, FUNRST, Xnnnn, Fnnnn) as time steps.
 *
 * The output follows the same contract as vtkGRDECLReader: a vtkExplicitStructuredGrid with
 * z = -depth, corners shared where ECLIPSE connects cells, cell arrays I, J, K (from 1) and
 * ACTNUM, HIDDENCELL for inactive cells. The grid is built by the same code.
 *
 * Companion files are found by the EGRID's basename. A damaged, empty or foreign INIT, and
 * report steps whose restart is cut short or damaged (a run still being written), are left
 * out with a warning (Warnings) naming the file, the step and the byte offset; the grid and
 * the other steps open. Reload() (File > Reload Files) indexes the companions again. Arrays with one value per active
 * cell are mapped to cells through the EGRID's ACTNUM; inactive cells get NaN (real arrays) or 0. Report steps become
 * time steps in days (TIME_STEPS); only the requested step's selected arrays are read, by seeking to record offsets
 * indexed once when the file is opened. The geometry and static arrays are built once and shared by every step's
 * output.
 *
 * LGRs and non-neighbour connections are not shown (a warning names them); dual-porosity
 * grids show the matrix grid. Field data: ReportStep, Days, Date of the step shown;
 * NonNeighbourConnections (count) and LocalGridRefinements (names) not shown.
 * Restarts without SOIL (OPM Flow writes SWAT and SGAS only) get SOIL = 1 - SWAT - SGAS.
 *
 * Work is forwarded to resmr::ReadEclipseGrid and resmr::EclipseResults (Core). Errors name
 * the file, keyword and byte offset and leave the output empty.
 */
#ifndef vtkEGRIDReader_h
#define vtkEGRIDReader_h

#include "ResMRReadersModule.h" // for export macro
#include "vtkExplicitStructuredGridAlgorithm.h"
#include "vtkNew.h" // for vtkNew

#include <memory> // for std::unique_ptr
#include <string> // for std::string

class vtkDataArraySelection;

class RESMRREADERS_EXPORT vtkEGRIDReader : public vtkExplicitStructuredGridAlgorithm
{
public:
  static vtkEGRIDReader* New();
  vtkTypeMacro(vtkEGRIDReader, vtkExplicitStructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The grid file (.EGRID, .FEGRID, either case).
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /// Show inactive cells instead of hiding them. Off by default.
  vtkSetMacro(ShowInactiveCells, bool);
  vtkGetMacro(ShowInactiveCells, bool);
  vtkBooleanMacro(ShowInactiveCells, bool);
  ///@}

  ///@{
  /// Memory, in MiB, a full-resolution grid may take (about 300 bytes a cell); 0, the
  /// default, means the memory available now. Bigger models are refused with a message
  /// pointing to the multiresolution path.
  void SetMemoryLimitMB(int megabytes);
  vtkGetMacro(MemoryLimitMB, int);
  ///@}

  ///@{
  /// Place the grid in map coordinates given by MAPAXES. On by default.
  vtkSetMacro(ApplyMapAxes, bool);
  vtkGetMacro(ApplyMapAxes, bool);
  vtkBooleanMacro(ApplyMapAxes, bool);
  ///@}

  ///@{
  /// Which INIT (static) and restart (dynamic) arrays to load. On by default for models up
  /// to DefaultAllArraysCellLimit cells; above it only the common ones (PORO, PERMX, NTG,
  /// PRESSURE, SWAT, SGAS, ...), as each array costs 4 bytes per cell.
  vtkDataArraySelection* GetCellArraySelection();
  int GetNumberOfCellArrays();
  const char* GetCellArrayName(int index);
  int GetCellArrayStatus(const char* name);
  void SetCellArrayStatus(const char* name, int status);
  ///@}

  /// Models with more cells than this start with only the common arrays selected.
  static constexpr long long DefaultAllArraysCellLimit = 5000000;

  /// Number of report steps found (0 without restart files).
  int GetNumberOfReportSteps();
  /// Index of the report step in the last output, -1 if none.
  vtkGetMacro(CurrentStep, int);

  /// The message of the last error, empty after a successful read.
  const char* GetLastError() { return this->LastError.c_str(); }
  /// Warnings of the last file opened (LGRs, dual porosity, missing companions, an INIT or
  /// report steps left out because their file is empty, cut short or damaged, each with the
  /// file, step and byte offset ...), one per line.
  const char* GetWarnings() { return this->Warnings.c_str(); }

  /// Indexes the INIT and restart files again on the next update (File > Reload Files,
  /// ReloadFiles() in pvpython): the report steps a simulator has completed since are
  /// offered. The grid itself is kept.
  void Reload();

  /// Returns 1 if the file is an ECLIPSE keyword file (EGRID; old GRID files are opened only
  /// to be refused with a message).
  static int CanReadFile(const char* fileName);

protected:
  vtkEGRIDReader();
  ~vtkEGRIDReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkEGRIDReader(const vtkEGRIDReader&) = delete;
  void operator=(const vtkEGRIDReader&) = delete;

  bool OpenIfNeeded();
  bool RescanCompanions();
  void ListArraysAndTimes();
  bool BuildBaseIfNeeded();
  void UpdateStaticArrays();
  void AddWarning(const std::string& message);
  void WarnOnce(const std::string& message); ///< unless Warnings holds it already (or empty)
  void ReportError(const std::string& message);

  char* FileName = nullptr;
  bool ShowInactiveCells = false;
  int MemoryLimitMB = 0;
  bool ApplyMapAxes = true;
  int CurrentStep = -1;
  std::string LastError;
  std::string Warnings;
  vtkNew<vtkDataArraySelection> CellArraySelection;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
