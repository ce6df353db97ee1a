// Temporary array files of the bounded-memory input path (paper Sec. 4.2 and 7).
#include "SpoolFile.h"

#include "Errors.h"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>
#include <vector>

namespace resmr
{

SpoolFile::SpoolFile(const std::string& folder, const std::string& name)
  : Folder(folder.empty() ? std::string(".") : folder)
  , ArrayName(name)
{
  std::string pattern = this->Folder + "/resmr-spool-" + name + "-XXXXXX";
  std::vector<char> path(pattern.begin(), pattern.end());
  path.push_back('\0');
  this->Descriptor = mkstemp(path.data());
  if (this->Descriptor < 0)
  {
    throw InputError(
      this->Folder, 0, name, std::string("cannot create a temporary file for the array: ") + std::strerror(errno));
  }
  // Unlinked at once: nothing is left behind, whatever happens to this process.
  unlink(path.data());
  fcntl(this->Descriptor, F_SETFD, FD_CLOEXEC);
}

SpoolFile::~SpoolFile()
{
  if (this->Descriptor >= 0)
  {
    close(this->Descriptor);
  }
}

void SpoolFile::WriteBytes(int64_t offset, const void* data, int64_t size)
{
  const auto* bytes = static_cast<const char*>(data);
  while (size > 0)
  {
    const ssize_t put = pwrite(this->Descriptor, bytes, static_cast<std::size_t>(size), offset);
    if (put < 0 && errno == EINTR)
    {
      continue;
    }
    if (put <= 0)
    {
      throw InputError(this->Folder, 0, this->ArrayName,
        "temporary file write at byte " + std::to_string(offset) +
          " failed: " + (put < 0 ? std::strerror(errno) : "no space left?"));
    }
    bytes += put;
    offset += put;
    size -= put;
  }
}

void SpoolFile::ReadBytes(int64_t offset, void* data, int64_t size) const
{
  auto* bytes = static_cast<char*>(data);
  while (size > 0)
  {
    const ssize_t got = pread(this->Descriptor, bytes, static_cast<std::size_t>(size), offset);
    if (got < 0 && errno == EINTR)
    {
      continue;
    }
    if (got <= 0)
    {
      throw InputError(this->Folder, 0, this->ArrayName,
        "temporary file read at byte " + std::to_string(offset) + " failed" +
          (got < 0 ? std::string(": ") + std::strerror(errno) : std::string(": short file")));
    }
    bytes += got;
    offset += got;
    size -= got;
  }
}

} // namespace resmr
