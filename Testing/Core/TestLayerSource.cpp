// Streaming grid input of the hierarchy builder (paper Sec. 4.2: the model is read layer by
// layer, never held whole): OpenLayerSource on every real EGRID/FEGRID and deck of the shared
// data gives exactly the layers and map placement (MAPAXES, units) of the in-memory path
// (ReadCornerPointModel, FromDeck, CornerPointLayerSource); decks with ACTNUM/DZ edits match too; corrupt files and the
// refused COPY into a spooled array fail with InputError naming file and keyword; spool files
// never show in the folder.
#include "CoreTesting.h"
#include "CornerPointGeometry.h"
#include "CornerPointModel.h"
#include "EclipseKeywordFile.h"
#include "Errors.h"
#include "LayerSource.h"

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace
{
std::string Directory; // temporary folder of this run
std::string SpoolDirectory;

int EntriesIn(const std::string& folder)
{
  int count = 0;
  if (DIR* dir = opendir(folder.c_str()))
  {
    while (dirent* entry = readdir(dir))
    {
      count += std::strcmp(entry->d_name, ".") != 0 && std::strcmp(entry->d_name, "..") != 0;
    }
    closedir(dir);
  }
  return count;
}

int MapAxesModels = 0; ///< models whose streamed source gives MAPAXES

bool SameBits(const void* a, const void* b, std::size_t bytes)
{
  return bytes == 0 || std::memcmp(a, b, bytes) == 0;
}

/// Streams `path` both ways and compares; returns false if the in-memory path rejects it
/// (then the streaming one must too).
bool CompareWithInMemory(const std::string& path)
{
  std::string memoryError, streamError;
  resmr::CornerPointModel deck;
  std::vector<bool> flags;
  std::unique_ptr<resmr::CornerPointGeometry> geometry;
  std::unique_ptr<resmr::CornerPointLayerSource> memory;
  try
  {
    resmr::ReadCornerPointModel(path, deck, flags);
    geometry.reset(new resmr::CornerPointGeometry(resmr::CornerPointGeometry::FromDeck(deck, false)));
    memory.reset(new resmr::CornerPointLayerSource(*geometry, flags, path, deck.Placement()));
  }
  catch (const resmr::InputError& error)
  {
    memoryError = error.what();
  }
  int64_t layers = 0;
  try
  {
    auto stream = resmr::OpenLayerSource(path, SpoolDirectory);
    CHECK(EntriesIn(SpoolDirectory) == 0); // spool files are unlinked at once
    if (memory)
    {
      CHECK(stream->Dims() == memory->Dims());
      CHECK(stream->Name() == path);
      CHECK(stream->Coord().size() == memory->Coord().size() &&
        SameBits(stream->Coord().data(), memory->Coord().data(), 8 * memory->Coord().size()));
      const resmr::MapPlacement a = stream->Placement(), b = memory->Placement();
      CHECK(a.hasMapAxes == b.hasMapAxes && a.gridUnitIsMap == b.gridUnitIsMap && a.mapUnits == b.mapUnits &&
        a.gridUnit == b.gridUnit && a.mapAxes.origin == b.mapAxes.origin &&
        a.mapAxes.xAxisPoint == b.mapAxes.xAxisPoint && a.mapAxes.yAxisPoint == b.mapAxes.yAxisPoint);
      MapAxesModels += a.hasMapAxes ? 1 : 0;
    }
    std::vector<float> z1, z2;
    std::vector<uint8_t> a1, a2;
    for (;;)
    {
      const bool more = stream->Next(z1, a1);
      if (!memory)
      {
        if (!more)
        {
          break;
        }
        continue;
      }
      const bool expected = memory->Next(z2, a2);
      CHECK(more == expected);
      if (!more || !expected)
      {
        break;
      }
      ++layers;
      const bool same = z1.size() == z2.size() && SameBits(z1.data(), z2.data(), 4 * z1.size()) && a1 == a2;
      if (!same)
      {
        std::fprintf(stderr, "%s: layer %lld differs (depths %s, active flags %s)\n", path.c_str(),
          static_cast<long long>(layers), z1 == z2 ? "same" : "differ", a1 == a2 ? "same" : "differ");
      }
      CHECK(same);
    }
    if (memory)
    {
      CHECK(layers == memory->Dims()[2]);
    }
  }
  catch (const resmr::InputError& error)
  {
    streamError = error.what();
  }
  if (memoryError.empty() != streamError.empty())
  {
    std::fprintf(
      stderr, "%s: in memory: '%s', streamed: '%s'\n", path.c_str(), memoryError.c_str(), streamError.c_str());
  }
  CHECK(memoryError.empty() == streamError.empty());
  CHECK(EntriesIn(SpoolDirectory) == 0);
  return memoryError.empty();
}

bool IsGridFile(const std::string& file)
{
  std::string upper = file;
  for (char& c : upper)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  for (const char* ending : { ".EGRID", ".FEGRID", ".DATA", ".GRDECL", ".BGRDECL", ".GRID" })
  {
    const std::size_t n = std::strlen(ending);
    if (upper.size() > n && upper.compare(upper.size() - n, n, ending) == 0)
    {
      return true;
    }
  }
  return false;
}

void TestRealModels(const std::string& data)
{
  std::ifstream list(data + "/reference-counts.jsonl");
  CHECK(list.good());
  std::string line;
  int compared = 0, rejected = 0;
  while (std::getline(list, line))
  {
    const std::string key = "\"file\": \"";
    const std::size_t at = line.find(key);
    if (at == std::string::npos)
    {
      continue;
    }
    const std::size_t start = at + key.size();
    const std::string file = line.substr(start, line.find('"', start) - start);
    if (!IsGridFile(file))
    {
      continue;
    }
    (CompareWithInMemory(data + "/" + file) ? compared : rejected)++;
  }
  std::printf("  %d real models identical layer by layer (%d with MAPAXES), %d rejected by both paths\n", compared,
    MapAxesModels, rejected);
  CHECK(compared >= 60);
  CHECK(MapAxesModels >= 5);
}

std::string ReadAll(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

void WriteAll(const std::string& path, const std::string& bytes)
{
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

void Drain(resmr::LayerSource& source)
{
  std::vector<float> zcorn;
  std::vector<uint8_t> active;
  while (source.Next(zcorn, active))
  {
  }
}

void TestCorruptEgrid(const std::string& data)
{
  const std::string original = data + "/brugge/Real0/BRUGGE_0000.EGRID";
  const std::string bytes = ReadAll(original);
  const resmr::EclipseKeywordFile file(original);
  const resmr::EclipseRecord* zcorn = file.Find("ZCORN");
  CHECK(zcorn && zcorn->standardBlocks);
  if (!zcorn)
  {
    return;
  }
  // Cut in the middle of ZCORN: refused when opened, naming the file and keyword.
  const std::string truncated = Directory + "/TRUNCATED.EGRID";
  WriteAll(truncated, bytes.substr(0, static_cast<std::size_t>((zcorn->dataOffset + zcorn->endOffset) / 2)));
  resmr_testing::ExpectError<resmr::InputError>("truncated EGRID",
    [&] { resmr::OpenLayerSource(truncated, SpoolDirectory); }, { truncated, "keyword ZCORN", "truncated" });

  // A data record's end marker broken deep inside ZCORN: found when that layer is read.
  const int64_t blockBytes = 1000 * 4 + 8;
  const int64_t block = (zcorn->endOffset - zcorn->dataOffset) / blockBytes * 3 / 4;
  std::string broken = bytes;
  broken[static_cast<std::size_t>(zcorn->dataOffset + block * blockBytes + blockBytes - 1)] ^= 0x40;
  const std::string marker = Directory + "/MARKER.EGRID";
  WriteAll(marker, broken);
  resmr_testing::ExpectError<resmr::InputError>("broken marker",
    [&] {
      auto source = resmr::OpenLayerSource(marker, SpoolDirectory);
      Drain(*source);
    },
    { marker, "keyword ZCORN", "end marker" });

  // A NaN depth in the last layer: the value's place named, as ReadEclipseGrid names it.
  std::string nan = bytes;
  const int64_t value = zcorn->count - 5; // 0-based, in the last data record
  const int64_t offset = zcorn->dataOffset + (value / 1000) * blockBytes + 4 + (value % 1000) * 4;
  const unsigned char quiet[4] = { 0x7f, 0xc0, 0, 0 };
  std::memcpy(&nan[static_cast<std::size_t>(offset)], quiet, 4);
  const std::string nanPath = Directory + "/NAN.EGRID";
  WriteAll(nanPath, nan);
  resmr_testing::ExpectError<resmr::InputError>("NaN depth",
    [&] {
      auto source = resmr::OpenLayerSource(nanPath, SpoolDirectory);
      Drain(*source);
    },
    { nanPath, "keyword ZCORN", "value " + std::to_string(value + 1) + " is not finite" });
  CompareWithInMemory(nanPath); // both refuse
}

const char* const CornerPointGrid = R"(SPECGRID
 3 2 2 1 F /
COORD
 0 0 0  0 0 10   1 0 0  1 0 10   2 0 0  2 0 10   3 0 0  3 0 10
 0 1 0  0 1 10   1 1 0  1 1 10   2 1 0  2 1 10   3 1 0  3 1 10
 0 2 0  0 2 10   1 2 0  1 2 10   2 2 0  2 2 10   3 2 0  3 2 10 /
ZCORN
 24*1.25 24*2.5 24*2.5 24*3.0000001 /
)";

void TestDeckEdits()
{
  // ACTNUM given, then edited by BOX, EQUALS (box), MULTIPLY, ADD and COPY from another
  // spooled array; properties and their edits are dropped.
  const std::string edited = Directory + "/EDITED.grdecl";
  WriteAll(edited, std::string(CornerPointGrid) + R"(ACTNUM
 12*1 /
BOX
 1 2 1 1 2 2 /
ACTNUM
 0 0 /
ENDBOX
EQUALS
 'ACTNUM' 0 3 3 2 2 1 1 /
 'PORO' 0.25 /
/
MULTIPLY
 'ACTNUM' 2 1 1 2 2 1 2 /
 'PORO' 2 /
/
ADD
 'ACTNUM' -2 1 1 2 2 2 2 /
/
COPY
 'PORO' 'NTG' /
/
PERMX
 12*100 /
)");
  CHECK(CompareWithInMemory(edited));

  // ACTNUM edited by COPYBOX, MINVALUE, MAXVALUE, OPERATE and EQUALREG (no MULTNUM: region 1
  // everywhere), among keywords the viewer skips and a local grid whose arrays are not read.
  const std::string more = Directory + "/MORE_EDITS.grdecl";
  WriteAll(more, std::string(CornerPointGrid) + R"(ACTNUM
 1 0 1 1 1 1 0 1 1 1 1 1 /
COPYBOX
 ACTNUM 1 3 1 2 1 1  1 3 1 2 2 2 /
/
MAXVALUE
 ACTNUM 1 /
/
MINVALUE
 ACTNUM 0 /
/
OPERATE
 ACTNUM 3 3 2 2 2 2 MULTX ACTNUM 0 /
/
EQUALREG
 ACTNUM 1 1 M 3 3 1 1 1 1 /
/
MULTFLT
 'F1' 0.5 /
/
CARFIN
 'L1' 1 1 1 1 1 1 2 2 2 /
ACTNUM
 8*0 /
ENDFIN
EQUALS
 TRANX 0 /
/
)");
  CHECK(CompareWithInMemory(more));
  {
    // EQUALREG leaves every cell active here (region 1 is the whole grid); the source of the
    // stream saw the deck's warnings.
    auto source = resmr::OpenLayerSource(more, SpoolDirectory);
    const std::vector<std::string> warnings = source->Warnings();
    CHECK(warnings.size() == 3);
  }
  // By region when MULTNUM is given: resmr build does not keep region arrays, so refused.
  const std::string byRegion = Directory + "/BY_REGION.grdecl";
  WriteAll(byRegion, std::string(CornerPointGrid) + "MULTNUM\n 12*1 /\nEQUALREG\n ACTNUM 0 1 M /\n/\n");
  resmr_testing::ExpectError<resmr::InputError>("EQUALREG on ACTNUM",
    [&] { resmr::OpenLayerSource(byRegion, SpoolDirectory); },
    { byRegion + ":", "keyword EQUALREG", "ACTNUM", "region" });

  // A Cartesian deck: DX/DY/DZ/TOPS, TOPS for the top layer only, a DZ edit in a box.
  const std::string cartesian = Directory + "/CARTESIAN.DATA";
  WriteAll(cartesian, R"(RUNSPEC
DIMENS
 4 3 3 /
GRID
DX
 36*10 /
DY
 36*20 /
DZ
 36*2.5 /
TOPS
 1000 1001 1002 1003 1000 1001 1002 1003 1000 1001 1002 1003 /
EQUALS
 'DZ' 4 2 3 1 2 2 3 /
 'ACTNUM' 1 /
/
ACTNUM
 35*1 0 /
COPY
 'DZ' 'DX' 1 1 1 1 1 1 /
/
PORO
 36*0.2 /
)");
  CHECK(CompareWithInMemory(cartesian));

  // COPY of a dropped property into ACTNUM: refused, naming file, line and keyword.
  const std::string refused = Directory + "/COPY.grdecl";
  WriteAll(refused, std::string(CornerPointGrid) + "PORO\n 12*0.3 /\nCOPY\n 'PORO' 'ACTNUM' /\n/\n");
  resmr_testing::ExpectError<resmr::InputError>("COPY into ACTNUM",
    [&] { resmr::OpenLayerSource(refused, SpoolDirectory); }, { refused + ":", "keyword COPY", "ACTNUM" });
  CHECK(EntriesIn(SpoolDirectory) == 0);

  // A spool folder that does not exist yet is made (the builder's scratch folder).
  const std::string fresh = Directory + "/fresh-scratch";
  {
    auto source = resmr::OpenLayerSource(edited, fresh);
    Drain(*source);
  }
  CHECK(EntriesIn(fresh) == 0);
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: TestLayerSource DATA_DIR\n");
    return 2;
  }
  char pattern[] = "/tmp/resmr-layer-test-XXXXXX";
  if (!mkdtemp(pattern))
  {
    return 2;
  }
  Directory = pattern;
  SpoolDirectory = Directory + "/spool";
  std::system(("mkdir -p '" + SpoolDirectory + "'").c_str());
  const std::string data = argv[1];
  const std::vector<std::pair<const char*, std::function<void()>>> tests = { { "real models",
                                                                               [&] { TestRealModels(data); } },
    { "corrupt egrid", [&] { TestCorruptEgrid(data); } }, { "deck edits", TestDeckEdits } };
  const bool passed = resmr_testing::RunNamedTests(tests);
  std::system(("rm -rf '" + Directory + "'").c_str());
  return passed ? 0 : 1;
}
