// Fuzz target for the .resmrp reader (PropertyFile: header, trailer, index) and its tables
// (ReadPacked and ReadLayer of every layer of every table).
//
// libFuzzer build (see run_fuzz.sh):
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I Core Core/*.cpp FuzzResmrpFile.cpp -llzo2
// Standalone replay build (ctest FuzzResmrpFile.SeedCorpus): compile with
// -DRESMR_FUZZ_STANDALONE; the executable runs the target over every file (or every file in
// every directory) named on its command line; `--unpack IN OUT` writes a valid file with its
// chunks unpacked (how seeds/resmrp/*.unpacked.resmrp are made).
//
// Per input: the checksums are made right again (FuzzResmrRepair.h: chunk CRCs, index CRC,
// trailer, header CRC; unpacked chunks compressed), the file is written to a private folder
// and opened, and every table read, packed and layer by layer, its values counted against
// the header. Expected outcomes: tables, or a resmr::FileFormatError (or another
// std::exception) for bad input, a table's failure costing that table only. Anything else --
// a crash, a sanitizer report, a hang, a runaway allocation or a broken invariant -- is a
// finding. Inputs whose name starts with "valid" must open and read without an error.
#include "FuzzReplay.h"
#include "FuzzResmrRepair.h"
#include "PropertyFile.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

namespace
{
#ifdef RESMR_FUZZ_STANDALONE
std::string LastOutcome;
bool MustBeValid = false; // the replayed file's name starts with "valid"
#define RESMR_FUZZ_OUTCOME(text) (LastOutcome = (text))
#else
constexpr bool MustBeValid = false;
#define RESMR_FUZZ_OUTCOME(text) ((void)0)
#endif

[[noreturn]] void BrokenInvariant(const std::string& what)
{
  resmr_fuzz::BrokenInvariant("FuzzResmrpFile", what);
}

/// What an opened file's index promises: as many tables as the header says fill it, each
/// chunk of the size its values call for.
void CheckIndex(const resmr::PropertyFile& file, const std::vector<uint8_t>& bytes, uint64_t slots)
{
  if (!resmr_fuzz::InvariantsChecked())
  {
    return;
  }
  const auto& dims = file.Dimensions();
  const uint64_t indexSize = resmr_fuzz::Load<uint64_t>(bytes, bytes.size() - resmr::IndexTrailerBytes + 8);
  const int64_t bands = file.Bands();
  const uint64_t perTable = 56 + 20 * (static_cast<uint64_t>(dims[2] * bands) + 1) + (file.HasBlockRanges() ? 40 : 0);
  if (indexSize != file.Tables().size() * perTable)
  {
    BrokenInvariant("opened with " + std::to_string(file.Tables().size()) + " tables in an index of " +
      std::to_string(indexSize) + " bytes");
  }
  for (std::size_t t = 0; t < file.Tables().size(); ++t)
  {
    const auto& table = file.Tables()[t];
    bool sized = table.packed.raw == slots * 4;
    for (int64_t n = 0; n < dims[2] * bands; ++n)
    {
      const int64_t b = n % bands, bi = b % file.BandsAlongI(), bj = b / file.BandsAlongI();
      const int64_t rows = std::min(file.BandRows(), dims[1] - bj * file.BandRows());
      const int64_t columns = std::min(file.BandColumns(), dims[0] - bi * file.BandColumns());
      sized = sized && file.LayerBand(t, n / bands, b).raw == static_cast<uint64_t>(columns * rows) * 4;
    }
    if (!sized)
    {
      BrokenInvariant("opened with table " + table.name + " of chunks the wrong size for its values");
    }
  }
}

/// Reads every table, packed and by layers; returns the number of parts refused.
int ReadEverything(
  const resmr::PropertyFile& file, const std::array<int64_t, 3>& dims, uint64_t slots, std::string& firstError)
{
  int refused = 0;
  for (std::size_t t = 0; t < file.Tables().size(); ++t)
  {
    if (resmr_fuzz::InvariantsChecked() && file.BandsAlongI() * file.BandColumns() < dims[0])
    {
      BrokenInvariant("table " + std::to_string(t) + ": bands of " + std::to_string(file.BandColumns()) +
        " columns do not cover " + std::to_string(dims[0]));
    }
    for (int64_t k = -1; k < dims[2]; ++k)
    {
      try
      {
        const auto values = k < 0 ? file.ReadPacked(t) : file.ReadLayer(t, k);
        const uint64_t expected = k < 0 ? slots : static_cast<uint64_t>(dims[0] * dims[1]);
        if (resmr_fuzz::InvariantsChecked() && values.size() != expected)
        {
          BrokenInvariant("table " + std::to_string(t) + " part " + std::to_string(k) + ": " +
            std::to_string(values.size()) + " values for " + std::to_string(expected));
        }
      }
      catch (const resmr::FileFormatError& error)
      {
        if (refused++ == 0)
        {
          firstError = error.what();
        }
      }
    }
  }
  return refused;
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size)
{
  static resmr_fuzz::ScratchInput input("input.resmrp");
  static const resmr_fuzz::FileLayout layout = resmr_fuzz::ResmrpLayout();
  const std::vector<uint8_t> bytes = resmr_fuzz::Repair(data, size, layout);
  const std::string& path = input.Write(bytes);
  try
  {
    const resmr::PropertyFile file(path);
    const std::array<int64_t, 3> dims = file.Dimensions();
    const auto& sides = file.HashTableSides();
    const uint64_t slots = uint64_t(sides[0]) * sides[1] * sides[2];
    CheckIndex(file, bytes, slots);
    std::string firstError;
    const int refused = ReadEverything(file, dims, slots, firstError);
    if (MustBeValid && refused > 0)
    {
      BrokenInvariant("a valid seed refused: " + firstError);
    }
    RESMR_FUZZ_OUTCOME("opened, " + std::to_string(file.Tables().size()) + " tables, " + std::to_string(refused) +
      " parts refused" + (refused ? ", first: " + firstError : std::string()));
  }
  catch (const std::bad_alloc&)
  {
    // A file of at most a few MiB never needs a GiB: a size taken from the file unchecked.
    BrokenInvariant("std::bad_alloc: an allocation beyond the file's means");
  }
  catch (const std::exception& error)
  {
    if (MustBeValid)
    {
      BrokenInvariant(std::string("a valid seed refused: ") + error.what());
    }
    // expected: bad input reported as such (FileFormatError, or std::bad_alloc and
    // the like from the standard library)
    RESMR_FUZZ_OUTCOME(std::string("refused: ") + error.what());
  }
  return 0;
}

#ifdef RESMR_FUZZ_STANDALONE
int main(int argc, char** argv)
{
  return resmr_fuzz::ResmrReplayMain(
    "FuzzResmrpFileReplay", argc, argv, resmr_fuzz::ResmrpLayout(), MustBeValid, LastOutcome, LLVMFuzzerTestOneInput);
}
#endif
