// Simulator results beside an EGRID (paper Sec. 3 input; Sec. 6.1: only the shown data is
// read): static arrays from INIT/FINIT and dynamic arrays per report step from a unified
// restart (UNRST/FUNRST) or per-step restarts (Xnnnn/Fnnnn).
//
// Contract:
// - Companions are found by the grid's basename, either case, unformatted preferred; a
//   unified restart wins over per-step files. Missing companions are warnings, not errors.
// - Opening indexes every companion once (record offsets, report numbers, times); reading
//   one array of one step then seeks straight to it: a step switch costs that step's bytes.
// - Arrays with one value per active cell are mapped to cells through the EGRID's ACTNUM
//   (the deck's may differ); arrays with one value per cell are taken as they are. Dual
//   porosity: the matrix values (the first part) are used. LGR sections are skipped.
// - Not thread-safe: per-step restarts keep the last step's file open between calls.
// - Arrays or steps that do not fit the grid (another active count) are left out with a
//   warning naming the file and keyword.
// - Damage costs only the damaged part (a run may be cut short, or still being written):
//   an empty, damaged or foreign INIT gives a warning and no static arrays; companions are
//   indexed up to their last whole record, and a report step is offered only when it is
//   complete: every record whole and, in files that close solutions with ENDSOL, its ENDSOL
//   written. An incomplete step (the last of a unified restart cut short, a per-step file
//   cut or damaged) is left out with a warning naming the file, the step and the byte
//   offset (SkippedSteps()); the other steps stay. Nothing here throws for a damaged
//   companion; reading a record whose blocks turn out damaged throws InputError.
#pragma once

#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace resmr
{

struct EclipseResultArray
{
  std::string name;
  EclipseDataType type = EclipseDataType::Real;
  bool IsInteger() const { return this->type == EclipseDataType::Integer || this->type == EclipseDataType::Logical; }
};

struct EclipseReportStep
{
  int reportNumber = 0;             ///< SEQNUM, or the nnnn of Xnnnn
  double days = 0;                  ///< simulated time since the start
  std::array<int, 3> date{};        ///< year, month, day; 0 if unknown
  std::size_t file = 0;             ///< index into RestartPaths()
  std::vector<std::string> names;   ///< arrays this step holds, one per shown cell
  std::vector<std::size_t> records; ///< their record index in the file
};

/// A report step left out because its file is cut short or damaged there.
struct EclipseSkippedStep
{
  std::string file;
  int reportNumber = -1; ///< -1 if the cut falls before the step's number is known
  int64_t offset = 0;    ///< byte offset of the first record that is not whole
  std::string reason;
};

class EclipseResults
{
public:
  /// Finds and indexes the companions of `gridPath`; throws InputError on corrupt files.
  /// Keeps what it needs of `grid` (the active cells), not a reference.
  EclipseResults(const std::string& gridPath, const EclipseGrid& grid);
  ~EclipseResults();

  const std::string& InitPath() const { return this->Init; }
  const std::vector<std::string>& RestartPaths() const { return this->Restarts; }
  bool UnifiedRestart() const { return this->Unified; }
  const std::vector<std::string>& Warnings() const { return this->Notes; }
  /// Report steps left out, in file order.
  const std::vector<EclipseSkippedStep>& SkippedSteps() const { return this->Skipped; }
  /// False if an INIT beside the grid could not be used at all (empty, damaged, foreign).
  bool InitUsable() const { return this->InitFile != nullptr; }

  const std::vector<EclipseResultArray>& StaticArrays() const { return this->Static; }
  const std::vector<EclipseResultArray>& DynamicArrays() const { return this->Dynamic; }
  const std::vector<EclipseReportStep>& Steps() const { return this->ReportSteps; }

  /// Fills cellValues[0 .. nx ny nz) with INIT array `name`; cells without a value get
  /// `fill`. False if there is no such array.
  template<typename T>
  bool ReadStatic(const std::string& name, T* cellValues, T fill) const;

  /// Same for array `name` of report step `step` (index into Steps()).
  template<typename T>
  bool ReadDynamic(std::size_t step, const std::string& name, T* cellValues, T fill) const;

  /// Companion paths of an EGRID, for tests and tools.
  static std::string FindInit(const std::string& gridPath);
  static std::vector<std::string> FindRestarts(const std::string& gridPath, bool& unified);

private:
  void OpenInit();
  bool IndexInit(); ///< false for an INIT of another grid (a warning says why)
  void OpenRestarts(const std::string& gridPath);
  /// Indexes one restart file's steps and leaves out its last one if it is not whole.
  void IndexRestart(std::size_t fileIndex, const EclipseKeywordFile& file, int fileReportNumber);
  struct RestartScan;
  void ScanRestart(std::size_t fileIndex, const EclipseKeywordFile& file, int fileReportNumber, RestartScan& scan);
  void LeaveOut(const std::string& path, int reportNumber, int64_t offset, const std::string& reason);
  void ListDynamicArrays();
  bool FitsGrid(int64_t count) const;
  template<typename T>
  void Scatter(const EclipseKeywordFile& file, const EclipseRecord& record, T* cellValues, T fill) const;

  /// Runs of consecutive active (matrix) cells: first cell, length. Values of active-cell
  /// arrays go to these cells in order.
  std::vector<std::pair<int64_t, int64_t>> ActiveRuns;
  std::vector<int64_t> ValuesBeforeRun; ///< active cells before each run (run lookup)
  int64_t CellCount = 0;
  int64_t ActiveCount = 0;
  bool DualPorosity = false;
  int64_t Expected = 0; ///< values per active-cell array: matrix (+ fracture) cells
  std::string Init;
  std::vector<std::string> Restarts;
  bool Unified = false;
  std::vector<std::string> Notes;
  std::vector<EclipseSkippedStep> Skipped;
  /// Record types of restart arrays as first met, for ListDynamicArrays.
  std::vector<EclipseResultArray> SeenDynamic;
  std::vector<EclipseResultArray> Static;
  std::vector<std::size_t> StaticRecords;
  std::vector<EclipseResultArray> Dynamic;
  std::vector<EclipseReportStep> ReportSteps;
  std::unique_ptr<EclipseKeywordFile> InitFile;
  std::unique_ptr<EclipseKeywordFile> UnifiedFile; ///< kept open
  /// The per-step file of the last step read, so a step's arrays share one open.
  mutable std::unique_ptr<EclipseKeywordFile> StepFile;
  mutable std::size_t StepFileIndex = 0;
  std::array<int, 3> StartDate{};
};

} // namespace resmr
