// Large per-cell arrays (paper Sec. 6.1: models of hundreds of millions of cells). Filling a
// freshly allocated gigabyte array costs one page fault per 4 KiB page, which on virtual
// machines takes longer than reading the data from the page cache. Asking for transparent
// huge pages (Linux, where THP is in "madvise" mode) makes that 512 times fewer faults.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace resmr
{

/// Hints that [data, data + bytes) will be written soon and should use huge pages. Only
/// whole 2 MiB pages inside the range are advised; a no-op elsewhere and for small ranges.
inline void AdviseHugePages(void* data, std::size_t bytes)
{
#ifdef __linux__
  constexpr std::uintptr_t huge = std::uintptr_t(2) << 20;
  const auto begin = (reinterpret_cast<std::uintptr_t>(data) + huge - 1) & ~(huge - 1);
  const auto end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(huge - 1);
  if (end > begin)
  {
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
#else
  (void)data;
  (void)bytes;
#endif
}

/// Resizes an empty vector to `count` elements, advising huge pages before the memory is
/// first touched.
template<typename T>
void ResizeLarge(std::vector<T>& values, std::size_t count)
{
  if (values.empty() && count * sizeof(T) >= (std::size_t(8) << 20))
  {
    values.reserve(count);
    AdviseHugePages(values.data(), count * sizeof(T));
  }
  values.resize(count);
}

} // namespace resmr
