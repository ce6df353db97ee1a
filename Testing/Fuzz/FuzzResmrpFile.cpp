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
// the header. Expected outcomes: tables, or a resmr::MultiresolutionFileError (or another
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
/// A private, initially empty directory holding the input file (one per process).
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
    this->Path = this->Directory + "/input.resmrp";
  }
  ~InputFile()
  {
    std::remove(this->Path.c_str());
    rmdir(this->Directory.c_str());
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::string& Write(const std::vector<uint8_t>& bytes)
  {
    std::FILE* file = std::fopen(this->Path.c_str(), "wb");
    if (!file || (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file) != bytes.size()) ||
      std::fclose(file) != 0)
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
  const uint64_t perTable = 56 + 20 * (static_cast<uint64_t>(dims[2]) + 1);
  if (indexSize != file.Tables().size() * perTable)
  {
    BrokenInvariant("opened with " + std::to_string(file.Tables().size()) + " tables in an index of " +
      std::to_string(indexSize) + " bytes");
  }
  for (const auto& table : file.Tables())
  {
    bool sized = table.packed.raw == slots * 4;
    for (const auto& layer : table.layers)
    {
      sized = sized && layer.raw == static_cast<uint64_t>(dims[0] * dims[1]) * 4;
    }
    if (!sized)
    {
      BrokenInvariant("opened with table " + table.name + " of chunks the wrong size for its values");
    }
  }
}

/// Reads every table, packed and by layers; returns the number of parts refused.
int ReadEverything(const resmr::PropertyFile& file, const std::array<int64_t, 3>& dims, uint64_t slots,
  std::string& firstError)
{
  int refused = 0;
  for (std::size_t t = 0; t < file.Tables().size(); ++t)
  {
    const auto& table = file.Tables()[t];
    if (resmr_fuzz::InvariantsChecked() && table.layers.size() != static_cast<std::size_t>(dims[2]))
    {
      BrokenInvariant("table " + std::to_string(t) + " has " + std::to_string(table.layers.size()) + " layers");
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
      catch (const resmr::MultiresolutionFileError& error)
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
  static InputFile input;
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
    RESMR_FUZZ_OUTCOME("opened, " + std::to_string(file.Tables().size()) + " tables, " +
      std::to_string(refused) + " parts refused" + (refused ? ", first: " + firstError : std::string()));
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
    // expected: bad input reported as such (MultiresolutionFileError, or std::bad_alloc and
    // the like from the standard library)
    RESMR_FUZZ_OUTCOME(std::string("refused: ") + error.what());
  }
  return 0;
}

#ifdef RESMR_FUZZ_STANDALONE
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define RESMR_FUZZ_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define RESMR_FUZZ_SANITIZED 1
#endif

int main(int argc, char** argv)
{
#ifndef RESMR_FUZZ_SANITIZED
  // What libFuzzer's malloc limit does when fuzzing: an allocation of a size taken from the
  // file unchecked fails (std::bad_alloc, a finding) instead of filling the machine. Not
  // under ASan, which reserves terabytes of address space for its shadow memory.
  const rlimit limit{ rlim_t(2) << 30, rlim_t(2) << 30 };
  setrlimit(RLIMIT_AS, &limit);
#endif
  if (argc == 4 && std::string(argv[1]) == "--unpack")
  {
    std::string contents;
    if (!resmr_fuzz::ReadWholeFile(argv[2], contents))
    {
      std::fprintf(stderr, "cannot read %s\n", argv[2]);
      return 1;
    }
    const auto unpacked = resmr_fuzz::UnpackChunks(std::vector<uint8_t>(contents.begin(), contents.end()),
      resmr_fuzz::ResmrpLayout());
    std::FILE* out = std::fopen(argv[3], "wb");
    const bool ok = out && std::fwrite(unpacked.data(), 1, unpacked.size(), out) == unpacked.size();
    return out && std::fclose(out) == 0 && ok ? 0 : 1;
  }
  long count = 0;
  return resmr_fuzz::ReplayMain("FuzzResmrpFileReplay", argc, argv, count,
    [&](const std::string& path, const std::string& contents) {
      std::printf("%s (%zu bytes): ", path.c_str(), contents.size());
      std::fflush(stdout); // the name is out before a crash
      LastOutcome.clear();
      MustBeValid = path.substr(path.find_last_of('/') + 1).rfind("valid", 0) == 0;
      LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(contents.data()), contents.size());
      std::printf("%s\n", LastOutcome.substr(0, 400).c_str());
      ++count;
    });
}
#endif
