// Streamed writer of unformatted ECLIPSE keyword files (paper Sec. 3 input).
#include "EclipseKeywordWriter.h"

#include "Errors.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>

namespace resmr
{
namespace
{
void PutBigEndian32(unsigned char* out, uint32_t value)
{
  value = __builtin_bswap32(value);
  std::memcpy(out, &value, 4);
}

void PutBigEndian64(unsigned char* out, uint64_t value)
{
  value = __builtin_bswap64(value);
  std::memcpy(out, &value, 8);
}
} // namespace

EclipseKeywordWriter::EclipseKeywordWriter(const std::string& path)
  : Output(path)
{
}

void EclipseKeywordWriter::Fail(const std::string& what)
{
  this->Output.Discard();
  throw InputError(this->Output.Path(), 0, this->Keyword, what);
}

void EclipseKeywordWriter::PutBytes(const void* data, std::size_t size)
{
  if (!this->Output.IsOpen())
  {
    throw InputError(this->Output.Path(), 0, this->Keyword, "writer already committed or failed");
  }
  if (!this->Output.Write(data, size))
  {
    this->Fail(std::string("write failed (disk full?): ") + std::strerror(errno));
  }
}

void EclipseKeywordWriter::PutMarker(uint32_t value)
{
  unsigned char bytes[4];
  PutBigEndian32(bytes, value);
  this->PutBytes(bytes, 4);
}

void EclipseKeywordWriter::Begin(const std::string& name, const std::string& type, int64_t count)
{
  if (this->Remaining > 0)
  {
    this->Fail(
      "started keyword " + name + " with " + std::to_string(this->Remaining) + " values of this one still missing");
  }
  this->Keyword = name;
  if (name.empty() || name.size() > 8 || type.size() != 4 ||
    std::any_of(name.begin(), name.end(), [](char c) { return c < 32 || c > 126; }))
  {
    this->Fail("keyword names have 1 to 8 printable characters and types 4");
  }
  if (type != "INTE" && type != "REAL" && type != "DOUB" && type != "LOGI" && type != "CHAR" && type != "MESS")
  {
    this->Fail("cannot write type '" + type + "'");
  }
  if (count < 0 || count > std::numeric_limits<int32_t>::max())
  {
    this->Fail(
      std::to_string(count) + " values do not fit the 32-bit count of an ECLIPSE keyword header (at most 2147483647)");
  }
  if (type == "MESS" && count != 0)
  {
    this->Fail("MESS keywords carry no data");
  }
  this->Type = type == "INTE" ? EclipseDataType::Integer
    : type == "REAL"          ? EclipseDataType::Real
    : type == "DOUB"          ? EclipseDataType::Double
    : type == "LOGI"          ? EclipseDataType::Logical
    : type == "CHAR"          ? EclipseDataType::Character
                              : EclipseDataType::Message;
  this->ElementSize = type == "DOUB" || type == "CHAR" ? 8 : (type == "MESS" ? 0 : 4);
  unsigned char header[24];
  PutBigEndian32(header, 16);
  std::memset(header + 4, ' ', 8);
  std::memcpy(header + 4, name.data(), name.size());
  PutBigEndian32(header + 12, static_cast<uint32_t>(count));
  std::memcpy(header + 16, type.data(), 4);
  PutBigEndian32(header + 20, 16);
  this->PutBytes(header, sizeof(header));
  this->Remaining = count;
  this->LeftInBlock = 0;
}

template<typename T>
void EclipseKeywordWriter::AppendNumbers(const T* values, int64_t count)
{
  if (this->Type == EclipseDataType::Character || this->Type == EclipseDataType::Message)
  {
    this->Fail("numbers given for a keyword of strings or no data");
  }
  if (count > this->Remaining)
  {
    this->Fail(std::to_string(count) + " values given, only " + std::to_string(this->Remaining) +
      " left of the count in the header");
  }
  const int64_t size = this->ElementSize;
  while (count > 0)
  {
    if (this->LeftInBlock == 0)
    {
      this->LeftInBlock = std::min<int64_t>(this->Remaining, 1000);
      this->BlockBytes = this->LeftInBlock * size;
      this->PutMarker(static_cast<uint32_t>(this->BlockBytes));
    }
    const int64_t take = std::min(count, this->LeftInBlock);
    this->Scratch.resize(static_cast<std::size_t>(take * size));
    unsigned char* out = this->Scratch.data();
    for (int64_t i = 0; i < take; ++i)
    {
      switch (this->Type)
      {
        case EclipseDataType::Integer:
          PutBigEndian32(out + 4 * i, static_cast<uint32_t>(static_cast<int32_t>(values[i])));
          break;
        case EclipseDataType::Logical:
          PutBigEndian32(out + 4 * i, values[i] != T(0) ? 0xffffffffu : 0u); // ECLIPSE's true
          break;
        case EclipseDataType::Real:
        {
          const float value = static_cast<float>(values[i]);
          uint32_t bits;
          std::memcpy(&bits, &value, 4);
          PutBigEndian32(out + 4 * i, bits);
          break;
        }
        default:
        {
          const double value = static_cast<double>(values[i]);
          uint64_t bits;
          std::memcpy(&bits, &value, 8);
          PutBigEndian64(out + 8 * i, bits);
          break;
        }
      }
    }
    this->PutBytes(out, static_cast<std::size_t>(take * size));
    values += take;
    count -= take;
    this->Remaining -= take;
    this->LeftInBlock -= take;
    if (this->LeftInBlock == 0)
    {
      this->PutMarker(static_cast<uint32_t>(this->BlockBytes)); // closes the data record
    }
  }
}

void EclipseKeywordWriter::Append(const int32_t* values, int64_t count)
{
  this->AppendNumbers(values, count);
}
void EclipseKeywordWriter::Append(const float* values, int64_t count)
{
  this->AppendNumbers(values, count);
}
void EclipseKeywordWriter::Append(const double* values, int64_t count)
{
  this->AppendNumbers(values, count);
}

void EclipseKeywordWriter::Append(const std::vector<std::string>& values)
{
  if (this->Type != EclipseDataType::Character)
  {
    this->Fail("strings given for a numeric keyword");
  }
  const int64_t count = static_cast<int64_t>(values.size());
  if (count > this->Remaining)
  {
    this->Fail(std::to_string(count) + " strings given, only " + std::to_string(this->Remaining) +
      " left of the count in the header");
  }
  for (const std::string& value : values)
  {
    if (this->LeftInBlock == 0)
    {
      this->LeftInBlock = std::min<int64_t>(this->Remaining, 105);
      this->BlockBytes = this->LeftInBlock * 8;
      this->PutMarker(static_cast<uint32_t>(this->BlockBytes));
    }
    char text[8];
    std::memset(text, ' ', 8);
    std::memcpy(text, value.data(), std::min<std::size_t>(8, value.size()));
    this->PutBytes(text, 8);
    --this->Remaining;
    if (--this->LeftInBlock == 0)
    {
      this->PutMarker(static_cast<uint32_t>(this->BlockBytes));
    }
  }
}

void EclipseKeywordWriter::WriteStrings(const std::string& name, const std::vector<std::string>& values)
{
  this->Begin(name, "CHAR", static_cast<int64_t>(values.size()));
  this->Append(values);
}

void EclipseKeywordWriter::Commit()
{
  if (this->Remaining > 0)
  {
    this->Fail(std::to_string(this->Remaining) + " values missing at the end of the file");
  }
  this->Output.Commit();
}

} // namespace resmr
