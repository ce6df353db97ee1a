// ECLIPSE unformatted keyword file reader (paper Sec. 3: model input).
#include "EclipseBinaryReader.h"

#include "GrdeclError.h"

#include <cerrno>
#include <cstring>

namespace resmr
{
namespace
{
uint32_t BigEndian32(const unsigned char* p)
{
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

uint64_t BigEndian64(const unsigned char* p)
{
  return (uint64_t(BigEndian32(p)) << 32) | BigEndian32(p + 4);
}

std::string Trimmed(const char* text, std::size_t size)
{
  std::string value(text, size);
  const auto last = value.find_last_not_of(' ');
  value.erase(last == std::string::npos ? 0 : last + 1);
  return value;
}

int64_t ElementSize(const std::string& type)
{
  if (type == "INTE" || type == "REAL" || type == "LOGI")
  {
    return 4;
  }
  if (type == "DOUB")
  {
    return 8;
  }
  if (type == "CHAR")
  {
    return 8;
  }
  if (type == "MESS")
  {
    return 0;
  }
  if (type.size() == 4 && type[0] == 'C' && type[1] >= '0' && type[1] <= '9' &&
    type[2] >= '0' && type[2] <= '9' && type[3] >= '0' && type[3] <= '9')
  {
    const int length = std::stoi(type.substr(1)); // C0nn: strings of nn characters
    return length > 0 ? length : -1;
  }
  return -1;
}
} // namespace

EclipseBinaryReader::EclipseBinaryReader(const std::string& path)
  : Path(path)
{
  this->File = std::fopen(path.c_str(), "rb");
  if (!this->File)
  {
    throw GrdeclError(path, 0, "", std::string("cannot open file: ") + std::strerror(errno));
  }
  std::fseek(this->File, 0, SEEK_END);
  this->FileSize = std::ftell(this->File);
  std::fseek(this->File, 0, SEEK_SET);
}

EclipseBinaryReader::~EclipseBinaryReader()
{
  if (this->File)
  {
    std::fclose(this->File);
  }
}

bool EclipseBinaryReader::LooksLikeEclipseBinary(const std::string& path)
{
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file)
  {
    return false;
  }
  unsigned char head[28];
  const std::size_t got = std::fread(head, 1, sizeof(head), file);
  std::fclose(file);
  return got == sizeof(head) && BigEndian32(head) == 16 && BigEndian32(head + 20) == 16;
}

void EclipseBinaryReader::Fail(const std::string& what) const
{
  std::string where = "at byte " + std::to_string(this->Position);
  throw GrdeclError(this->Path, 0, this->Current.name, what + " (" + where + ")");
}

void EclipseBinaryReader::ReadExact(void* data, std::size_t size)
{
  if (std::fread(data, 1, size, this->File) != size)
  {
    this->Fail("file truncated");
  }
  this->Position += static_cast<int64_t>(size);
}

uint32_t EclipseBinaryReader::ReadMarker()
{
  unsigned char marker[4];
  this->ReadExact(marker, 4);
  return BigEndian32(marker);
}

bool EclipseBinaryReader::NextKeyword(EclipseKeywordHeader& header)
{
  if (this->DataPending)
  {
    this->SkipData();
  }
  if (this->Position == this->FileSize)
  {
    return false;
  }
  this->Current = EclipseKeywordHeader{};
  this->Current.offset = this->Position;
  if (this->ReadMarker() != 16)
  {
    this->Fail("expected a 16-byte keyword header record; not an ECLIPSE binary file or corrupt");
  }
  unsigned char raw[16];
  this->ReadExact(raw, 16);
  if (this->ReadMarker() != 16)
  {
    this->Fail("keyword header record has a bad end marker");
  }
  this->Current.name = Trimmed(reinterpret_cast<const char*>(raw), 8);
  this->Current.count = static_cast<int32_t>(BigEndian32(raw + 8));
  this->Current.type = std::string(reinterpret_cast<const char*>(raw + 12), 4);
  for (char c : this->Current.name + this->Current.type)
  {
    if (c < 32 || c > 126)
    {
      this->Fail("keyword header holds non-text bytes; corrupt file");
    }
  }
  const int64_t elementSize = ElementSize(this->Current.type);
  if (elementSize < 0)
  {
    this->Fail("unknown data type '" + this->Current.type + "'");
  }
  if (this->Current.count < 0)
  {
    this->Fail("negative element count " + std::to_string(this->Current.count));
  }
  if (this->Current.count * elementSize > this->FileSize - this->Position)
  {
    this->Fail("declares " + std::to_string(this->Current.count) +
      " elements but the file is too short to hold them (truncated?)");
  }
  this->DataPending = true;
  header = this->Current;
  return true;
}

template <typename Consumer>
void EclipseBinaryReader::ReadBlocks(int64_t elementSize, Consumer&& consume)
{
  int64_t remaining = this->Current.count;
  while (remaining > 0)
  {
    const uint32_t length = this->ReadMarker();
    if (length == 0 || length % elementSize != 0 || int64_t(length) > remaining * elementSize)
    {
      this->Fail("data record of " + std::to_string(length) + " bytes does not fit " +
        std::to_string(remaining) + " remaining elements of " + std::to_string(elementSize) +
        " bytes");
    }
    this->Block.resize(length);
    this->ReadExact(this->Block.data(), length);
    if (this->ReadMarker() != length)
    {
      this->Fail("data record end marker differs from its start marker");
    }
    const int64_t elements = length / elementSize;
    consume(this->Block.data(), elements);
    remaining -= elements;
  }
  this->DataPending = false;
}

void EclipseBinaryReader::ReadNumbers(std::vector<double>& values)
{
  const std::string& type = this->Current.type;
  if (type != "INTE" && type != "REAL" && type != "DOUB" && type != "LOGI")
  {
    this->Fail("expected numeric data, found type " + type);
  }
  values.clear();
  values.reserve(static_cast<std::size_t>(this->Current.count));
  const int64_t elementSize = ElementSize(type);
  enum class Kind
  {
    Integer,
    Real,
    Double,
    Logical
  };
  const Kind kind = type == "REAL" ? Kind::Real
    : type == "DOUB"               ? Kind::Double
    : type == "LOGI"               ? Kind::Logical
                                   : Kind::Integer;
  this->ReadBlocks(elementSize, [&](const unsigned char* data, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
    {
      const unsigned char* p = data + i * elementSize;
      switch (kind)
      {
        case Kind::Real:
        {
          const uint32_t bits = BigEndian32(p);
          float value;
          std::memcpy(&value, &bits, 4);
          values.push_back(value);
          break;
        }
        case Kind::Double:
        {
          const uint64_t bits = BigEndian64(p);
          double value;
          std::memcpy(&value, &bits, 8);
          values.push_back(value);
          break;
        }
        case Kind::Logical:
          values.push_back(BigEndian32(p) != 0 ? 1.0 : 0.0);
          break;
        case Kind::Integer:
          values.push_back(static_cast<int32_t>(BigEndian32(p)));
          break;
      }
    }
  });
}

void EclipseBinaryReader::ReadStrings(std::vector<std::string>& values)
{
  const int64_t elementSize = ElementSize(this->Current.type);
  if (this->Current.type != "CHAR" && this->Current.type[0] != 'C')
  {
    this->Fail("expected character data, found type " + this->Current.type);
  }
  values.clear();
  this->ReadBlocks(elementSize, [&](const unsigned char* data, int64_t n) {
    for (int64_t i = 0; i < n; ++i)
    {
      values.push_back(Trimmed(reinterpret_cast<const char*>(data + i * elementSize),
        static_cast<std::size_t>(elementSize)));
    }
  });
}

void EclipseBinaryReader::SkipData()
{
  const int64_t elementSize = ElementSize(this->Current.type);
  if (elementSize == 0 || this->Current.count == 0)
  {
    this->DataPending = false;
    return;
  }
  int64_t remaining = this->Current.count;
  while (remaining > 0)
  {
    const uint32_t length = this->ReadMarker();
    if (length == 0 || length % elementSize != 0 || int64_t(length) > remaining * elementSize ||
      int64_t(length) + 4 > this->FileSize - this->Position)
    {
      this->Fail("corrupt data record of " + std::to_string(length) + " bytes");
    }
    std::fseek(this->File, length, SEEK_CUR);
    this->Position += length;
    if (this->ReadMarker() != length)
    {
      this->Fail("data record end marker differs from its start marker");
    }
    remaining -= length / elementSize;
  }
  this->DataPending = false;
}

} // namespace resmr
