// Streams a synthetic model layer by layer through the Core API (SyntheticLayerStream), with
// no file: what the hierarchy builder will consume for models beyond one EGRID (1 billion
// cells and more). Prints one JSON line: cells, seconds, cells per second, peak RSS, and a
// checksum of every ZCORN value and cell state (so the work cannot be optimised away).
//
// usage: bench_synth_stream NX NY NZ [SEED]
#include "SyntheticReservoir.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sys/resource.h>

int main(int argc, char** argv)
{
  if (argc < 4)
  {
    std::fprintf(stderr, "usage: bench_synth_stream NX NY NZ [SEED]\n");
    return 2;
  }
  resmr::SyntheticParameters parameters;
  parameters.nx = std::atoll(argv[1]);
  parameters.ny = std::atoll(argv[2]);
  parameters.nz = std::atoll(argv[3]);
  parameters.seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1;
  try
  {
    const auto start = std::chrono::steady_clock::now();
    const resmr::SyntheticReservoir model(parameters);
    const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    resmr::SyntheticLayerStream stream(model);
    resmr::SyntheticLayer layer;
    uint64_t checksum = 0;
    while (stream.Next(layer))
    {
      for (float value : layer.zcorn)
      {
        uint32_t bits;
        std::memcpy(&bits, &value, 4);
        checksum = checksum * 1099511628211ull + bits;
      }
      for (resmr::SyntheticCellState state : layer.state)
      {
        checksum += static_cast<uint64_t>(state);
      }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    struct rusage usage;
    getrusage(RUSAGE_SELF, &usage);
    const resmr::SyntheticStatistics& s = stream.Statistics();
    std::printf("{\"dims\": [%lld, %lld, %lld], \"cells\": %lld, \"active\": %lld, \"setup_seconds\": %.3f, "
                "\"seconds\": %.3f, \"cells_per_second\": %.0f, \"peak_rss_mb\": %.1f, \"checksum\": \"%016llx\"}\n",
      static_cast<long long>(parameters.nx), static_cast<long long>(parameters.ny),
      static_cast<long long>(parameters.nz), static_cast<long long>(s.cells), static_cast<long long>(s.active), setup,
      seconds, static_cast<double>(s.cells) / seconds, usage.ru_maxrss / 1024.0,
      static_cast<unsigned long long>(checksum));
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "bench_synth_stream: error: %s\n", error.what());
    return 1;
  }
  return 0;
}
