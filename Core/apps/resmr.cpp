// resmr: command-line front end of the Core library (paper Sec. 3 input; later the
// multiresolution builder of Sec. 4-6 joins here).
//
//   resmr info [--skip-missing-includes] DECK
//                       prints the deck's dimensions, active cells, arrays and faults as JSON
//   resmr info GRID.EGRID
//                       prints the grid's dimensions and active cells, its INIT arrays and
//                       restart report steps as JSON
//   resmr synth NX NY NZ -o FILE.EGRID|FILE.GRDECL [options]
//                       writes a synthetic faulted reservoir (ResmrSynth.cpp)
//   resmr simplify MODEL [options]
//                       simplifies a model by column collapses, prints quality (ResmrSimplify.cpp)
//   resmr build INPUT -o OUT.resmr [options]
//                       builds the multiresolution file (ResmrBuild.cpp)
//   resmr info [--regions] FILE.resmr
//                       levels, regions, sizes and errors of a multiresolution file
//   resmr add-properties FILE.resmr RESULTS... [-o FILE.resmrp]
//                       property tables beside the geometry (ResmrProperties.cpp)
#include "ResmrCommands.h"

#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseResults.h"
#include "Errors.h"
#include "GrdeclParser.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace
{
std::string JsonNames(const std::vector<resmr::EclipseResultArray>& arrays)
{
  std::string out = "[";
  for (std::size_t a = 0; a < arrays.size(); ++a)
  {
    out += (a ? ", " : "") + JsonString(arrays[a].name);
  }
  return out + "]";
}

int GridInfo(const char* path)
{
  const resmr::EclipseGrid grid = resmr::ReadEclipseGrid(path);
  const resmr::EclipseResults results(path, grid);
  for (const std::string& warning : grid.deck.warnings)
  {
    std::fprintf(stderr, "resmr: warning: %s\n", warning.c_str());
  }
  for (const std::string& warning : results.Warnings())
  {
    std::fprintf(stderr, "resmr: warning: %s\n", warning.c_str());
  }
  const auto& d = grid.deck.dims;
  std::printf(
    "{\"file\": %s, \"kind\": \"egrid\", \"dims\": [%lld, %lld, %lld], \"cells\": %lld, "
    "\"active\": %lld, \"nonzero_actnum\": %lld, \"dual_porosity\": %s, \"fracture_cells\": %lld, \"lgrs\": %zu, "
    "\"nnc\": %lld, \"units\": %s, \"init\": %s, \"init_arrays\": %s, \"restarts\": %zu, "
    "\"unified\": %s, \"restart_arrays\": %s, \"steps\": [",
    JsonString(path).c_str(), static_cast<long long>(d[0]), static_cast<long long>(d[1]), static_cast<long long>(d[2]),
    static_cast<long long>(grid.deck.CellCount()), static_cast<long long>(grid.activeCells),
    static_cast<long long>(std::count_if(grid.actnum.begin(), grid.actnum.end(), [](int32_t v) { return v > 0; })),
    grid.dualPorosity ? "true" : "false", static_cast<long long>(grid.fractureCells), grid.localGridNames.size(),
    static_cast<long long>(grid.nonNeighbourConnections), JsonString(grid.units).c_str(),
    JsonString(results.InitPath()).c_str(), JsonNames(results.StaticArrays()).c_str(), results.RestartPaths().size(),
    results.UnifiedRestart() ? "true" : "false", JsonNames(results.DynamicArrays()).c_str());
  for (std::size_t s = 0; s < results.Steps().size(); ++s)
  {
    const resmr::EclipseReportStep& step = results.Steps()[s];
    std::printf("%s{\"report\": %d, \"days\": %.17g, \"date\": \"%04d-%02d-%02d\", \"arrays\": [", s ? ", " : "",
      step.reportNumber, step.days, step.date[0], step.date[1], step.date[2]);
    for (std::size_t a = 0; a < step.names.size(); ++a)
    {
      std::printf("%s%s", a ? ", " : "", JsonString(step.names[a]).c_str());
    }
    std::printf("]}");
  }
  // Steps of a run cut short (or still being written) that are not offered, and why.
  std::printf("], \"init_used\": %s, \"steps_left_out\": [", results.InitUsable() ? "true" : "false");
  for (std::size_t s = 0; s < results.SkippedSteps().size(); ++s)
  {
    const resmr::EclipseSkippedStep& skipped = results.SkippedSteps()[s];
    std::printf("%s{\"file\": %s, \"report\": %d, \"offset\": %lld, \"reason\": %s}", s ? ", " : "",
      JsonString(skipped.file).c_str(), skipped.reportNumber, static_cast<long long>(skipped.offset),
      JsonString(skipped.reason).c_str());
  }
  std::printf("]}\n");
  return 0;
}

int Info(const char* path, bool skipMissingIncludes)
{
  std::string extension = std::strrchr(path, '.') ? std::strrchr(path, '.') : "";
  for (char& c : extension)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  const bool keywordFile =
    resmr::EclipseKeywordFile::LooksLikeUnformatted(path) || resmr::EclipseKeywordFile::LooksLikeFormatted(path);
  if (resmr::LooksLikeEclipseGridFile(path) ||
    (keywordFile && (extension == ".EGRID" || extension == ".FEGRID" || extension == ".GRID" || extension == ".FGRID")))
  {
    return GridInfo(path);
  }
  // A missing INCLUDE is a warning either way (an error only when the grid then lacks what it
  // needs); the option stays accepted for older scripts.
  (void)skipMissingIncludes;
  resmr::GrdeclParseOptions options;
  resmr::CornerPointModel deck = resmr::ParseGrdeclFile(path, options);
  for (const std::string& warning : deck.warnings)
  {
    std::fprintf(stderr, "resmr: warning: %s\n", warning.c_str());
  }
  const int64_t cells = deck.CellCount();
  int64_t active = cells;
  if (const resmr::CellArray* actnum = deck.FindArray("ACTNUM"))
  {
    active = 0;
    for (double value : actnum->values)
    {
      active += value > 0;
    }
  }
  int64_t faultRecords = 0;
  for (const resmr::Fault& fault : deck.faults)
  {
    faultRecords += static_cast<int64_t>(fault.faces.size());
  }
  std::string geometry = "none";
  bool leftHanded = false;
  if (deck.HasCornerPointGeometry() || deck.FindArray("TOPS"))
  {
    geometry = deck.HasCornerPointGeometry() ? "corner-point" : "cartesian";
    leftHanded = resmr::CornerPointGeometry::FromDeck(deck, true).IsLeftHanded();
  }
  std::printf("{\"file\": %s, \"dims\": [%lld, %lld, %lld], \"cells\": %lld, \"active\": %lld, "
              "\"geometry\": \"%s\", \"left_handed\": %s, \"fault_records\": %lld, \"faults\": [",
    JsonString(path).c_str(), static_cast<long long>(deck.dims[0]), static_cast<long long>(deck.dims[1]),
    static_cast<long long>(deck.dims[2]), static_cast<long long>(cells), static_cast<long long>(active),
    geometry.c_str(), leftHanded ? "true" : "false", static_cast<long long>(faultRecords));
  for (std::size_t f = 0; f < deck.faults.size(); ++f)
  {
    std::printf("%s%s", f ? ", " : "", JsonString(deck.faults[f].name).c_str());
  }
  std::printf("], \"arrays\": [");
  for (std::size_t a = 0; a < deck.arrays.size(); ++a)
  {
    std::printf("%s%s", a ? ", " : "", JsonString(deck.arrays[a].name).c_str());
  }
  std::printf("], \"files\": %zu}\n", deck.files.size());
  return 0;
}
} // namespace

namespace
{
/// A .resmr name, or a file starting with its magic.
bool LooksLikeMultiresolutionFile(const char* path)
{
  const std::string name = path;
  if (name.size() > 6 && name.compare(name.size() - 6, 6, ".resmr") == 0)
  {
    return true;
  }
  char magic[5] = {};
  std::FILE* file = std::fopen(path, "rb");
  const bool read = file && std::fread(magic, 1, 5, file) == 5;
  if (file)
  {
    std::fclose(file);
  }
  return read && std::memcmp(magic, "RESMR", 5) == 0;
}
} // namespace

int main(int argc, char** argv)
{
  if (argc >= 2 && std::strcmp(argv[1], "synth") == 0)
  {
    return SynthCommand(argc, argv);
  }
  if (argc >= 2 && std::strcmp(argv[1], "simplify") == 0)
  {
    return SimplifyCommand(argc, argv);
  }
  if (argc >= 2 && std::strcmp(argv[1], "build") == 0)
  {
    return BuildCommand(argc, argv);
  }
  if (argc >= 2 && std::strcmp(argv[1], "add-properties") == 0)
  {
    return AddPropertiesCommand(argc, argv);
  }
  const bool listRegions = argc == 4 && std::strcmp(argv[2], "--regions") == 0;
  if ((argc == 3 || listRegions) && std::strcmp(argv[1], "info") == 0 && LooksLikeMultiresolutionFile(argv[argc - 1]))
  {
    try
    {
      return MultiresolutionInfo(argv[argc - 1], listRegions);
    }
    catch (const std::exception& error)
    {
      std::fprintf(stderr, "resmr: error: %s\n", error.what());
      return 1;
    }
  }
  const bool lenient = argc == 4 && std::strcmp(argv[2], "--skip-missing-includes") == 0;
  if ((argc == 3 || lenient) && std::strcmp(argv[1], "info") == 0)
  {
    try
    {
      return Info(argv[argc - 1], lenient);
    }
    catch (const std::exception& error)
    {
      std::fprintf(stderr, "resmr: error: %s\n", error.what());
      return 1;
    }
  }
  std::fprintf(stderr,
    "usage: resmr info [--skip-missing-includes] DECK|GRID.EGRID\n"
    "  prints dimensions, active cells, arrays and faults of an Eclipse deck,\n"
    "  or of an EGRID with its INIT arrays and restart steps\n"
    "usage: resmr synth NX NY NZ -o FILE.EGRID|FILE.GRDECL [options]\n"
    "  writes a synthetic faulted reservoir model (resmr synth --help)\n"
    "usage: resmr simplify MODEL [--fraction F | --columns N | --uniform B]\n"
    "  column-collapse simplification and its quality (resmr simplify --help)\n"
    "usage: resmr build INPUT -o OUT.resmr [--cmax N] [--threads N] [--memory SIZE]\n"
    "  builds the multiresolution file (resmr build --help)\n"
    "usage: resmr info [--regions] FILE.resmr\n"
    "  levels, regions, sizes, errors and bytes per cell of a multiresolution file\n"
    "usage: resmr add-properties FILE.resmr RESULTS... [-o FILE.resmrp]\n"
    "  stores properties of every step apart from the geometry (resmr add-properties --help)\n");
  return 2;
}
