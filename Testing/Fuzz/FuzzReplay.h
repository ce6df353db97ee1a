// Shared by the fuzz targets: invariant reporting, and the replay driver of their
// standalone builds (-DRESMR_FUZZ_STANDALONE), which runs a target over every file, or
// every file in every directory, named on the command line, so ctest replays seeds and
// past findings without libFuzzer.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <dirent.h>
#include <functional>
#include <string>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define RESMR_FUZZ_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define RESMR_FUZZ_SANITIZED 1
#endif

namespace resmr_fuzz
{

/// A finding no sanitizer sees: the parsed data breaks a promise its consumers rely on.
[[noreturn]] inline void BrokenInvariant(const char* target, const std::string& what)
{
  std::fprintf(stderr, "==%s== broken invariant: %s\n", target, what.c_str());
  std::fflush(stderr);
  std::abort();
}

/// RESMR_FUZZ_NO_INVARIANTS=1 skips the invariant checks, to see what broken data does
/// downstream.
inline bool InvariantsChecked()
{
  static const bool checked = [] {
    const char* value = std::getenv("RESMR_FUZZ_NO_INVARIANTS");
    return !(value && *value && std::strcmp(value, "0") != 0);
  }();
  return checked;
}

inline bool ReadWholeFile(const std::string& path, std::string& contents)
{
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file)
  {
    return false;
  }
  contents.clear();
  char buffer[1 << 16];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file)) > 0)
  {
    contents.append(buffer, got);
  }
  const bool ok = !std::ferror(file);
  std::fclose(file);
  return ok;
}

using InputRunner = std::function<void(const std::string& path, const std::string& contents)>;

/// Calls `run` for every file at or under `path` (hidden names skipped); returns the number
/// of paths that could not be read.
inline int ForEachInput(const char* tool, const std::string& path, const InputRunner& run)
{
  struct stat info;
  if (stat(path.c_str(), &info) != 0)
  {
    std::fprintf(stderr, "%s: cannot stat %s\n", tool, path.c_str());
    return 1;
  }
  if (S_ISDIR(info.st_mode))
  {
    DIR* dir = opendir(path.c_str());
    if (!dir)
    {
      std::fprintf(stderr, "%s: cannot open directory %s\n", tool, path.c_str());
      return 1;
    }
    int failures = 0;
    while (const dirent* entry = readdir(dir))
    {
      const std::string name = entry->d_name;
      if (name[0] != '.')
      {
        failures += ForEachInput(tool, path + "/" + name, run);
      }
    }
    closedir(dir);
    return failures;
  }
  std::string contents;
  if (!ReadWholeFile(path, contents))
  {
    std::fprintf(stderr, "%s: cannot read %s\n", tool, path.c_str());
    return 1;
  }
  run(path, contents);
  return 0;
}

/// The file an input is written to, alone in a private directory made for this process and
/// removed with it; reused from one input to the next.
class ScratchInput
{
public:
  explicit ScratchInput(const std::string& name)
  {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/resmr-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data()))
    {
      std::perror("mkdtemp");
      std::abort();
    }
    this->Directory = pattern;
    this->Path = this->Directory + "/" + name;
  }
  ~ScratchInput()
  {
    std::remove(this->Path.c_str());
    rmdir(this->Directory.c_str());
  }
  ScratchInput(const ScratchInput&) = delete;
  ScratchInput& operator=(const ScratchInput&) = delete;

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

/// What libFuzzer's malloc and RSS limits do when fuzzing, for the replay: an allocation of a
/// size taken from the input unchecked fails (std::bad_alloc) instead of filling the machine.
/// Not under ASan, which reserves terabytes of address space for its shadow memory.
inline void LimitAddressSpace(unsigned gibibytes)
{
#ifndef RESMR_FUZZ_SANITIZED
  const rlimit limit{ rlim_t(gibibytes) << 30, rlim_t(gibibytes) << 30 };
  setrlimit(RLIMIT_AS, &limit);
#else
  (void)gibibytes;
#endif
}

/// The replay main: every argument through ForEachInput; `count` is incremented by the
/// runner. Prints the tally ctest checks and fails when nothing ran or a path was unreadable.
inline int ReplayMain(const char* tool, int argc, char** argv, long& count, const InputRunner& run)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: %s FILE_OR_DIRECTORY...\n", argv[0]);
    return 2;
  }
  int failures = 0;
  for (int i = 1; i < argc; ++i)
  {
    failures += ForEachInput(tool, argv[i], run);
  }
  std::printf("%s: ran %ld inputs, %d unreadable paths\n", tool, count, failures);
  return failures == 0 && count > 0 ? 0 : 1;
}

} // namespace resmr_fuzz
