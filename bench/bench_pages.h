// Shared by the benchmarks that time reads from a cold page cache.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <string>

/// Drops the file's pages from the page cache (a cold read), as far as the kernel lets us.
inline void DropPages(const std::string& path)
{
  const int fd = open(path.c_str(), O_RDONLY);
  if (fd >= 0)
  {
    fdatasync(fd);
    posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED);
    close(fd);
  }
}
