// ECLIPSE keyword file index and record reader (paper Sec. 3: model input; Sec. 6.1: read
// only what is shown).
#include "EclipseKeywordFile.h"

#include "Errors.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fcntl.h>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace resmr
{
namespace
{
constexpr int64_t HeaderBytes = 24;       // marker, 8 + 4 + 4 bytes, marker
constexpr int64_t ChunkBytes = 4 << 20;   // read granularity for record data
constexpr int64_t NumbersPerBlock = 1000; // ECLIPSE's Fortran record sizes
constexpr int64_t StringsPerBlock = 105;
// Headers are read through a window this big: small consecutive records share one read,
// while a window past a big record wastes little copying.
constexpr int64_t IndexWindowBytes = 8 << 10;
constexpr std::size_t MaxNumberCharacters = 256; // formatted numbers are at most ~25 wide

uint32_t BigEndian32(const unsigned char* p)
{
  uint32_t value;
  std::memcpy(&value, p, 4);
  return __builtin_bswap32(value);
}

std::string Trimmed(const char* text, std::size_t size)
{
  std::string value(text, size);
  const auto last = value.find_last_not_of(' ');
  value.erase(last == std::string::npos ? 0 : last + 1);
  return value;
}

/// Sets type and element size from the 4-character type name; false if unknown.
bool ParseType(EclipseRecord& record)
{
  const std::string& t = record.typeName;
  if (t == "INTE" || t == "REAL" || t == "LOGI" || t == "DOUB")
  {
    record.type = t == "INTE" ? EclipseDataType::Integer
      : t == "REAL"           ? EclipseDataType::Real
      : t == "LOGI"           ? EclipseDataType::Logical
                              : EclipseDataType::Double;
    record.elementSize = t == "DOUB" ? 8 : 4;
    return true;
  }
  if (t == "CHAR")
  {
    record.type = EclipseDataType::Character;
    record.elementSize = 8;
    return true;
  }
  if (t == "MESS")
  {
    record.type = EclipseDataType::Message;
    record.elementSize = 0;
    return true;
  }
  if (t.size() == 4 && t[0] == 'C' && std::isdigit(static_cast<unsigned char>(t[1])) &&
    std::isdigit(static_cast<unsigned char>(t[2])) && std::isdigit(static_cast<unsigned char>(t[3])))
  {
    record.type = EclipseDataType::Character;
    record.elementSize = std::stoi(t.substr(1));
    return record.elementSize > 0;
  }
  return false;
}

int64_t ItemsPerBlock(const EclipseRecord& record)
{
  return record.type == EclipseDataType::Character ? StringsPerBlock : NumbersPerBlock;
}

/// Byte-swaps n 32-bit (or 64-bit) big-endian words into out, which may be any type of
/// that width. SSE2 (the x86-64 baseline) does 4 (or 2) words per instruction: this is the
/// hot loop of every grid and result load, and compilers do not vectorize bswap without
/// SSSE3.
void SwapWords32(const unsigned char* in, int64_t n, void* out)
{
  auto* bytes = static_cast<unsigned char*>(out);
  int64_t i = 0;
#if defined(__SSE2__)
  const __m128i low = _mm_set1_epi32(0x0000ff00), high = _mm_set1_epi32(0x00ff0000);
  for (; i + 4 <= n; i += 4)
  {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 4 * i));
    const __m128i swapped = _mm_or_si128(_mm_or_si128(_mm_srli_epi32(v, 24), _mm_slli_epi32(v, 24)),
      _mm_or_si128(_mm_and_si128(_mm_srli_epi32(v, 8), low), _mm_and_si128(_mm_slli_epi32(v, 8), high)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(bytes + 4 * i), swapped);
  }
#endif
  for (; i < n; ++i)
  {
    const uint32_t value = BigEndian32(in + 4 * i);
    std::memcpy(bytes + 4 * i, &value, 4);
  }
}

void SwapWords64(const unsigned char* in, int64_t n, void* out)
{
  auto* bytes = static_cast<unsigned char*>(out);
  SwapWords32(in, 2 * n, out); // each half swapped; then the halves exchanged
  int64_t i = 0;
#if defined(__SSE2__)
  for (; i + 2 <= n; i += 2)
  {
    auto* at = reinterpret_cast<__m128i*>(bytes + 8 * i);
    _mm_storeu_si128(at, _mm_shuffle_epi32(_mm_loadu_si128(at), _MM_SHUFFLE(2, 3, 0, 1)));
  }
#endif
  for (; i < n; ++i)
  {
    uint32_t halves[2];
    std::memcpy(halves, bytes + 8 * i, 8);
    std::swap(halves[0], halves[1]);
    std::memcpy(bytes + 8 * i, halves, 8);
  }
}

/// Converts a value to T; out-of-range (or NaN) reals would be undefined behaviour as
/// integers and become 0.
template<typename T, typename Source>
T Narrowed(Source value)
{
  if constexpr (std::is_integral_v<T> && std::is_floating_point_v<Source>)
  {
    return std::fabs(value) < Source(2147483520.0) ? static_cast<T>(value) : T(0);
  }
  else
  {
    return static_cast<T>(value);
  }
}

/// Converts n big-endian elements of `type` to T: straight byte swaps when T is the file's
/// type, otherwise swaps into a small buffer and a (vectorizable) conversion loop.
template<typename T>
void ConvertBigEndian(EclipseDataType type, const unsigned char* in, int64_t n, T* out)
{
  if ((type == EclipseDataType::Real && std::is_same_v<T, float>) ||
    (type == EclipseDataType::Integer && std::is_same_v<T, int32_t>))
  {
    SwapWords32(in, n, out);
    return;
  }
  if (type == EclipseDataType::Double && std::is_same_v<T, double>)
  {
    SwapWords64(in, n, out);
    return;
  }
  constexpr int64_t Chunk = 1024;
  alignas(16) unsigned char words[8 * Chunk];
  for (int64_t first = 0; first < n; first += Chunk)
  {
    const int64_t count = std::min(Chunk, n - first);
    T* target = out + first;
    switch (type)
    {
      case EclipseDataType::Real:
      {
        float values[Chunk];
        SwapWords32(in + 4 * first, count, values);
        for (int64_t i = 0; i < count; ++i)
        {
          target[i] = Narrowed<T>(values[i]);
        }
        break;
      }
      case EclipseDataType::Double:
      {
        double values[Chunk];
        SwapWords64(in + 8 * first, count, values);
        for (int64_t i = 0; i < count; ++i)
        {
          target[i] = Narrowed<T>(values[i]);
        }
        break;
      }
      case EclipseDataType::Integer:
      case EclipseDataType::Logical:
      {
        SwapWords32(in + 4 * first, count, words);
        int32_t values[Chunk];
        std::memcpy(values, words, static_cast<std::size_t>(4 * count));
        for (int64_t i = 0; i < count; ++i)
        {
          target[i] = type == EclipseDataType::Logical ? (values[i] != 0 ? T(1) : T(0)) : static_cast<T>(values[i]);
        }
        break;
      }
      default:
        break;
    }
  }
}

/// Sequential tokens of a formatted file, read in chunks; offsets are absolute.
class TextCursor
{
public:
  TextCursor(int descriptor, int64_t fileSize, int64_t offset)
    : Offset(offset)
    , Descriptor(descriptor)
    , FileSize(fileSize)
  {
  }

  int64_t Offset;

  /// Next token: a quoted string (quotes removed) or a run of non-blank characters.
  /// Returns false at end of file. `quoted` tells which.
  bool Next(std::string& token, bool& quoted, int64_t& start)
  {
    int c;
    while ((c = this->Peek()) >= 0 && (c == ' ' || c == '\n' || c == '\r' || c == '\t'))
    {
      ++this->Offset;
    }
    if (c < 0)
    {
      return false;
    }
    start = this->Offset;
    token.clear();
    quoted = c == '\'';
    if (quoted)
    {
      ++this->Offset;
      while ((c = this->Peek()) >= 0 && c != '\'')
      {
        if (c == '\n' || token.size() > 1024)
        {
          return false; // unterminated string; caller reports it
        }
        token.push_back(static_cast<char>(c));
        ++this->Offset;
      }
      if (c < 0)
      {
        return false;
      }
      ++this->Offset;
      return true;
    }
    while ((c = this->Peek()) >= 0 && c != ' ' && c != '\n' && c != '\r' && c != '\t')
    {
      // An absurdly long token is consumed whole (so indexing and reading agree on where
      // tokens are) but only its start is kept: the caller's conversion rejects it.
      if (token.size() <= MaxNumberCharacters)
      {
        token.push_back(static_cast<char>(c));
      }
      ++this->Offset;
    }
    return true;
  }

private:
  int Peek()
  {
    if (this->Offset < this->BufferStart ||
      this->Offset >= this->BufferStart + static_cast<int64_t>(this->Buffer.size()))
    {
      if (this->Offset >= this->FileSize)
      {
        return -1;
      }
      this->Buffer.resize(static_cast<std::size_t>(std::min<int64_t>(1 << 20, this->FileSize - this->Offset)));
      const ssize_t got = pread(this->Descriptor, this->Buffer.data(), this->Buffer.size(), this->Offset);
      if (got <= 0)
      {
        this->Buffer.clear();
        return -1;
      }
      this->Buffer.resize(static_cast<std::size_t>(got));
      this->BufferStart = this->Offset;
    }
    return static_cast<unsigned char>(this->Buffer[static_cast<std::size_t>(this->Offset - this->BufferStart)]);
  }

  int Descriptor;
  int64_t FileSize;
  int64_t BufferStart = 0;
  std::vector<char> Buffer;
};

/// Parses all of [begin, end) as a number of type T (a leading '+' allowed).
template<typename T>
bool ParseWhole(const char* begin, const char* end, T& value)
{
  if (begin != end && *begin == '+')
  {
    ++begin;
  }
  const auto result = std::from_chars(begin, end, value);
  return result.ec == std::errc() && result.ptr == end;
}

bool ParseInteger(const std::string& token, int64_t& value)
{
  return ParseWhole(token.data(), token.data() + token.size(), value);
}

bool ParseReal(std::string token, double& value)
{
  for (char& c : token)
  {
    if (c == 'D' || c == 'd')
    {
      c = 'E'; // Fortran double exponent
    }
  }
  return ParseWhole(token.data(), token.data() + token.size(), value);
}
} // namespace

EclipseKeywordFile::EclipseKeywordFile(const std::string& path, KeywordFileIndexing indexing)
  : FilePath(path)
  , Indexing(indexing)
{
  this->Descriptor = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (this->Descriptor < 0)
  {
    throw InputError(path, 0, "", std::string("cannot open file: ") + std::strerror(errno));
  }
  struct stat info;
  if (fstat(this->Descriptor, &info) != 0 || !S_ISREG(info.st_mode))
  {
    close(this->Descriptor);
    throw InputError(path, 0, "", "not a regular file");
  }
  this->FileSize = static_cast<int64_t>(info.st_size);
  try
  {
    if (LooksLikeUnformatted(path))
    {
      this->IndexLeniently(&EclipseKeywordFile::IndexUnformatted);
    }
    else if (LooksLikeFormatted(path))
    {
      this->Formatted = true;
      this->IndexLeniently(&EclipseKeywordFile::IndexFormatted);
    }
    else
    {
      throw InputError(path, 0, "",
        "not an ECLIPSE keyword file (neither a binary record header nor a formatted "
        "'KEYWORD' count 'TYPE' line at the start)");
    }
  }
  catch (...)
  {
    close(this->Descriptor);
    throw;
  }
}

EclipseKeywordFile::~EclipseKeywordFile()
{
  if (this->Descriptor >= 0)
  {
    close(this->Descriptor);
  }
}

std::string EclipseKeywordFile::FileHead(const std::string& path, std::size_t size)
{
  std::string head(size, '\0');
  std::FILE* file = std::fopen(path.c_str(), "rb");
  head.resize(file ? std::fread(&head[0], 1, size, file) : 0);
  if (file)
  {
    std::fclose(file);
  }
  return head;
}

bool EclipseKeywordFile::LooksLikeUnformatted(const std::string& path)
{
  const std::string head = FileHead(path, 24);
  const auto* bytes = reinterpret_cast<const unsigned char*>(head.data());
  return head.size() == 24 && BigEndian32(bytes) == 16 && BigEndian32(bytes + 20) == 16;
}

bool EclipseKeywordFile::LooksLikeFormatted(const std::string& path)
{
  const std::string text = FileHead(path, 63);
  const char* head = text.c_str();
  const std::size_t got = text.size();
  std::size_t p = 0;
  while (p < got && (head[p] == ' ' || head[p] == '\n' || head[p] == '\r'))
  {
    ++p;
  }
  // 'NAME    ' then a count then 'TYPE'
  if (p + 10 > got || head[p] != '\'' || head[p + 9] != '\'')
  {
    return false;
  }
  const char* second = std::strchr(head + p + 10, '\'');
  return second && second + 5 < head + got && second[5] == '\'';
}

void EclipseKeywordFile::Fail(const EclipseRecord* record, int64_t offset, const std::string& what) const
{
  throw InputError(
    this->FilePath, 0, record ? record->name : std::string(), what + " (at byte " + std::to_string(offset) + ")");
}

const EclipseRecord* EclipseKeywordFile::Find(const std::string& name, std::size_t from) const
{
  for (std::size_t r = from; r < this->Index.size(); ++r)
  {
    if (this->Index[r].name == name)
    {
      return &this->Index[r];
    }
  }
  return nullptr;
}

void EclipseKeywordFile::ReadRaw(int64_t offset, void* data, int64_t size, const EclipseRecord* record) const
{
  if (offset < 0 || size < 0 || offset + size > this->FileSize)
  {
    this->Fail(record, offset, "file truncated: needs " + std::to_string(size) + " more bytes");
  }
  auto* bytes = static_cast<unsigned char*>(data);
  while (size > 0)
  {
    const ssize_t got = pread(this->Descriptor, bytes, static_cast<std::size_t>(size), offset);
    if (got < 0 && errno == EINTR)
    {
      continue;
    }
    if (got <= 0)
    {
      this->Fail(
        record, offset, got < 0 ? std::string("read error: ") + std::strerror(errno) : std::string("file truncated"));
    }
    bytes += got;
    offset += got;
    size -= got;
  }
}

void EclipseKeywordFile::IndexLeniently(void (EclipseKeywordFile::*pass)())
{
  try
  {
    (this->*pass)();
  }
  catch (const InputError& error)
  {
    if (this->Indexing == KeywordFileIndexing::WholeFile)
    {
      throw;
    }
    // The records before the failing one are whole and checked; they are kept.
    this->Stopped = this->IndexPosition;
    this->StoppedBecause = error.what();
  }
}

void EclipseKeywordFile::IndexUnformatted()
{
  // Headers and markers are read through a small window: files of many small records
  // (restart headers, well data) are indexed with a few reads, not three per record.
  std::vector<unsigned char> window;
  int64_t windowStart = 0;
  const auto peek = [&](int64_t offset, void* data, int64_t size, const EclipseRecord* record) {
    if (offset < windowStart || offset + size > windowStart + static_cast<int64_t>(window.size()))
    {
      const int64_t want = std::min<int64_t>(std::max<int64_t>(size, IndexWindowBytes), this->FileSize - offset);
      window.resize(static_cast<std::size_t>(std::max<int64_t>(want, 0)));
      windowStart = offset;
      this->ReadRaw(offset, window.data(), static_cast<int64_t>(window.size()), record);
      if (static_cast<int64_t>(window.size()) < size)
      {
        this->Fail(record, offset, "file truncated");
      }
    }
    std::memcpy(data, window.data() + (offset - windowStart), static_cast<std::size_t>(size));
  };
  int64_t position = 0;
  while (position < this->FileSize)
  {
    this->IndexPosition = position;
    EclipseRecord record;
    record.headerOffset = position;
    if (this->FileSize - position < HeaderBytes)
    {
      this->Fail(nullptr, position, "file truncated inside a keyword header");
    }
    unsigned char raw[HeaderBytes];
    peek(position, raw, HeaderBytes, nullptr);
    if (BigEndian32(raw) != 16 || BigEndian32(raw + 20) != 16)
    {
      this->Fail(
        nullptr, position, "expected a 16-byte keyword header record; record markers disagree or the file is corrupt");
    }
    for (int c = 4; c < 20; ++c)
    {
      if (c >= 12 && c < 16)
      {
        continue; // the count
      }
      if (raw[c] < 32 || raw[c] > 126)
      {
        this->Fail(nullptr, position, "keyword header holds non-text bytes; corrupt file");
      }
    }
    record.name = Trimmed(reinterpret_cast<const char*>(raw + 4), 8);
    record.count = static_cast<int32_t>(BigEndian32(raw + 12));
    record.typeName = std::string(reinterpret_cast<const char*>(raw + 16), 4);
    if (!ParseType(record))
    {
      this->Fail(&record, position, "unknown data type '" + record.typeName + "'");
    }
    if (record.count < 0)
    {
      this->Fail(&record, position, "negative element count " + std::to_string(record.count));
    }
    record.dataOffset = position + HeaderBytes;
    const int64_t payload = record.count * record.elementSize;
    if (payload > this->FileSize - record.dataOffset)
    {
      this->Fail(&record, position,
        "declares " + std::to_string(record.count) + " elements of type " + record.typeName +
          " but the file is too short to hold them (truncated?)");
    }
    record.endOffset = record.dataOffset;
    if (payload > 0)
    {
      // Standard layout first: full blocks of 1000 numbers / 105 strings. Checked cheaply by
      // the first marker and the next header's marker; anything else is walked.
      const int64_t perBlock = ItemsPerBlock(record);
      const int64_t blocks = (record.count + perBlock - 1) / perBlock;
      const int64_t end = record.dataOffset + payload + 8 * blocks;
      unsigned char marker[4];
      peek(record.dataOffset, marker, 4, &record);
      bool standard =
        BigEndian32(marker) == std::min(record.count, perBlock) * record.elementSize && end <= this->FileSize;
      if (standard && end < this->FileSize)
      {
        standard = this->FileSize - end >= 4 && (peek(end, marker, 4, &record), BigEndian32(marker) == 16);
      }
      record.endOffset = standard ? end : this->WalkBlocks(record);
      record.standardBlocks = standard;
    }
    position = record.endOffset;
    this->Index.push_back(std::move(record));
  }
}

int64_t EclipseKeywordFile::WalkBlocks(const EclipseRecord& record) const
{
  int64_t position = record.dataOffset;
  int64_t remaining = record.count;
  while (remaining > 0)
  {
    unsigned char marker[4];
    this->ReadRaw(position, marker, 4, &record);
    const int64_t length = BigEndian32(marker);
    if (length == 0 || length % record.elementSize != 0 || length > remaining * record.elementSize)
    {
      this->Fail(&record, position,
        "data record of " + std::to_string(length) + " bytes does not fit the " + std::to_string(remaining) +
          " remaining elements of " + std::to_string(record.elementSize) + " bytes");
    }
    if (length + 8 > this->FileSize - position)
    {
      this->Fail(&record, position, "file truncated inside a data record");
    }
    this->ReadRaw(position + 4 + length, marker, 4, &record);
    if (BigEndian32(marker) != length)
    {
      this->Fail(&record, position + 4 + length, "data record end marker differs from its start marker");
    }
    position += length + 8;
    remaining -= length / record.elementSize;
  }
  return position;
}

template<typename Consumer>
void EclipseKeywordFile::ForEachBlock(
  const EclipseRecord& record, Consumer&& consume, int64_t firstBlock, int64_t endBlock) const
{
  if (record.count == 0 || record.elementSize == 0)
  {
    return;
  }
  // A range of blocks exists only for standard layouts, where block b starts at a known
  // offset; the whole record otherwise.
  const int64_t perBlock = ItemsPerBlock(record);
  int64_t position = record.dataOffset;
  int64_t remaining = record.count;
  int64_t done = 0;
  if (record.standardBlocks && (firstBlock > 0 || endBlock >= 0))
  {
    done = std::min(record.count, firstBlock * perBlock);
    const int64_t end = endBlock < 0 ? record.count : std::min(record.count, endBlock * perBlock);
    position += firstBlock * (perBlock * record.elementSize + 8);
    remaining = end - done;
  }
  std::vector<unsigned char> buffer;
  int64_t bufferStart = 0;
  int64_t bufferEnd = 0; // absolute offsets of the bytes held in buffer
  const auto ensure = [&](int64_t offset, int64_t size) -> const unsigned char* {
    if (offset < bufferStart || offset + size > bufferEnd)
    {
      const int64_t want = std::min(std::max(size, ChunkBytes), record.endOffset - offset);
      if (want < size)
      {
        this->Fail(&record, offset, "data records run past the end of the keyword");
      }
      buffer.resize(static_cast<std::size_t>(want));
      this->ReadRaw(offset, buffer.data(), want, &record);
      bufferStart = offset;
      bufferEnd = offset + want;
    }
    return buffer.data() + (offset - bufferStart);
  };
  while (remaining > 0)
  {
    const int64_t length = BigEndian32(ensure(position, 4));
    if (length == 0 || length % record.elementSize != 0 || length > remaining * record.elementSize)
    {
      this->Fail(&record, position,
        "data record of " + std::to_string(length) + " bytes does not fit the " + std::to_string(remaining) +
          " remaining elements of " + std::to_string(record.elementSize) + " bytes");
    }
    const unsigned char* block = ensure(position, length + 8);
    if (BigEndian32(block + 4 + length) != static_cast<uint32_t>(length))
    {
      this->Fail(&record, position + 4 + length, "data record end marker differs from its start marker");
    }
    const int64_t elements = length / record.elementSize;
    consume(block + 4, done, elements);
    done += elements;
    remaining -= elements;
    position += length + 8;
  }
}

namespace
{
std::atomic<int64_t> ParallelMinimum{ -1 };
}

int64_t EclipseKeywordFile::ParallelMinimumValues()
{
  int64_t value = ParallelMinimum.load();
  if (value < 0)
  {
    value = int64_t(4) << 20;
    if (const char* text = std::getenv("RESMR_PARALLEL_MIN_VALUES"))
    {
      int64_t parsed = 0;
      if (ParseWhole(text, text + std::strlen(text), parsed) && parsed > 0)
      {
        value = parsed;
      }
    }
    ParallelMinimum.store(value);
  }
  return value;
}

void EclipseKeywordFile::SetParallelMinimumValues(int64_t values)
{
  ParallelMinimum.store(std::max<int64_t>(1, values));
}

template<typename Consumer>
void EclipseKeywordFile::ForEachBlockInParallel(const EclipseRecord& record, Consumer&& consume) const
{
  if (!record.standardBlocks || record.count < ParallelMinimumValues())
  {
    this->ForEachBlock(record, consume);
    return;
  }
  // hardware_concurrency() reads sysfs: asked once, and only for large records.
  static const int64_t cores = std::max(1u, std::thread::hardware_concurrency());
  const int64_t perBlock = ItemsPerBlock(record);
  const int64_t blocks = (record.count + perBlock - 1) / perBlock;
  const int64_t workers = std::min<int64_t>({ cores, 8, blocks });
  if (workers < 2)
  {
    this->ForEachBlock(record, consume);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(workers));
  const auto work = [&](int64_t w) {
    try
    {
      this->ForEachBlock(record, consume, blocks * w / workers, blocks * (w + 1) / workers);
    }
    catch (...)
    {
      errors[static_cast<std::size_t>(w)] = std::current_exception();
    }
  };
  std::vector<std::thread> threads;
  for (int64_t w = 1; w < workers; ++w)
  {
    threads.emplace_back(work, w);
  }
  work(0);
  for (std::thread& thread : threads)
  {
    thread.join();
  }
  for (const std::exception_ptr& error : errors)
  {
    if (error)
    {
      std::rethrow_exception(error); // the first range's error: the earliest offset
    }
  }
}

template<typename T>
void EclipseKeywordFile::Read(const EclipseRecord& record, T* out) const
{
  if (!record.IsNumeric())
  {
    this->Fail(&record, record.headerOffset, "expected numeric data, found type " + record.typeName);
  }
  if (this->Formatted)
  {
    this->ReadFormatted(record, out);
    return;
  }
  this->ForEachBlockInParallel(record,
    [&](const unsigned char* data, int64_t first, int64_t n) { ConvertBigEndian(record.type, data, n, out + first); });
}

template<typename T>
void EclipseKeywordFile::ReadInPieces(
  const EclipseRecord& record, const std::function<void(const T*, int64_t, int64_t)>& sink) const
{
  if (!record.IsNumeric())
  {
    this->Fail(&record, record.headerOffset, "expected numeric data, found type " + record.typeName);
  }
  constexpr int64_t Piece = 4096;
  if (this->Formatted)
  {
    // Formatted files are small; one pass over the whole record, handed on in pieces.
    std::vector<T> all(static_cast<std::size_t>(record.count));
    this->ReadFormatted(record, all.data());
    for (int64_t first = 0; first < record.count; first += Piece)
    {
      sink(all.data() + first, first, std::min(Piece, record.count - first));
    }
    return;
  }
  this->ForEachBlockInParallel(record, [&](const unsigned char* data, int64_t first, int64_t n) {
    T values[Piece]; // per call, so each thread converts into its own
    for (int64_t done = 0; done < n; done += Piece)
    {
      const int64_t count = std::min(Piece, n - done);
      ConvertBigEndian(record.type, data + done * record.elementSize, count, values);
      sink(values, first + done, count);
    }
  });
}

template void EclipseKeywordFile::ReadInPieces<int32_t>(
  const EclipseRecord&, const std::function<void(const int32_t*, int64_t, int64_t)>&) const;
template void EclipseKeywordFile::ReadInPieces<float>(
  const EclipseRecord&, const std::function<void(const float*, int64_t, int64_t)>&) const;
template void EclipseKeywordFile::ReadInPieces<double>(
  const EclipseRecord&, const std::function<void(const double*, int64_t, int64_t)>&) const;

template void EclipseKeywordFile::Read<int32_t>(const EclipseRecord&, int32_t*) const;
template void EclipseKeywordFile::Read<float>(const EclipseRecord&, float*) const;
template void EclipseKeywordFile::Read<double>(const EclipseRecord&, double*) const;

void EclipseKeywordFile::ReadNumbers(const EclipseRecord& record, std::vector<double>& values) const
{
  if (!record.IsNumeric())
  {
    this->Fail(&record, record.headerOffset, "expected numeric data, found type " + record.typeName);
  }
  values.resize(static_cast<std::size_t>(record.count));
  this->Read(record, values.data());
}

std::vector<std::string> EclipseKeywordFile::ReadStrings(const EclipseRecord& record) const
{
  if (record.type != EclipseDataType::Character)
  {
    this->Fail(&record, record.headerOffset, "expected character data, found type " + record.typeName);
  }
  if (this->Formatted)
  {
    return this->ReadFormattedStrings(record);
  }
  std::vector<std::string> values;
  values.reserve(static_cast<std::size_t>(record.count));
  this->ForEachBlock(record, [&](const unsigned char* data, int64_t, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
    {
      values.push_back(Trimmed(
        reinterpret_cast<const char*>(data + i * record.elementSize), static_cast<std::size_t>(record.elementSize)));
    }
  });
  return values;
}

// ------------------------------------------------------------------ formatted files

void EclipseKeywordFile::IndexFormatted()
{
  TextCursor cursor(this->Descriptor, this->FileSize, 0);
  std::string token;
  bool quoted = false;
  int64_t start = 0;
  while ((this->IndexPosition = cursor.Offset, cursor.Next(token, quoted, start)))
  {
    EclipseRecord record;
    record.headerOffset = start;
    if (!quoted || token.size() > 8)
    {
      this->Fail(nullptr, start, "expected a quoted keyword name, found '" + token.substr(0, 20) + "'");
    }
    record.name = Trimmed(token.data(), token.size());
    int64_t count = 0;
    if (!cursor.Next(token, quoted, start) || quoted || !ParseInteger(token, count) || count < 0 || count > INT32_MAX)
    {
      this->Fail(&record, start, "expected an element count after the keyword name");
    }
    record.count = count;
    if (!cursor.Next(token, quoted, start) || !quoted || token.size() != 4)
    {
      this->Fail(&record, start, "expected a quoted 4-character type after the count");
    }
    record.typeName = token;
    if (!ParseType(record))
    {
      this->Fail(&record, start, "unknown data type '" + record.typeName + "'");
    }
    record.dataOffset = cursor.Offset;
    const bool strings = record.type == EclipseDataType::Character;
    const int64_t tokens = record.type == EclipseDataType::Message ? 0 : record.count;
    for (int64_t i = 0; i < tokens; ++i)
    {
      if (!cursor.Next(token, quoted, start))
      {
        this->Fail(&record, cursor.Offset,
          "file ends after " + std::to_string(i) + " of " + std::to_string(record.count) + " values");
      }
      if (quoted != strings)
      {
        this->Fail(&record, start,
          "value " + std::to_string(i + 1) + " of " + std::to_string(record.count) +
            (strings ? " is not a quoted string" : " is a string, expected a number") +
            " (declared count larger than the data?)");
      }
    }
    record.endOffset = cursor.Offset;
    if (this->Indexing == KeywordFileIndexing::UpToLastWholeRecord && tokens > 0 && record.endOffset == this->FileSize)
    {
      // Writers end every line; a last value touching the end may have been cut inside.
      this->Fail(&record, start, "the last value ends the file without a line end (cut inside it?)");
    }
    this->Index.push_back(std::move(record));
  }
  if (cursor.Offset < this->FileSize)
  {
    // Next() stops early only on an unterminated quoted string.
    int64_t rest = cursor.Offset;
    this->Fail(nullptr, rest, "unterminated quoted string");
  }
}

namespace
{
/// Converts the next token of a formatted record, value `i` (0-based), to T.
template<typename T>
void ReadFormattedValue(
  const EclipseKeywordFile& file, const EclipseRecord& record, TextCursor& cursor, int64_t i, T& out)
{
  std::string token;
  bool quoted = false;
  int64_t start = 0;
  if (!cursor.Next(token, quoted, start) || quoted)
  {
    file.Fail(&record, cursor.Offset, "missing value " + std::to_string(i + 1));
  }
  bool ok = true;
  switch (record.type)
  {
    case EclipseDataType::Integer:
    {
      int64_t value = 0;
      ok = ParseInteger(token, value) && value >= INT32_MIN && value <= INT32_MAX;
      out = static_cast<T>(value);
      break;
    }
    case EclipseDataType::Logical:
      ok = token == "T" || token == "F";
      out = token == "T" ? T(1) : T(0);
      break;
    default:
    {
      double value = 0;
      ok = ParseReal(token, value);
      out = Narrowed<T>(value);
      break;
    }
  }
  ok = ok && token.size() <= MaxNumberCharacters; // longer ones were cut by the cursor
  if (!ok)
  {
    file.Fail(&record, start,
      "value " + std::to_string(i + 1) + " '" + token.substr(0, 30) +
        (token.size() > 30 ? "...' (" + std::to_string(token.size()) + "+ characters)" : "'") + " is not a valid " +
        record.typeName);
  }
}
} // namespace

template<typename T>
void EclipseKeywordFile::ReadFormatted(const EclipseRecord& record, T* out) const
{
  TextCursor cursor(this->Descriptor, this->FileSize, record.dataOffset);
  for (int64_t i = 0; i < record.count; ++i)
  {
    ReadFormattedValue(*this, record, cursor, i, out[i]);
  }
}

std::vector<std::string> EclipseKeywordFile::ReadFormattedStrings(const EclipseRecord& record) const
{
  TextCursor cursor(this->Descriptor, this->FileSize, record.dataOffset);
  std::vector<std::string> values;
  std::string token;
  bool quoted = false;
  int64_t start = 0;
  for (int64_t i = 0; i < record.count; ++i)
  {
    if (!cursor.Next(token, quoted, start) || !quoted)
    {
      this->Fail(&record, cursor.Offset, "missing string " + std::to_string(i + 1));
    }
    values.push_back(Trimmed(token.data(), token.size()));
  }
  return values;
}

// ------------------------------------------------------------------ record cursor

struct EclipseRecordCursor::Text
{
  TextCursor Tokens;
};

EclipseRecordCursor::EclipseRecordCursor(const EclipseKeywordFile& file, const EclipseRecord& record)
  : File(file)
  , Header(record)
{
  if (!record.IsNumeric())
  {
    file.Fail(&record, record.headerOffset, "expected numeric data, found type " + record.typeName);
  }
  this->NextBlock = record.dataOffset;
  if (file.Formatted)
  {
    this->Formatted.reset(new Text{ TextCursor(file.Descriptor, file.FileSize, record.dataOffset) });
  }
}

EclipseRecordCursor::~EclipseRecordCursor() = default;

const unsigned char* EclipseRecordCursor::Ensure(int64_t offset, int64_t size)
{
  if (offset < this->BufferStart || offset + size > this->BufferEnd)
  {
    const int64_t want = std::min(std::max(size, ChunkBytes), this->Header.endOffset - offset);
    if (want < size)
    {
      this->File.Fail(&this->Header, offset, "data records run past the end of the keyword");
    }
    this->Buffer.resize(static_cast<std::size_t>(want));
    this->File.ReadRaw(offset, this->Buffer.data(), want, &this->Header);
    this->BufferStart = offset;
    this->BufferEnd = offset + want;
  }
  return this->Buffer.data() + (offset - this->BufferStart);
}

template<typename T>
void EclipseRecordCursor::Read(int64_t count, T* out)
{
  const EclipseRecord& record = this->Header;
  if (count < 0 || count > record.count - this->Done)
  {
    this->File.Fail(&record, record.headerOffset,
      "asked for values " + std::to_string(this->Done + 1) + " to " + std::to_string(this->Done + count) +
        " of a record of " + std::to_string(record.count));
  }
  if (this->Formatted)
  {
    for (int64_t i = 0; i < count; ++i)
    {
      ReadFormattedValue(this->File, record, this->Formatted->Tokens, this->Done + i, out[i]);
    }
    this->Done += count;
    return;
  }
  while (count > 0)
  {
    if (this->BlockLeft == 0)
    {
      // The next Fortran data record: checked as ForEachBlock checks it.
      const int64_t remaining = record.count - this->Done;
      const int64_t position = this->NextBlock;
      const int64_t length = BigEndian32(this->Ensure(position, 4));
      if (length == 0 || length % record.elementSize != 0 || length > remaining * record.elementSize)
      {
        this->File.Fail(&record, position,
          "data record of " + std::to_string(length) + " bytes does not fit the " + std::to_string(remaining) +
            " remaining elements of " + std::to_string(record.elementSize) + " bytes");
      }
      const unsigned char* block = this->Ensure(position, length + 8);
      if (BigEndian32(block + 4 + length) != static_cast<uint32_t>(length))
      {
        this->File.Fail(&record, position + 4 + length, "data record end marker differs from its start marker");
      }
      this->BlockData = position + 4;
      this->BlockLeft = length / record.elementSize;
      this->NextBlock = position + length + 8;
    }
    const int64_t n = std::min(count, this->BlockLeft);
    ConvertBigEndian(record.type, this->Ensure(this->BlockData, n * record.elementSize), n, out);
    out += n;
    count -= n;
    this->Done += n;
    this->BlockLeft -= n;
    this->BlockData += n * record.elementSize;
  }
}

template void EclipseRecordCursor::Read<int32_t>(int64_t, int32_t*);
template void EclipseRecordCursor::Read<float>(int64_t, float*);
template void EclipseRecordCursor::Read<double>(int64_t, double*);

} // namespace resmr
