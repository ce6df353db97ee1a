// resmr add-properties of a synth: spec (streamed from the generator, no file: models beyond
// an EGRID's 268M cells) against the same command on the EGRID, INIT and UNRST resmr synth
// writes for the same size, seed and steps: the same tables, every packed and layer value
// bit for bit (NaN for NaN), the same ranges, steps, report numbers and days. Also: the spec
// parser shared by build, simplify and add-properties; specs of another grid or seed refused
// with nothing written; the layer-by-layer writer's misuse refused.
#include "CoreTesting.h"

#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "SyntheticReservoir.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

using namespace resmr;

namespace
{
int Run(const std::string& command)
{
  std::fprintf(stderr, "$ %s\n", command.c_str());
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool Exists(const std::string& path)
{
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

bool SameValue(float a, float b)
{
  return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, 4) == 0;
}

/// Values of `a` and `b` that differ, NaN equal to NaN.
int64_t Differences(const std::vector<float>& a, const std::vector<float>& b)
{
  if (a.size() != b.size())
  {
    return static_cast<int64_t>(std::max(a.size(), b.size()));
  }
  int64_t wrong = 0;
  for (std::size_t v = 0; v < a.size(); ++v)
  {
    wrong += !SameValue(a[v], b[v]);
  }
  return wrong;
}

std::string Slurp(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// resmr add-properties of synth:NIxNJxNK:SEED:STEPS against the same command on the files
/// resmr synth writes for that model, on a geometry built from the spec; leaves the geometry
/// and both property files in `temp` (synth.resmr, files.resmrp, spec.resmrp). Returns the
/// tables a generator pass gave.
uint64_t CompareWithFiles(
  const std::string& resmrTool, const std::string& temp, int64_t ni, int64_t nj, int64_t nk, uint64_t seed, int steps)
{
  const std::string spec = "synth:" + std::to_string(ni) + "x" + std::to_string(nj) + "x" + std::to_string(nk) + ":" +
    std::to_string(seed) + ":" + std::to_string(steps);
  const std::string egrid = temp + "/synth.EGRID", geometryPath = temp + "/synth.resmr";
  const std::string fromFiles = temp + "/files.resmrp", fromSpec = temp + "/spec.resmrp";
  const std::string report = temp + "/report.json";
  for (const std::string& path : { fromFiles, fromSpec })
  {
    std::remove(path.c_str());
  }
  CHECK(
    Run(resmrTool + " synth " + std::to_string(ni) + " " + std::to_string(nj) + " " + std::to_string(nk) + " --seed " +
      std::to_string(seed) + " --steps " + std::to_string(steps) + " -o '" + egrid + "' --quiet > /dev/null") == 0);
  // The geometry from the generator, as for models no EGRID can hold (the steps change no cell).
  CHECK(Run(resmrTool + " build " + spec + " -o '" + geometryPath + "' --quiet > /dev/null") == 0);
  const std::string addProperties = resmrTool + " add-properties '" + geometryPath + "' ";
  CHECK(Run(addProperties + "'" + egrid + "' -o '" + fromFiles + "' 2>/dev/null >/dev/null") == 0);
  CHECK(Run(addProperties + spec + " -o '" + fromSpec + "' 2>/dev/null > '" + report + "'") == 0);
  const MultiresolutionFile geometry(geometryPath);
  const PropertyFile files(fromFiles), generated(fromSpec);
  generated.CheckGeometry(geometry);
  const auto& h = geometry.Header();
  // Every INIT array, and PRESSURE, SWAT and the derived SOIL of each step.
  const std::size_t tables = 10 + 3 * static_cast<std::size_t>(steps);
  CHECK(files.Tables().size() == tables);
  CHECK(generated.Tables().size() == tables);
  for (const char* name : { "PORV", "DEPTH", "DX", "DY", "DZ", "PORO", "PERMX", "PERMY", "PERMZ", "NTG" })
  {
    CHECK(generated.Find(name, -1) >= 0);
  }
  for (int32_t step = 0; step < steps; ++step)
  {
    CHECK(
      generated.Find("PRESSURE", step) >= 0 && generated.Find("SWAT", step) >= 0 && generated.Find("SOIL", step) >= 0);
  }
  // As many tables a pass as their packed tables fit in one whole array.
  const uint64_t slots = uint64_t(h.hashTableSides[0]) * h.hashTableSides[1] * h.hashTableSides[2];
  const uint64_t group = std::max<uint64_t>(1, uint64_t(ni * nj * nk) / slots);
  const std::string json = Slurp(report);
  const std::size_t at = json.find("\"generator_passes\": ");
  CHECK(at != std::string::npos);
  const long passes = at == std::string::npos ? -1 : std::atol(json.c_str() + at + 20);
  CHECK(passes == static_cast<long>((tables + group - 1) / group));
  int64_t values = 0, finite = 0, wrong = 0;
  for (std::size_t t = 0; t < files.Tables().size(); ++t)
  {
    const PropertyTable& expected = files.Tables()[t];
    const int found = generated.Find(expected.name, expected.step);
    CHECK(found == static_cast<int>(t)); // same order too
    if (found < 0)
    {
      continue;
    }
    const PropertyTable& got = generated.Tables()[static_cast<std::size_t>(found)];
    CHECK(got.reportNumber == expected.reportNumber && got.days == expected.days);
    CHECK(SameValue(got.minimum, expected.minimum) && SameValue(got.maximum, expected.maximum));
    int64_t differ = Differences(generated.ReadPacked(static_cast<std::size_t>(found)), files.ReadPacked(t));
    for (int64_t k = 0; k < nk; ++k)
    {
      const std::vector<float> layer = files.ReadLayer(t, k);
      differ += Differences(generated.ReadLayer(static_cast<std::size_t>(found), k), layer);
      for (float v : layer)
      {
        finite += std::isfinite(v);
      }
      values += static_cast<int64_t>(layer.size());
    }
    if (differ)
    {
      std::fprintf(stderr, "%s step %d: %lld values differ\n", expected.name.c_str(), expected.step,
        static_cast<long long>(differ));
    }
    wrong += differ;
  }
  CHECK(wrong == 0);
  CHECK(finite > values / 4); // real values compared, not NaN with NaN
  const PropertyTable& poro = generated.Tables()[static_cast<std::size_t>(generated.Find("PORO", -1))];
  CHECK(poro.minimum > 0 && poro.maximum > poro.minimum && poro.maximum < 1);
  const int lastStep = generated.Find("SWAT", steps - 1);
  CHECK(lastStep >= 0 && generated.Tables()[static_cast<std::size_t>(lastStep)].reportNumber == steps &&
    generated.Tables()[static_cast<std::size_t>(lastStep)].days == 3650);
  std::printf("%s: %zu tables in %ld generator passes (%llu a pass); %lld layer values (%lld with a value) and "
              "the packed tables (%llu slots each) equal the files'\n",
    spec.c_str(), tables, passes, static_cast<unsigned long long>(group), static_cast<long long>(values),
    static_cast<long long>(finite), static_cast<unsigned long long>(slots));
  std::remove(report.c_str());
  return group;
}

void TestSpecParser()
{
  const SyntheticParameters plain = ParseSyntheticSpec("synth:40x30x5");
  CHECK(plain.nx == 40 && plain.ny == 30 && plain.nz == 5 && plain.seed == 1 && plain.steps == 0);
  const SyntheticParameters seeded = ParseSyntheticSpec("synth:2000x1500x100:18446744073709551615");
  CHECK(seeded.nx == 2000 && seeded.ny == 1500 && seeded.nz == 100 && seeded.seed == ~uint64_t(0));
  const SyntheticParameters stepped = ParseSyntheticSpec("synth:4x3x2:7:12");
  CHECK(stepped.seed == 7 && stepped.steps == 12);
  CHECK(IsSyntheticSpec("synth:4x3x2") && !IsSyntheticSpec("model.EGRID") && !IsSyntheticSpec("SYNTH:4x3x2"));
  for (const char* bad : { "synth:", "synth:40x30", "synth:40x30x", "synth:40x30x5:", "synth:40x30x5x",
         "synth:40x30x5:1:2:3", "synth:40x30x5:-1", "synth: 40x30x5", "synth:40x30x5:1 ", "model.EGRID" })
  {
    resmr_testing::ExpectError<std::invalid_argument>(
      bad, [&] { ParseSyntheticSpec(bad); }, { bad, "synth:NIxNJxNK[:SEED[:STEPS]]" });
  }
  // Well formed, but not a model the generator makes: the spec and the parameter named.
  resmr_testing::ExpectError<std::invalid_argument>(
    "zero layers", [&] { ParseSyntheticSpec("synth:40x30x0"); }, { "synth:40x30x0", "dimensions" });
  resmr_testing::ExpectError<std::invalid_argument>(
    "too many steps", [&] { ParseSyntheticSpec("synth:40x30x5:1:10001"); }, { "synth:40x30x5:1:10001", "steps" });
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 3)
  {
    std::fprintf(stderr, "usage: TestSyntheticProperties RESMR TEMP_DIR\n");
    return 2;
  }
  const std::string resmrTool = argv[1], temp = argv[2];
  mkdir(temp.c_str(), 0755);
  TestSpecParser();

  // Two models, written as files by resmr synth and named by a spec. Their hash tables hold
  // a little under and a little over half their cells: the spec's tables come two a pass
  // and one a pass.
  const std::string geometryPath = temp + "/synth.resmr";
  const std::string fromFiles = temp + "/files.resmrp", fromSpec = temp + "/spec.resmrp";
  CHECK(CompareWithFiles(resmrTool, temp, 160, 120, 10, 2, 1) >= 2);
  CHECK(CompareWithFiles(resmrTool, temp, 40, 30, 5, 7, 3) >= 1);

  // Again without steps into the same file: the INIT's tables replaced, the steps kept.
  CHECK(Run(resmrTool + " add-properties '" + geometryPath + "' synth:40x30x5:7 -o '" + fromSpec +
          "' 2>/dev/null >/dev/null") == 0);
  {
    const PropertyFile generated(fromSpec);
    CHECK(generated.Tables().size() == 10 + 3 * 3);
  }

  // Another grid, another seed (other active cells), a malformed spec: refused, nothing written.
  const std::string refused = temp + "/refused.resmrp";
  std::remove(refused.c_str());
  for (const char* bad : { "synth:40x30x6:7", "synth:40x30x5:8", "synth:40x30" })
  {
    CHECK(Run(resmrTool + " add-properties '" + geometryPath + "' " + bad + " -o '" + refused + "' 2>/dev/null") == 1);
    CHECK(!Exists(refused));
  }

  // The layer-by-layer writer refuses a table ended early or given too many layers.
  {
    const MultiresolutionFile geometry(geometryPath);
    const auto& dims = geometry.Header().dims;
    const std::vector<float> layer(static_cast<std::size_t>(dims[0] * dims[1]), 1.0f);
    PropertyFileWriter writer(refused, geometry);
    PropertyTable table;
    table.name = "ONES";
    const std::size_t early = writer.BeginTable(table);
    writer.AddLayer(early, layer.data());
    resmr_testing::ExpectError<std::invalid_argument>(
      "ended early", [&] { writer.EndTable(early); }, { "ONES", "after 1 of its 5 layers" });
    resmr_testing::ExpectError<std::invalid_argument>(
      "unknown handle", [&] { writer.AddLayer(early + 1, layer.data()); }, { "no open table" });
    resmr_testing::ExpectError<std::invalid_argument>("left open", [&] { writer.Commit(); }, { "ONES", "never ended" });
    for (int64_t k = 1; k < dims[2]; ++k)
    {
      writer.AddLayer(early, layer.data());
    }
    resmr_testing::ExpectError<std::invalid_argument>(
      "too many layers", [&] { writer.AddLayer(early, layer.data()); }, { "ONES", "more than its 5 layers" });
    writer.EndTable(early);
    writer.Commit();
    const PropertyFile ones(refused);
    CHECK(ones.Tables().size() == 1 && ones.Tables()[0].minimum == 1.0f && ones.Tables()[0].maximum == 1.0f);
  }

  for (const std::string& path : { fromFiles, fromSpec, refused, geometryPath })
  {
    std::remove(path.c_str());
  }
  for (const char* ext : { ".EGRID", ".INIT", ".UNRST" })
  {
    std::remove((temp + "/synth" + ext).c_str());
  }
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d checks failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("synthetic property tests passed\n");
  return 0;
}
