/**
 * @class   vtkGRDECLReader
 * @brief   Reads Eclipse corner-point grid decks (GRDECL, DATA, binary GRDECL) into a
 *          vtkExplicitStructuredGrid.
 *
 * Output port 0 is the grid: one hexahedron per cell (I fastest, then J, then K), points in
 * double precision with z = -depth (z up), corners shared between cells exactly where
 * ECLIPSE connects them, so faults and layer gaps show as surfaces. Cell arrays: I, J, K
 * (1-based, as ECLIPSE counts), ACTNUM and the selected properties. Inactive cells carry
 * the HIDDENCELL ghost bit unless ShowInactiveCells is on.
 *
 * For left-handed grids the hexahedra are stored bottom layer first (structured k runs up)
 * so that every cell has a positive volume; the K array always holds ECLIPSE's K.
 *
 * Output port 1 holds the faces of the selected FAULTS as quads, with cell arrays
 * FaultIndex and the field array FaultNames (FaultIndex -> name).
 *
 * Parsing is done by resmr::ParseGrdeclFile (Core); errors name the file, line and
 * keyword and leave the outputs empty.
 */
#ifndef vtkGRDECLReader_h
#define vtkGRDECLReader_h

#include "ResMRReadersModule.h" // for export macro
#include "vtkExplicitStructuredGridAlgorithm.h"
#include "vtkNew.h" // for vtkNew

#include <memory> // for std::unique_ptr
#include <string> // for std::string

class vtkDataArraySelection;

class RESMRREADERS_EXPORT vtkGRDECLReader : public vtkExplicitStructuredGridAlgorithm
{
public:
  static vtkGRDECLReader* New();
  vtkTypeMacro(vtkGRDECLReader, vtkExplicitStructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The deck to read (.grdecl, .GRDECL, .DATA, .data, .inc, .INC, .bgrdecl).
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /// Show cells with ACTNUM = 0 instead of hiding them. Off by default.
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
  /// Which cell properties (PORO, PERMX, SATNUM, ...) to load. All are on by default.
  vtkDataArraySelection* GetCellArraySelection();
  int GetNumberOfCellArrays();
  const char* GetCellArrayName(int index);
  int GetCellArrayStatus(const char* name);
  void SetCellArrayStatus(const char* name, int status);
  ///@}

  ///@{
  /// Which faults (by FAULTS name) go to output port 1. All are on by default.
  vtkDataArraySelection* GetFaultSelection();
  int GetNumberOfFaultArrays();
  const char* GetFaultArrayName(int index);
  int GetFaultArrayStatus(const char* name);
  void SetFaultArrayStatus(const char* name, int status);
  ///@}

  /// True if the last grid read was left-handed (stored with k running up).
  vtkGetMacro(LeftHanded, bool);

  /// The message of the last error, empty after a successful read.
  const char* GetLastError() { return this->LastError.c_str(); }

  /// What the deck left out (edits of arrays the viewer does not build, flow-only keywords,
  /// local grids, missing INCLUDE files), one per line naming the file, line and keyword.
  const char* GetWarnings() { return this->Warnings.c_str(); }

  /// Returns 1 if the file looks like a deck this reader can open.
  static int CanReadFile(const char* fileName);

protected:
  vtkGRDECLReader();
  ~vtkGRDECLReader() override;

  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkGRDECLReader(const vtkGRDECLReader&) = delete;
  void operator=(const vtkGRDECLReader&) = delete;

  bool ParseIfNeeded();
  void ReportError(const std::string& message);

  char* FileName = nullptr;
  bool ShowInactiveCells = false;
  int MemoryLimitMB = 0;
  bool ApplyMapAxes = true;
  bool LeftHanded = false;
  std::string LastError;
  std::string Warnings;
  vtkNew<vtkDataArraySelection> CellArraySelection;
  vtkNew<vtkDataArraySelection> FaultSelection;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
