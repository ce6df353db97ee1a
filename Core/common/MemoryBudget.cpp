// The memory policy (see MemoryBudget.h).
#include "MemoryBudget.h"

#include <cstdio>
#include <cstring>
#include <unistd.h>

namespace resmr
{

int64_t AvailableMemoryBytes()
{
  if (std::FILE* meminfo = std::fopen("/proc/meminfo", "r"))
  {
    char line[256];
    long long kilobytes = -1;
    while (std::fgets(line, sizeof(line), meminfo))
    {
      if (std::sscanf(line, "MemAvailable: %lld kB", &kilobytes) == 1)
      {
        break;
      }
    }
    std::fclose(meminfo);
    if (kilobytes > 0)
    {
      return static_cast<int64_t>(kilobytes) * 1024;
    }
  }
  return PhysicalMemoryBytes();
}

int64_t PhysicalMemoryBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0 ? static_cast<int64_t>(pages) * pageSize : int64_t(1) << 34;
}

int64_t MaxParsableCells()
{
  return PhysicalMemoryBytes() / 64;
}

int64_t DefaultBuildMemoryBytes()
{
  return AvailableMemoryBytes() / 2;
}

int64_t MaxFullResolutionCells(int64_t limitBytes)
{
  const int64_t budget = limitBytes > 0 ? limitBytes : AvailableMemoryBytes();
  return budget / FullResolutionBytesPerCell;
}

std::string MultiresolutionAdvice(const std::string& path)
{
  return "open it through the multiresolution path instead, which loads only what the view "
         "needs: resmr build " +
    path + " -o MODEL.resmr, then open MODEL.resmr";
}

} // namespace resmr
