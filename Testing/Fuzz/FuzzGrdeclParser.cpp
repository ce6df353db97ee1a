// Fuzz target for the GRDECL parser and the corner-point geometry built from its decks.
//
// libFuzzer build (see run_fuzz.sh):
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I Core Core/*.cpp FuzzGrdeclParser.cpp
// Standalone replay build (ctest FuzzGrdeclParser.SeedCorpus): compile with
// -DRESMR_FUZZ_STANDALONE; the executable runs the target over every file (or every file in
// every directory) named on its command line.
//
// Expected outcomes: a parsed deck with its geometry, or a resmr::InputError (or another
// std::exception) for bad input. Anything else -- a crash, a sanitizer report, a hang or a
// runaway allocation -- is a finding.
#include "CornerPointGeometry.h"
#include "Errors.h"
#include "FuzzReplay.h"
#include "GrdeclParser.h"

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
#include <sys/stat.h>
#include <unistd.h>

namespace
{
/// A private, initially empty directory holding only the input file, so that fuzzed INCLUDE
/// / IMPORT names relative to the deck find nothing but the deck itself.
class InputFile
{
public:
  InputFile()
  {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/resmr-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data()))
    {
      std::perror("mkdtemp");
      std::abort();
    }
    this->Directory = pattern;
    // A fixed, dictionary-friendly name: the fuzzer can learn `INCLUDE 'input.grdecl' /`.
    this->Path = this->Directory + "/input.grdecl";
  }
  ~InputFile()
  {
    std::remove(this->Path.c_str());
    rmdir(this->Directory.c_str());
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::string& Write(const uint8_t* data, std::size_t size)
  {
    std::FILE* file = std::fopen(this->Path.c_str(), "wb");
    if (!file || (size > 0 && std::fwrite(data, 1, size, file) != size) || std::fclose(file) != 0)
    {
      std::perror(this->Path.c_str());
      std::abort();
    }
    return this->Path;
  }

private:
  std::string Directory;
  std::string Path;
};

#ifdef RESMR_FUZZ_STANDALONE
std::string LastOutcome; // what the last input did, for the replay log
#define RESMR_FUZZ_OUTCOME(text) (LastOutcome = (text))
#else
#define RESMR_FUZZ_OUTCOME(text) ((void)0)
#endif

InputFile& TheInputFile()
{
  static InputFile file; // one per process, reused across iterations
  return file;
}

/// Absolute INCLUDE paths are followed by design; keep the fuzzer away from device and
/// kernel files (/dev/urandom would never end, /dev/stdin would block). Reading an ordinary
/// file elsewhere is harmless: the parser only reads.
bool NamesSpecialFiles(const uint8_t* data, std::size_t size)
{
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const char* prefix : { "/dev/", "/proc/", "/sys/", "/run/" })
  {
    if (text.find(prefix) != std::string_view::npos)
    {
      return true;
    }
  }
  return false;
}

[[noreturn]] void BrokenInvariant(const std::string& what)
{
  resmr_fuzz::BrokenInvariant("FuzzGrdeclParser", what);
}
using resmr_fuzz::InvariantsChecked;

void CheckDeck(const resmr::CornerPointModel& deck)
{
  if (!InvariantsChecked())
  {
    return;
  }
  const auto& d = deck.dims;
  if (d[0] <= 0 || d[1] <= 0 || d[2] <= 0)
  {
    BrokenInvariant("parsed deck has no dimensions");
  }
  const auto n = static_cast<std::size_t>(deck.CellCount());
  for (const resmr::CellArray& array : deck.arrays)
  {
    if (array.values.size() != n)
    {
      BrokenInvariant("array " + array.name + " has " + std::to_string(array.values.size()) + " values for " +
        std::to_string(n) + " cells");
    }
  }
  if (!deck.coord.empty() && deck.coord.size() != static_cast<std::size_t>(6 * (d[0] + 1) * (d[1] + 1)))
  {
    BrokenInvariant("COORD has " + std::to_string(deck.coord.size()) + " values");
  }
  if (!deck.zcorn.empty() && deck.zcorn.size() != 8 * n)
  {
    BrokenInvariant("ZCORN has " + std::to_string(deck.zcorn.size()) + " values");
  }
  const std::vector<double>* vectors[3] = { &deck.dxv, &deck.dyv, &deck.dzv };
  for (int axis = 0; axis < 3; ++axis)
  {
    if (!vectors[axis]->empty() && vectors[axis]->size() != static_cast<std::size_t>(d[axis]))
    {
      BrokenInvariant(std::string("D") + "XYZ"[axis] + "V has " + std::to_string(vectors[axis]->size()) +
        " values for " + std::to_string(d[axis]) + " cells along the axis");
    }
  }
  for (const resmr::Fault& fault : deck.faults)
  {
    for (const resmr::FaultFace& face : fault.faces)
    {
      for (int axis = 0; axis < 3; ++axis)
      {
        const int32_t lo = face.box[2 * axis], hi = face.box[2 * axis + 1];
        if (lo < 0 || lo > hi || hi >= d[axis])
        {
          BrokenInvariant("fault " + fault.name + " box " + std::to_string(lo) + "-" + std::to_string(hi) +
            " is outside the grid along axis " + std::to_string(axis));
        }
      }
      if (face.face < resmr::FaultFace::IMinus || face.face > resmr::FaultFace::KPlus)
      {
        BrokenInvariant("fault " + fault.name + " has face " + std::to_string(int(face.face)));
      }
    }
  }
}

/// What the reader does with fault faces: the corners of every cell in each box (capped).
void VisitFaultCells(const resmr::CornerPointModel& deck, const resmr::CornerPointGeometry& geometry)
{
  int64_t budget = 100000;
  double corners[8][3];
  for (const resmr::Fault& fault : deck.faults)
  {
    for (const resmr::FaultFace& face : fault.faces)
    {
      for (int64_t k = face.box[4]; k <= face.box[5]; ++k)
      {
        for (int64_t j = face.box[2]; j <= face.box[3]; ++j)
        {
          for (int64_t i = face.box[0]; i <= face.box[1]; ++i)
          {
            if (--budget < 0)
            {
              return;
            }
            geometry.CellCorners(i, j, k, corners);
          }
        }
      }
    }
  }
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size)
{
  if (NamesSpecialFiles(data, size))
  {
    RESMR_FUZZ_OUTCOME("names a device or kernel file, skipped");
    return -1; // not added to the corpus
  }
  const std::string& path = TheInputFile().Write(data, size);
  resmr::GrdeclParseOptions options;
  options.maxCells = 2'000'000; // reject huge dimensions quickly
  try
  {
    resmr::CornerPointModel deck = resmr::ParseGrdeclFile(path, options);
    CheckDeck(deck);
    resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(deck, true);
    VisitFaultCells(deck, geometry);
    const resmr::CornerPointGeometry::SharedCorners shared = geometry.BuildSharedCorners();
    // Every cell corner must name a point.
    const std::size_t points = shared.points.size() / 3;
    for (const int64_t id : shared.cellPoints)
    {
      if (id < 0 || static_cast<std::size_t>(id) >= points)
      {
        BrokenInvariant(
          "BuildSharedCorners: corner point id " + std::to_string(id) + " outside [0, " + std::to_string(points) + ")");
      }
    }
    RESMR_FUZZ_OUTCOME(
      "parsed, " + std::to_string(geometry.CellCount()) + " cells, " + std::to_string(points) + " shared points");
  }
  catch (const resmr::InputError& error)
  {
    // expected: bad input reported as such
    RESMR_FUZZ_OUTCOME(std::string("InputError: ") + error.what());
  }
  catch (const std::exception& error)
  {
    // expected too: e.g. std::bad_alloc, std::out_of_range from the standard library
    RESMR_FUZZ_OUTCOME(std::string("std::exception: ") + error.what());
  }
  return 0;
}

#ifdef RESMR_FUZZ_STANDALONE
namespace
{
void RunOne(const std::string& path, const std::string& contents, long& count)
{
  std::printf("%s (%zu bytes): ", path.c_str(), contents.size());
  std::fflush(stdout); // the name is out before a crash
  LastOutcome.clear();
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(contents.data()), contents.size());
  std::printf("%s\n", LastOutcome.substr(0, 300).c_str());
  ++count;
}
} // namespace

int main(int argc, char** argv)
{
  long count = 0;
  return resmr_fuzz::ReplayMain("FuzzGrdeclParserReplay", argc, argv, count,
    [&](const std::string& path, const std::string& contents) { RunOne(path, contents, count); });
}
#endif
