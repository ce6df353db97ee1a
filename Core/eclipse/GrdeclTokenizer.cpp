// Streaming tokenizer for Eclipse ASCII decks (paper Sec. 3: model input).
#include "GrdeclTokenizer.h"

#include "Errors.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>

namespace resmr
{
namespace
{
constexpr std::size_t MaxTokenBytes = std::size_t(1) << 20;

struct CharClasses
{
  std::array<bool, 256> delimiter{};
  std::array<bool, 256> blank{};
  constexpr CharClasses()
  {
    for (unsigned char c : { ' ', '\t', '\r', '\n', '\f', '\v' })
    {
      this->delimiter[c] = true;
      this->blank[c] = true;
    }
    this->delimiter[static_cast<unsigned char>('/')] = true;
  }
};
constexpr CharClasses Classes;

inline bool IsDigit(char c)
{
  return static_cast<unsigned char>(c - '0') < 10;
}

constexpr double ExactPowersOfTen[] = { 1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14,
  1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22 };
} // namespace

bool ParseDouble(std::string_view word, double& out)
{
  const char* p = word.data();
  const char* const end = p + word.size();
  bool negative = false;
  if (p < end && (*p == '-' || *p == '+'))
  {
    negative = *p == '-';
    ++p;
  }
  uint64_t mantissa = 0;
  int significantDigits = 0;
  int exponent10 = 0;
  bool anyDigit = false;
  bool truncated = false;
  for (; p < end && IsDigit(*p); ++p)
  {
    anyDigit = true;
    if (significantDigits < 19)
    {
      mantissa = mantissa * 10 + static_cast<uint64_t>(*p - '0');
      significantDigits += mantissa != 0;
    }
    else
    {
      ++exponent10;
      truncated = true;
    }
  }
  if (p < end && *p == '.')
  {
    for (++p; p < end && IsDigit(*p); ++p)
    {
      anyDigit = true;
      if (significantDigits < 19)
      {
        mantissa = mantissa * 10 + static_cast<uint64_t>(*p - '0');
        significantDigits += mantissa != 0;
        --exponent10;
      }
      else
      {
        truncated = true;
      }
    }
  }
  if (!anyDigit)
  {
    return false; // also rejects nan, inf
  }
  if (p < end && (*p == 'e' || *p == 'E' || *p == 'd' || *p == 'D'))
  {
    ++p;
    bool negativeExponent = false;
    if (p < end && (*p == '-' || *p == '+'))
    {
      negativeExponent = *p == '-';
      ++p;
    }
    if (p == end || !IsDigit(*p))
    {
      return false;
    }
    int explicitExponent = 0;
    for (; p < end && IsDigit(*p); ++p)
    {
      if (explicitExponent < 100000)
      {
        explicitExponent = explicitExponent * 10 + (*p - '0');
      }
    }
    exponent10 += negativeExponent ? -explicitExponent : explicitExponent;
  }
  if (p != end)
  {
    return false;
  }
  // Clinger's fast path: exact when the mantissa and the power of ten are exact doubles.
  if (!truncated && mantissa < (uint64_t(1) << 53) && exponent10 >= -22 && exponent10 <= 22)
  {
    double value = static_cast<double>(mantissa);
    value = exponent10 < 0 ? value / ExactPowersOfTen[-exponent10] : value * ExactPowersOfTen[exponent10];
    out = negative ? -value : value;
    return true;
  }
  // Rare: long mantissas or large exponents. Correctly rounded, overflow rejected.
  char text[128];
  if (word.size() >= sizeof(text))
  {
    return false;
  }
  for (std::size_t i = 0; i < word.size(); ++i)
  {
    text[i] = (word[i] == 'd' || word[i] == 'D') ? 'e' : word[i];
  }
  const char* first = text[0] == '+' ? text + 1 : text;
  double value = 0;
  auto result = std::from_chars(first, text + word.size(), value);
  if (result.ec != std::errc() || result.ptr != text + word.size())
  {
    return false;
  }
  out = value;
  return true;
}

bool ParseNumberToken(std::string_view word, NumberToken& out)
{
  const std::size_t star = word.find('*');
  if (star == std::string_view::npos)
  {
    out.repeat = 1;
    out.isDefault = false;
    return ParseDouble(word, out.value);
  }
  if (star == 0 || star > 12)
  {
    return false;
  }
  int64_t repeat = 0;
  for (std::size_t i = 0; i < star; ++i)
  {
    if (!IsDigit(word[i]))
    {
      return false;
    }
    repeat = repeat * 10 + (word[i] - '0');
  }
  if (repeat <= 0)
  {
    return false;
  }
  out.repeat = repeat;
  if (star + 1 == word.size())
  {
    out.isDefault = true;
    out.value = 0.0;
    return true;
  }
  out.isDefault = false;
  return ParseDouble(word.substr(star + 1), out.value);
}

GrdeclTokenizer::GrdeclTokenizer(const std::string& path, std::size_t chunkSize)
  : Path(path)
  , ChunkSize(chunkSize < 4096 ? 4096 : chunkSize)
{
  this->File = std::fopen(path.c_str(), "rb");
  if (!this->File)
  {
    throw InputError(path, 0, "", std::string("cannot open file: ") + std::strerror(errno));
  }
  // Small files (most INCLUDEs) get a buffer of their own size, not a whole chunk.
  if (std::fseek(this->File, 0, SEEK_END) == 0)
  {
    const long size = std::ftell(this->File);
    std::rewind(this->File);
    if (size >= 0 && static_cast<std::size_t>(size) + 1 < this->ChunkSize)
    {
      this->ChunkSize = std::max<std::size_t>(static_cast<std::size_t>(size) + 1, 4096);
    }
  }
  this->Buffer.resize(this->ChunkSize);
}

GrdeclTokenizer::~GrdeclTokenizer()
{
  if (this->File)
  {
    std::fclose(this->File);
  }
}

bool GrdeclTokenizer::Refill(std::size_t keepFrom)
{
  if (this->Eof)
  {
    return false;
  }
  const std::size_t kept = this->EndOfData - keepFrom;
  if (keepFrom > 0 && kept > 0)
  {
    std::memmove(this->Buffer.data(), this->Buffer.data() + keepFrom, kept);
  }
  this->EndOfData = kept;
  this->Begin = this->Begin >= keepFrom ? this->Begin - keepFrom : 0;
  if (kept == this->Buffer.size())
  {
    if (kept >= MaxTokenBytes)
    {
      throw InputError(this->Path, this->Line, "", "token longer than 1 MiB (binary file?)");
    }
    this->Buffer.resize(this->Buffer.size() * 2);
  }
  const std::size_t got = std::fread(this->Buffer.data() + kept, 1, this->Buffer.size() - kept, this->File);
  if (got == 0)
  {
    if (std::ferror(this->File))
    {
      throw InputError(this->Path, this->Line, "", "read error");
    }
    this->Eof = true;
    return false;
  }
  this->BytesRead += got;
  this->EndOfData = kept + got;
  return true;
}

void GrdeclTokenizer::SkipRestOfLine()
{
  for (;;)
  {
    const char* data = this->Buffer.data();
    const void* newline = std::memchr(data + this->Begin, '\n', this->EndOfData - this->Begin);
    if (newline)
    {
      this->Begin = static_cast<std::size_t>(static_cast<const char*>(newline) - data);
      return; // the newline itself is consumed by Next(), which counts lines
    }
    this->Begin = this->EndOfData;
    if (!this->Refill(this->Begin))
    {
      return;
    }
  }
}

const Token& GrdeclTokenizer::Next()
{
  if (this->PushedBack)
  {
    this->PushedBack = false;
    return this->Current;
  }
  for (;;)
  {
    if (this->Begin >= this->EndOfData && !this->Refill(this->Begin))
    {
      this->Current = Token{ TokenKind::End, {}, this->Line, false };
      return this->Current;
    }
    const char c = this->Buffer[this->Begin];
    if (c == '\n')
    {
      ++this->Line;
      this->LineStart = true;
      ++this->Begin;
      continue;
    }
    if (Classes.blank[static_cast<unsigned char>(c)])
    {
      this->LineStart = false;
      ++this->Begin;
      continue;
    }
    if (c == '-')
    {
      if (this->Begin + 1 >= this->EndOfData)
      {
        this->Refill(this->Begin);
      }
      if (this->Begin + 1 < this->EndOfData && this->Buffer[this->Begin + 1] == '-')
      {
        this->SkipRestOfLine();
        continue;
      }
    }
    const bool atLineStart = this->LineStart;
    this->LineStart = false;
    if (c == '/')
    {
      ++this->Begin;
      this->Current = Token{ TokenKind::Slash, "/", this->Line, atLineStart };
      this->SkipRestOfLine(); // ECLIPSE: text after a record terminator is a comment
      return this->Current;
    }
    if (c == '\'' || c == '"')
    {
      // Quoted string on one line; an unterminated one ends at the end of the line.
      std::size_t length = 1; // bytes after Begin scanned so far (the opening quote)
      for (;;)
      {
        if (this->Begin + length >= this->EndOfData)
        {
          if (!this->Refill(this->Begin))
          {
            break;
          }
          continue;
        }
        const char ch = this->Buffer[this->Begin + length];
        if (ch == c || ch == '\n')
        {
          break;
        }
        ++length;
      }
      const std::size_t textStart = this->Begin + 1;
      const std::size_t textEnd = this->Begin + length;
      this->Current = Token{ TokenKind::String, std::string_view(this->Buffer.data() + textStart, textEnd - textStart),
        this->Line, atLineStart };
      const bool closed = textEnd < this->EndOfData && this->Buffer[textEnd] == c;
      this->Begin = closed ? textEnd + 1 : textEnd;
      return this->Current;
    }
    std::size_t length = 1;
    for (;;)
    {
      if (this->Begin + length >= this->EndOfData)
      {
        if (!this->Refill(this->Begin))
        {
          break;
        }
        continue;
      }
      if (Classes.delimiter[static_cast<unsigned char>(this->Buffer[this->Begin + length])])
      {
        break;
      }
      ++length;
    }
    if (length > MaxTokenBytes)
    {
      throw InputError(this->Path, this->Line, "", "token longer than 1 MiB (binary file?)");
    }
    this->Current =
      Token{ TokenKind::Word, std::string_view(this->Buffer.data() + this->Begin, length), this->Line, atLineStart };
    this->Begin += length;
    return this->Current;
  }
}

} // namespace resmr
