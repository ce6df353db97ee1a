// Parse throughput and peak memory of resmr::ParseGrdeclFile on one deck.
//
//   bench_grdecl_parse DECK [RUNS=3]
//
// Prints one JSON line per run: wall seconds of ParseGrdeclFile, MB/s (file bytes / s / 1e6),
// the output size (8 bytes per value in coord, zcorn, dx/dy/dz and every cell array) and the
// process peak RSS so far (VmHWM, bytes). Each run's deck is destroyed before the next one, so
// the peak is that of one parse. Exit status 1 (with a JSON "error") if parsing fails.
#include "Errors.h"
#include "GrdeclParser.h"

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>
#include <sys/stat.h>

namespace
{
long long PeakRssBytes()
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.rfind("VmHWM:", 0) == 0)
    {
      return std::atoll(line.c_str() + 6) * 1024; // "VmHWM:  123456 kB"
    }
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<long long>(usage.ru_maxrss) * 1024;
}

long long OutputBytes(const resmr::CornerPointModel& deck)
{
  std::size_t values = deck.coord.size() + deck.zcorn.size() + deck.dxv.size() + deck.dyv.size() + deck.dzv.size();
  for (const auto& array : deck.arrays)
  {
    values += array.values.size();
  }
  return static_cast<long long>(values * sizeof(double));
}

/// What a geometry-only loader keeps: COORD, ZCORN and ACTNUM.
long long GeometryBytes(const resmr::CornerPointModel& deck)
{
  std::size_t values = deck.coord.size() + deck.zcorn.size();
  if (const resmr::CellArray* actnum = deck.FindArray("ACTNUM"))
  {
    values += actnum->values.size();
  }
  return static_cast<long long>(values * sizeof(double));
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
} // namespace

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: %s DECK [RUNS=3]\n", argv[0]);
    return 2;
  }
  const std::string path = argv[1];
  const int runs = argc > 2 ? std::atoi(argv[2]) : 3;
  struct stat info
  {
  };
  if (stat(path.c_str(), &info) != 0)
  {
    std::fprintf(stderr, "cannot stat %s\n", path.c_str());
    return 2;
  }
  const double fileBytes = static_cast<double>(info.st_size);
  for (int run = 1; run <= runs; ++run)
  {
    try
    {
      const auto start = std::chrono::steady_clock::now();
      resmr::CornerPointModel deck = resmr::ParseGrdeclFile(path);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::size_t faces = 0;
      for (const auto& fault : deck.faults)
      {
        faces += fault.faces.size();
      }
      std::printf("{\"tool\": \"resmr\", \"run\": %d, \"file_bytes\": %.0f, \"seconds\": %.3f, "
                  "\"mb_per_s\": %.1f, \"output_bytes\": %lld, \"geometry_bytes\": %lld, "
                  "\"peak_rss_bytes\": %lld, "
                  "\"cells\": %lld, \"arrays\": %zu, \"fault_faces\": %zu}\n",
        run, fileBytes, seconds, fileBytes / seconds / 1e6, OutputBytes(deck), GeometryBytes(deck), PeakRssBytes(),
        static_cast<long long>(deck.CellCount()), deck.arrays.size(), faces);
      std::fflush(stdout);
    }
    catch (const std::exception& error)
    {
      std::printf("{\"tool\": \"resmr\", \"run\": %d, \"error\": \"%s\"}\n", run, JsonEscape(error.what()).c_str());
      return 1;
    }
  }
  return 0;
}
