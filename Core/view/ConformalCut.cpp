// Conformal cuts of the diamond hierarchy by error or by level, paper Sec. 6.2.
#include "ConformalCut.h"

#include <algorithm>
#include <map>
#include <utility>

namespace resmr
{

std::vector<std::size_t> SelectByError(const MultiresolutionFile& file, double tolerance)
{
  std::map<std::pair<int, int64_t>, std::size_t> byName;
  for (std::size_t i = 0; i < file.Regions().size(); ++i)
  {
    byName[{ file.Regions()[i].level, file.Regions()[i].index }] = i;
  }
  const int leaves = file.Header().leafLevel;
  std::vector<std::size_t> selected;
  // Triangles whose region is absent are empty (no column): nothing to show or split.
  std::vector<std::pair<int, int64_t>> stack{ { 0, 0 }, { 0, 1 } };
  while (!stack.empty())
  {
    const auto triangle = stack.back();
    stack.pop_back();
    const auto found = byName.find(triangle);
    if (found == byName.end())
    {
      continue;
    }
    const RegionRecord& record = file.Regions()[found->second];
    if (triangle.first < leaves && record.error > tolerance)
    {
      stack.push_back({ triangle.first + 1, 2 * triangle.second });
      stack.push_back({ triangle.first + 1, 2 * triangle.second + 1 });
    }
    else
    {
      selected.push_back(found->second);
    }
  }
  std::sort(selected.begin(), selected.end());
  return selected;
}

std::vector<std::size_t> SelectLevel(const MultiresolutionFile& file, int level)
{
  level = std::max(0, std::min(level, file.Header().leafLevel));
  std::vector<std::size_t> selected;
  for (std::size_t i = 0; i < file.Regions().size(); ++i)
  {
    if (file.Regions()[i].level == level)
    {
      selected.push_back(i);
    }
  }
  return selected;
}

} // namespace resmr
