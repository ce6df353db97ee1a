// resmr add-properties: simulation properties of every step (or a generated model's) into a
// property file beside the geometry (paper Sec. 5.5: one hierarchy serves every simulation of
// the same grid).
#include "ResmrCommands.h"

#include "DerivedArrays.h"
#include "EclipseGrid.h"
#include "EclipseResults.h"
#include "Errors.h"
#include "GrdeclParser.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "SyntheticReservoir.h"
#include "SyntheticReservoirWriter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <vector>

namespace
{
const char* AddPropertiesUsage =
  "usage: resmr add-properties FILE.resmr RESULTS... [-o FILE.resmrp]\n"
  "  RESULTS: an EGRID (its INIT and restart companions are found by name: every INIT\n"
  "           array and every array of every report step), an INIT or a UNRST/restart file\n"
  "           beside its EGRID (only that file's arrays), a GRDECL/DATA deck (its cell\n"
  "           arrays other than geometry), or synth:NIxNJxNK[:SEED[:STEPS]]: the arrays of\n"
  "           the INIT (and, with STEPS, the UNRST of that many report steps) that\n"
  "           resmr synth NI NJ NK --seed SEED --steps STEPS would write, streamed from the\n"
  "           generator layer by layer (no file; any size, beyond an EGRID's 268M cells)\n"
  "  -o FILE  property file (default: FILE.resmrp beside FILE.resmr); tables it already\n"
  "           holds are kept unless replaced (same name and step). Report steps it holds\n"
  "           already (same array, step, report number and time) are kept and not read\n"
  "           again: run again on a run still being written, it adds the new steps. The\n"
  "           .resmr file is only read, never written.\n"
  "  A restart cut short or damaged gives its complete steps; the incomplete ones are\n"
  "  reported (file, step, byte offset) and left out, and the exit status is 0 unless\n"
  "  nothing could be read.\n";

bool Exists(const std::string& path)
{
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

std::string Upper(std::string text)
{
  for (char& c : text)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return text;
}

std::string Extension(const std::string& path)
{
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of('/');
  return dot == std::string::npos || (slash != std::string::npos && dot < slash) ? "" : Upper(path.substr(dot + 1));
}

/// The EGRID beside a results file (same basename, either case, formatted or not).
std::string GridBeside(const std::string& path)
{
  const std::size_t dot = path.find_last_of('.');
  const std::string stem = path.substr(0, dot);
  for (const char* ext : { ".EGRID", ".egrid", ".FEGRID", ".fegrid" })
  {
    if (Exists(stem + ext))
    {
      return stem + ext;
    }
  }
  throw std::invalid_argument(
    path + ": no EGRID beside it (" + stem + ".EGRID): its active cells are needed to place the values");
}

/// The properties of the generated model `spec` names, as the INIT (and UNRST) resmr synth
/// writes for it hold them (the same SyntheticInitArrays and FillStep), streamed: each pass of
/// the generator gives a group of tables layer by layer. A table held open keeps its packed
/// table (4 bytes a hash slot) until its last layer, so a group holds as many tables as fit
/// in one whole array (4 bytes a cell; at least one): memory never exceeds what a file input
/// needs, and no whole array is held. Every layer's active cells must be the geometry's.
/// Returns the generator passes made.
int AddSyntheticProperties(const std::string& spec, const resmr::MultiresolutionFile& geometry,
  resmr::PropertyFileWriter& writer, const std::function<void(const resmr::PropertyTable&)>& added)
{
  const resmr::SyntheticParameters parameters = resmr::ParseSyntheticSpec(spec);
  const auto& h = geometry.Header();
  if (parameters.nx != h.dims[0] || parameters.ny != h.dims[1] || parameters.nz != h.dims[2])
  {
    throw std::invalid_argument(spec + ": grid " + std::to_string(parameters.nx) + "x" + std::to_string(parameters.ny) +
      "x" + std::to_string(parameters.nz) + " is not the grid of " + geometry.Path());
  }
  const resmr::SyntheticReservoir model(parameters);
  const auto& arrays = resmr::SyntheticInitArrays();
  // Every table, in the order of an add-properties of the files: the INIT's arrays, then
  // PRESSURE, SWAT and the derived SOIL of each step (array -1).
  enum class Quantity
  {
    Init,
    Pressure,
    Water,
    Oil
  };
  struct Job
  {
    int array = -1;
    int step = 0;
    Quantity quantity = Quantity::Init;
  };
  std::vector<Job> jobs;
  for (std::size_t a = 0; a < arrays.size(); ++a)
  {
    jobs.push_back({ static_cast<int>(a), 0, Quantity::Init });
  }
  for (int step = 1; step <= parameters.steps; ++step)
  {
    for (Quantity quantity : { Quantity::Pressure, Quantity::Water, Quantity::Oil })
    {
      jobs.push_back({ -1, step, quantity });
    }
  }
  const uint64_t slots = uint64_t(h.hashTableSides[0]) * h.hashTableSides[1] * h.hashTableSides[2];
  const uint64_t cells = static_cast<uint64_t>(parameters.CellCount());
  const std::size_t group = static_cast<std::size_t>(std::max<uint64_t>(1, slots > 0 ? cells / slots : jobs.size()));

  std::vector<float> values, pressure, swat;
  int passes = 0;
  for (std::size_t first = 0; first < jobs.size(); first += group)
  {
    const std::size_t last = std::min(jobs.size(), first + group);
    std::vector<resmr::PropertyTable> tables;
    std::vector<std::size_t> handles;
    for (std::size_t j = first; j < last; ++j)
    {
      resmr::PropertyTable table;
      if (jobs[j].array >= 0)
      {
        table.name = arrays[static_cast<std::size_t>(jobs[j].array)].name;
      }
      else
      {
        const Quantity quantity = jobs[j].quantity;
        table.name = quantity == Quantity::Pressure ? "PRESSURE"
          : quantity == Quantity::Water             ? "SWAT"
                                                    : resmr::DerivedOilName;
        table.step = jobs[j].step - 1;
        table.reportNumber = jobs[j].step;
        table.days = model.StepDays(jobs[j].step);
      }
      tables.push_back(table);
      handles.push_back(writer.BeginTable(std::move(table)));
    }
    resmr::SyntheticLayerStream stream(model);
    resmr::SyntheticLayer layer;
    while (stream.Next(layer))
    {
      if (passes == 0)
      {
        const std::vector<uint8_t> active = geometry.ReadActiveLayer(layer.k);
        for (std::size_t c = 0; c < layer.state.size(); ++c)
        {
          if ((layer.state[c] == resmr::SyntheticCellState::Active) != (c < active.size() && active[c] != 0))
          {
            throw std::invalid_argument(spec + ": the active cells of layer " + std::to_string(layer.k + 1) +
              " differ from those of " + geometry.Path() + ": another model (seed?)");
          }
        }
      }
      values.resize(layer.state.size());
      pressure.resize(layer.state.size());
      swat.resize(layer.state.size());
      int filledStep = 0; // the step whose PRESSURE and SWAT this layer's buffers hold
      for (std::size_t j = first; j < last; ++j)
      {
        const Job& job = jobs[j];
        if (job.array >= 0)
        {
          resmr::FillSyntheticInitArray(model, static_cast<std::size_t>(job.array), layer, values.data());
          writer.AddLayer(handles[j - first], values.data());
          continue;
        }
        if (filledStep != job.step)
        {
          model.FillStep(job.step, layer, pressure.data(), swat.data());
          filledStep = job.step;
        }
        if (job.quantity == Quantity::Oil)
        {
          // What ReadDerivedOil gives for a run without gas: 1 - SWAT.
          for (std::size_t c = 0; c < swat.size(); ++c)
          {
            values[c] = 1.0f - swat[c];
          }
        }
        writer.AddLayer(handles[j - first],
          job.quantity == Quantity::Pressure  ? pressure.data()
            : job.quantity == Quantity::Water ? swat.data()
                                              : values.data());
      }
    }
    ++passes;
    for (std::size_t t = 0; t < handles.size(); ++t)
    {
      writer.EndTable(handles[t]);
      added(tables[t]);
    }
  }
  return passes;
}

/// True if `older` holds this report step's table already, for the same step of the run.
bool HoldsStep(const resmr::PropertyFile& older, const resmr::PropertyTable& table)
{
  const int index = older.Find(table.name, table.step);
  if (index < 0)
  {
    return false;
  }
  const resmr::PropertyTable& held = older.Tables()[static_cast<std::size_t>(index)];
  return held.reportNumber == table.reportNumber && held.days == table.days;
}

/// The tables of an EGRID's INIT and restarts (or of an INIT or restart beside its EGRID), by
/// `add`: steps `older` holds already are counted in `kept`, not read again; steps and arrays
/// of files cut short or damaged are counted in `leftOut`, with a warning.
void AddEclipseResults(const std::string& input, bool isInit, bool isRestart, const std::string& geometryPath,
  const std::array<int64_t, 3>& dims, int64_t active, const resmr::PropertyFile* older, std::vector<float>& values,
  const std::function<void(resmr::PropertyTable)>& add, int64_t& kept, int64_t& leftOut)
{
  const float none = std::numeric_limits<float>::quiet_NaN();
  const std::string gridPath = (isInit || isRestart) ? GridBeside(input) : input;
  const resmr::EclipseGrid grid = resmr::ReadEclipseGrid(gridPath, 0, resmr::EclipseGridParts::ActiveCellsOnly);
  if (grid.deck.dims != dims)
  {
    throw std::invalid_argument(gridPath + ": grid " + std::to_string(grid.deck.dims[0]) + "x" +
      std::to_string(grid.deck.dims[1]) + "x" + std::to_string(grid.deck.dims[2]) + " is not the grid of " +
      geometryPath);
  }
  if (grid.activeCells != active)
  {
    throw std::invalid_argument(gridPath + ": " + std::to_string(grid.activeCells) + " active cells, " + geometryPath +
      " has " + std::to_string(active) + ": results of another grid");
  }
  const resmr::EclipseResults results(gridPath, grid);
  for (const std::string& warning : results.Warnings())
  {
    std::fprintf(stderr, "resmr add-properties: warning: %s\n", warning.c_str());
  }
  leftOut += static_cast<int64_t>(results.SkippedSteps().size());
  // A record whose blocks turn out damaged costs that table only.
  const auto readable = [&](const std::function<bool()>& read) {
    try
    {
      return read();
    }
    catch (const resmr::InputError& error)
    {
      std::fprintf(stderr, "resmr add-properties: warning: %s; left out\n", error.what());
      ++leftOut;
      return false;
    }
  };
  if (!isRestart)
  {
    for (const auto& array : results.StaticArrays())
    {
      if (readable([&] { return results.ReadStatic<float>(array.name, values.data(), none); }))
      {
        resmr::PropertyTable table;
        table.name = array.name;
        add(table);
      }
    }
  }
  if (!isInit)
  {
    const auto& steps = results.Steps();
    for (std::size_t s = 0; s < steps.size(); ++s)
    {
      const bool deriveOil = resmr::NeedsDerivedOil(steps[s].names);
      std::vector<std::string> names = steps[s].names;
      if (deriveOil)
      {
        names.push_back(resmr::DerivedOilName);
      }
      for (const std::string& name : names)
      {
        resmr::PropertyTable table;
        table.name = name;
        table.step = static_cast<int32_t>(s);
        table.reportNumber = steps[s].reportNumber;
        table.days = steps[s].days;
        if (older && HoldsStep(*older, table))
        {
          ++kept; // copied from the older file below
          continue;
        }
        const bool derived = deriveOil && name == resmr::DerivedOilName;
        if (readable([&] {
              return derived ? resmr::ReadDerivedOil(results, s, values.data(), int64_t(values.size()))
                             : results.ReadDynamic<float>(s, name, values.data(), none);
            }))
        {
          add(table);
        }
      }
    }
  }
}

/// The geometry's active cells per layer, to check that results belong to this grid.
int64_t ActiveCount(const resmr::MultiresolutionFile& geometry)
{
  int64_t count = 0;
  for (int64_t k = 0; k < geometry.Header().dims[2]; ++k)
  {
    for (uint8_t a : geometry.ReadActiveLayer(k))
    {
      count += a;
    }
  }
  return count;
}
} // namespace

int AddPropertiesCommand(int argc, char** argv)
{
  std::string geometryPath, output;
  std::vector<std::string> inputs;
  try
  {
    for (int a = 2; a < argc; ++a)
    {
      const std::string arg = argv[a];
      if (arg == "-h" || arg == "--help")
      {
        std::fputs(AddPropertiesUsage, stdout);
        return 0;
      }
      if (arg == "-o")
      {
        output = OptionValue(a, argc, argv);
      }
      else if (!arg.empty() && arg[0] == '-')
      {
        throw std::invalid_argument("unknown option " + arg);
      }
      else if (geometryPath.empty())
      {
        geometryPath = arg;
      }
      else
      {
        inputs.push_back(arg);
      }
    }
    if (geometryPath.empty() || inputs.empty())
    {
      std::fputs(AddPropertiesUsage, stderr);
      return 2;
    }
    if (output.empty())
    {
      output = (Extension(geometryPath) == "RESMR" ? geometryPath.substr(0, geometryPath.size() - 6) : geometryPath) +
        ".resmrp";
    }
    const resmr::MultiresolutionFile geometry(geometryPath);
    const auto& dims = geometry.Header().dims;
    const int64_t cells = dims[0] * dims[1] * dims[2];
    const int64_t active = ActiveCount(geometry);
    std::unique_ptr<resmr::PropertyFile> older;
    if (Exists(output))
    {
      older.reset(new resmr::PropertyFile(output));
      older->CheckGeometry(geometry);
    }
    resmr::PropertyFileWriter writer(output, geometry);
    std::vector<float> values; // one whole array, for file inputs only
    int64_t added = 0, kept = 0, leftOut = 0;
    int generatorPasses = 0;
    const auto report = [&](const resmr::PropertyTable& table) {
      ++added;
      std::fprintf(stderr, "resmr add-properties: %s%s\n", table.name.c_str(),
        table.step < 0
          ? ""
          : (" step " + std::to_string(table.step) + " (report " + std::to_string(table.reportNumber) + ")").c_str());
    };
    const auto add = [&](resmr::PropertyTable table) {
      writer.Add(table, values);
      report(table);
    };
    for (const std::string& input : inputs)
    {
      if (resmr::IsSyntheticSpec(input))
      {
        generatorPasses += AddSyntheticProperties(input, geometry, writer, report);
        continue;
      }
      values.resize(static_cast<std::size_t>(cells));
      const std::string ext = Extension(input);
      const bool isInit = ext == "INIT" || ext == "FINIT";
      const bool isRestart = ext == "UNRST" || ext == "FUNRST" ||
        (ext.size() == 5 && (ext[0] == 'X' || ext[0] == 'F') && std::isdigit(static_cast<unsigned char>(ext[1])));
      if (ext == "EGRID" || ext == "FEGRID" || isInit || isRestart)
      {
        AddEclipseResults(
          input, isInit, isRestart, geometryPath, dims, active, older.get(), values, add, kept, leftOut);
      }
      else
      {
        const resmr::CornerPointModel deck = resmr::ParseGrdeclFile(input);
        if (deck.dims != dims)
        {
          throw std::invalid_argument(input + ": grid " + std::to_string(deck.dims[0]) + "x" +
            std::to_string(deck.dims[1]) + "x" + std::to_string(deck.dims[2]) + " is not the grid of " + geometryPath);
        }
        for (const auto& array : deck.arrays)
        {
          if (resmr::IsGeometryArrayName(array.name) || array.name == "ACTNUM" ||
            static_cast<int64_t>(array.values.size()) != cells)
          {
            continue;
          }
          for (int64_t c = 0; c < cells; ++c)
          {
            values[static_cast<std::size_t>(c)] = static_cast<float>(array.values[static_cast<std::size_t>(c)]);
          }
          resmr::PropertyTable table;
          table.name = array.name;
          add(table);
        }
      }
    }
    if (added == 0 && kept == 0)
    {
      throw std::invalid_argument("no property found in the inputs; " + output + " not written");
    }
    std::size_t tables = older ? older->Tables().size() : 0;
    if (added > 0)
    {
      if (older)
      {
        writer.CopyFrom(*older);
      }
      writer.Commit();
      tables = writer.TableCount();
    }
    else
    {
      std::fprintf(stderr, "resmr add-properties: %s already holds every step found; not rewritten\n", output.c_str());
    }
    if (leftOut > 0)
    {
      std::fprintf(stderr, "resmr add-properties: warning: %lld report steps or tables left out (see above)\n",
        static_cast<long long>(leftOut));
    }
    std::printf("{\"geometry\": \"%s\", \"properties\": \"%s\", \"tables_added\": %lld, \"tables_kept\": %lld, "
                "\"tables\": %zu, \"left_out\": %lld, \"generator_passes\": %d}\n",
      geometryPath.c_str(), output.c_str(), static_cast<long long>(added), static_cast<long long>(kept), tables,
      static_cast<long long>(leftOut), generatorPasses);
    return 0;
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "resmr add-properties: error: %s\n", error.what());
    return 1;
  }
}
