// Reader for ECLIPSE unformatted (Fortran sequential, big-endian) keyword files: binary
// GRDECL here, EGRID/INIT/UNRST later (paper Sec. 3: model input).
//
// Contract:
// - Streams: NextKeyword() reads one 16-byte header; the caller then reads or skips the
//   data. Memory use is the caller's arrays plus one small buffer.
// - Every record marker, length and type is checked; a truncated or corrupt file throws
//   GrdeclError naming the file, the byte offset and the keyword. Never reads past the
//   declared sizes, never allocates more than the file can hold.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace resmr
{

struct EclipseKeywordHeader
{
  std::string name;   ///< trimmed, up to 8 characters
  int64_t count = 0;  ///< number of elements
  std::string type;   ///< INTE, REAL, DOUB, LOGI, CHAR, MESS, C0nn
  int64_t offset = 0; ///< byte offset of the header record
};

class EclipseBinaryReader
{
public:
  explicit EclipseBinaryReader(const std::string& path);
  ~EclipseBinaryReader();
  EclipseBinaryReader(const EclipseBinaryReader&) = delete;
  EclipseBinaryReader& operator=(const EclipseBinaryReader&) = delete;

  /// True if the file starts like an ECLIPSE unformatted file (a 16-byte header record).
  static bool LooksLikeEclipseBinary(const std::string& path);

  /// Reads the next keyword header; false at a clean end of file.
  bool NextKeyword(EclipseKeywordHeader& header);

  /// Reads the data of the current numeric keyword (INTE, REAL, DOUB, LOGI) as doubles.
  void ReadNumbers(std::vector<double>& values);
  /// Reads the data of the current CHAR keyword.
  void ReadStrings(std::vector<std::string>& values);
  /// Skips the data of the current keyword.
  void SkipData();

  const std::string& GetPath() const { return this->Path; }

private:
  template <typename Consumer>
  void ReadBlocks(int64_t elementSize, Consumer&& consume);
  uint32_t ReadMarker();
  void ReadExact(void* data, std::size_t size);
  [[noreturn]] void Fail(const std::string& what) const;

  std::string Path;
  std::FILE* File = nullptr;
  int64_t FileSize = 0;
  int64_t Position = 0;
  EclipseKeywordHeader Current;
  bool DataPending = false;
  std::vector<unsigned char> Block;
};

} // namespace resmr
