// Property side apart from geometry (paper Sec. 5.2, 5.4, 5.5), through the resmr tool:
// resmr build on SPE9 (an OPM Flow run: EGRID, INIT, UNRST), resmr add-properties of every
// INIT array and every array of every report step, then of the GRDECL deck's arrays;
// the geometry file's bytes never change; every packed value, found through the geometry's
// perfect hash, and every layer value equal the simulator's; files of another geometry,
// truncated or corrupt property files are refused with the file named; a run still being
// written (Reek's UNRST growing, cut inside a step) gets its complete steps, and only the new
// ones when add-properties runs again.
#include "CoreTesting.h"

#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseResults.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

using namespace resmr;

namespace
{
std::string Slurp(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

int Run(const std::string& command)
{
  std::fprintf(stderr, "$ %s\n", command.c_str());
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool SameValue(float a, float b)
{
  return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, 4) == 0;
}

/// Every table of `properties` against the simulator's values, through the geometry's hash
/// (packed) and layer by layer. Returns the tables checked.
/// SOIL as add-properties derives it where the run writes SWAT and no SOIL: 1 - SWAT - SGAS,
/// SGAS 0 in a run without gas.
bool DerivedOil(const EclipseResults& results, std::size_t step, std::vector<float>& oil)
{
  const float none = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> gas(oil.size(), 0.0f);
  if (!results.ReadDynamic<float>(step, "SWAT", oil.data(), none))
  {
    return false;
  }
  results.ReadDynamic<float>(step, "SGAS", gas.data(), none);
  for (std::size_t c = 0; c < oil.size(); ++c)
  {
    oil[c] = 1.0f - oil[c] - gas[c];
  }
  return true;
}

/// Tables a report step gives: its arrays, and SOIL where it has SWAT and no SOIL.
std::size_t StepTables(const std::vector<std::string>& names)
{
  const bool water = std::find(names.begin(), names.end(), "SWAT") != names.end();
  const bool oil = std::find(names.begin(), names.end(), "SOIL") != names.end();
  return names.size() + (water && !oil ? 1 : 0);
}

int CheckTables(const MultiresolutionFile& geometry, const PropertyFile& properties, const EclipseGrid& grid,
  const EclipseResults& results)
{
  const auto& dims = geometry.Header().dims;
  const int64_t layer = dims[0] * dims[1], cells = layer * dims[2];
  const PerfectSpatialHash hash = geometry.ReadHash();
  const auto cellBytes = geometry.ReadModelArray(ModelChunk::HashCells);
  std::vector<uint64_t> slotCell(cellBytes.size() / 8);
  std::memcpy(slotCell.data(), cellBytes.data(), cellBytes.size());
  std::vector<float> expected(static_cast<std::size_t>(cells));
  const float none = std::numeric_limits<float>::quiet_NaN();
  int checked = 0;
  int64_t inactiveSlots = 0;
  for (std::size_t t = 0; t < properties.Tables().size(); ++t)
  {
    const PropertyTable& table = properties.Tables()[t];
    bool found = table.step < 0
      ? results.ReadStatic<float>(table.name, expected.data(), none)
      : results.ReadDynamic<float>(static_cast<std::size_t>(table.step), table.name, expected.data(), none);
    if (!found && table.name == "SOIL" && table.step >= 0)
    {
      found = DerivedOil(results, static_cast<std::size_t>(table.step), expected);
    }
    if (!found)
    {
      continue; // a GRDECL table: checked by its own test below
    }
    for (int64_t c = 0; c < cells; ++c)
    {
      if (!grid.IsActive(c))
      {
        expected[static_cast<std::size_t>(c)] = none;
      }
    }
    const std::vector<float> packed = properties.ReadPacked(t);
    CHECK(packed.size() == hash.TableSize());
    int64_t wrong = 0;
    for (std::size_t slot = 0; slot < slotCell.size(); ++slot)
    {
      const uint64_t n = slotCell[slot];
      if (n == ~uint64_t(0))
      {
        continue;
      }
      const uint32_t i = uint32_t(n % uint64_t(dims[0])), j = uint32_t(n / uint64_t(dims[0]) % uint64_t(dims[1])),
                     k = uint32_t(n / uint64_t(layer));
      // What a shader does: the cell's slot from the hash, then the packed value there.
      const float got = packed[static_cast<std::size_t>(hash.Slot(i, j, k))];
      if (grid.IsActive(static_cast<int64_t>(n)))
      {
        wrong += !SameValue(got, expected[n]);
        continue;
      }
      // An inactive cell's slot holds the value of an active cell of its layer at the fewest
      // i/j steps (found here by brute force), NaN if the layer has none.
      int64_t best = std::numeric_limits<int64_t>::max();
      bool matches = false;
      ++inactiveSlots;
      for (int64_t c = 0; c < layer; ++c)
      {
        const int64_t other = int64_t(k) * layer + c;
        if (!grid.IsActive(other))
        {
          continue;
        }
        const int64_t steps = std::llabs(c % dims[0] - int64_t(i)) + std::llabs(c / dims[0] - int64_t(j));
        if (steps < best)
        {
          best = steps;
          matches = false;
        }
        matches = matches || (steps == best && SameValue(got, expected[static_cast<std::size_t>(other)]));
      }
      wrong += best == std::numeric_limits<int64_t>::max() ? !std::isnan(got) : !matches;
    }
    for (int64_t k = 0; k < dims[2]; ++k)
    {
      const std::vector<float> values = properties.ReadLayer(t, k);
      for (int64_t c = 0; c < layer; ++c)
      {
        wrong += !SameValue(values[static_cast<std::size_t>(c)], expected[static_cast<std::size_t>(k * layer + c)]);
      }
      // One cell alone (its layer decoded up to it, a pick's read): the first, a middle, the last.
      for (const int64_t c : { int64_t(0), layer / 2, layer - 1 })
      {
        const std::array<int64_t, 3> cell{ c % dims[0], c / dims[0], k };
        wrong += !SameValue(properties.ReadCell(t, cell), values[static_cast<std::size_t>(c)]);
      }
    }
    // Planes of one I and one J (a range's cut faces): every value where the layers put it.
    for (const int64_t i : { int64_t(0), dims[0] / 2, dims[0] - 1 })
    {
      const std::vector<float> plane = properties.ReadPlane(t, 0, i);
      CHECK(plane.size() == std::size_t(dims[1] * dims[2]));
      for (int64_t n = 0; n < int64_t(plane.size()); ++n)
      {
        const int64_t j = n % dims[1], k = n / dims[1];
        wrong += !SameValue(plane[std::size_t(n)], expected[std::size_t(k * layer + j * dims[0] + i)]);
      }
    }
    for (const std::array<int64_t, 2> bad : { std::array<int64_t, 2>{ 0, dims[0] }, { 1, -1 }, { 3, 0 } })
    {
      bool refused = false;
      try
      {
        properties.ReadPlane(t, int(bad[0]), bad[1]);
      }
      catch (const std::out_of_range&)
      {
        refused = true;
      }
      CHECK(refused);
    }
    for (const int64_t j : { int64_t(0), dims[1] / 2, dims[1] - 1 })
    {
      const std::vector<float> plane = properties.ReadPlane(t, 1, j);
      CHECK(plane.size() == std::size_t(dims[0] * dims[2]));
      for (int64_t n = 0; n < int64_t(plane.size()); ++n)
      {
        const int64_t i = n % dims[0], k = n / dims[0];
        wrong += !SameValue(plane[std::size_t(n)], expected[std::size_t(k * layer + j * dims[0] + i)]);
      }
    }
    // Block ranges (a property filter's): each block's bounds are its active cells' values
    // over all layers, brute force; -infinity low where an active cell has no value.
    const std::vector<ValueRange> blocks = properties.ReadBlockRanges(t);
    const auto counts = properties.BlockCounts();
    CHECK(blocks.size() == std::size_t(counts[0] * counts[1]));
    std::vector<ValueRange> want(
      blocks.size(), ValueRange{ std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity() });
    for (int64_t n = 0; n < layer * dims[2]; ++n)
    {
      if (!grid.IsActive(n))
      {
        continue;
      }
      const int64_t i = n % dims[0], j = n / dims[0] % dims[1];
      ValueRange& b = want[std::size_t(i / ColumnBlockSide + counts[0] * (j / ColumnBlockSide))];
      const float v = expected[std::size_t(n)];
      b.low = std::isnan(v) ? -std::numeric_limits<float>::infinity() : std::min(b.low, v);
      b.high = std::isnan(v) ? b.high : std::max(b.high, v);
    }
    for (std::size_t b = 0; b < blocks.size() && b < want.size(); ++b)
    {
      wrong += blocks[b].low != want[b].low || blocks[b].high != want[b].high;
    }
    // Layer blocks: each block's range and mean in each layer, brute force.
    const std::vector<BlockSummary> summaries = properties.ReadLayerBlocks(t);
    const auto layerCounts = properties.LayerBlockCounts();
    CHECK(summaries.size() == std::size_t(layerCounts[0] * layerCounts[1] * dims[2]));
    for (std::size_t b = 0; b < summaries.size(); ++b)
    {
      const int64_t bi = int64_t(b) % layerCounts[0], bj = int64_t(b) / layerCounts[0] % layerCounts[1],
                    k = int64_t(b) / (layerCounts[0] * layerCounts[1]);
      float low = std::numeric_limits<float>::infinity(), high = -low;
      double sum = 0;
      int64_t count = 0;
      for (int64_t j = bj * LayerBlockSide; j < std::min(dims[1], (bj + 1) * LayerBlockSide); ++j)
      {
        for (int64_t i = bi * LayerBlockSide; i < std::min(dims[0], (bi + 1) * LayerBlockSide); ++i)
        {
          const int64_t n = k * layer + j * dims[0] + i;
          if (!grid.IsActive(n))
          {
            continue;
          }
          const float v = expected[std::size_t(n)];
          low = std::isnan(v) ? -std::numeric_limits<float>::infinity() : std::min(low, v);
          high = std::isnan(v) ? high : std::max(high, v);
          sum += std::isnan(v) ? 0.0 : double(v);
          count += std::isnan(v) ? 0 : 1;
        }
      }
      const BlockSummary& s = summaries[b];
      const float mean = count ? float(sum / double(count)) : std::numeric_limits<float>::quiet_NaN();
      wrong += s.low != low || s.high != high || !(s.mean == mean || (std::isnan(s.mean) && std::isnan(mean)));
    }
    // A box of cells (a filtered leaf's): every value where the layers put it.
    const std::array<int64_t, 3> lo{ dims[0] / 3, dims[1] / 4, 0 }, hi{ dims[0] - 1, dims[1] * 3 / 4, dims[2] - 1 };
    const std::vector<float> box = properties.ReadBox(t, lo, hi);
    CHECK(box.size() == std::size_t((hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1)));
    for (std::size_t n = 0; n < box.size(); ++n)
    {
      const int64_t w = hi[0] - lo[0] + 1, h = hi[1] - lo[1] + 1;
      const int64_t i = lo[0] + int64_t(n) % w, j = lo[1] + int64_t(n) / w % h, k = lo[2] + int64_t(n) / (w * h);
      wrong += !SameValue(box[n], expected[std::size_t(k * layer + j * dims[0] + i)]);
    }
    if (wrong)
    {
      std::fprintf(
        stderr, "%s step %d: %lld values differ\n", table.name.c_str(), table.step, static_cast<long long>(wrong));
    }
    CHECK(wrong == 0);
    ++checked;
  }
  std::printf(
    "%lld inactive cells' slots checked against their nearest active cell\n", static_cast<long long>(inactiveSlots));
  return checked;
}
/// The number after `"key": ` in a JSON line, or -1.
long long JsonNumber(const std::string& json, const std::string& key)
{
  const std::size_t at = json.find("\"" + key + "\": ");
  return at == std::string::npos ? -1 : std::atoll(json.c_str() + at + key.size() + 4);
}

/// A run still being written (Reek's UNRST growing step by step, cut inside a step):
/// add-properties writes the complete steps and reports the cut one (exit 0); run again, it
/// adds only the steps completed since and keeps the others; every table equals the whole
/// run's. Nothing readable at all is an error.
void GrowingRun(const std::string& resmrTool, const std::string& egrid, const std::string& geometryPath,
  const std::string& temp, const EclipseGrid& grid, const EclipseResults& whole)
{
  const std::string folder = temp + "/reek-run", stem = "/2_R001_REEK-0";
  const std::string source = egrid.substr(0, egrid.size() - 6);
  const std::string unrst = Slurp(source + ".UNRST");
  const std::string run = folder + stem + ".EGRID", properties = folder + "/run.resmrp";
  mkdir(folder.c_str(), 0755);
  for (const char* extension : { ".EGRID", ".INIT", ".UNRST" })
  {
    std::remove((folder + stem + extension).c_str());
  }
  CHECK(symlink(egrid.c_str(), run.c_str()) == 0);
  std::remove(properties.c_str());
  const EclipseKeywordFile file(source + ".UNRST");
  std::vector<int64_t> starts;
  for (const EclipseRecord& record : file.Records())
  {
    if (record.name == "SEQNUM")
    {
      starts.push_back(record.headerOffset);
    }
  }
  CHECK(starts.size() == 4 && whole.Steps().size() == 4);
  if (starts.size() != 4)
  {
    return;
  }
  const auto writeRestart = [&](int64_t size) {
    std::ofstream out(folder + stem + ".UNRST", std::ios::binary | std::ios::trunc);
    out.write(unrst.data(), static_cast<std::streamsize>(size));
  };
  const std::string output = folder + "/out.json", errors = folder + "/err.txt";
  const std::string command = resmrTool + " add-properties '" + geometryPath + "' '" + run + "' -o '" + properties +
    "' > '" + output + "' 2> '" + errors + "'";

  // No INIT and an empty restart: nothing readable, an error.
  writeRestart(0);
  CHECK(Run(command) != 0);
  CHECK(Slurp(errors).find("no property found") != std::string::npos);

  CHECK(symlink((source + ".INIT").c_str(), (folder + stem + ".INIT").c_str()) == 0);
  const std::size_t names = StepTables(whole.Steps()[0].names), statics = whole.StaticArrays().size();
  const struct
  {
    int64_t size;
    std::size_t complete;
  } stages[] = { { starts[2] + 1000, 2 }, { starts[3] + 5, 3 }, { file.Size(), 4 } };
  std::size_t before = 0;
  for (const auto& stage : stages)
  {
    writeRestart(stage.size);
    CHECK(Run(command) == 0);
    const std::string json = Slurp(output), warnings = Slurp(errors);
    std::printf("UNRST of %lld bytes: %s", static_cast<long long>(stage.size), json.c_str());
    const bool cut = stage.size != file.Size();
    CHECK((warnings.find("left out: incomplete at byte") != std::string::npos) == cut);
    CHECK(JsonNumber(json, "left_out") == (cut ? 1 : 0));
    // resmr info lists the same steps, and the one left out with its file and offset.
    CHECK(Run(resmrTool + " info '" + run + "' > '" + output + "' 2> '" + errors + "'") == 0);
    const std::string info = Slurp(output);
    std::size_t offered = 0;
    for (std::size_t at = info.find("\"days\": "); at != std::string::npos; at = info.find("\"days\": ", at + 1))
    {
      ++offered;
    }
    CHECK(offered == stage.complete);
    const std::string leftOut = cut ? "\"steps_left_out\": [{\"file\": \"" + folder + stem + ".UNRST\", \"report\": " +
        // (-1 while the cut step's SEQNUM record is not whole)
        std::to_string(stage.size >= starts[stage.complete] + 36 ? whole.Steps()[stage.complete].reportNumber : -1) +
        ", \"offset\": "
                                    : std::string("\"steps_left_out\": []");
    CHECK(info.find(leftOut) != std::string::npos);
    // The INIT's arrays are read again each time; only the new steps' arrays are added.
    CHECK(JsonNumber(json, "tables_added") == static_cast<long long>(statics + (stage.complete - before) * names));
    CHECK(JsonNumber(json, "tables_kept") == static_cast<long long>(before * names));
    const MultiresolutionFile geometry(geometryPath);
    const PropertyFile written(properties);
    CHECK(written.Tables().size() == statics + stage.complete * names);
    CHECK(written.Find("PRESSURE", static_cast<int32_t>(stage.complete - 1)) >= 0);
    CHECK(written.Find("PRESSURE", static_cast<int32_t>(stage.complete)) < 0);
    CHECK(CheckTables(geometry, written, grid, whole) == static_cast<int>(written.Tables().size()));
    before = stage.complete;
  }
  // Nothing new: every step kept, only the INIT's arrays read again.
  CHECK(Run(command) == 0);
  CHECK(JsonNumber(Slurp(output), "tables_kept") == static_cast<long long>(4 * names));
  CHECK(JsonNumber(Slurp(output), "tables_added") == static_cast<long long>(statics));
  {
    const MultiresolutionFile geometry(geometryPath);
    const PropertyFile written(properties);
    CHECK(written.Tables().size() == statics + 4 * names);
    CHECK(CheckTables(geometry, written, grid, whole) == static_cast<int>(written.Tables().size()));
  }
  for (const char* extension : { ".EGRID", ".INIT", ".UNRST" })
  {
    std::remove((folder + stem + extension).c_str());
  }
  for (const std::string& path : { properties, output, errors })
  {
    std::remove(path.c_str());
  }
  rmdir(folder.c_str());
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 4)
  {
    std::fprintf(stderr, "usage: TestPropertyFile RESMR DATA_DIR TEMP_DIR\n");
    return 2;
  }
  const std::string resmrTool = argv[1], data = argv[2], temp = argv[3];
  mkdir(temp.c_str(), 0755);
  const std::string egrid = data + "/spe9/opmflow2022_run_of_opm-data_SPE9_CP/SPE9_CP.EGRID";
  const std::string deck = data + "/spe9/opm-data_deck/SPE9_CP.DATA";
  const std::string geometryPath = temp + "/spe9.resmr", propertyPath = temp + "/spe9.resmrp";
  std::remove(propertyPath.c_str());
  CHECK(Run(resmrTool + " build '" + egrid + "' -o '" + geometryPath + "' --quiet > /dev/null") == 0);
  const std::string before = Slurp(geometryPath);
  CHECK(before.size() > 1000);

  // Every INIT array and every array of every step.
  CHECK(Run(resmrTool + " add-properties '" + geometryPath + "' '" + egrid + "' > /dev/null 2>&1") == 0);
  CHECK(Slurp(geometryPath) == before); // geometry untouched, byte for byte
  const EclipseGrid grid = ReadEclipseGrid(egrid);
  const EclipseResults results(egrid, grid);
  std::size_t expectedTables = results.StaticArrays().size();
  for (const auto& step : results.Steps())
  {
    expectedTables += StepTables(step.names);
  }
  {
    const MultiresolutionFile geometry(geometryPath);
    const PropertyFile properties(propertyPath);
    properties.CheckGeometry(geometry);
    CHECK(properties.Tables().size() == expectedTables);
    CHECK(results.Steps().size() > 1 && properties.Find("PRESSURE", int32_t(results.Steps().size() - 1)) >= 0);
    CHECK(properties.Find("PORO", -1) >= 0);
    CHECK(CheckTables(geometry, properties, grid, results) == static_cast<int>(expectedTables));
    const int pressure = properties.Find("PRESSURE", 0);
    CHECK(pressure >= 0 && properties.Tables()[static_cast<std::size_t>(pressure)].maximum > 1000);
  }

  // Reek has inactive cells that coarse faces reach over: their slots hold a neighbour's value.
  {
    const std::string reek = data + "/reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID";
    const std::string reekGeometry = temp + "/reek.resmr", reekProperties = temp + "/reek.resmrp";
    std::remove(reekProperties.c_str());
    CHECK(Run(resmrTool + " build '" + reek + "' -o '" + reekGeometry + "' --quiet > /dev/null") == 0);
    CHECK(Run(resmrTool + " add-properties '" + reekGeometry + "' '" + reek + "' > /dev/null 2>&1") == 0);
    const EclipseGrid reekGrid = ReadEclipseGrid(reek);
    const EclipseResults reekResults(reek, reekGrid);
    const MultiresolutionFile geometry(reekGeometry);
    const PropertyFile properties(reekProperties);
    CHECK(CheckTables(geometry, properties, reekGrid, reekResults) == static_cast<int>(properties.Tables().size()));
    CHECK(properties.Bands() == 1 && properties.BandRows() == reekGrid.deck.dims[1]);
    // Layers cut into bands of 5 rows (the last of 4), then copied back into one band a layer
    // (what copying an older version's file does): the same values either way.
    const std::string banded = temp + "/reek-banded.resmrp", again = temp + "/reek-again.resmrp";
    {
      PropertyFileWriter writer(banded, geometry, 5);
      writer.CopyFrom(properties);
      writer.Commit();
    }
    {
      const PropertyFile cut(banded);
      CHECK(cut.BandRows() == 5 && cut.Bands() == (reekGrid.deck.dims[1] + 4) / 5 && cut.Bands() > 2);
      CHECK(CheckTables(geometry, cut, reekGrid, reekResults) == static_cast<int>(properties.Tables().size()));
      // Tiles of 5 rows x 7 columns (the last of each row and column smaller), copied from the
      // bands of rows: boxes, planes, cells and layers read across tile edges.
      const std::string tiled = temp + "/reek-tiled.resmrp";
      {
        PropertyFileWriter writer(tiled, geometry, 5, 7);
        writer.CopyFrom(cut);
        writer.Commit();
      }
      const PropertyFile tiles(tiled);
      CHECK(
        tiles.BandRows() == 5 && tiles.BandColumns() == 7 && tiles.BandsAlongI() == (reekGrid.deck.dims[0] + 6) / 7);
      CHECK(tiles.Bands() == tiles.BandsAlongI() * cut.Bands() && tiles.BandsAlongI() > 2);
      CHECK(CheckTables(geometry, tiles, reekGrid, reekResults) == static_cast<int>(properties.Tables().size()));
      PropertyFileWriter writer(again, geometry);
      writer.CopyFrom(tiles);
      writer.Commit();
      std::remove(tiled.c_str());
    }
    {
      const PropertyFile whole(again);
      CHECK(whole.Bands() == 1);
      CHECK(CheckTables(geometry, whole, reekGrid, reekResults) == static_cast<int>(properties.Tables().size()));
    }
    std::remove(banded.c_str());
    std::remove(again.c_str());
    std::remove(reekProperties.c_str());
    GrowingRun(resmrTool, reek, reekGeometry, temp, reekGrid, reekResults);
    std::remove(reekProperties.c_str());
    std::remove(reekGeometry.c_str());
  }

  // The deck's arrays (PORO, PERMX, ...) replace the INIT arrays of the same name, the
  // other tables stay; the geometry still does not change.
  CHECK(Run(resmrTool + " add-properties '" + geometryPath + "' '" + deck + "' > /dev/null 2>&1") == 0);
  CHECK(Slurp(geometryPath) == before);
  {
    const MultiresolutionFile geometry(geometryPath);
    const PropertyFile properties(propertyPath);
    CHECK(properties.Tables().size() == expectedTables);
    CHECK(properties.Find("PRESSURE", 0) >= 0 && properties.Find("PERMX", -1) >= 0);
    CHECK(CheckTables(geometry, properties, grid, results) == static_cast<int>(expectedTables));
  }

  // Another geometry (the same grid cut into other regions) is refused by name.
  const std::string otherPath = temp + "/spe9-cmax.resmr";
  CHECK(Run(resmrTool + " build '" + egrid + "' -o '" + otherPath + "' --cmax 64 --quiet > /dev/null") == 0);
  {
    const MultiresolutionFile other(otherPath);
    const PropertyFile properties(propertyPath);
    resmr_testing::ExpectError<FileFormatError>(
      "other geometry", [&] { properties.CheckGeometry(other); }, { propertyPath, "another geometry" });
  }
  CHECK(
    Run(resmrTool + " add-properties '" + otherPath + "' '" + egrid + "' -o '" + propertyPath + "' 2>/dev/null") != 0);
  CHECK(Slurp(otherPath).size() > 0);

  // Damaged property files are refused with the file and the place named.
  const std::string bytes = Slurp(propertyPath);
  const std::string damaged = temp + "/damaged.resmrp";
  const auto writeBytes = [&](const std::string& content) {
    std::ofstream out(damaged, std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
  };
  writeBytes(bytes.substr(0, bytes.size() - 10));
  resmr_testing::ExpectError<FileFormatError>("truncated", [&] { PropertyFile f(damaged); }, { damaged, "truncated" });
  std::string flipped = bytes;
  flipped[200] ^= 0x5a; // inside the first table's first chunk
  writeBytes(flipped);
  {
    const PropertyFile f(damaged);
    resmr_testing::ExpectError<FileFormatError>("flipped chunk, one cell read",
      [&] {
        for (std::size_t t = 0; t < f.Tables().size(); ++t)
        {
          for (int64_t k = 0; k < 15; ++k)
          {
            f.ReadCell(t, { 0, 0, k });
          }
        }
      },
      { damaged, "checksum" });
    resmr_testing::ExpectError<FileFormatError>("flipped chunk",
      [&] {
        for (std::size_t t = 0; t < f.Tables().size(); ++t)
        {
          for (int64_t k = 0; k < 15; ++k)
          {
            f.ReadLayer(t, k);
          }
          f.ReadPacked(t);
        }
      },
      { damaged, "checksum" });
  }
  std::remove(damaged.c_str());
  std::remove(otherPath.c_str());
  std::remove(propertyPath.c_str());
  std::remove(geometryPath.c_str());
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d checks failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("property file tests passed\n");
  return 0;
}
