// An output file that appears under its final name only when complete (paper Sec. 6.1 asks
// the same of the multiresolution file; every writer of this project uses it).
//
// Contract:
// - The constructor creates a temporary file beside the target (same folder, so the final
//   rename is atomic); it throws InputError naming the target if the folder is not writable.
// - Write() returns false on a failed write (errno tells why); the caller names the place.
// - Commit() flushes, syncs and renames into place; it throws InputError on failure.
// - Discard(), the destructor, or a failed Commit() remove the temporary: nothing partial is
//   ever left under the final name, and an older file there stays untouched until Commit.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace resmr
{

class AtomicOutputFile
{
public:
  explicit AtomicOutputFile(const std::string& path);
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  bool Write(const void* data, std::size_t size);
  /// Overwrites bytes already written (a header patched at the end); same errors as Write.
  bool WriteAt(const void* data, std::size_t size, long offset);
  void Commit();
  void Discard();

  bool IsOpen() const { return this->File != nullptr; }
  const std::string& Path() const { return this->FinalPath; }
  const std::string& TemporaryPath() const { return this->Temporary; }

private:
  std::string FinalPath;
  std::string Temporary;
  std::FILE* File = nullptr;
};

} // namespace resmr
