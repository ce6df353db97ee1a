// The order of a one-process hierarchy build (paper Sec. 4.2 builds level by level; ours):
// every leaf and every diamond is a task, a diamond runs once the four child triangles it
// merges are built, and tasks run in the post-order of a depth-first walk from the roots.
// Level by level, a whole level of region meshes with their quadrics lies on disk while the
// next is built (more than 100 bytes a cell); depth first, only the regions made but not yet
// merged do: about one region a level along the border between the built and the unbuilt
// part of the model, a small share of one level.
//
// Contract:
// - Tasks() lists every task once, each after every task it depends on; leaves are given by
//   their triangle at the leaf level, diamonds are those of the tree with a built child.
// - Run() runs each task not marked done exactly once, on `threads` threads, each only once
//   the tasks it depends on have finished (or are marked done), the earliest in Tasks()'
//   order first; the first exception stops new tasks, waits for running ones and is rethrown.
#pragma once

#include "DiamondHierarchy.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace resmr
{

class BuildSchedule
{
public:
  struct Task
  {
    int level = 0;
    /// A leaf: its triangle and -1; a diamond: its triangles (second -1 on the box's edge).
    int64_t first = -1, second = -1;
    bool leaf = false;
    int64_t leafIndex = -1;         ///< a leaf's position in the list given to the constructor
    std::vector<int32_t> dependsOn; ///< tasks (positions in Tasks()) that build its children
  };

  /// `leafTriangles`: the triangles of the leaf level that hold columns, in any order.
  BuildSchedule(const DiamondHierarchy& tree, const std::vector<int64_t>& leafTriangles);

  const std::vector<Task>& Tasks() const { return this->List; }

  /// The child triangles (level + 1) a diamond merges; none for a leaf.
  static std::vector<int64_t> Children(const Task& task);

  void Run(int threads, const std::vector<uint8_t>& done, const std::function<void(int32_t)>& run) const;

private:
  std::vector<Task> List;
};

} // namespace resmr
