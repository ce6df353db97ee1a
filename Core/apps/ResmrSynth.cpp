// resmr synth: writes a synthetic faulted reservoir model of any size (see SyntheticReservoir.h).
#include "ResmrCommands.h"

#include "SyntheticReservoir.h"
#include "SyntheticReservoirWriter.h"

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <sys/resource.h>
#include <unistd.h>

namespace
{
const char* SynthUsage =
  "usage: resmr synth NX NY NZ -o FILE.EGRID|FILE.GRDECL [options]\n"
  "  writes a synthetic faulted reservoir: EGRID + INIT (+ UNRST with --steps), or a GRDECL deck\n"
  "  --seed N        random seed (default 1); the same seed gives the same bytes\n"
  "  --faults N      normal faults, 0-32 (default 6; every third along i or j, others oblique)\n"
  "  --throw F       largest throw as a fraction of the gross thickness (default 0.3)\n"
  "  --dip DEG       regional dip in degrees (default 2)\n"
  "  --pinched F     fraction of cells pinched out inside the outline (default 0.05)\n"
  "  --water F       fraction of cells below the oil-water contact (default 0.2)\n"
  "  --outside F     fraction of columns outside the field outline (default 0.25)\n"
  "  --steps N       report steps of PRESSURE and SWAT, written to an UNRST (default 0)\n"
  "  --cell-size M   lateral cell size in metres (default: 8 km / max(NX, NY), 10-100 m)\n"
  "  --thickness M   gross thickness in metres (default: 3 m a layer, 40-400 m)\n"
  "  --quiet         no progress on stderr\n"
  "  Prints a JSON summary (files, counts, fractions, time, peak memory) on stdout.\n";

double ParseNumber(const char* text, const char* what)
{
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (errno != 0 || end == text || *end != '\0' || !std::isfinite(value))
  {
    throw std::invalid_argument(std::string(what) + " must be a number (got '" + text + "')");
  }
  return value;
}

bool EndsWithNoCase(const std::string& text, const std::string& suffix)
{
  if (text.size() < suffix.size())
  {
    return false;
  }
  for (std::size_t i = 0; i < suffix.size(); ++i)
  {
    if (std::toupper(static_cast<unsigned char>(text[text.size() - suffix.size() + i])) != suffix[i])
    {
      return false;
    }
  }
  return true;
}
/// The JSON line `resmr synth` prints: what was written and the model's measured geology.
void PrintReport(const resmr::SyntheticParameters& parameters, const resmr::SyntheticReservoir& model,
  const resmr::SyntheticOutput& written, double seconds)
{
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  const resmr::SyntheticStatistics& s = written.statistics;
  const double inside = static_cast<double>(s.cells - s.outside);
  std::string files;
  for (const std::string& file : written.files)
  {
    files += (files.empty() ? "\"" : ", \"") + file + "\"";
  }
  std::printf("{\"files\": [%s], \"dims\": [%lld, %lld, %lld], \"seed\": %llu, \"cells\": %lld, "
              "\"active\": %lld, \"outside_cells\": %lld, \"pinched_cells\": %lld, \"water_cells\": %lld, "
              "\"inactive_fraction\": %.6f, \"outside_fraction\": %.6f, \"pinched_fraction\": %.6f, "
              "\"water_fraction\": %.6f, \"fault_face_fraction\": %.6f, \"oil_water_contact\": %.3f, "
              "\"steps\": %d, \"bytes\": %lld, \"seconds\": %.3f, \"cells_per_minute\": %.0f, "
              "\"peak_rss_mb\": %.1f}\n",
    files.c_str(), static_cast<long long>(parameters.nx), static_cast<long long>(parameters.ny),
    static_cast<long long>(parameters.nz), static_cast<unsigned long long>(parameters.seed),
    static_cast<long long>(s.cells), static_cast<long long>(s.active), static_cast<long long>(s.outside),
    static_cast<long long>(s.pinched), static_cast<long long>(s.water),
    1.0 - static_cast<double>(s.active) / static_cast<double>(s.cells),
    static_cast<double>(s.outside) / static_cast<double>(s.cells),
    inside > 0 ? static_cast<double>(s.pinched) / inside : 0.0,
    inside > 0 ? static_cast<double>(s.water) / inside : 0.0,
    s.lateralFaces > 0 ? static_cast<double>(s.faultFaces) / static_cast<double>(s.lateralFaces) : 0.0,
    std::isfinite(model.OilWaterContact()) ? model.OilWaterContact() : -1.0, parameters.steps,
    static_cast<long long>(written.bytes), seconds, seconds > 0 ? static_cast<double>(s.cells) / seconds * 60 : 0.0,
    usage.ru_maxrss / 1024.0);
}
} // namespace

int SynthCommand(int argc, char** argv)
{
  resmr::SyntheticParameters parameters;
  std::string output;
  bool quiet = false;
  try
  {
    int positional = 0;
    for (int a = 2; a < argc; ++a)
    {
      const std::string option = argv[a];
      auto value = [&]() { return OptionValue(a, argc, argv); };
      if (option == "-o" || option == "--output")
        output = value();
      else if (option == "--seed")
      {
        const char* text = value();
        if (text[0] == '-')
        {
          throw std::invalid_argument(std::string("--seed must be a whole number from 0 (got '") + text + "')");
        }
        errno = 0;
        char* end = nullptr;
        parameters.seed = std::strtoull(text, &end, 10);
        if (errno != 0 || end == text || *end != '\0')
        {
          throw std::invalid_argument(std::string("--seed must be a whole number from 0 (got '") + text + "')");
        }
      }
      else if (option == "--faults")
        parameters.faults =
          static_cast<int>(std::max<int64_t>(-1, std::min<int64_t>(1000, ParseInteger(value(), "--faults"))));
      else if (option == "--throw")
        parameters.maxThrow = ParseNumber(value(), "--throw");
      else if (option == "--dip")
        parameters.dipDegrees = ParseNumber(value(), "--dip");
      else if (option == "--pinched")
        parameters.pinchedFraction = ParseNumber(value(), "--pinched");
      else if (option == "--water")
        parameters.waterFraction = ParseNumber(value(), "--water");
      else if (option == "--outside")
        parameters.outsideFraction = ParseNumber(value(), "--outside");
      else if (option == "--steps")
        parameters.steps =
          static_cast<int>(std::max<int64_t>(-1, std::min<int64_t>(100000, ParseInteger(value(), "--steps"))));
      else if (option == "--cell-size")
        parameters.cellSize = ParseNumber(value(), "--cell-size");
      else if (option == "--thickness")
        parameters.grossThickness = ParseNumber(value(), "--thickness");
      else if (option == "--quiet")
        quiet = true;
      else if (option == "-h" || option == "--help")
      {
        std::fputs(SynthUsage, stdout);
        return 0;
      }
      else if (!option.empty() && option[0] == '-' && !std::isdigit(static_cast<unsigned char>(option[1])))
        throw std::invalid_argument("unknown option " + option);
      else
      {
        const char* names[3] = { "NX", "NY", "NZ" };
        if (positional >= 3)
        {
          throw std::invalid_argument("unexpected argument '" + option + "'");
        }
        const int64_t cells = ParseInteger(argv[a], names[positional]);
        (positional == 0 ? parameters.nx : positional == 1 ? parameters.ny : parameters.nz) = cells;
        ++positional;
      }
    }
    if (positional != 3 || output.empty())
    {
      std::fputs(SynthUsage, stderr);
      return 2;
    }
    const bool grdecl = EndsWithNoCase(output, ".GRDECL");
    if (!grdecl && !EndsWithNoCase(output, ".EGRID"))
    {
      throw std::invalid_argument(output +
        ": the extension chooses the format: .EGRID (with .INIT "
        "and .UNRST beside it) or .GRDECL");
    }
    parameters.Validate();
    if (!grdecl && parameters.CellCount() > resmr::MaxEgridCells)
    {
      throw std::invalid_argument(output +
        ": an EGRID holds at most 268,435,455 cells (ZCORN's 8 "
        "values a cell must fit the 32-bit count of an ECLIPSE keyword header); " +
        std::to_string(parameters.CellCount()) +
        " cells were asked for. Models this large are "
        "streamed straight into the multiresolution builder (input synth:" +
        std::to_string(parameters.nx) + "x" + std::to_string(parameters.ny) + "x" + std::to_string(parameters.nz) +
        ":" + std::to_string(parameters.seed) + ") instead of a file");
    }

    const auto start = std::chrono::steady_clock::now();
    const resmr::SyntheticReservoir model(parameters);
    const bool showProgress = !quiet && isatty(STDERR_FILENO);
    int shown = -1;
    const resmr::SyntheticProgress progress = [&](double fraction) {
      const int percent = static_cast<int>(fraction * 100);
      if (showProgress && percent != shown)
      {
        shown = percent;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "\rresmr synth: %3d%%  %.0f s, about %.0f s left ", percent, elapsed,
          fraction > 0.01 ? elapsed * (1 - fraction) / fraction : 0.0);
      }
    };
    const resmr::SyntheticOutput written = grdecl ? resmr::WriteSyntheticGrdecl(model, output, progress)
                                                  : resmr::WriteSyntheticEclipse(model, output, progress);
    if (showProgress)
    {
      std::fputs("\n", stderr);
    }
    for (const std::string& removed : written.removed)
    {
      std::fprintf(stderr, "resmr: note: removed %s, left from an older model (no steps asked)\n", removed.c_str());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    PrintReport(parameters, model, written, seconds);
    return 0;
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "resmr synth: error: %s\n", error.what());
    return 1;
  }
}
