// Synthetic models to EGRID/INIT/UNRST or GRDECL, one pass over the layers per keyword.
#include "SyntheticReservoirWriter.h"

#include "AtomicOutputFile.h"
#include "EclipseKeywordWriter.h"
#include "Errors.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <sys/stat.h>

namespace resmr
{
namespace
{
/// Reports progress as passes over the layers complete.
class PassCounter
{
public:
  PassCounter(const SyntheticProgress& progress, int passes, int64_t layers)
    : Progress(progress)
    , Passes(passes)
    , Layers(layers)
  {
  }
  void Layer(int64_t k)
  {
    if (this->Progress)
    {
      this->Progress((this->Done + static_cast<double>(k + 1) / static_cast<double>(this->Layers)) / this->Passes);
    }
  }
  void EndPass() { ++this->Done; }

private:
  const SyntheticProgress& Progress;
  int Passes;
  int64_t Layers;
  int Done = 0;
};

/// Runs one pass over the model's layers.
template<typename Visit>
SyntheticStatistics EachLayer(const SyntheticReservoir& model, PassCounter& counter, Visit visit)
{
  SyntheticLayerStream stream(model);
  SyntheticLayer layer;
  while (stream.Next(layer))
  {
    visit(layer);
    counter.Layer(layer.k);
  }
  counter.EndPass();
  return stream.Statistics();
}

std::vector<float> ActiveValues(const SyntheticLayer& layer, const std::vector<float>& values)
{
  std::vector<float> active;
  active.reserve(static_cast<std::size_t>(layer.activeCells));
  for (std::size_t c = 0; c < values.size(); ++c)
  {
    if (layer.state[c] == SyntheticCellState::Active)
    {
      active.push_back(values[c]);
    }
  }
  return active;
}

std::string CompanionPath(const std::string& egridPath, const char* extension)
{
  const std::size_t slash = egridPath.find_last_of('/');
  const std::size_t dot = egridPath.find_last_of('.');
  const bool hasExtension = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  const std::string base = hasExtension ? egridPath.substr(0, dot) : egridPath;
  bool lower = hasExtension;
  for (std::size_t i = dot + 1; hasExtension && i < egridPath.size(); ++i)
  {
    lower = lower && std::islower(static_cast<unsigned char>(egridPath[i]));
  }
  std::string ext = extension;
  for (char& c : ext)
  {
    c = lower ? static_cast<char>(std::tolower(static_cast<unsigned char>(c))) : c;
  }
  return base + "." + ext;
}

int64_t FileSize(const std::string& path)
{
  struct stat info;
  return stat(path.c_str(), &info) == 0 ? static_cast<int64_t>(info.st_size) : 0;
}

std::vector<int32_t> Intehead(const SyntheticReservoir& model, int64_t active, SyntheticDate date)
{
  const SyntheticParameters& p = model.Parameters();
  std::vector<int32_t> head(411, 0);
  head[1] = 201802; // file format version written by current simulators
  head[2] = 1;      // METRIC
  head[8] = static_cast<int32_t>(p.nx);
  head[9] = static_cast<int32_t>(p.ny);
  head[10] = static_cast<int32_t>(p.nz);
  head[11] = static_cast<int32_t>(active);
  head[14] = 3; // phases: oil + water
  head[64] = date.day;
  head[65] = date.month;
  head[66] = date.year;
  head[94] = 100; // simulator: ECLIPSE 100 compatible
  return head;
}

void WriteHeaders(
  EclipseKeywordWriter& out, const SyntheticReservoir& model, int64_t active, SyntheticDate date, double days)
{
  out.Write("INTEHEAD", "INTE", Intehead(model, active, date));
  out.Write("LOGIHEAD", "LOGI", std::vector<int32_t>(121, 0));
  std::vector<double> doubhead(229, 0.0);
  doubhead[0] = days;
  out.Write("DOUBHEAD", "DOUB", doubhead);
}
} // namespace

const std::vector<SyntheticInitArray>& SyntheticInitArrays()
{
  static const std::vector<SyntheticInitArray> arrays = { { "PORV", true }, { "DEPTH", false }, { "DX", false },
    { "DY", false }, { "DZ", false }, { "PORO", false }, { "PERMX", false }, { "PERMY", false }, { "PERMZ", false },
    { "NTG", false } };
  return arrays;
}

void FillSyntheticInitArray(
  const SyntheticReservoir& model, std::size_t index, const SyntheticLayer& layer, float* values)
{
  const std::size_t cells = layer.state.size();
  const auto copy = [&](const std::vector<float>& from, float scale) {
    for (std::size_t c = 0; c < cells; ++c)
    {
      values[c] = from[c] * scale;
    }
  };
  const auto fill = [&](double size) { std::fill(values, values + cells, static_cast<float>(size)); };
  switch (index)
  {
    case 0:
      copy(layer.poreVolume, 1);
      break;
    case 1:
      copy(layer.depth, 1);
      break;
    case 2:
      fill(model.CellSizeX());
      break;
    case 3:
      fill(model.CellSizeY());
      break;
    case 4:
      copy(layer.thickness, 1);
      break;
    case 5:
      copy(layer.poro, 1);
      break;
    case 6:
      copy(layer.permx, 1);
      break;
    case 7:
      copy(layer.permx, 1);
      break; // isotropic in the bedding plane
    case 8:
      copy(layer.permx, 0.1f);
      break;
    case 9:
      copy(layer.ntg, 1);
      break;
    default:
      throw std::out_of_range("no synthetic INIT array " + std::to_string(index));
  }
}

SyntheticOutput WriteSyntheticEclipse(
  const SyntheticReservoir& model, const std::string& egridPath, const SyntheticProgress& progress)
{
  const SyntheticParameters& p = model.Parameters();
  if (p.CellCount() > MaxEgridCells)
  {
    throw InputError(egridPath, 0, "",
      "an EGRID holds at most 268,435,455 cells (ZCORN's 8 values a cell must fit the 32-bit "
      "count of an ECLIPSE keyword header), and " +
        std::to_string(p.nx) + " x " + std::to_string(p.ny) + " x " + std::to_string(p.nz) + " = " +
        std::to_string(p.CellCount()) +
        " cells were asked for. Models this large are not written to files: the hierarchy builder "
        "streams them straight from the generator (input synth:" +
        std::to_string(p.nx) + "x" + std::to_string(p.ny) + "x" + std::to_string(p.nz) + ":" + std::to_string(p.seed) +
        "), or write GRDECL for an ASCII deck");
  }
  const int64_t nz = p.nz;
  const int passes = 2 + static_cast<int>(SyntheticInitArrays().size()) + 2 * p.steps;
  PassCounter counter(progress, passes, nz);
  SyntheticOutput output;

  // EGRID: geometry and ACTNUM.
  EclipseKeywordWriter grid(egridPath);
  std::vector<int32_t> filehead(100, 0);
  filehead[0] = 3;    // version
  filehead[1] = 2007; // release year of the format
  filehead[6] = 1;    // corner-point grid
  grid.Write("FILEHEAD", "INTE", filehead);
  grid.WriteStrings("GRIDUNIT", { "METRES", "" });
  std::vector<int32_t> gridhead(100, 0);
  gridhead[0] = 1; // corner point
  gridhead[1] = static_cast<int32_t>(p.nx);
  gridhead[2] = static_cast<int32_t>(p.ny);
  gridhead[3] = static_cast<int32_t>(p.nz);
  gridhead[24] = 1; // reservoirs
  grid.Write("GRIDHEAD", "INTE", gridhead);
  grid.Write("COORD", "REAL", model.Coord());
  grid.Begin("ZCORN", "REAL", 8 * p.CellCount());
  output.statistics = EachLayer(model, counter,
    [&](const SyntheticLayer& layer) { grid.Append(layer.zcorn.data(), static_cast<int64_t>(layer.zcorn.size())); });
  grid.Begin("ACTNUM", "INTE", p.CellCount());
  std::vector<int32_t> actnum;
  EachLayer(model, counter, [&](const SyntheticLayer& layer) {
    actnum.resize(layer.state.size());
    for (std::size_t c = 0; c < actnum.size(); ++c)
    {
      actnum[c] = layer.state[c] == SyntheticCellState::Active ? 1 : 0;
    }
    grid.Append(actnum.data(), static_cast<int64_t>(actnum.size()));
  });
  grid.Write("ENDGRID", "INTE", std::vector<int32_t>());
  const int64_t active = output.statistics.active;

  // INIT: static properties, PORV for every cell, the rest for active cells as simulators do.
  const std::string initPath = CompanionPath(egridPath, "INIT");
  EclipseKeywordWriter init(initPath);
  WriteHeaders(init, model, active, SyntheticReservoir::StartDate(), 0.0);
  std::vector<float> values;
  for (std::size_t a = 0; a < SyntheticInitArrays().size(); ++a)
  {
    const SyntheticInitArray& array = SyntheticInitArrays()[a];
    init.Begin(array.name, "REAL", array.everyCell ? p.CellCount() : active);
    EachLayer(model, counter, [&](const SyntheticLayer& layer) {
      values.resize(layer.state.size());
      FillSyntheticInitArray(model, a, layer, values.data());
      if (array.everyCell)
      {
        init.Append(values.data(), static_cast<int64_t>(values.size()));
      }
      else
      {
        const std::vector<float> written = ActiveValues(layer, values);
        init.Append(written.data(), static_cast<int64_t>(written.size()));
      }
    });
  }

  // UNRST: PRESSURE and SWAT per report step.
  std::unique_ptr<EclipseKeywordWriter> restart;
  const std::string restartPath = CompanionPath(egridPath, "UNRST");
  if (p.steps > 0)
  {
    restart.reset(new EclipseKeywordWriter(restartPath));
    std::vector<float> pressure, swat;
    for (int step = 1; step <= p.steps; ++step)
    {
      restart->Write("SEQNUM", "INTE", std::vector<int32_t>{ step });
      WriteHeaders(*restart, model, active, model.StepDate(step), model.StepDays(step));
      restart->Begin("STARTSOL", "MESS", 0);
      for (const char* name : { "PRESSURE", "SWAT" })
      {
        const bool isPressure = name[0] == 'P';
        restart->Begin(name, "REAL", active);
        EachLayer(model, counter, [&](const SyntheticLayer& layer) {
          pressure.resize(layer.state.size());
          swat.resize(layer.state.size());
          model.FillStep(step, layer, pressure.data(), swat.data());
          const std::vector<float> values = ActiveValues(layer, isPressure ? pressure : swat);
          restart->Append(values.data(), static_cast<int64_t>(values.size()));
        });
      }
      restart->Begin("ENDSOL", "MESS", 0);
    }
  }

  // Everything is complete: only now do the files take their names.
  if (restart)
  {
    restart->Commit();
    output.files.push_back(restartPath);
  }
  init.Commit();
  output.files.push_back(initPath);
  grid.Commit();
  output.files.insert(output.files.begin(), egridPath);
  if (!restart && std::remove(restartPath.c_str()) == 0)
  {
    output.removed.push_back(restartPath); // an older model's steps would not fit this grid
  }
  for (const std::string& file : output.files)
  {
    output.bytes += FileSize(file);
  }
  return output;
}

namespace
{
/// ASCII keyword data with ECLIPSE repeat counts (n*value), about ten items a line.
class GrdeclTextWriter
{
public:
  explicit GrdeclTextWriter(const std::string& path)
    : Output(path)
  {
  }
  void Text(const std::string& text)
  {
    this->Buffer += text;
    this->FlushIfFull();
  }
  void Value(double value, bool integer)
  {
    if (this->Count > 0 && value == this->Last)
    {
      ++this->Count;
      return;
    }
    this->EndRun();
    this->Last = value;
    this->Integer = integer;
    this->Count = 1;
  }
  void EndKeyword()
  {
    this->EndRun();
    this->Buffer += "\n/\n\n";
    this->OnLine = 0;
    this->FlushIfFull();
  }
  void Commit()
  {
    this->Flush();
    this->Output.Commit();
  }

private:
  void EndRun()
  {
    if (this->Count == 0)
    {
      return;
    }
    char text[32];
    if (this->Count > 1)
    {
      this->Buffer.append(text, std::to_chars(text, text + sizeof(text), this->Count).ptr);
      this->Buffer += '*';
    }
    char* end = this->Integer ? std::to_chars(text, text + sizeof(text), static_cast<int64_t>(this->Last)).ptr
                              : std::to_chars(text, text + sizeof(text), static_cast<float>(this->Last)).ptr;
    this->Buffer.append(text, end);
    this->Buffer += ++this->OnLine % 10 == 0 ? '\n' : ' ';
    this->Count = 0;
    this->FlushIfFull();
  }
  void FlushIfFull()
  {
    if (this->Buffer.size() >= (1u << 20))
    {
      this->Flush();
    }
  }
  void Flush()
  {
    if (!this->Output.Write(this->Buffer.data(), this->Buffer.size()))
    {
      const int error = errno;
      this->Output.Discard();
      throw InputError(this->Output.Path(), 0, "", std::string("write failed (disk full?): ") + std::strerror(error));
    }
    this->Buffer.clear();
  }

  AtomicOutputFile Output;
  std::string Buffer;
  double Last = 0;
  bool Integer = false;
  int64_t Count = 0;
  int64_t OnLine = 0;
};
} // namespace

SyntheticOutput WriteSyntheticGrdecl(
  const SyntheticReservoir& model, const std::string& path, const SyntheticProgress& progress)
{
  const SyntheticParameters& p = model.Parameters();
  if (p.steps > 0)
  {
    throw InputError(path, 0, "",
      "report steps need EGRID output (they go to an UNRST beside "
      "it); a GRDECL deck holds the grid and static properties only");
  }
  PassCounter counter(progress, 7, p.nz);
  SyntheticOutput output;
  GrdeclTextWriter out(path);
  char header[512];
  std::snprintf(header, sizeof(header),
    "-- Synthetic reservoir written by resmr synth: %lld x %lld x %lld cells, seed %llu,\n"
    "-- %d faults, throw %g, dip %g deg, pinched %g, water %g, outside %g.\n\n"
    "SPECGRID\n%lld %lld %lld 1 F /\n\nCOORD\n",
    static_cast<long long>(p.nx), static_cast<long long>(p.ny), static_cast<long long>(p.nz),
    static_cast<unsigned long long>(p.seed), p.faults, p.maxThrow, p.dipDegrees, p.pinchedFraction, p.waterFraction,
    p.outsideFraction, static_cast<long long>(p.nx), static_cast<long long>(p.ny), static_cast<long long>(p.nz));
  out.Text(header);
  for (double value : model.Coord())
  {
    out.Value(static_cast<float>(value), false);
  }
  out.EndKeyword();
  out.Text("ZCORN\n");
  output.statistics = EachLayer(model, counter, [&](const SyntheticLayer& layer) {
    for (float value : layer.zcorn)
    {
      out.Value(value, false);
    }
  });
  out.EndKeyword();
  out.Text("ACTNUM\n");
  EachLayer(model, counter, [&](const SyntheticLayer& layer) {
    for (SyntheticCellState state : layer.state)
    {
      out.Value(state == SyntheticCellState::Active ? 1 : 0, true);
    }
  });
  out.EndKeyword();
  struct Array
  {
    const char* name;
    std::vector<float> SyntheticLayer::*values;
    float scale;
  };
  for (const Array& array : { Array{ "PORO", &SyntheticLayer::poro, 1 }, Array{ "PERMX", &SyntheticLayer::permx, 1 },
         Array{ "PERMY", &SyntheticLayer::permx, 1 }, Array{ "PERMZ", &SyntheticLayer::permx, 0.1f },
         Array{ "NTG", &SyntheticLayer::ntg, 1 } })
  {
    out.Text(std::string(array.name) + "\n");
    EachLayer(model, counter, [&](const SyntheticLayer& layer) {
      for (float value : layer.*(array.values))
      {
        out.Value(value * array.scale, false);
      }
    });
    out.EndKeyword();
  }
  out.Commit();
  output.files.push_back(path);
  output.bytes = FileSize(path);
  return output;
}

} // namespace resmr
