// Running one piece of work on several threads at once (ours): the builder's worker pools.
#pragma once

#include <functional>
#include <thread>
#include <vector>

namespace resmr
{

/// Runs `work` on `threads` threads at once, this one among them, and returns once every one
/// has returned. `work` must not throw (catch inside and hand the error back).
inline void RunOnThreads(int threads, const std::function<void()>& work)
{
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t)
  {
    pool.emplace_back(work);
  }
  work();
  for (auto& thread : pool)
  {
    thread.join();
  }
}

} // namespace resmr
