// Little-endian byte streams of this project's binary files (paper Sec. 6.1: the .resmr file;
// property files; the builder's manifests): what ByteWriter puts, ByteReader gets back,
// refusing to run past the end.
#pragma once

#include "Errors.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace resmr
{

class ByteWriter
{
public:
  /// A value's bytes as they lie in memory (little-endian machines only, as the formats say):
  /// numbers, and std::arrays of them, which hold no padding.
  template<typename T>
  void Put(const T& value)
  {
    static_assert(std::is_trivially_copyable<T>::value, "raw bytes of a trivially copyable value only");
    this->PutBytes(&value, sizeof(T));
  }
  void PutBytes(const void* data, std::size_t size)
  {
    const auto* bytes = static_cast<const uint8_t*>(data);
    this->Bytes.insert(this->Bytes.end(), bytes, bytes + size);
  }
  void PutString(const std::string& text)
  {
    this->Put(static_cast<uint64_t>(text.size()));
    this->PutBytes(text.data(), text.size());
  }
  std::vector<uint8_t> Bytes;
};

class ByteReader
{
public:
  ByteReader() = default;
  ByteReader(const uint8_t* data, std::size_t size, std::string place) { this->Reset(data, size, std::move(place)); }
  void Reset(const uint8_t* data, std::size_t size, std::string place)
  {
    this->Data = data;
    this->Size = size;
    this->At = 0;
    this->Place = std::move(place);
  }
  template<typename T>
  T Get()
  {
    static_assert(std::is_trivially_copyable<T>::value, "raw bytes of a trivially copyable value only");
    T value{};
    this->GetBytes(&value, sizeof(T));
    return value;
  }
  /// Get() into an existing variable (its type says how many bytes).
  template<typename T>
  void Get(T& value)
  {
    value = this->Get<T>();
  }
  void GetBytes(void* out, std::size_t size)
  {
    const uint8_t* from = this->Skip(size);
    if (size > 0)
    {
      std::memcpy(out, from, size);
    }
  }
  std::string GetString()
  {
    const uint64_t size = this->Get<uint64_t>();
    const uint8_t* from = this->Skip(static_cast<std::size_t>(std::min<uint64_t>(size, this->Left() + 1)));
    return std::string(reinterpret_cast<const char*>(from), static_cast<std::size_t>(size));
  }
  /// The next `size` bytes, in place; throws if fewer are left.
  const uint8_t* Skip(std::size_t size)
  {
    if (size > this->Size - this->At)
    {
      throw FileFormatError(this->Place + ": ends early (needs " + std::to_string(size) + " more bytes at byte " +
        std::to_string(this->At) + " of " + std::to_string(this->Size) + ")");
    }
    const uint8_t* from = this->Data + this->At;
    this->At += size;
    return from;
  }
  std::size_t Left() const { return this->Size - this->At; }
  const std::string& Where() const { return this->Place; }

private:
  const uint8_t* Data = nullptr;
  std::size_t Size = 0;
  std::size_t At = 0;
  std::string Place;
};

} // namespace resmr
