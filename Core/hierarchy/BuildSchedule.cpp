// Depth-first order of the hierarchy build's tasks (ours; the paper builds level by level).
#include "BuildSchedule.h"

#include "ThreadGroup.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <unordered_map>

namespace resmr
{

BuildSchedule::BuildSchedule(const DiamondHierarchy& tree, const std::vector<int64_t>& leafTriangles)
{
  // Bottom-up: the task that builds each triangle of a level, then the diamonds above.
  std::vector<Task> tasks;
  std::unordered_map<int64_t, int32_t> below;
  for (std::size_t n = 0; n < leafTriangles.size(); ++n)
  {
    Task leaf;
    leaf.level = tree.LeafLevel();
    leaf.first = leafTriangles[n];
    leaf.leaf = true;
    leaf.leafIndex = static_cast<int64_t>(n);
    below[leaf.first] = static_cast<int32_t>(tasks.size());
    tasks.push_back(leaf);
  }
  for (int level = tree.LeafLevel() - 1; level >= 0; --level)
  {
    std::unordered_map<int64_t, int32_t> here;
    for (const auto& d : tree.Diamonds(level))
    {
      Task task;
      task.level = level;
      task.first = d.first;
      task.second = d.second;
      for (int64_t child : Children(task))
      {
        const auto found = below.find(child);
        if (found != below.end() &&
          std::find(task.dependsOn.begin(), task.dependsOn.end(), found->second) == task.dependsOn.end())
        {
          task.dependsOn.push_back(found->second);
        }
      }
      if (task.dependsOn.empty())
      {
        continue;
      }
      here[d.first] = static_cast<int32_t>(tasks.size());
      if (d.second >= 0)
      {
        here[d.second] = static_cast<int32_t>(tasks.size());
      }
      tasks.push_back(std::move(task));
    }
    below.swap(here);
  }

  // Post-order of a depth-first walk from the roots (the tasks nothing depends on).
  std::vector<uint8_t> needed(tasks.size(), 0);
  for (const Task& task : tasks)
  {
    for (int32_t d : task.dependsOn)
    {
      needed[static_cast<std::size_t>(d)] = 1;
    }
  }
  std::vector<int32_t> order, position(tasks.size(), -1);
  const std::function<void(int32_t)> visit = [&](int32_t t) {
    position[static_cast<std::size_t>(t)] = 0;
    for (int32_t d : tasks[static_cast<std::size_t>(t)].dependsOn)
    {
      if (position[static_cast<std::size_t>(d)] < 0)
      {
        visit(d);
      }
    }
    position[static_cast<std::size_t>(t)] = static_cast<int32_t>(order.size());
    order.push_back(t);
  };
  for (int32_t t = static_cast<int32_t>(tasks.size()) - 1; t >= 0; --t)
  {
    if (!needed[static_cast<std::size_t>(t)] && position[static_cast<std::size_t>(t)] < 0)
    {
      visit(t);
    }
  }
  for (int32_t t : order)
  {
    Task task = tasks[static_cast<std::size_t>(t)];
    for (int32_t& d : task.dependsOn)
    {
      d = position[static_cast<std::size_t>(d)];
    }
    this->List.push_back(std::move(task));
  }
}

std::vector<int64_t> BuildSchedule::Children(const Task& task)
{
  std::vector<int64_t> children;
  if (task.leaf)
  {
    return children;
  }
  for (int64_t triangle : { task.first, task.second })
  {
    if (triangle >= 0)
    {
      children.push_back(2 * triangle);
      children.push_back(2 * triangle + 1);
    }
  }
  return children;
}

void BuildSchedule::Run(int threads, const std::vector<uint8_t>& done, const std::function<void(int32_t)>& run) const
{
  const std::size_t count = this->List.size();
  std::vector<int32_t> waiting(count, 0);
  std::vector<std::vector<int32_t>> consumers(count);
  for (std::size_t t = 0; t < count; ++t)
  {
    for (int32_t d : this->List[t].dependsOn)
    {
      consumers[static_cast<std::size_t>(d)].push_back(static_cast<int32_t>(t));
      waiting[t] += done[static_cast<std::size_t>(d)] ? 0 : 1;
    }
  }
  std::set<int32_t> ready;
  std::size_t left = 0;
  for (std::size_t t = 0; t < count; ++t)
  {
    if (!done[t])
    {
      ++left;
      if (waiting[t] == 0)
      {
        ready.insert(static_cast<int32_t>(t));
      }
    }
  }
  std::mutex lock;
  std::condition_variable changed;
  std::exception_ptr failure;
  int running = 0;
  auto work = [&] {
    std::unique_lock<std::mutex> guard(lock);
    for (;;)
    {
      changed.wait(guard, [&] { return failure || left == 0 || !ready.empty() || running == 0; });
      if (failure || left == 0 || ready.empty())
      {
        return; // nothing ready and nothing running means nothing ever will be
      }
      const int32_t t = *ready.begin();
      ready.erase(ready.begin());
      ++running;
      guard.unlock();
      std::exception_ptr error;
      try
      {
        run(t);
      }
      catch (...)
      {
        error = std::current_exception();
      }
      guard.lock();
      --running;
      if (error && !failure)
      {
        failure = error;
      }
      if (!error)
      {
        --left;
        for (int32_t c : consumers[static_cast<std::size_t>(t)])
        {
          if (--waiting[static_cast<std::size_t>(c)] == 0)
          {
            ready.insert(c);
          }
        }
      }
      changed.notify_all();
    }
  };
  RunOnThreads(threads, work);
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  if (left != 0)
  {
    throw std::logic_error("hierarchy build: " + std::to_string(left) + " tasks never became ready");
  }
}

} // namespace resmr
