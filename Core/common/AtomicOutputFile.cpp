// Temporary file renamed into place on success (see AtomicOutputFile.h).
#include "AtomicOutputFile.h"

#include "Errors.h"

#include <cerrno>
#include <cstring>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{

AtomicOutputFile::AtomicOutputFile(const std::string& path)
  : FinalPath(path)
{
  std::string pattern = path + ".partial-XXXXXX";
  const int descriptor = mkstemp(&pattern[0]);
  if (descriptor < 0)
  {
    throw InputError(path, 0, "", std::string("cannot create the output file beside it: ") + std::strerror(errno));
  }
  this->Temporary = pattern;
  this->File = fdopen(descriptor, "wb");
  if (!this->File)
  {
    const int error = errno;
    close(descriptor);
    unlink(this->Temporary.c_str());
    throw InputError(path, 0, "", std::string("cannot open the output file: ") + std::strerror(error));
  }
  fchmod(descriptor, 0644); // mkstemp creates 0600; outputs are ordinary files
  std::setvbuf(this->File, nullptr, _IOFBF, 1 << 20);
}

AtomicOutputFile::~AtomicOutputFile()
{
  this->Discard();
}

void AtomicOutputFile::Discard()
{
  if (this->File)
  {
    std::fclose(this->File);
    this->File = nullptr;
    unlink(this->Temporary.c_str());
  }
}

bool AtomicOutputFile::Write(const void* data, std::size_t size)
{
  return this->File && std::fwrite(data, 1, size, this->File) == size;
}

bool AtomicOutputFile::WriteAt(const void* data, std::size_t size, long offset)
{
  if (!this->File)
  {
    return false;
  }
  const long end = std::ftell(this->File);
  const bool ok =
    end >= 0 && std::fseek(this->File, offset, SEEK_SET) == 0 && std::fwrite(data, 1, size, this->File) == size;
  return std::fseek(this->File, end, SEEK_SET) == 0 && ok;
}

void AtomicOutputFile::Commit()
{
  if (!this->File)
  {
    throw InputError(this->FinalPath, 0, "", "output already committed or failed");
  }
  const bool flushed = std::fflush(this->File) == 0 && fsync(fileno(this->File)) == 0;
  const int error = errno;
  const bool closed = std::fclose(this->File) == 0;
  this->File = nullptr;
  if (!flushed || !closed)
  {
    unlink(this->Temporary.c_str());
    throw InputError(
      this->FinalPath, 0, "", std::string("write failed (disk full?): ") + std::strerror(flushed ? errno : error));
  }
  if (std::rename(this->Temporary.c_str(), this->FinalPath.c_str()) != 0)
  {
    const int renameError = errno;
    unlink(this->Temporary.c_str());
    throw InputError(
      this->FinalPath, 0, "", std::string("cannot move the finished file into place: ") + std::strerror(renameError));
  }
}

} // namespace resmr
