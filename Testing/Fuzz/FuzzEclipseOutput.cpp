// Fuzz target for the ECLIPSE keyword-file reader (EclipseKeywordFile), the EGRID/FEGRID grid
// reader (ReadEclipseGrid) and the INIT/restart results beside it (EclipseResults).
//
// libFuzzer build (see run_fuzz.sh):
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I Core Core/*.cpp FuzzEclipseOutput.cpp
// Standalone replay build (ctest FuzzEclipseOutput.SeedCorpus): compile with
// -DRESMR_FUZZ_STANDALONE; the executable runs the target over every file (or every file in
// every directory) named on its command line.
//
// Input layout: up to 8 parts separated by the 8 bytes "%RESMR%\n" (SplitMarker). The parts
// are written into a private, otherwise empty folder as companions of one grid:
//   part 0            input.EGRID   (input.FEGRID if it starts like a formatted file)
//   part 1            input.INIT    (input.FINIT)
//   part 2, 3 parts   input.UNRST   (input.FUNRST)                     unified restart
//   part 2.., more    input.X0000, input.X0001, ... (input.Fnnnn)      per-step restarts
// An empty part writes no file (a missing companion), except an empty part 0 of an input
// with more parts: it becomes the fixed grid, a valid small EGRID (the 6x5x3 model of
// resmr synth 6 5 3, seed 1, generated once per process), so that fuzzed INIT and restart
// files always meet a sound grid and reach the companion paths (cut and damaged files,
// incomplete report steps). An input without the marker is a single EGRID (or any keyword
// file: INIT, UNRST, binary GRDECL), so real files are seeds as they are.
//
// Per input: every part is sniffed (LooksLike*), opened as an EclipseKeywordFile (and, for
// parts 1.., indexed up to the last whole record as results files are) and every record read (numeric ones as double,
// float and int32_t, character ones as strings, MESS ones must be refused); then ReadEclipseGrid on part 0 (maxCells 1
// << 20), grid invariants checked, EclipseResults built and every static array and every dynamic array of every step
// read (double, float, int32_t); last the corner-point geometry of the grid is built as the reader does (FromDeck,
// BuildSharedCorners).
//
// Expected outcomes: results, or a resmr::InputError (or another std::exception) for bad
// input. Anything else -- a crash, a sanitizer report, a hang or a runaway allocation -- is
// a finding.
#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseResults.h"
#include "Errors.h"
#include "FuzzReplay.h"
#include "SyntheticReservoir.h"
#include "SyntheticReservoirWriter.h"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <string_view>
#include <vector>

#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

namespace
{
constexpr std::string_view SplitMarker("%RESMR%\n", 8);
constexpr std::size_t MaxParts = 8;
constexpr int64_t MaxCells = int64_t(1) << 20;

/// A private, initially empty directory holding only this input's files, so that companion
/// lookup (by basename, and the Xnnnn directory scan) sees nothing else.
class InputFiles
{
public:
  InputFiles()
  {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/resmr-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data()))
    {
      std::perror("mkdtemp");
      std::abort();
    }
    this->Directory = pattern;
  }
  ~InputFiles()
  {
    this->Clear();
    rmdir(this->Directory.c_str());
  }
  InputFiles(const InputFiles&) = delete;
  InputFiles& operator=(const InputFiles&) = delete;

  /// Removes the files of the previous input.
  void Clear()
  {
    for (const std::string& path : this->Paths)
    {
      std::remove(path.c_str());
    }
    this->Paths.clear();
  }

  const std::string& Write(const std::string& name, std::string_view data)
  {
    const std::string path = this->Directory + "/" + name;
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file || (!data.empty() && std::fwrite(data.data(), 1, data.size(), file) != data.size()) ||
      std::fclose(file) != 0)
    {
      std::perror(path.c_str());
      std::abort();
    }
    this->Paths.push_back(path);
    return this->Paths.back();
  }

private:
  std::string Directory;
  std::vector<std::string> Paths;
};

#ifdef RESMR_FUZZ_STANDALONE
std::string LastOutcome; // what the last input did, for the replay log
#define RESMR_FUZZ_OUTCOME(text) (LastOutcome = (text))
#else
#define RESMR_FUZZ_OUTCOME(text) ((void)0)
#endif

/// The bytes of the fixed grid (see the input layout above).
const std::string& FixedGrid()
{
  static const std::string bytes = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string directory = std::string(tmp && *tmp ? tmp : "/tmp") + "/resmr-fuzz-grid-XXXXXX";
    if (!mkdtemp(directory.data()))
    {
      std::perror("mkdtemp");
      std::abort();
    }
    resmr::SyntheticParameters parameters;
    parameters.nx = 6;
    parameters.ny = 5;
    parameters.nz = 3;
    const resmr::SyntheticOutput written =
      resmr::WriteSyntheticEclipse(resmr::SyntheticReservoir(parameters), directory + "/FIXED.EGRID");
    std::string grid;
    resmr_fuzz::ReadWholeFile(directory + "/FIXED.EGRID", grid);
    for (const std::string& path : written.files)
    {
      std::remove(path.c_str());
    }
    rmdir(directory.c_str());
    if (grid.empty())
    {
      std::fprintf(stderr, "FuzzEclipseOutput: the fixed grid was not written\n");
      std::abort();
    }
    return grid;
  }();
  return bytes;
}

InputFiles& TheInputFiles()
{
  static InputFiles files; // one per process, reused across iterations
  return files;
}

/// The input cut at every SplitMarker, at most MaxParts parts (the last keeps the rest).
std::vector<std::string_view> SplitInput(std::string_view input)
{
  std::vector<std::string_view> parts;
  while (parts.size() + 1 < MaxParts)
  {
    const std::size_t at = input.find(SplitMarker);
    if (at == std::string_view::npos)
    {
      break;
    }
    parts.push_back(input.substr(0, at));
    input.remove_prefix(at + SplitMarker.size());
  }
  parts.push_back(input);
  return parts;
}

/// What EclipseKeywordFile::LooksLikeFormatted keys on: a quote after leading blanks.
bool StartsFormatted(std::string_view data)
{
  const std::size_t first = data.find_first_not_of(" \r\n");
  return first != std::string_view::npos && data[first] == '\'';
}

/// File name of part `index` of `count`, formatted or not.
std::string PartName(std::size_t index, std::size_t count, bool formatted)
{
  if (index == 0)
  {
    return formatted ? "input.FEGRID" : "input.EGRID";
  }
  if (index == 1)
  {
    return formatted ? "input.FINIT" : "input.INIT";
  }
  if (count == 3)
  {
    return formatted ? "input.FUNRST" : "input.UNRST";
  }
  char name[32];
  std::snprintf(name, sizeof(name), "input.%c%04zu", formatted ? 'F' : 'X', index - 2);
  return name;
}

[[noreturn]] void BrokenInvariant(const std::string& what)
{
  resmr_fuzz::BrokenInvariant("FuzzEclipseOutput", what);
}
using resmr_fuzz::InvariantsChecked;

/// Whitespace-separated tokens in text, and the length of the longest.
int64_t CountTokens(std::string_view text, std::size_t& longest)
{
  int64_t tokens = 0;
  std::size_t length = 0;
  longest = 0;
  for (const char c : text)
  {
    const bool blank = c == ' ' || c == '\n' || c == '\r' || c == '\t';
    tokens += !blank && length == 0;
    length = blank ? 0 : length + 1;
    longest = std::max(longest, length);
  }
  return tokens;
}

/// Opens one keyword file (its bytes are `contents`) and reads every record the ways a
/// caller may; a results file (INIT, restart) indexed up to its last whole record.
std::string ReadEveryRecord(const std::string& path, std::string_view contents, bool results)
{
  int64_t records = 0, errors = 0;
  std::string other;
  // The cheap sniffers of file dialogs and `resmr info` (they read the file's head only).
  const bool unformatted = resmr::EclipseKeywordFile::LooksLikeUnformatted(path);
  const bool formatted = resmr::EclipseKeywordFile::LooksLikeFormatted(path);
  const bool grid = resmr::LooksLikeEclipseGridFile(path);
  if (grid && !unformatted && !formatted)
  {
    BrokenInvariant(path + ": LooksLikeEclipseGridFile but neither LooksLike(Un)formatted");
  }
  try
  {
    const resmr::EclipseKeywordFile file(
      path, results ? resmr::KeywordFileIndexing::UpToLastWholeRecord : resmr::KeywordFileIndexing::WholeFile);
    // A lenient index stops exactly where its last whole record ends.
    const int64_t lastEnd = file.Records().empty() ? 0 : file.Records().back().endOffset;
    if (file.StoppedAt() >= 0 && (file.StoppedAt() != lastEnd || file.StoppedAt() >= file.Size()))
    {
      BrokenInvariant(path + ": index stopped at byte " + std::to_string(file.StoppedAt()) +
        ", its last whole record ends at " + std::to_string(lastEnd) + ", the file has " + std::to_string(file.Size()) +
        " bytes");
    }
    std::vector<double> numbers;
    std::vector<float> floats;
    std::vector<int32_t> integers;
    for (const resmr::EclipseRecord& record : file.Records())
    {
      ++records;
      if (record.count < 0 || record.dataOffset < record.headerOffset || record.endOffset < record.dataOffset ||
        record.endOffset > file.Size())
      {
        BrokenInvariant(path + ": record " + record.name + " has count " + std::to_string(record.count) + ", offsets " +
          std::to_string(record.headerOffset) + "/" + std::to_string(record.dataOffset) + "/" +
          std::to_string(record.endOffset) + " in a file of " + std::to_string(file.Size()) + " bytes");
      }
      // Formatted numbers are one blank-separated token each (finding 04).
      std::size_t longest = 0;
      if (file.IsFormatted() && record.IsNumeric())
      {
        const int64_t tokens = CountTokens(contents.substr(static_cast<std::size_t>(record.dataOffset),
                                             static_cast<std::size_t>(record.endOffset - record.dataOffset)),
          longest);
        if (tokens != record.count)
        {
          BrokenInvariant(path + ": formatted record " + record.name + " indexed with count " +
            std::to_string(record.count) + " but its data holds " + std::to_string(tokens) + " tokens (longest " +
            std::to_string(longest) + " characters)");
        }
      }
      if (file.Find(record.name) == nullptr)
      {
        BrokenInvariant(path + ": Find(\"" + record.name + "\") misses an indexed record");
      }
      try
      {
        if (record.IsNumeric())
        {
          file.ReadNumbers(record, numbers);
          // TextCursor keeps 257 characters of a longer token, for the conversion to refuse
          // (finding 05: a valid number's first 257 characters parse too).
          if (longest > 257)
          {
            BrokenInvariant(path + ": formatted record " + record.name + " read although a value is " +
              std::to_string(longest) + " characters long");
          }
          floats.assign(static_cast<std::size_t>(record.count), 0.0f);
          file.Read(record, floats.data());
          integers.assign(static_cast<std::size_t>(record.count), 0);
          file.Read(record, integers.data()); // REAL/DOUB out of int32 range: 0 (finding 01)
        }
        else if (record.type == resmr::EclipseDataType::Character)
        {
          const std::vector<std::string> strings = file.ReadStrings(record);
          if (strings.size() != static_cast<std::size_t>(record.count))
          {
            BrokenInvariant(path + ": ReadStrings(" + record.name + ") gave " + std::to_string(strings.size()) +
              " strings for count " + std::to_string(record.count));
          }
        }
        else
        {
          // MESS: must be refused before allocating: nothing bounds a MESS count (finding 03).
          file.ReadNumbers(record, numbers);
          BrokenInvariant(path + ": numeric read accepted MESS record " + record.name);
        }
      }
      catch (const resmr::InputError&)
      {
        ++errors;
      }
      catch (const std::exception& error)
      {
        ++errors; // e.g. std::bad_alloc: reported by the sanitizers' allocator when fuzzing
        other = std::string(" std::exception: ") + error.what();
      }
    }
  }
  catch (const resmr::InputError& error)
  {
    return std::string("index: InputError: ") + error.what();
  }
  return std::to_string(records) + " records (" + std::to_string(errors) + " unreadable)" + other;
}

/// The promises the reader relies on: every array sized for the dimensions.
void CheckGrid(const resmr::EclipseGrid& grid)
{
  if (!InvariantsChecked())
  {
    return;
  }
  const auto& d = grid.deck.dims;
  if (d[0] <= 0 || d[1] <= 0 || d[2] <= 0 || d[0] * d[1] * d[2] > MaxCells)
  {
    BrokenInvariant("grid dims " + std::to_string(d[0]) + " x " + std::to_string(d[1]) + " x " + std::to_string(d[2]) +
      " (maxCells " + std::to_string(MaxCells) + ")");
  }
  const auto n = static_cast<std::size_t>(grid.deck.CellCount());
  if (grid.deck.coord.size() != static_cast<std::size_t>(6 * (d[0] + 1) * (d[1] + 1)))
  {
    BrokenInvariant("COORD has " + std::to_string(grid.deck.coord.size()) + " values for " + std::to_string(d[0]) +
      " x " + std::to_string(d[1]) + " x " + std::to_string(d[2]));
  }
  const std::size_t depths = grid.deck.zcorn.size() + grid.deck.zcornSingle.size();
  if (depths != 8 * n || (!grid.deck.zcorn.empty() && !grid.deck.zcornSingle.empty()))
  {
    BrokenInvariant("ZCORN has " + std::to_string(depths) + " values for " + std::to_string(n) +
      " cells (double and single precision copies: " + std::to_string(grid.deck.zcorn.size()) + ", " +
      std::to_string(grid.deck.zcornSingle.size()) + ")");
  }
  if (grid.actnum.size() != n)
  {
    BrokenInvariant("actnum has " + std::to_string(grid.actnum.size()) + " values for " + std::to_string(n) + " cells");
  }
  for (const resmr::CellArray& array : grid.deck.arrays)
  {
    if (array.values.size() != n)
    {
      BrokenInvariant("array " + array.name + " has " + std::to_string(array.values.size()) + " values for " +
        std::to_string(n) + " cells");
    }
  }
  if (grid.activeCells < 0 || grid.activeCells > grid.deck.CellCount() || grid.fractureCells < 0 ||
    grid.fractureCells > grid.deck.CellCount())
  {
    BrokenInvariant("active " + std::to_string(grid.activeCells) + ", fracture " + std::to_string(grid.fractureCells) +
      " of " + std::to_string(n) + " cells");
  }
}

/// Reads every static array and every dynamic array of every step, as double and int32_t.
std::string ReadEveryResult(const resmr::EclipseResults& results, int64_t cells)
{
  const auto n = static_cast<std::size_t>(cells);
  std::vector<double> values(n);
  std::vector<int32_t> integers(n);
  int64_t read = 0;
  std::vector<float> floats(n);
  for (const resmr::EclipseResultArray& array : results.StaticArrays())
  {
    if (!results.ReadStatic(array.name, values.data(), -1.0) || !results.ReadStatic(array.name, floats.data(), -1.0f) ||
      !results.ReadStatic(array.name, integers.data(), int32_t(-1)))
    {
      BrokenInvariant("ReadStatic(" + array.name + ") misses a listed static array");
    }
    ++read;
  }
  for (std::size_t step = 0; step < results.Steps().size(); ++step)
  {
    const resmr::EclipseReportStep& info = results.Steps()[step];
    if (info.names.size() != info.records.size())
    {
      BrokenInvariant("step " + std::to_string(step) + " has " + std::to_string(info.names.size()) + " names and " +
        std::to_string(info.records.size()) + " records");
    }
    for (const resmr::EclipseResultArray& array : results.DynamicArrays())
    {
      const bool listed = std::find(info.names.begin(), info.names.end(), array.name) != info.names.end();
      const bool got = results.ReadDynamic(step, array.name, values.data(), -1.0);
      if (got != listed || results.ReadDynamic(step, array.name, floats.data(), -1.0f) != got ||
        results.ReadDynamic(step, array.name, integers.data(), int32_t(-1)) != got)
      {
        BrokenInvariant("ReadDynamic(" + std::to_string(step) + ", " + array.name + ") returned " +
          (got ? "true" : "false") + " for a" + (listed ? " listed" : "n unlisted") + " array");
      }
      read += got;
    }
    // Out of range: false, not a crash.
    if (results.ReadDynamic(results.Steps().size(), info.names.empty() ? "" : info.names[0], values.data(), 0.0))
    {
      BrokenInvariant("ReadDynamic accepted a step past the end");
    }
  }
  for (const resmr::EclipseSkippedStep& skipped : results.SkippedSteps())
  {
    if (skipped.offset < 0 || skipped.reason.empty())
    {
      BrokenInvariant(skipped.file + ": step left out at byte " + std::to_string(skipped.offset) + " with reason '" +
        skipped.reason + "'");
    }
  }
  if (results.Warnings().size() < results.SkippedSteps().size())
  {
    BrokenInvariant("a step was left out without a warning");
  }
  return std::to_string(results.StaticArrays().size()) + " static, " + std::to_string(results.Steps().size()) +
    " steps, " + std::to_string(results.DynamicArrays().size()) + " dynamic names, " + std::to_string(read) +
    " arrays read, " + std::to_string(results.SkippedSteps().size()) + " steps left out, " +
    std::to_string(results.Warnings().size()) + " warnings";
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size)
{
  InputFiles& files = TheInputFiles();
  files.Clear();
  const std::vector<std::string_view> parts = SplitInput(std::string_view(reinterpret_cast<const char*>(data), size));
  std::string gridPath;
  std::string outcome;
  for (std::size_t p = 0; p < parts.size(); ++p)
  {
    if (parts[p].empty() && p > 0)
    {
      continue; // a missing companion
    }
    const std::string_view part = p == 0 && parts.size() > 1 && parts[0].empty() ? FixedGrid() : parts[p];
    const std::string& path = files.Write(PartName(p, parts.size(), StartsFormatted(part)), part);
    if (p == 0)
    {
      gridPath = path;
    }
    outcome +=
      (outcome.empty() ? "" : "; ") + path.substr(path.rfind('/') + 1) + ": " + ReadEveryRecord(path, part, p > 0);
  }
  try
  {
    resmr::EclipseGrid grid = resmr::ReadEclipseGrid(gridPath, MaxCells);
    CheckGrid(grid);
    outcome +=
      "; grid " + std::to_string(grid.deck.CellCount()) + " cells, " + std::to_string(grid.activeCells) + " active";
    const resmr::EclipseResults results(gridPath, grid);
    outcome += "; " + ReadEveryResult(results, grid.deck.CellCount());
    resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(grid.deck, true);
    const resmr::CornerPointGeometry::SharedCorners shared = geometry.BuildSharedCorners();
    const std::size_t points = shared.points.size() / 3;
    for (const int64_t id : shared.cellPoints)
    {
      if (id < 0 || static_cast<std::size_t>(id) >= points)
      {
        BrokenInvariant(
          "BuildSharedCorners: corner point id " + std::to_string(id) + " outside [0, " + std::to_string(points) + ")");
      }
    }
    outcome += "; geometry " + std::to_string(points) + " shared points";
  }
  catch (const resmr::InputError& error)
  {
    // expected: bad input reported as such
    outcome += std::string("; InputError: ") + error.what();
  }
  catch (const std::exception& error)
  {
    // expected too: e.g. std::bad_alloc, std::out_of_range from the standard library
    outcome += std::string("; std::exception: ") + error.what();
  }
  RESMR_FUZZ_OUTCOME(outcome);
  (void)outcome;
  return 0;
}

#ifdef RESMR_FUZZ_STANDALONE
namespace
{
using resmr_fuzz::ReadWholeFile;

void RunInput(const std::string& name, const std::string& contents, long& count)
{
  std::printf("%s (%zu bytes): ", name.c_str(), contents.size());
  std::fflush(stdout); // the name is out before a crash
  LastOutcome.clear();
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(contents.data()), contents.size());
  std::printf("%s\n", LastOutcome.substr(0, 400).c_str());
  ++count;
}

/// For an EGRID/FEGRID with an INIT or restarts beside it: grid, INIT and restarts joined by
/// SplitMarker (per-step restarts, at most 5, end with an empty part so that they are written
/// as Xnnnn, not as a unified restart). False for other files and sets over 1 MiB.
bool GridSet(const std::string& path, std::string& set)
{
  std::string extension = path.substr(path.find_last_of("./") + 1);
  for (char& c : extension)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  if (extension != "EGRID" && extension != "FEGRID")
  {
    return false;
  }
  const std::string init = resmr::EclipseResults::FindInit(path);
  bool unified = false;
  std::vector<std::string> restarts = resmr::EclipseResults::FindRestarts(path, unified);
  if (init.empty() && restarts.empty())
  {
    return false;
  }
  restarts.resize(std::min<std::size_t>(restarts.size(), 5));
  std::vector<std::string> names = { path, init };
  names.insert(names.end(), restarts.begin(), restarts.end());
  if (!unified && !restarts.empty())
  {
    names.emplace_back(); // a fourth part at least: per-step files
  }
  set.clear();
  for (std::size_t p = 0; p < names.size(); ++p)
  {
    std::string contents;
    if (!names[p].empty() && !ReadWholeFile(names[p], contents))
    {
      return false;
    }
    set += (p ? std::string(SplitMarker) : std::string()) + contents;
    if (set.size() > (std::size_t(1) << 20))
    {
      return false;
    }
  }
  return true;
}

} // namespace

int main(int argc, char** argv)
{
  resmr_fuzz::LimitAddressSpace(4);
  long count = 0;
  return resmr_fuzz::ReplayMain(
    "FuzzEclipseOutputReplay", argc, argv, count, [&](const std::string& path, const std::string& contents) {
      RunInput(path, contents, count);
      // A grid with companions beside it is also replayed as a set, as run_fuzz.sh seeds it.
      std::string set;
      if (GridSet(path, set))
      {
        RunInput(path + " +companions", set, count);
      }
    });
}
#endif
