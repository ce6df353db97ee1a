#include "ChunkStorage.h"

#include "ByteStream.h"

#include <lzo/lzo1x.h>

#include <algorithm>
#include <array>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{
namespace
{
void InitialiseLzo()
{
  static std::once_flag once;
  std::call_once(once, [] {
    if (lzo_init() != LZO_E_OK)
    {
      throw std::runtime_error("LZO library failed to initialise");
    }
  });
}

void CheckChunk(const uint8_t* data, uint64_t size, const ChunkRef& ref, const std::string& place, bool verify = true)
{
  if (ref.offset > size || ref.stored > size - ref.offset)
  {
    throw FileFormatError(place + ": lies outside the file");
  }
  if (verify && Crc32(data + ref.offset, ref.stored) != ref.crc)
  {
    throw FileFormatError(place + ": checksum mismatch (corrupt data)");
  }
  if (ref.raw > MaxDecompressedBytes(ref.stored))
  {
    throw FileFormatError(place + ": " + std::to_string(ref.stored) + " bytes cannot decompress to " +
      std::to_string(ref.raw) + " (corrupt)");
  }
}

std::vector<uint8_t> Decompress(const uint8_t* data, uint64_t size, const ChunkRef& ref, const std::string& place)
{
  CheckChunk(data, size, ref, place);
  std::vector<uint8_t> raw(ref.raw);
  lzo_uint length = ref.raw;
  const int status = lzo1x_decompress_safe(data + ref.offset, ref.stored, raw.data(), &length, nullptr);
  if (status != LZO_E_OK || length != ref.raw)
  {
    throw FileFormatError(place + ": does not decompress to its " + std::to_string(ref.raw) + " bytes");
  }
  return raw;
}
} // namespace

/// Most bytes `stored` bytes of LZO1X can decompress to: a match's length grows by 255 a
/// byte, so no byte stands for more than 255 (a margin for the stream's ends).
uint64_t MaxDecompressedBytes(uint64_t stored)
{
  return 256 * stored + 64;
}

std::vector<uint8_t> CompressChunk(const std::vector<uint8_t>& raw)
{
  InitialiseLzo();
  std::vector<uint8_t> stored(raw.size() + raw.size() / 16 + 64 + 3);
  // LZO's dictionary, one a thread, never zeroed: it needs no initial contents.
  thread_local std::unique_ptr<uint8_t[]> work(new uint8_t[LZO1X_1_MEM_COMPRESS]);
  lzo_uint length = 0;
  lzo1x_1_compress(raw.data(), raw.size(), stored.data(), &length, work.get());
  stored.resize(length);
  return stored;
}

std::vector<uint8_t> DecompressChunk(const uint8_t* data, uint64_t size, const ChunkRef& ref, const std::string& place)
{
  InitialiseLzo();
  return Decompress(data, size, ref, place);
}

std::vector<uint8_t> DecompressChunkPrefix(
  const uint8_t* data, uint64_t size, const ChunkRef& ref, uint64_t bytes, const std::string& place, bool verify)
{
  InitialiseLzo();
  if (bytes >= ref.raw && verify)
  {
    return Decompress(data, size, ref, place);
  }
  CheckChunk(data, size, ref, place, verify);
  // LZO stops before a run that would pass the output's end, leaving what it wrote whole; the
  // margin lets the run holding the last byte wanted finish, most of the time.
  std::vector<uint8_t> raw(std::min<uint64_t>(ref.raw, std::min<uint64_t>(bytes, ref.raw) + PrefixMarginBytes));
  lzo_uint length = raw.size();
  const int status = lzo1x_decompress_safe(data + ref.offset, ref.stored, raw.data(), &length, nullptr);
  const bool whole = status == LZO_E_OK && length == ref.raw;
  if (whole || (status == LZO_E_OUTPUT_OVERRUN && length >= bytes))
  {
    raw.resize(std::min<uint64_t>(bytes, ref.raw));
    return raw;
  }
  if (status != LZO_E_OUTPUT_OVERRUN)
  {
    throw FileFormatError(place + ": does not decompress to its " + std::to_string(ref.raw) + " bytes");
  }
  raw.assign(ref.raw, 0); // a run longer than the margin: the whole chunk
  length = ref.raw;
  if (lzo1x_decompress_safe(data + ref.offset, ref.stored, raw.data(), &length, nullptr) != LZO_E_OK ||
    length != ref.raw)
  {
    throw FileFormatError(place + ": does not decompress to its " + std::to_string(ref.raw) + " bytes");
  }
  raw.resize(bytes);
  return raw;
}

const uint8_t* MapReadOnlyFile(const std::string& path, uint64_t& size, int* keep)
{
  if (keep)
  {
    *keep = -1;
  }
  const int descriptor = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (descriptor < 0)
  {
    throw FileFormatError(path + ": cannot open: " + std::strerror(errno));
  }
  struct stat info;
  if (fstat(descriptor, &info) != 0 || !S_ISREG(info.st_mode))
  {
    close(descriptor);
    throw FileFormatError(path + ": not a regular file");
  }
  size = static_cast<uint64_t>(info.st_size);
  if (size == 0)
  {
    close(descriptor);
    return nullptr;
  }
  void* map = mmap(nullptr, size, PROT_READ, MAP_SHARED, descriptor, 0);
  const int mapError = errno;
  if (map == MAP_FAILED || !keep)
  {
    close(descriptor);
  }
  if (map == MAP_FAILED)
  {
    throw FileFormatError(path + ": cannot map: " + std::strerror(mapError));
  }
  if (keep)
  {
    *keep = descriptor;
  }
  return static_cast<const uint8_t*>(map);
}

void CheckMappedSize(int descriptor, uint64_t size, const std::string& path)
{
  struct stat info;
  if (descriptor >= 0 && fstat(descriptor, &info) == 0 && static_cast<uint64_t>(info.st_size) < size)
  {
    throw FileFormatError(path + ": the file is now " + std::to_string(info.st_size) + " bytes, " +
      std::to_string(size) + " when it was opened (cut or rewritten in place while open)");
  }
}

void CloseDescriptor(int& descriptor)
{
  if (descriptor >= 0)
  {
    close(descriptor);
    descriptor = -1;
  }
}

const uint8_t* MapOwnFile(const std::string& path, uint64_t minimumBytes, const char (&magic)[8],
  const std::string& kind, const std::string& extension, uint64_t& size, int& descriptor)
{
  const uint8_t* data = MapReadOnlyFile(path, size, &descriptor);
  std::string problem;
  if (size < minimumBytes)
  {
    problem = std::to_string(size) + " bytes, too short for a " + kind + " file (truncated?)";
  }
  else if (std::memcmp(data, magic, 8) != 0)
  {
    problem = "not a " + kind + " (" + extension + ") file (bad magic at byte 0)";
  }
  if (!problem.empty())
  {
    UnmapFile(data, size);
    CloseDescriptor(descriptor);
    throw FileFormatError(path + ": " + problem);
  }
  return data;
}

void UnmapFile(const uint8_t* data, uint64_t size)
{
  if (data)
  {
    munmap(const_cast<uint8_t*>(data), size);
  }
}

/// Eight bytes a step through eight tables ("slicing by 8"): the same CRC as one byte a step
/// with the first table, faster, as the builder checks every scratch block it reads.
uint32_t Crc32(const void* data, std::size_t size, uint32_t crc)
{
  static const auto tables = [] {
    std::array<std::array<uint32_t, 256>, 8> t{};
    for (uint32_t i = 0; i < 256; ++i)
    {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k)
      {
        c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      }
      t[0][i] = c;
    }
    for (uint32_t i = 0; i < 256; ++i)
    {
      for (int s = 1; s < 8; ++s)
      {
        t[s][i] = (t[s - 1][i] >> 8) ^ t[0][t[s - 1][i] & 0xFF];
      }
    }
    return t;
  }();
  crc = ~crc;
  const auto* bytes = static_cast<const uint8_t*>(data);
  for (; size >= 8; size -= 8, bytes += 8)
  {
    uint32_t low, high;
    std::memcpy(&low, bytes, 4); // little-endian, as every format here is
    std::memcpy(&high, bytes + 4, 4);
    low ^= crc;
    crc = tables[7][low & 0xFF] ^ tables[6][(low >> 8) & 0xFF] ^ tables[5][(low >> 16) & 0xFF] ^ tables[4][low >> 24] ^
      tables[3][high & 0xFF] ^ tables[2][(high >> 8) & 0xFF] ^ tables[1][(high >> 16) & 0xFF] ^ tables[0][high >> 24];
  }
  for (; size > 0; --size, ++bytes)
  {
    crc = tables[0][(crc ^ *bytes) & 0xFF] ^ (crc >> 8);
  }
  return ~crc;
}

std::vector<uint8_t> IndexTrailer(uint64_t indexOffset, const std::vector<uint8_t>& index, const char (&magic)[8])
{
  ByteWriter trailer;
  trailer.Put(indexOffset);
  trailer.Put(static_cast<uint64_t>(index.size()));
  trailer.Put(Crc32(index.data(), index.size()));
  trailer.Put(static_cast<uint32_t>(0));
  trailer.PutBytes(magic, 8);
  return std::move(trailer.Bytes);
}

std::pair<uint64_t, uint64_t> ReadIndexTrailer(
  const uint8_t* data, uint64_t size, uint64_t headerBytes, const char (&magic)[8], const std::string& path)
{
  ByteReader tail(data + size - IndexTrailerBytes, IndexTrailerBytes, path + ": trailer");
  const uint64_t indexOffset = tail.Get<uint64_t>(), indexSize = tail.Get<uint64_t>();
  const uint32_t indexCrc = tail.Get<uint32_t>();
  const uint32_t reserved = tail.Get<uint32_t>();
  char stored[8];
  tail.GetBytes(stored, 8);
  if (std::memcmp(stored, magic, 8) != 0)
  {
    throw FileFormatError(path + ": no index trailer at the end of the file (truncated or unfinished)");
  }
  if (reserved != 0)
  {
    throw FileFormatError(path + ": trailer bytes " + std::to_string(size - 12) + "-" + std::to_string(size - 9) +
      " (reserved) are not zero (corrupt)");
  }
  const uint64_t indexEnd = size - IndexTrailerBytes;
  if (indexOffset < headerBytes || indexOffset > indexEnd || indexSize != indexEnd - indexOffset)
  {
    throw FileFormatError(path + ": index at byte " + std::to_string(indexOffset) + " of " + std::to_string(indexSize) +
      " bytes does not fit a file of " + std::to_string(size) + " bytes (truncated or corrupt)");
  }
  if (Crc32(data + indexOffset, indexSize) != indexCrc)
  {
    throw FileFormatError(path + ": index checksum mismatch (bytes " + std::to_string(indexOffset) + "-" +
      std::to_string(indexEnd) + " are corrupt)");
  }
  return { indexOffset, indexSize };
}

} // namespace resmr
