// INIT and restart results of an EGRID (paper Sec. 3 input; Sec. 6.1: read only what is
// shown).
#include "EclipseResults.h"

#include "CivilCalendar.h"

#include "Errors.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>

namespace resmr
{
namespace
{
namespace fs = std::filesystem;

/// Header and table records that are never per-cell arrays, whatever their length.
bool IsHeaderRecord(const std::string& name)
{
  static const std::set<std::string> names = { "INTEHEAD", "LOGIHEAD", "DOUBHEAD", "SEQNUM", "TABDIMS", "TAB", "CON",
    "TRANNNC", "TRANGL", "TRANGG", "IGRP", "SGRP", "XGRP", "ZGRP", "IWEL", "SWEL", "XWEL", "ZWEL", "ICON", "SCON",
    "XCON", "IWLS", "ZWLS", "DLYTIM", "HIDDEN", "REGDIMS", "REGRPT", "FIPFAMNA", "LGRNAMES", "ZNODE", "INODE", "RNODE",
    "IBRAN", "ISEG", "RSEG", "ILBS", "ILBR", "IUAD", "IUAP", "IGPH", "IUDQ", "DUDW", "DUDG", "DUDF", "ZUDN", "ZUDL",
    "IACT", "SACT", "ZACT", "ZLACT", "XHEAD", "ZFMFWE" };
  return names.count(name) > 0;
}

bool ValidDate(const std::array<int, 3>& date)
{
  return date[0] > 1000 && date[0] < 10000 && date[1] >= 1 && date[1] <= 12 && date[2] >= 1 && date[2] <= 31;
}

std::string Upper(std::string text)
{
  for (char& c : text)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return text;
}

std::string StemOf(const std::string& path)
{
  return fs::path(path).stem().string();
}

std::string FirstExisting(
  const fs::path& directory, const std::string& stem, std::initializer_list<const char*> extensions)
{
  std::error_code error;
  for (const char* extension : extensions)
  {
    for (const std::string& candidate : { std::string(extension), Upper(extension) })
    {
      const fs::path path = directory / (stem + candidate);
      if (fs::is_regular_file(path, error))
      {
        return path.string();
      }
    }
  }
  return {};
}

/// An error message without the file name it starts with (the caller names the file).
std::string WithoutPath(const std::string& message, const std::string& path)
{
  return message.compare(0, path.size() + 2, path + ": ") == 0 ? message.substr(path.size() + 2) : message;
}

/// Why a results file cannot be used at all, or empty if it opened: `file` is then set.
std::string OpenResultsFile(const std::string& path, std::unique_ptr<EclipseKeywordFile>& file)
{
  std::error_code error;
  if (fs::file_size(path, error) == 0 && !error)
  {
    return "the file is empty";
  }
  try
  {
    file = std::make_unique<EclipseKeywordFile>(path, KeywordFileIndexing::UpToLastWholeRecord);
  }
  catch (const std::exception& failure)
  {
    return WithoutPath(failure.what(), path);
  }
  return {};
}
} // namespace

std::string EclipseResults::FindInit(const std::string& gridPath)
{
  const fs::path directory = fs::path(gridPath).parent_path();
  const bool formattedGrid = Upper(fs::path(gridPath).extension().string()) == ".FEGRID";
  return formattedGrid ? FirstExisting(directory, StemOf(gridPath), { ".finit", ".init" })
                       : FirstExisting(directory, StemOf(gridPath), { ".init", ".finit" });
}

std::vector<std::string> EclipseResults::FindRestarts(const std::string& gridPath, bool& unified)
{
  const fs::path directory = fs::path(gridPath).parent_path();
  const std::string stem = StemOf(gridPath);
  const bool formattedGrid = Upper(fs::path(gridPath).extension().string()) == ".FEGRID";
  const std::string unifiedPath = formattedGrid ? FirstExisting(directory, stem, { ".funrst", ".unrst" })
                                                : FirstExisting(directory, stem, { ".unrst", ".funrst" });
  unified = !unifiedPath.empty();
  if (unified)
  {
    return { unifiedPath };
  }
  // Per-step files: STEM.Xnnnn (unformatted) or STEM.Fnnnn (formatted), either case.
  std::vector<std::pair<int, std::string>> found;
  std::error_code error;
  for (fs::directory_iterator entry(directory.empty() ? fs::path(".") : directory, error), end; !error && entry != end;
       entry.increment(error))
  {
    const std::string name = entry->path().filename().string();
    if (name.size() != stem.size() + 6 || name.compare(0, stem.size(), stem) != 0 || name[stem.size()] != '.')
    {
      continue;
    }
    const char kind = static_cast<char>(std::toupper(static_cast<unsigned char>(name[stem.size() + 1])));
    const std::string digits = name.substr(stem.size() + 2);
    if ((kind != 'X' && kind != 'F') ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
    {
      continue;
    }
    const int number = std::stoi(digits);
    const bool preferred = (kind == 'F') == formattedGrid;
    auto same = std::find_if(found.begin(), found.end(), [&](const auto& item) { return item.first == number; });
    if (same == found.end())
    {
      found.emplace_back(number, entry->path().string());
    }
    else if (preferred)
    {
      same->second = entry->path().string();
    }
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> paths;
  for (const auto& item : found)
  {
    paths.push_back(item.second);
  }
  return paths;
}

EclipseResults::EclipseResults(const std::string& gridPath, const EclipseGrid& grid)
{
  this->CellCount = grid.deck.CellCount();
  this->ActiveCount = grid.activeCells;
  this->DualPorosity = grid.dualPorosity;
  this->Expected = grid.activeCells + (grid.dualPorosity ? grid.fractureCells : 0);
  for (int64_t cell = 0; cell < this->CellCount; ++cell)
  {
    if (!grid.IsActive(cell))
    {
      continue;
    }
    if (!this->ActiveRuns.empty() && this->ActiveRuns.back().first + this->ActiveRuns.back().second == cell)
    {
      ++this->ActiveRuns.back().second;
    }
    else
    {
      this->ActiveRuns.emplace_back(cell, 1);
    }
  }
  int64_t before = 0;
  for (const auto& run : this->ActiveRuns)
  {
    this->ValuesBeforeRun.push_back(before);
    before += run.second;
  }

  this->Init = FindInit(gridPath);
  if (this->Init.empty())
  {
    this->Notes.push_back(gridPath + ": no INIT file beside it (" + StemOf(gridPath) + ".INIT): no static properties");
  }
  else
  {
    this->OpenInit();
  }
  this->OpenRestarts(gridPath);
  this->ListDynamicArrays();

  // Times: DOUBHEAD's day count when written, else dates counted from the start date.
  for (EclipseReportStep& step : this->ReportSteps)
  {
    if (!std::isfinite(step.days) || step.days < 0)
    {
      const std::array<int, 3>& start = ValidDate(this->StartDate) ? this->StartDate : this->ReportSteps.front().date;
      step.days = ValidDate(step.date) && ValidDate(start)
        ? static_cast<double>(
            DaysFromCivil(step.date[0], step.date[1], step.date[2]) - DaysFromCivil(start[0], start[1], start[2]))
        : static_cast<double>(step.reportNumber);
    }
  }
}

EclipseResults::~EclipseResults() = default;

bool EclipseResults::FitsGrid(int64_t count) const
{
  return count > 0 &&
    (count == this->Expected || count == this->CellCount || (this->DualPorosity && count == 2 * this->CellCount));
}

void EclipseResults::OpenInit()
{
  std::string problem = OpenResultsFile(this->Init, this->InitFile);
  if (problem.empty() && this->InitFile->StoppedAt() >= 0)
  {
    problem = "damaged or cut short at byte " + std::to_string(this->InitFile->StoppedAt()) + " (" +
      WithoutPath(this->InitFile->StopReason(), this->Init) + ")";
  }
  else if (problem.empty() && this->InitFile->Records().empty())
  {
    problem = "holds no records";
  }
  if (problem.empty())
  {
    try
    {
      if (this->IndexInit())
      {
        return;
      }
      problem.clear(); // a foreign INIT: IndexInit said why
    }
    catch (const std::exception& failure)
    {
      problem = WithoutPath(failure.what(), this->Init);
    }
  }
  this->InitFile.reset();
  this->Static.clear();
  this->StaticRecords.clear();
  if (!problem.empty())
  {
    this->Notes.push_back(this->Init + ": " + problem + ": the INIT file is not used (no static properties)");
  }
}

void EclipseResults::OpenRestarts(const std::string& gridPath)
{
  this->Restarts = FindRestarts(gridPath, this->Unified);
  if (this->Restarts.empty())
  {
    this->Notes.push_back(
      gridPath + ": no restart files beside it (" + StemOf(gridPath) + ".UNRST or .Xnnnn): no time steps");
    return;
  }
  for (std::size_t f = 0; f < this->Restarts.size(); ++f)
  {
    const std::string& path = this->Restarts[f];
    const int number = this->Unified ? -1 : std::stoi(path.substr(path.size() - 4));
    std::unique_ptr<EclipseKeywordFile> file;
    const std::string problem = OpenResultsFile(path, file);
    if (!problem.empty())
    {
      this->LeaveOut(path, number, 0, problem);
      continue;
    }
    this->IndexRestart(f, *file, number);
    if (this->Unified)
    {
      this->UnifiedFile = std::move(file);
    }
  }
}

void EclipseResults::LeaveOut(const std::string& path, int reportNumber, int64_t offset, const std::string& reason)
{
  this->Skipped.push_back({ path, reportNumber, offset, reason });
  const std::string step = reportNumber >= 0 ? "report step " + std::to_string(reportNumber)
    : this->Unified && !this->ReportSteps.empty()
    ? "the report step after report " + std::to_string(this->ReportSteps.back().reportNumber)
    : std::string("its report steps");
  this->Notes.push_back(path + ": " + step + " left out: incomplete at byte " + std::to_string(offset) + " (" + reason +
    "); the other steps are kept");
}

void EclipseResults::ListDynamicArrays()
{
  // Arrays of the steps kept only, in the order they were first met.
  this->Dynamic.clear();
  for (const EclipseResultArray& array : this->SeenDynamic)
  {
    const bool used =
      std::any_of(this->ReportSteps.begin(), this->ReportSteps.end(), [&](const EclipseReportStep& step) {
        return std::find(step.names.begin(), step.names.end(), array.name) != step.names.end();
      });
    if (used)
    {
      this->Dynamic.push_back(array);
    }
  }
}

bool EclipseResults::IndexInit()
{
  const EclipseKeywordFile& file = *this->InitFile;
  const auto& records = file.Records();
  bool inLocalGrid = false;
  std::vector<int32_t> header;
  for (std::size_t r = 0; r < records.size(); ++r)
  {
    const EclipseRecord& record = records[r];
    if (record.name == "LGR")
    {
      inLocalGrid = true;
      continue;
    }
    if (record.name == "LGRSGONE" || record.name == "ENDLGR")
    {
      inLocalGrid = false;
      continue;
    }
    if (inLocalGrid)
    {
      continue;
    }
    if (record.name == "INTEHEAD" && record.IsNumeric() && record.count > 66 && header.empty())
    {
      header.resize(static_cast<std::size_t>(record.count));
      file.Read(record, header.data());
      this->StartDate = { header[66], header[65], header[64] };
      if (header[11] != this->Expected)
      {
        this->Notes.push_back(this->Init + ": keyword INTEHEAD: " + std::to_string(header[11]) +
          " active cells, but the grid has " + std::to_string(this->Expected) +
          ": the INIT file does not belong to this grid; its arrays are not shown");
        this->Static.clear();
        this->StaticRecords.clear();
        return false;
      }
      continue;
    }
    if (!record.IsNumeric() || IsHeaderRecord(record.name) || !this->FitsGrid(record.count))
    {
      continue;
    }
    const bool seen = std::any_of(this->Static.begin(), this->Static.end(),
      [&](const EclipseResultArray& array) { return array.name == record.name; });
    if (!seen)
    {
      this->Static.push_back({ record.name, record.type });
      this->StaticRecords.push_back(r);
    }
  }
  return true;
}

struct EclipseResults::RestartScan
{
  int64_t damagedAt = -1; ///< the record where reading the index failed, or -1
  std::string damage;
  bool closesSolutions = false; ///< STARTSOL met: a step is whole only with its ENDSOL
  bool lastClosed = false;      ///< the last step's ENDSOL met
};

void EclipseResults::IndexRestart(std::size_t fileIndex, const EclipseKeywordFile& file, int fileReportNumber)
{
  const std::size_t firstStep = this->ReportSteps.size();
  RestartScan scan;
  this->ScanRestart(fileIndex, file, fileReportNumber, scan);
  if (scan.damagedAt < 0 && file.StoppedAt() >= 0)
  {
    scan.damagedAt = file.StoppedAt();
    scan.damage = WithoutPath(file.StopReason(), file.Path());
  }
  const bool started = this->ReportSteps.size() > firstStep;
  const bool damaged = scan.damagedAt >= 0;
  // Files with STARTSOL close each solution with ENDSOL. Without them a step's end is not
  // written: one holding no array yet, or fewer than the step before it, is still being
  // written.
  const std::size_t count = this->ReportSteps.size();
  const bool unclosed = scan.closesSolutions ? !scan.lastClosed
                                             : started &&
      (this->ReportSteps.back().names.empty() ||
        (count > firstStep + 1 && this->ReportSteps.back().names.size() < this->ReportSteps[count - 2].names.size()));
  // In a unified restart, damage after the last step's ENDSOL belongs to the step after it;
  // a per-step file is one step, left out for any damage.
  const bool lastWhole = !unclosed && (!damaged || (this->Unified && scan.closesSolutions));
  const std::string rest = damaged ? scan.damage + "; nothing after it is read" : std::string();
  if (started && !lastWhole)
  {
    // A writer still appending, or a cut.
    const int number = this->ReportSteps.back().reportNumber;
    this->ReportSteps.pop_back();
    this->LeaveOut(file.Path(), number, damaged ? scan.damagedAt : file.Size(),
      damaged ? rest : "its solution has no ENDSOL: the file ends there (still being written, or cut)");
  }
  else if (damaged)
  {
    this->LeaveOut(file.Path(), fileReportNumber, scan.damagedAt, rest);
  }
}

void EclipseResults::ScanRestart(
  std::size_t fileIndex, const EclipseKeywordFile& file, int fileReportNumber, RestartScan& scan)
{
  const auto& records = file.Records();
  const std::string& path = file.Path();
  EclipseReportStep* step = nullptr;
  bool inLocalGrid = false, inSolution = false, sawSolution = false, headerRead = false, timeRead = false,
       mismatch = false;
  std::vector<int32_t> integers;
  std::vector<double> numbers;
  const auto startStep = [&](int reportNumber) {
    this->ReportSteps.emplace_back();
    step = &this->ReportSteps.back();
    step->reportNumber = reportNumber;
    step->file = fileIndex;
    step->days = std::nan("");
    inLocalGrid = inSolution = sawSolution = headerRead = timeRead = mismatch = false;
    scan.lastClosed = false;
  };
  std::size_t r = 0;
  try
  {
    for (; r < records.size(); ++r)
    {
      const EclipseRecord& record = records[r];
      const std::string& name = record.name;
      if (name == "SEQNUM")
      {
        int32_t number = static_cast<int32_t>(this->ReportSteps.size());
        if (record.IsNumeric() && record.count >= 1)
        {
          integers.resize(static_cast<std::size_t>(record.count));
          file.Read(record, integers.data());
          number = integers[0];
        }
        startStep(fileReportNumber >= 0 ? fileReportNumber : number);
        continue;
      }
      if (!step)
      {
        if (name != "INTEHEAD")
        {
          continue; // nothing before the first step's header belongs to a step
        }
        startStep(fileReportNumber >= 0 ? fileReportNumber : static_cast<int>(this->ReportSteps.size()));
      }
      if (name == "LGR")
      {
        inLocalGrid = true;
        continue;
      }
      if (name == "ENDLGR")
      {
        inLocalGrid = false;
        continue;
      }
      if (inLocalGrid)
      {
        continue;
      }
      if (name == "INTEHEAD" && !headerRead && record.IsNumeric() && record.count > 66)
      {
        headerRead = true;
        integers.resize(static_cast<std::size_t>(record.count));
        file.Read(record, integers.data());
        step->date = { integers[66], integers[65], integers[64] };
        if (integers[11] != this->Expected)
        {
          mismatch = true;
          this->Notes.push_back(path + ": keyword INTEHEAD: report step " + std::to_string(step->reportNumber) +
            " has " + std::to_string(integers[11]) + " active cells, but the grid has " +
            std::to_string(this->Expected) + ": this restart does not belong to the grid; its arrays are not shown");
        }
        continue;
      }
      if (name == "DOUBHEAD" && !timeRead && record.IsNumeric() && record.count >= 1)
      {
        timeRead = true;
        file.ReadNumbers(record, numbers);
        step->days = numbers[0];
        continue;
      }
      if (name == "STARTSOL")
      {
        inSolution = sawSolution = scan.closesSolutions = true;
        continue;
      }
      if (name == "ENDSOL")
      {
        inSolution = false;
        scan.lastClosed = true;
        continue;
      }
      if (mismatch || !record.IsNumeric() || IsHeaderRecord(name) || (sawSolution && !inSolution))
      {
        continue;
      }
      if (!this->FitsGrid(record.count))
      {
        static const std::set<std::string> perCell = { "PRESSURE", "SWAT", "SGAS", "SOIL", "RS", "RV" };
        if (perCell.count(name) > 0)
        {
          this->Notes.push_back(path + ": keyword " + name + ": report step " + std::to_string(step->reportNumber) +
            " has " + std::to_string(record.count) + " values, the grid has " + std::to_string(this->Expected) +
            " active cells; not shown");
        }
        continue;
      }
      if (std::find(step->names.begin(), step->names.end(), name) != step->names.end())
      {
        continue;
      }
      step->names.push_back(name);
      step->records.push_back(r);
      const bool known = std::any_of(this->SeenDynamic.begin(), this->SeenDynamic.end(),
        [&](const EclipseResultArray& array) { return array.name == name; });
      if (!known)
      {
        this->SeenDynamic.push_back({ name, record.type });
      }
    }
  }
  catch (const std::exception& failure)
  {
    // A header record whose data blocks are damaged: the index ends before it.
    scan.damagedAt = records[r].headerOffset;
    scan.damage = WithoutPath(failure.what(), path);
  }
}

template<typename T>
void EclipseResults::Scatter(const EclipseKeywordFile& file, const EclipseRecord& record, T* cellValues, T fill) const
{
  const bool perActiveCell = record.count == this->Expected;
  if ((perActiveCell && this->ActiveCount == this->CellCount && !this->DualPorosity) ||
    (!perActiveCell && record.count == this->CellCount))
  {
    file.Read(record, cellValues); // one value per cell, in cell order: no copy
    return;
  }
  if (!perActiveCell)
  {
    // Dual porosity, one value per cell and porosity: the matrix half comes first.
    file.ReadInPieces<T>(record, [&](const T* values, int64_t first, int64_t count) {
      if (first < this->CellCount)
      {
        std::copy(values, values + std::min(count, this->CellCount - first), cellValues + first);
      }
    });
    return;
  }
  // Active cells in order, matrix values first (fracture values, after them, are dropped).
  // Pieces may arrive from several threads: each finds its run by the value index, and the
  // gap before a run gets `fill` from whoever writes that run's first value.
  const auto& runs = this->ActiveRuns;
  const auto& before = this->ValuesBeforeRun;
  file.ReadInPieces<T>(record, [&](const T* values, int64_t first, int64_t count) {
    if (runs.empty() || first >= this->ActiveCount)
    {
      return;
    }
    count = std::min(count, this->ActiveCount - first);
    std::size_t run =
      static_cast<std::size_t>(std::upper_bound(before.begin(), before.end(), first) - before.begin() - 1);
    int64_t intoRun = first - before[run];
    while (count > 0)
    {
      const auto& [start, length] = runs[run];
      if (intoRun == 0)
      {
        const int64_t gapStart = run > 0 ? runs[run - 1].first + runs[run - 1].second : 0;
        std::fill(cellValues + gapStart, cellValues + start, fill);
      }
      const int64_t take = std::min(count, length - intoRun);
      std::copy(values, values + take, cellValues + start + intoRun);
      values += take;
      count -= take;
      intoRun = 0;
      ++run;
    }
  });
  const int64_t tail = runs.empty() ? 0 : runs.back().first + runs.back().second;
  std::fill(cellValues + tail, cellValues + this->CellCount, fill);
}

template<typename T>
bool EclipseResults::ReadStatic(const std::string& name, T* cellValues, T fill) const
{
  for (std::size_t a = 0; a < this->Static.size(); ++a)
  {
    if (this->Static[a].name == name)
    {
      const EclipseRecord& record = this->InitFile->Records()[this->StaticRecords[a]];
      this->Scatter(*this->InitFile, record, cellValues, fill);
      return true;
    }
  }
  return false;
}

template<typename T>
bool EclipseResults::ReadDynamic(std::size_t stepIndex, const std::string& name, T* cellValues, T fill) const
{
  if (stepIndex >= this->ReportSteps.size())
  {
    return false;
  }
  const EclipseReportStep& step = this->ReportSteps[stepIndex];
  const auto found = std::find(step.names.begin(), step.names.end(), name);
  if (found == step.names.end())
  {
    return false;
  }
  const std::size_t recordIndex = step.records[static_cast<std::size_t>(found - step.names.begin())];
  if (this->Unified)
  {
    this->Scatter(*this->UnifiedFile, this->UnifiedFile->Records()[recordIndex], cellValues, fill);
    return true;
  }
  // Only the last step's file is kept open, so hundreds of steps never hold hundreds of
  // open files, and a step's arrays share one open.
  if (!this->StepFile || this->StepFileIndex != step.file)
  {
    this->StepFile.reset();
    this->StepFile =
      std::make_unique<EclipseKeywordFile>(this->Restarts[step.file], KeywordFileIndexing::UpToLastWholeRecord);
    this->StepFileIndex = step.file;
  }
  const EclipseKeywordFile& file = *this->StepFile;
  if (recordIndex >= file.Records().size() || file.Records()[recordIndex].name != name)
  {
    throw InputError(file.Path(), 0, name, "file changed since it was opened; reload it");
  }
  this->Scatter(file, file.Records()[recordIndex], cellValues, fill);
  return true;
}

template bool EclipseResults::ReadStatic<float>(const std::string&, float*, float) const;
template bool EclipseResults::ReadStatic<double>(const std::string&, double*, double) const;
template bool EclipseResults::ReadStatic<int32_t>(const std::string&, int32_t*, int32_t) const;
template bool EclipseResults::ReadDynamic<float>(std::size_t, const std::string&, float*, float) const;
template bool EclipseResults::ReadDynamic<double>(std::size_t, const std::string&, double*, double) const;
template bool EclipseResults::ReadDynamic<int32_t>(std::size_t, const std::string&, int32_t*, int32_t) const;

} // namespace resmr
