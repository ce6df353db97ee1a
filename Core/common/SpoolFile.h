// Temporary files for arrays too big to hold: the bounded-memory input path of the hierarchy
// builder (paper Sec. 4.2 and 7: the model is streamed, never held whole) spools a deck's
// ZCORN and ACTNUM here while parsing and reads them back layer by layer.
//
// Contract:
// - The file is created in `folder` with a unique name (mkstemp: several processes, MPI ranks
//   included, may share the folder) and unlinked at once: it never shows in the folder and
//   its space is freed when the object is destroyed, however the program ends.
// - Positional reads and writes (pread/pwrite) of whole values; a failure (disk full, a read
//   past what was written) throws InputError naming the folder and the array.
#pragma once

#include <cstdint>
#include <string>

namespace resmr
{

class SpoolFile
{
public:
  /// `name` is what errors call the array (ZCORN, ACTNUM ...).
  SpoolFile(const std::string& folder, const std::string& name);
  ~SpoolFile();
  SpoolFile(const SpoolFile&) = delete;
  SpoolFile& operator=(const SpoolFile&) = delete;

  const std::string& Name() const { return this->ArrayName; }

  /// values[0 .. count) to elements [first, first + count) of T.
  template<typename T>
  void Write(int64_t first, const T* values, int64_t count)
  {
    this->WriteBytes(first * int64_t(sizeof(T)), values, count * int64_t(sizeof(T)));
  }
  template<typename T>
  void Read(int64_t first, T* values, int64_t count) const
  {
    this->ReadBytes(first * int64_t(sizeof(T)), values, count * int64_t(sizeof(T)));
  }
  /// Elements [first, first + count) of T all set to `value`.
  template<typename T>
  void Fill(int64_t first, int64_t count, T value)
  {
    T block[4096];
    for (T& v : block)
    {
      v = value;
    }
    for (int64_t done = 0; done < count; done += 4096)
    {
      this->Write(first + done, block, count - done < 4096 ? count - done : 4096);
    }
  }

private:
  void WriteBytes(int64_t offset, const void* data, int64_t size);
  void ReadBytes(int64_t offset, void* data, int64_t size) const;

  std::string Folder;
  std::string ArrayName;
  int Descriptor = -1;
};

} // namespace resmr
