// The machine's own stalls: one thread per core reads the monotonic clock in a tight loop and
// records every gap longer than a threshold, that is, every time the thread was not running
// for reasons of the machine (hypervisor, host, kernel) rather than of any program's work.
// The view benchmark's frame times (run_view_bench.py) include these stalls; this measures
// them without ParaView, the plugin or a GPU stack in the process.
//
//   bench_cpu_gaps SECONDS [THREADS] [THRESHOLD_MS]   -> JSON on stdout
//
// The first half second (threads starting, pages faulting in) is not counted. Gaps closer
// than 100 ms to each other, on any thread, form one burst; the JSON lists the bursts (start,
// time lost summed over threads, longest gap) and the intervals between bursts that lost at
// least 20 ms, the ones that can push a frame of a 100 ms budget over it.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

namespace
{
struct Gap
{
  double start = 0; // seconds since the run began
  double ms = 0;
  int thread = 0;
};

double Seconds(std::chrono::steady_clock::time_point t, std::chrono::steady_clock::time_point origin)
{
  return std::chrono::duration<double>(t - origin).count();
}
} // namespace

int main(int argc, char** argv)
{
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: bench_cpu_gaps SECONDS [THREADS] [THRESHOLD_MS]\n");
    return 2;
  }
  const double seconds = std::atof(argv[1]);
  const int threads = argc > 2 ? std::atoi(argv[2]) : static_cast<int>(std::thread::hardware_concurrency());
  const double thresholdMs = argc > 3 ? std::atof(argv[3]) : 2.0;
  if (!(seconds > 0) || threads < 1 || !(thresholdMs > 0))
  {
    std::fprintf(stderr, "bench_cpu_gaps: SECONDS, THREADS and THRESHOLD_MS must be positive\n");
    return 2;
  }
  const auto origin = std::chrono::steady_clock::now();
  std::vector<std::vector<Gap>> found(static_cast<std::size_t>(threads));
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t)
  {
    workers.emplace_back([&, t] {
      auto last = std::chrono::steady_clock::now();
      for (;;)
      {
        const auto now = std::chrono::steady_clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - last).count();
        if (ms > thresholdMs && Seconds(last, origin) > 0.5)
        {
          found[static_cast<std::size_t>(t)].push_back({ Seconds(last, origin), ms, t });
        }
        last = now;
        if (Seconds(now, origin) > seconds)
        {
          break;
        }
      }
    });
  }
  for (auto& w : workers)
  {
    w.join();
  }

  std::vector<Gap> gaps;
  for (const auto& list : found)
  {
    gaps.insert(gaps.end(), list.begin(), list.end());
  }
  std::sort(gaps.begin(), gaps.end(), [](const Gap& a, const Gap& b) { return a.start < b.start; });
  struct Burst
  {
    double start = 0, end = 0, lostMs = 0, longestMs = 0;
    int gaps = 0;
  };
  std::vector<Burst> bursts;
  for (const Gap& g : gaps)
  {
    if (bursts.empty() || g.start > bursts.back().end + 0.1)
    {
      bursts.push_back({ g.start, g.start, 0, 0, 0 });
    }
    Burst& b = bursts.back();
    b.end = std::max(b.end, g.start + g.ms / 1000);
    b.lostMs += g.ms;
    b.longestMs = std::max(b.longestMs, g.ms);
    ++b.gaps;
  }

  std::printf("{\"seconds\": %.1f, \"threads\": %d, \"threshold_ms\": %.1f, \"gaps\": %zu,\n", seconds, threads,
    thresholdMs, gaps.size());
  std::printf(" \"bursts\": [");
  for (std::size_t n = 0; n < bursts.size(); ++n)
  {
    const Burst& b = bursts[n];
    std::printf("%s\n  {\"start_s\": %.3f, \"span_ms\": %.1f, \"gaps\": %d, \"lost_ms\": %.1f, \"longest_ms\": %.1f}",
      n ? "," : "", b.start, 1000 * (b.end - b.start), b.gaps, b.lostMs, b.longestMs);
  }
  std::printf("],\n \"large_burst_intervals_s\": [");
  double previous = -1;
  bool first = true;
  for (const Burst& b : bursts)
  {
    if (b.lostMs < 20)
    {
      continue;
    }
    if (previous >= 0)
    {
      std::printf("%s%.3f", first ? "" : ", ", b.start - previous);
      first = false;
    }
    previous = b.start;
  }
  std::printf("]}\n");
  return 0;
}
