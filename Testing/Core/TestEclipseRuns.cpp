// Simulator runs cut short, damaged or still being written (EclipseResults over companions
// indexed up to their last whole record): the steps offered are exactly the complete ones,
// their values equal the whole run's, and what is left out is named (file, step, byte).
// Damaged copies of the real models are made at test time in TEMP_DIR (the unchanged
// companions are symbolic links), cut at offsets drawn from a fixed seed.
//
//   TestEclipseRuns DATA_DIR TEMP_DIR
#include "CoreTesting.h"

#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseResults.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace resmr;
namespace fs = std::filesystem;

namespace
{
std::string DataDir, TempDir;
constexpr int Cuts = 10;

std::string Slurp(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void Spit(const std::string& path, const std::string& bytes)
{
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// A fresh folder holding links to `files` (in `from`, named `stem` + extension), so that one
/// of them can be replaced by a damaged copy.
std::string LinkedRun(
  const std::string& name, const std::string& from, const std::string& stem, const std::vector<std::string>& extensions)
{
  const std::string folder = TempDir + "/" + name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  for (const std::string& extension : extensions)
  {
    fs::create_symlink(from + "/" + stem + extension, folder + "/" + stem + extension);
  }
  return folder;
}

/// Replaces the link `path` by a file holding `bytes`.
void Replace(const std::string& path, const std::string& bytes)
{
  fs::remove(path);
  Spit(path, bytes);
}

std::vector<int64_t> CutOffsets(std::mt19937_64& random, int64_t size)
{
  std::uniform_int_distribution<int64_t> offset(1, size - 1);
  std::vector<int64_t> cuts;
  for (int c = 0; c < Cuts; ++c)
  {
    cuts.push_back(offset(random));
  }
  return cuts;
}

bool HasWarning(const EclipseResults& results, const std::vector<std::string>& fragments)
{
  return std::any_of(results.Warnings().begin(), results.Warnings().end(), [&](const std::string& warning) {
    return std::all_of(fragments.begin(), fragments.end(),
      [&](const std::string& fragment) { return warning.find(fragment) != std::string::npos; });
  });
}

/// Every array of every step `cut` offers equals the same step's of `whole`, bit for bit;
/// `offered[s]` is the index in `whole` of cut's step s.
void CheckSameValues(
  const EclipseResults& whole, const EclipseResults& cut, const std::vector<std::size_t>& offered, int64_t cells)
{
  std::vector<float> expected(static_cast<std::size_t>(cells)), got(static_cast<std::size_t>(cells));
  for (std::size_t s = 0; s < offered.size(); ++s)
  {
    const EclipseReportStep& step = whole.Steps()[offered[s]];
    CHECK(cut.Steps()[s].names == step.names);
    for (const std::string& name : step.names)
    {
      CHECK(whole.ReadDynamic(offered[s], name, expected.data(), -1.0f));
      CHECK(cut.ReadDynamic(s, name, got.data(), -1.0f));
      CHECK(std::memcmp(expected.data(), got.data(), expected.size() * sizeof(float)) == 0);
    }
  }
}

/// Reek's unified restart (4 report steps, STARTSOL/ENDSOL) cut at random offsets: the steps
/// wholly before the cut are offered, the one cut is named with its byte offset.
void UnifiedRestartCut()
{
  const std::string from = DataDir + "/reek/res2df_sim/eclipse/model", stem = "2_R001_REEK-0";
  const std::string grid = from + "/" + stem + ".EGRID";
  const EclipseGrid eclipseGrid = ReadEclipseGrid(grid);
  const EclipseResults whole(grid, eclipseGrid);
  CHECK(whole.Steps().size() == 4 && whole.SkippedSteps().empty());
  const std::string bytes = Slurp(from + "/" + stem + ".UNRST");
  // Where each step's records start and end: at the SEQNUMs, the last at the end of the file.
  const EclipseKeywordFile file(from + "/" + stem + ".UNRST");
  std::vector<int64_t> starts;
  for (const EclipseRecord& record : file.Records())
  {
    if (record.name == "SEQNUM")
    {
      starts.push_back(record.headerOffset);
    }
  }
  CHECK(starts.size() == whole.Steps().size());
  starts.push_back(file.Size());

  std::mt19937_64 random(20261126);
  std::vector<int64_t> cuts = CutOffsets(random, file.Size());
  cuts.push_back(starts[2]);     // exactly after a whole step: nothing left out
  cuts.push_back(starts[1] + 7); // inside a SEQNUM header: its number is not known
  const std::string folder = LinkedRun("reek-unrst", from, stem, { ".EGRID", ".INIT", ".UNRST" });
  const std::string cutPath = folder + "/" + stem + ".UNRST";
  for (const int64_t cut : cuts)
  {
    Replace(cutPath, bytes.substr(0, static_cast<std::size_t>(cut)));
    const EclipseResults results(folder + "/" + stem + ".EGRID", eclipseGrid);
    std::size_t complete = 0;
    while (complete + 1 < starts.size() && starts[complete + 1] <= cut)
    {
      ++complete;
    }
    std::printf("UNRST cut at byte %lld: %zu steps offered (expected %zu), %zu left out\n", static_cast<long long>(cut),
      results.Steps().size(), complete, results.SkippedSteps().size());
    CHECK(results.Steps().size() == complete);
    CHECK(results.StaticArrays().size() == whole.StaticArrays().size());
    std::vector<std::size_t> offered;
    for (std::size_t s = 0; s < std::min(complete, results.Steps().size()); ++s)
    {
      offered.push_back(s);
      CHECK(results.Steps()[s].reportNumber == whole.Steps()[s].reportNumber);
      CHECK(results.Steps()[s].days == whole.Steps()[s].days);
    }
    if (results.Steps().size() == complete)
    {
      CheckSameValues(whole, results, offered, eclipseGrid.deck.CellCount());
    }
    const bool atBoundary = std::find(starts.begin(), starts.end(), cut) != starts.end();
    CHECK(results.SkippedSteps().size() == (atBoundary ? 0u : 1u));
    if (results.SkippedSteps().size() == 1)
    {
      const EclipseSkippedStep& skipped = results.SkippedSteps()[0];
      CHECK(skipped.file == cutPath);
      CHECK(skipped.offset >= starts[complete] && skipped.offset <= cut);
      // The step's number is known once its SEQNUM record is whole (24 + 12 bytes).
      const bool numbered = cut >= starts[complete] + 36;
      CHECK(skipped.reportNumber == (numbered ? whole.Steps()[complete].reportNumber : -1));
      CHECK(HasWarning(results,
        { cutPath, "left out", "byte " + std::to_string(skipped.offset),
          numbered ? "report step " + std::to_string(skipped.reportNumber) : "after report" }));
    }
  }
}

/// Brugge's per-step restarts: X0010 (the last) and X0004 (one in the middle) cut at random
/// offsets; every other step stays, with its values.
void PerStepRestartCut()
{
  const std::string from = DataDir + "/brugge/Real0", stem = "BRUGGE_0000";
  std::vector<std::string> extensions = { ".EGRID", ".INIT" };
  for (int n = 0; n <= 10; ++n)
  {
    char name[8];
    std::snprintf(name, sizeof(name), ".X%04d", n);
    extensions.push_back(name);
  }
  const std::string grid = from + "/" + stem + ".EGRID";
  const EclipseGrid eclipseGrid = ReadEclipseGrid(grid);
  const EclipseResults whole(grid, eclipseGrid);
  CHECK(whole.Steps().size() == 11 && whole.SkippedSteps().empty());
  std::mt19937_64 random(7);
  for (const int victim : { 10, 4 })
  {
    const std::string folder = LinkedRun("brugge-x", from, stem, extensions);
    char name[8];
    std::snprintf(name, sizeof(name), ".X%04d", victim);
    const std::string cutPath = folder + "/" + stem + name;
    const std::string bytes = Slurp(from + "/" + stem + name);
    std::vector<int64_t> cuts = CutOffsets(random, static_cast<int64_t>(bytes.size()));
    cuts.push_back(0); // an empty file
    for (const int64_t cut : cuts)
    {
      Replace(cutPath, bytes.substr(0, static_cast<std::size_t>(cut)));
      const EclipseResults results(folder + "/" + stem + ".EGRID", eclipseGrid);
      std::printf("X%04d cut at byte %lld: %zu steps offered, %zu left out\n", victim, static_cast<long long>(cut),
        results.Steps().size(), results.SkippedSteps().size());
      CHECK(results.Steps().size() == whole.Steps().size() - 1);
      CHECK(results.SkippedSteps().size() == 1);
      std::vector<std::size_t> offered;
      for (std::size_t s = 0; s < whole.Steps().size(); ++s)
      {
        if (whole.Steps()[s].reportNumber != victim)
        {
          offered.push_back(s);
        }
      }
      for (std::size_t s = 0; s < std::min(offered.size(), results.Steps().size()); ++s)
      {
        CHECK(results.Steps()[s].reportNumber == whole.Steps()[offered[s]].reportNumber);
      }
      if (results.Steps().size() == offered.size())
      {
        CheckSameValues(whole, results, offered, eclipseGrid.deck.CellCount());
      }
      if (results.SkippedSteps().size() == 1)
      {
        const EclipseSkippedStep& skipped = results.SkippedSteps()[0];
        CHECK(skipped.file == cutPath && skipped.reportNumber == victim);
        CHECK(skipped.offset >= 0 && skipped.offset <= cut);
        CHECK(HasWarning(
          results, { cutPath, "report step " + std::to_string(victim), "byte " + std::to_string(skipped.offset) }));
      }
    }
  }
}

/// A formatted unified restart (SPE1's FUNRST beside its grid) cut at random offsets,
/// inside tokens and between them: the steps whose ENDSOL is whole are offered.
void FormattedRestartCut()
{
  const std::string from = DataDir + "/spe1/opm-common";
  const std::string folder = TempDir + "/spe1-funrst";
  fs::remove_all(folder);
  fs::create_directories(folder);
  fs::create_symlink(from + "/SPE1CASE1.EGRID", folder + "/SPE1_TESTCASE.EGRID");
  const EclipseGrid grid = ReadEclipseGrid(folder + "/SPE1_TESTCASE.EGRID");
  const std::string bytes = Slurp(from + "/SPE1_TESTCASE.FUNRST");
  // Each step ends with its ENDSOL record: the closing quote of its 'MESS' type.
  std::vector<int64_t> ends;
  for (std::size_t at = bytes.find("'ENDSOL  '"); at != std::string::npos; at = bytes.find("'ENDSOL  '", at + 1))
  {
    ends.push_back(static_cast<int64_t>(bytes.find("'MESS'", at) + 6));
  }
  CHECK(ends.size() == 9);
  std::mt19937_64 random(11);
  std::vector<int64_t> cuts = CutOffsets(random, static_cast<int64_t>(bytes.size()));
  cuts.push_back(ends[3]);
  cuts.push_back(ends[3] - 1);
  const std::string path = folder + "/SPE1_TESTCASE.FUNRST";
  for (const int64_t cut : cuts)
  {
    Spit(path, bytes.substr(0, static_cast<std::size_t>(cut)));
    const EclipseResults results(folder + "/SPE1_TESTCASE.EGRID", grid);
    const auto complete =
      static_cast<std::size_t>(std::count_if(ends.begin(), ends.end(), [&](int64_t end) { return end <= cut; }));
    std::printf("FUNRST cut at byte %lld: %zu steps offered (expected %zu), %zu left out\n",
      static_cast<long long>(cut), results.Steps().size(), complete, results.SkippedSteps().size());
    CHECK(results.Steps().size() == complete);
    CHECK(results.SkippedSteps().size() == (cut == ends[3] ? 0u : 1u));
  }
}

/// An empty, a damaged and a foreign INIT: a warning, no static arrays, the steps intact.
void BadInit()
{
  const std::string from = DataDir + "/reek/res2df_sim/eclipse/model", stem = "2_R001_REEK-0";
  const EclipseGrid grid = ReadEclipseGrid(from + "/" + stem + ".EGRID");
  const std::string init = Slurp(from + "/" + stem + ".INIT");
  // A bit flipped in the leading marker of the fifth record's header.
  const EclipseKeywordFile file(from + "/" + stem + ".INIT");
  CHECK(file.Records().size() > 5);
  std::string flipped = init;
  flipped[static_cast<std::size_t>(file.Records()[4].headerOffset) + 3] ^= 0x04;
  const std::string foreign = Slurp(DataDir + "/spe1/resdata_rft/SPE1.INIT");
  const struct
  {
    const char* label;
    const std::string& bytes;
    std::vector<std::string> fragments;
  } cases[] = {
    { "empty", std::string(), { "the file is empty" } },
    { "bit-flipped", flipped, { "damaged or cut short at byte " + std::to_string(file.Records()[4].headerOffset) } },
    { "cut", init.substr(0, init.size() / 2), { "damaged or cut short at byte" } },
    { "foreign", foreign, { "does not belong to this grid" } },
  };
  for (const auto& item : cases)
  {
    const std::string folder = LinkedRun("reek-init", from, stem, { ".EGRID", ".INIT", ".UNRST" });
    const std::string path = folder + "/" + stem + ".INIT";
    Replace(path, item.bytes);
    const EclipseResults results(folder + "/" + stem + ".EGRID", grid);
    std::printf("%s INIT: %zu static arrays, %zu steps; %s\n", item.label, results.StaticArrays().size(),
      results.Steps().size(), results.Warnings().empty() ? "" : results.Warnings().front().c_str());
    CHECK(!results.InitUsable());
    CHECK(results.StaticArrays().empty());
    CHECK(results.Steps().size() == 4);
    std::vector<std::string> fragments = item.fragments;
    fragments.push_back(path);
    CHECK(HasWarning(results, fragments));
    float value = 0;
    CHECK(!results.ReadStatic("PORO", &value, 0.0f));
  }
}

/// A run written step by step, record by record (as a simulator appends): at every stage
/// exactly the steps whose ENDSOL is written are offered.
void AppendedRun()
{
  const std::string from = DataDir + "/spe9/opmflow2022_run_of_opm-data_SPE9_CP", stem = "SPE9_CP";
  const std::string grid = from + "/" + stem + ".EGRID";
  const EclipseGrid eclipseGrid = ReadEclipseGrid(grid);
  const EclipseResults whole(grid, eclipseGrid);
  const EclipseKeywordFile file(from + "/" + stem + ".UNRST");
  const std::string bytes = Slurp(from + "/" + stem + ".UNRST");
  const std::string folder = LinkedRun("spe9-appended", from, stem, { ".EGRID", ".INIT" });
  const std::string path = folder + "/" + stem + ".UNRST";
  std::size_t closed = 0, stages = 0, mismatches = 0;
  // Every record of the first 4 steps, and a partial record after each.
  for (const EclipseRecord& record : file.Records())
  {
    if (closed >= 4)
    {
      break;
    }
    for (const int64_t end : { record.endOffset - 5, record.endOffset })
    {
      Spit(path, bytes.substr(0, static_cast<std::size_t>(end)));
      const EclipseResults results(folder + "/" + stem + ".EGRID", eclipseGrid);
      const std::size_t expected = closed + (end == record.endOffset && record.name == "ENDSOL" ? 1 : 0);
      if (results.Steps().size() != expected)
      {
        ++mismatches;
        std::fprintf(stderr, "UNRST of %lld bytes (in or after %s): %zu steps offered, %zu closed\n",
          static_cast<long long>(end), record.name.c_str(), results.Steps().size(), expected);
      }
      ++stages;
    }
    closed += record.name == "ENDSOL";
  }
  std::printf("appended run: %zu stages, %zu offered a step count other than the closed steps'\n", stages, mismatches);
  CHECK(stages > 40 && mismatches == 0);
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 3)
  {
    std::fprintf(stderr, "usage: TestEclipseRuns DATA_DIR TEMP_DIR\n");
    return 2;
  }
  DataDir = argv[1];
  TempDir = std::string(argv[2]) + "/eclipse-runs";
  fs::create_directories(TempDir);
  const bool passed = resmr_testing::RunNamedTests({
    { "unified restart cut at random offsets", UnifiedRestartCut },
    { "per-step restarts cut at random offsets", PerStepRestartCut },
    { "formatted restart cut at random offsets", FormattedRestartCut },
    { "empty, damaged and foreign INIT", BadInit },
    { "run appended record by record", AppendedRun },
  });
  fs::remove_all(TempDir);
  return passed ? 0 : 1;
}
