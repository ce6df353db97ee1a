// Writer of unformatted ECLIPSE keyword files (EGRID, INIT, UNRST), streamed: paper Sec. 3
// input for the synthetic models that stand in for real ones of any size.
//
// Contract:
// - Writes big-endian Fortran records exactly as ECLIPSE, OPM and resdata do: a 16-byte
//   header record (name, count, type), then data records of 1000 numbers or 105 strings.
// - Data may be handed over in pieces of any size (Append), so a keyword of billions of
//   bytes never has to be in memory; the writer checks that each keyword gets exactly the
//   count its header promised.
// - Everything goes to a temporary file beside the target; Commit() renames it into place.
//   A writer destroyed without Commit(), or any error (disk full, unwritable folder, count
//   over the format's 32-bit limit), removes the temporary: no partial file is ever left
//   under the final name. Errors throw InputError naming the file and keyword.
#pragma once

#include "AtomicOutputFile.h"
#include "EclipseKeywordFile.h"

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace resmr
{

class EclipseKeywordWriter
{
public:
  /// Opens a temporary file beside `path`; throws InputError if the folder is not writable.
  explicit EclipseKeywordWriter(const std::string& path);
  EclipseKeywordWriter(const EclipseKeywordWriter&) = delete;
  EclipseKeywordWriter& operator=(const EclipseKeywordWriter&) = delete;

  /// Starts keyword `name` (up to 8 characters) of `count` elements of `type` (INTE, REAL,
  /// DOUB, LOGI, CHAR, MESS). The previous keyword must be complete.
  void Begin(const std::string& name, const std::string& type, int64_t count);

  /// Appends values of the current numeric keyword, converted to its type.
  void Append(const int32_t* values, int64_t count);
  void Append(const float* values, int64_t count);
  void Append(const double* values, int64_t count);
  /// Appends strings of the current CHAR keyword (padded or cut to 8 characters).
  void Append(const std::vector<std::string>& values);

  /// Begin + Append of a whole keyword.
  template<typename T>
  void Write(const std::string& name, const std::string& type, const std::vector<T>& values)
  {
    this->Begin(name, type, static_cast<int64_t>(values.size()));
    this->Append(values.data(), static_cast<int64_t>(values.size()));
  }
  void WriteStrings(const std::string& name, const std::vector<std::string>& values);

  /// Flushes, checks the last keyword is complete and renames the file into place.
  void Commit();

  const std::string& Path() const { return this->Output.Path(); }

private:
  template<typename T>
  void AppendNumbers(const T* values, int64_t count);
  void PutBytes(const void* data, std::size_t size);
  void PutMarker(uint32_t value);
  [[noreturn]] void Fail(const std::string& what);

  AtomicOutputFile Output;
  std::string Keyword;
  EclipseDataType Type = EclipseDataType::Message;
  int32_t ElementSize = 0;
  int64_t Remaining = 0;   ///< elements the current keyword still needs
  int64_t LeftInBlock = 0; ///< elements left in the open data record
  int64_t BlockBytes = 0;  ///< size of the open data record
  std::vector<unsigned char> Scratch;
};

} // namespace resmr
