// EGRID + INIT open and restart step switch of resmr::ReadEclipseGrid / EclipseResults, next
// to the machine's sequential read speed of the same files from the page cache.
//
//   bench_egrid_load GRID.EGRID [RUNS=5] [SWITCHES=RUNS]
//
// Prints one JSON line per measurement:
// - "seqread": read() of EGRID + INIT (whole files, in 1 MiB and 16 MiB chunks into one
//   reused buffer, after a warm-up read so they come from the page cache); best of RUNS.
// - "seqread_fresh": the same files read whole into newly mapped memory of their size, with
//   4 KiB pages and with MADV_HUGEPAGE: what any loader keeping every byte pays at least
//   (page faults included); best of RUNS.
// - "load" (RUNS times): ReadEclipseGrid (FILEHEAD .. ENDGRID: COORD and ZCORN as doubles,
//   ACTNUM), the EclipseResults constructor (finds and indexes INIT and restarts) and every
//   INIT array EclipseResults lists (StaticArrays(): one value per cell or active cell) read
//   into its own per-cell array, float (REAL/DOUB) or int32 (INTE/LOGI), newly allocated as
//   a reader would. Each run's grid and arrays are freed before the next, so the peak RSS is
//   that of one load. Bytes = EGRID + INIT file sizes.
// - "switch" (SWITCHES times, after the first load, arrays kept): ReadDynamic of PRESSURE,
//   SWAT and SGAS (those present) for a step other than the one shown before, into per-cell
//   float arrays allocated (and touched) once beforehand, as a viewer that keeps its arrays
//   would. Steps cycle through every step; the first step is read once untimed. Reported
//   with the bytes of the three records in the file and of the whole step.
// BENCH_LOAD_ONLY=1 in the environment leaves out "seqread" and "seqread_fresh" (profiling).
// Exit status 1 (with a JSON "error") if anything throws.
#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseResults.h"
#include "LargeArrays.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

long long StatusBytes(const char* key)
{
  std::ifstream status("/proc/self/status");
  std::string line;
  const std::size_t length = std::char_traits<char>::length(key);
  while (std::getline(status, line))
  {
    if (line.compare(0, length, key) == 0)
    {
      return std::atoll(line.c_str() + length) * 1024; // "VmHWM:  123456 kB"
    }
  }
  return -1;
}

long long PeakRssBytes()
{
  const long long hwm = StatusBytes("VmHWM:");
  if (hwm >= 0)
  {
    return hwm;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<long long>(usage.ru_maxrss) * 1024;
}

long long MinorFaults()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

long long FileBytes(const std::string& path)
{
  struct stat info
  {
  };
  return stat(path.c_str(), &info) == 0 ? static_cast<long long>(info.st_size) : 0;
}

/// Reads the files whole with read() into one buffer of `chunk` bytes; returns seconds.
double ReadFiles(const std::vector<std::string>& paths, std::vector<char>& buffer)
{
  const auto start = Clock::now();
  for (const std::string& path : paths)
  {
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
    {
      throw std::runtime_error("cannot open " + path);
    }
    while (read(fd, buffer.data(), buffer.size()) > 0)
    {
    }
    close(fd);
  }
  return Since(start);
}

/// Reads the files whole into newly mapped memory of their size (what a loader that keeps
/// every byte must at least do): page faults included. `huge`: MADV_HUGEPAGE on it.
double ReadFilesFresh(const std::vector<std::string>& paths, bool huge)
{
  const auto start = Clock::now();
  for (const std::string& path : paths)
  {
    const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
    const std::size_t size = static_cast<std::size_t>(FileBytes(path));
    if (fd < 0 || size == 0)
    {
      throw std::runtime_error("cannot open " + path);
    }
    void* memory = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (memory == MAP_FAILED)
    {
      throw std::runtime_error("cannot map memory for " + path);
    }
    if (huge)
    {
      madvise(memory, size, MADV_HUGEPAGE);
    }
    char* data = static_cast<char*>(memory);
    std::size_t done = 0;
    ssize_t got = 0;
    while (done < size && (got = read(fd, data + done, std::min<std::size_t>(size - done, std::size_t(16) << 20))) > 0)
    {
      done += static_cast<std::size_t>(got);
    }
    close(fd);
    munmap(memory, size);
  }
  return Since(start);
}

std::string JsonEscape(const std::string& text)
{
  std::string out;
  for (char c : text)
  {
    if (c == '"' || c == '\\')
    {
      out += '\\';
      out += c;
    }
    else if (static_cast<unsigned char>(c) < 0x20)
    {
      out += ' ';
    }
    else
    {
      out += c;
    }
  }
  return out;
}

/// One INIT array read for the benchmark: float or int32, one value per cell.
struct CellValues
{
  std::string name;
  std::unique_ptr<float[]> real;
  std::unique_ptr<int32_t[]> integer;
};

struct Loaded
{
  resmr::EclipseGrid grid;
  std::unique_ptr<resmr::EclipseResults> results;
  std::vector<CellValues> arrays;
};

/// Bytes in the file of the step's whole record range and of the `names` records in it.
void StepBytes(const resmr::EclipseResults& results, std::size_t step, const std::vector<std::string>& names,
  long long& stepBytes, long long& arrayBytes)
{
  const resmr::EclipseReportStep& info = results.Steps()[step];
  const resmr::EclipseKeywordFile file(results.RestartPaths()[info.file]);
  const auto& records = file.Records();
  std::size_t first = 0, last = records.size();
  if (results.UnifiedRestart())
  {
    // Steps are in file order, each starting at its SEQNUM.
    std::size_t seen = 0;
    for (std::size_t r = 0; r < records.size(); ++r)
    {
      if (records[r].name == "SEQNUM")
      {
        if (seen == step)
        {
          first = r;
        }
        else if (seen == step + 1)
        {
          last = r;
          break;
        }
        ++seen;
      }
    }
  }
  const long long end = last < records.size() ? records[last].headerOffset : file.Size();
  stepBytes = end - records[first].headerOffset;
  arrayBytes = 0;
  for (const std::string& name : names)
  {
    for (std::size_t r = first; r < last; ++r)
    {
      if (records[r].name == name)
      {
        arrayBytes += records[r].endOffset - records[r].headerOffset;
        break;
      }
    }
  }
}
/// (c) Sequential read of `files` from the page cache (warm-up read, then best of `runs`),
/// and the same bytes read into fresh memory: the floor for a loader keeping them all.
void MeasureSequentialReads(const std::vector<std::string>& files, double loadBytes, int runs)
{
  for (const std::size_t chunk : { std::size_t(1) << 20, std::size_t(16) << 20 })
  {
    std::vector<char> buffer(chunk, 1);
    ReadFiles(files, buffer);
    double best = 1e30;
    for (int run = 0; run < std::max(runs, 3); ++run)
    {
      best = std::min(best, ReadFiles(files, buffer));
    }
    std::printf("{\"kind\": \"seqread\", \"chunk_bytes\": %zu, \"bytes\": %.0f, "
                "\"seconds\": %.6f, \"mb_per_s\": %.1f}\n",
      chunk, loadBytes, best, loadBytes / best / 1e6);
  }
  for (const bool huge : { false, true })
  {
    double best = 1e30;
    for (int run = 0; run < std::max(runs, 3); ++run)
    {
      best = std::min(best, ReadFilesFresh(files, huge));
    }
    std::printf("{\"kind\": \"seqread_fresh\", \"huge_pages\": %s, \"bytes\": %.0f, "
                "\"seconds\": %.6f, \"mb_per_s\": %.1f}\n",
      huge ? "true" : "false", loadBytes, best, loadBytes / best / 1e6);
  }
  std::fflush(stdout);
}

/// (a) EGRID + INIT open, `runs` times; returns the last load, kept for the step switches.
Loaded MeasureLoads(const std::string& path, double loadBytes, long long egridBytes, long long initBytes, int runs)
{
  Loaded kept;
  for (int run = 1; run <= runs; ++run)
  {
    kept = Loaded(); // free the previous run's grid and arrays first
    const long long faultsBefore = MinorFaults();
    const auto start = Clock::now();
    Loaded loaded;
    loaded.grid = resmr::ReadEclipseGrid(path);
    const double gridSeconds = Since(start);
    auto mark = Clock::now();
    loaded.results = std::make_unique<resmr::EclipseResults>(path, loaded.grid);
    const double indexSeconds = Since(mark);
    mark = Clock::now();
    const std::size_t cells = static_cast<std::size_t>(loaded.grid.deck.CellCount());
    for (const resmr::EclipseResultArray& array : loaded.results->StaticArrays())
    {
      CellValues values;
      values.name = array.name;
      if (array.IsInteger())
      {
        // As the VTK reader allocates its arrays: malloc'd, huge pages advised.
        values.integer.reset(new int32_t[cells]);
        resmr::AdviseHugePages(values.integer.get(), cells * sizeof(int32_t));
        loaded.results->ReadStatic(array.name, values.integer.get(), int32_t(0));
      }
      else
      {
        values.real.reset(new float[cells]);
        resmr::AdviseHugePages(values.real.get(), cells * sizeof(float));
        loaded.results->ReadStatic(array.name, values.real.get(), 0.0f);
      }
      loaded.arrays.push_back(std::move(values));
    }
    const double initSeconds = Since(mark);
    const double seconds = Since(start);
    const long long faults = MinorFaults() - faultsBefore;
    std::string names;
    for (const CellValues& values : loaded.arrays)
    {
      names += (names.empty() ? "\"" : ", \"") + JsonEscape(values.name) + "\"";
    }
    const auto& d = loaded.grid.deck.dims;
    std::printf("{\"kind\": \"load\", \"run\": %d, \"bytes\": %.0f, \"egrid_bytes\": %lld, "
                "\"init_bytes\": %lld, \"seconds\": %.6f, \"grid_seconds\": %.6f, "
                "\"index_seconds\": %.6f, \"init_seconds\": %.6f, \"mb_per_s\": %.1f, "
                "\"minor_faults\": %lld, \"peak_rss_bytes\": %lld, \"dims\": [%lld, %lld, %lld], "
                "\"cells\": %zu, \"active\": %lld, \"steps\": %zu, \"unified\": %s, "
                "\"init_arrays\": [%s]}\n",
      run, loadBytes, egridBytes, initBytes, seconds, gridSeconds, indexSeconds, initSeconds, loadBytes / seconds / 1e6,
      faults, PeakRssBytes(), static_cast<long long>(d[0]), static_cast<long long>(d[1]), static_cast<long long>(d[2]),
      cells, static_cast<long long>(loaded.grid.activeCells), loaded.results->Steps().size(),
      loaded.results->UnifiedRestart() ? "true" : "false", names.c_str());
    std::fflush(stdout);
    kept = std::move(loaded);
  }

  return kept;
}

/// (b) Step switches on a kept load: PRESSURE, SWAT and SGAS of the next step read into the
/// shown arrays, `switches` times.
void MeasureStepSwitches(const Loaded& kept, int switches)
{
  const resmr::EclipseResults& results = *kept.results;
  const std::size_t steps = results.Steps().size();
  if (steps < 2 || switches == 0)
  {
    return;
  }
  const std::size_t cells = static_cast<std::size_t>(kept.grid.deck.CellCount());
  std::vector<std::string> names;
  for (const char* name : { "PRESSURE", "SWAT", "SGAS" })
  {
    names.emplace_back(name);
  }
  std::vector<std::vector<float>> shown(names.size(), std::vector<float>(cells, 0.0f));
  const auto readStep = [&](std::size_t step) {
    int found = 0;
    for (std::size_t a = 0; a < names.size(); ++a)
    {
      found += results.ReadDynamic(step, names[a], shown[a].data(), 0.0f);
    }
    return found;
  };
  readStep(0); // the step shown before the first switch
  std::size_t current = 0;
  for (int s = 1; s <= switches; ++s)
  {
    const std::size_t next = (current + 1) % steps;
    long long stepBytes = 0, arrayBytes = 0;
    StepBytes(results, next, names, stepBytes, arrayBytes);
    const long long faultsBefore = MinorFaults();
    const auto start = Clock::now();
    const int found = readStep(next);
    const double seconds = Since(start);
    const long long faults = MinorFaults() - faultsBefore;
    std::printf("{\"kind\": \"switch\", \"switch\": %d, \"from\": %d, \"to\": %d, "
                "\"arrays\": %d, \"seconds\": %.6f, \"array_bytes\": %lld, \"step_bytes\": %lld, "
                "\"restart_file_bytes\": %lld, \"mb_per_s\": %.1f, \"minor_faults\": %lld, "
                "\"peak_rss_bytes\": %lld}\n",
      s, results.Steps()[current].reportNumber, results.Steps()[next].reportNumber, found, seconds, arrayBytes,
      stepBytes, FileBytes(results.RestartPaths()[results.Steps()[next].file]),
      static_cast<double>(arrayBytes) / seconds / 1e6, faults, PeakRssBytes());
    std::fflush(stdout);
    current = next;
  }
}

} // namespace

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: %s GRID.EGRID [RUNS=5] [SWITCHES=RUNS]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  const int switches = argc > 3 ? std::max(0, std::atoi(argv[3])) : runs;
  try
  {
    const std::string initPath = resmr::EclipseResults::FindInit(path);
    const long long egridBytes = FileBytes(path);
    const long long initBytes = initPath.empty() ? 0 : FileBytes(initPath);
    const double loadBytes = static_cast<double>(egridBytes + initBytes);
    // BENCH_LOAD_ONLY=1 leaves the references out (for profiling the loads alone).
    const char* loadOnlyVariable = std::getenv("BENCH_LOAD_ONLY");
    if (!(loadOnlyVariable && std::string(loadOnlyVariable) == "1"))
    {
      std::vector<std::string> files{ path };
      if (!initPath.empty())
      {
        files.push_back(initPath);
      }
      MeasureSequentialReads(files, loadBytes, runs);
    }
    const Loaded kept = MeasureLoads(path, loadBytes, egridBytes, initBytes, runs);
    MeasureStepSwitches(kept, switches);
  }
  catch (const std::exception& error)
  {
    std::printf("{\"kind\": \"error\", \"error\": \"%s\"}\n", JsonEscape(error.what()).c_str());
    return 1;
  }
  return 0;
}
