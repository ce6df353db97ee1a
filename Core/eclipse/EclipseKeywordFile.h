// ECLIPSE keyword files: EGRID, INIT, UNRST, Xnnnn and binary GRDECL, unformatted
// (Fortran sequential records, big-endian) or formatted (ASCII). Paper Sec. 3: model input;
// Sec. 6.1: only the data on screen is read.
//
// Contract:
// - Opening a file builds an index of every record (name, type, count, byte offsets) once.
//   Unformatted files are indexed by seeking past standard blocks (1000 numbers or 105
//   strings per Fortran record); a file with other block sizes is walked record marker by
//   record marker instead. Formatted files are scanned token by token.
// - Read() then seeks straight to one record and converts it to the caller's type in large
//   chunks: the cost of reading a record is proportional to its size, not the file's.
// - Every marker, length, count and type is checked. Corrupt or truncated files throw
//   InputError naming the file, the keyword and the byte offset. Never reads past the end of
//   the file, never allocates more than the file can hold.
// - Opened with KeywordFileIndexing::UpToLastWholeRecord (results files: INIT, restarts,
//   which a simulator may still be appending to or may have cut short), indexing stops at
//   the first record that is cut or damaged instead of throwing: Records() holds every whole
//   record before it, and StoppedAt()/StopReason() say where and why. The size is taken once,
//   at open, so a file still being written is never read past that point.
// - Reads are positional (pread), so one open file may be read from several threads.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace resmr
{

enum class EclipseDataType : int8_t
{
  Integer,   ///< INTE: int32
  Real,      ///< REAL: float32
  Double,    ///< DOUB: float64
  Logical,   ///< LOGI: int32, 0 false
  Character, ///< CHAR (8 characters) or C0nn (nn characters)
  Message    ///< MESS: no data
};

struct EclipseRecord
{
  std::string name;     ///< trimmed, up to 8 characters
  std::string typeName; ///< as written: INTE, REAL, DOUB, LOGI, CHAR, MESS, C0nn
  EclipseDataType type = EclipseDataType::Message;
  int32_t elementSize = 0;  ///< bytes per element in unformatted files (CHAR: 8, C0nn: nn)
  int64_t count = 0;        ///< number of elements
  int64_t headerOffset = 0; ///< byte offset of the keyword header
  int64_t dataOffset = 0;   ///< byte offset of the first data record (or token)
  int64_t endOffset = 0;    ///< byte offset just past the data
  /// Unformatted data in full records of 1000 numbers / 105 strings (as ECLIPSE, OPM and
  /// resdata write them): any element's byte offset is known, so a record can be read in
  /// parallel pieces.
  bool standardBlocks = false;

  bool IsNumeric() const { return this->type != EclipseDataType::Character && this->type != EclipseDataType::Message; }
};

enum class KeywordFileIndexing
{
  WholeFile,          ///< any damage throws (grids)
  UpToLastWholeRecord ///< stop before the first cut or damaged record (results)
};

class EclipseKeywordFile
{
public:
  /// Opens and indexes the file; throws InputError if it is not a valid keyword file (with
  /// UpToLastWholeRecord: only if it does not start like one).
  explicit EclipseKeywordFile(const std::string& path, KeywordFileIndexing indexing = KeywordFileIndexing::WholeFile);
  ~EclipseKeywordFile();
  EclipseKeywordFile(const EclipseKeywordFile&) = delete;
  EclipseKeywordFile& operator=(const EclipseKeywordFile&) = delete;

  /// The first `size` bytes of a file (fewer if it is shorter; empty if unreadable).
  static std::string FileHead(const std::string& path, std::size_t size);
  /// True if the file starts like an unformatted keyword file (a 16-byte header record).
  static bool LooksLikeUnformatted(const std::string& path);
  /// True if the file starts like a formatted keyword file ('NAME' count 'TYPE').
  static bool LooksLikeFormatted(const std::string& path);

  const std::string& Path() const { return this->FilePath; }
  int64_t Size() const { return this->FileSize; }
  bool IsFormatted() const { return this->Formatted; }
  const std::vector<EclipseRecord>& Records() const { return this->Index; }
  /// UpToLastWholeRecord: the byte offset where indexing stopped before the end of the file
  /// (the first cut or damaged record), or -1 if every byte was indexed.
  int64_t StoppedAt() const { return this->Stopped; }
  /// Why indexing stopped there (the error a whole-file index would have thrown).
  const std::string& StopReason() const { return this->StoppedBecause; }

  /// First record named `name` at or after index `from`, or nullptr.
  const EclipseRecord* Find(const std::string& name, std::size_t from = 0) const;

  /// Reads a numeric record (any of INTE, REAL, DOUB, LOGI) into out[0 .. count), converting
  /// to T. Defined for int32_t, float and double.
  template<typename T>
  void Read(const EclipseRecord& record, T* out) const;

  /// Reads a numeric record piece by piece, with no buffer the size of the record:
  /// `sink(values, first, count)` receives the converted values [first, first + count).
  /// Large records call the sink from several threads at once, each with its own ranges in
  /// increasing order; the sink must only write where `first` says. Defined for int32_t,
  /// float and double.
  template<typename T>
  void ReadInPieces(const EclipseRecord& record, const std::function<void(const T*, int64_t, int64_t)>& sink) const;

  /// Records of at least this many values are read by several threads (one per core, at
  /// most 8), each converting its own range of blocks: on a workstation the conversion and
  /// the first touch of fresh memory then run on every core. The default is 4 Mi values;
  /// the environment variable RESMR_PARALLEL_MIN_VALUES overrides it (tests set it low).
  static int64_t ParallelMinimumValues();
  static void SetParallelMinimumValues(int64_t values);

  /// Convenience: a numeric record as doubles.
  void ReadNumbers(const EclipseRecord& record, std::vector<double>& values) const;
  /// A CHAR or C0nn record, each string with trailing blanks removed.
  std::vector<std::string> ReadStrings(const EclipseRecord& record) const;

  /// Throws InputError for `record` at byte `offset`.
  [[noreturn]] void Fail(const EclipseRecord* record, int64_t offset, const std::string& what) const;

private:
  friend class EclipseRecordCursor;
  void IndexUnformatted();
  void IndexFormatted();
  /// Runs an indexing pass; with UpToLastWholeRecord, a failure at `position` ends the index
  /// there instead of propagating.
  void IndexLeniently(void (EclipseKeywordFile::*pass)());
  int64_t WalkBlocks(const EclipseRecord& record) const;
  void ReadRaw(int64_t offset, void* data, int64_t size, const EclipseRecord* record) const;
  template<typename T>
  void ReadFormatted(const EclipseRecord& record, T* out) const;
  std::vector<std::string> ReadFormattedStrings(const EclipseRecord& record) const;
  template<typename Consumer>
  void ForEachBlock(
    const EclipseRecord& record, Consumer&& consume, int64_t firstBlock = 0, int64_t endBlock = -1) const;
  template<typename Consumer>
  void ForEachBlockInParallel(const EclipseRecord& record, Consumer&& consume) const;

  std::string FilePath;
  int Descriptor = -1;
  int64_t FileSize = 0;
  bool Formatted = false;
  KeywordFileIndexing Indexing = KeywordFileIndexing::WholeFile;
  int64_t Stopped = -1;
  std::string StoppedBecause;
  int64_t IndexPosition = 0; ///< start of the record being indexed (where a lenient index stops)
  std::vector<EclipseRecord> Index;
};

/// Reads one numeric record front to back in pieces of the caller's choosing (a layer of
/// ZCORN, of ACTNUM ...), holding at most one read chunk (4 MiB) of it: what a layer-by-layer
/// reader needs from a record bigger than memory.
///
/// Contract:
/// - Read(count, out) gives the next `count` values converted to T as
///   EclipseKeywordFile::Read converts them; asking for more values than remain, and corrupt
///   or truncated data met on the way, throw InputError naming the file, the keyword and the
///   byte offset.
/// - Unformatted records are walked data record by data record (any block size, markers
///   checked as Read checks them), formatted ones token by token. Forward only.
/// - `file` must outlive the cursor; one cursor serves one thread.
class EclipseRecordCursor
{
public:
  EclipseRecordCursor(const EclipseKeywordFile& file, const EclipseRecord& record);
  ~EclipseRecordCursor();
  EclipseRecordCursor(const EclipseRecordCursor&) = delete;
  EclipseRecordCursor& operator=(const EclipseRecordCursor&) = delete;

  /// Defined for int32_t, float and double.
  template<typename T>
  void Read(int64_t count, T* out);
  /// Values read so far: the index of the next one.
  int64_t Position() const { return this->Done; }
  const EclipseRecord& Record() const { return this->Header; }

private:
  const unsigned char* Ensure(int64_t offset, int64_t size);

  struct Text;
  const EclipseKeywordFile& File;
  EclipseRecord Header;
  int64_t Done = 0;
  int64_t NextBlock = 0; ///< byte offset of the next data record's start marker
  int64_t BlockData = 0; ///< byte offset of the next unread element of the current one
  int64_t BlockLeft = 0; ///< elements left in the current data record
  std::vector<unsigned char> Buffer;
  int64_t BufferStart = 0, BufferEnd = 0; ///< absolute offsets of the bytes held in Buffer
  std::unique_ptr<Text> Formatted;        ///< formatted files: the token cursor
};

} // namespace resmr
