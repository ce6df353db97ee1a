// The chunk container shared by the .resmr and .resmrp files (paper Sec. 6.1): data stored as
// LZO1X-1 compressed chunks, each checked by a CRC-32, read from memory-mapped files, with an
// index found through a trailer written last. Ours: the checks that let a damaged or
// truncated file fail with a message instead of a crash (the paper trusts its files).
#pragma once

#include "Errors.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace resmr
{

/// Where one compressed chunk lies.
struct ChunkRef
{
  uint64_t offset = 0;
  uint32_t stored = 0; ///< compressed bytes
  uint32_t raw = 0;    ///< bytes once decompressed
  uint32_t crc = 0;    ///< CRC-32 of the stored bytes
};

/// Largest chunk before compression: sizes are stored in 32 bits.
constexpr uint64_t MaxChunkBytes = uint64_t(1) << 31;
/// Most bytes `stored` bytes of LZO1X can decompress to.
uint64_t MaxDecompressedBytes(uint64_t stored);

/// LZO1X-1 compression, what every chunk of .resmr and .resmrp files holds.
std::vector<uint8_t> CompressChunk(const std::vector<uint8_t>& raw);
/// Checks a chunk of a mapped file (in the file, CRC, exact size) and decompresses it;
/// throws FileFormatError naming `place`.
std::vector<uint8_t> DecompressChunk(const uint8_t* data, uint64_t size, const ChunkRef& ref, const std::string& place);

/// The first `bytes` bytes of a chunk once decompressed, with DecompressChunk's checks (the CRC
/// over the whole stored chunk, unless `verify` is false: a caller that checked this chunk
/// already): LZO decodes front to back, so one value costs the chunk up to it (a picked cell's
/// value in a layer table). The output buffer reaches PrefixMarginBytes past the bytes wanted.
constexpr uint64_t PrefixMarginBytes = 1 << 16;
std::vector<uint8_t> DecompressChunkPrefix(const uint8_t* data, uint64_t size, const ChunkRef& ref, uint64_t bytes,
  const std::string& place, bool verify = true);

/// Maps a whole regular file read-only (nullptr for an empty one); throws
/// FileFormatError naming the file. Release with UnmapFile. With `keep`, the file
/// stays open and its descriptor is stored there (-1 if none; release with CloseDescriptor),
/// for CheckMappedSize.
const uint8_t* MapReadOnlyFile(const std::string& path, uint64_t& size, int* keep = nullptr);
void UnmapFile(const uint8_t* data, uint64_t size);
/// Maps one of this project's files as MapReadOnlyFile does (kept open, for CheckMappedSize)
/// and checks that it holds at least `minimumBytes` and starts with `magic`; throws
/// FileFormatError naming the file and the `kind` of file (e.g. "property", ".resmrp").
const uint8_t* MapOwnFile(const std::string& path, uint64_t minimumBytes, const char (&magic)[8],
  const std::string& kind, const std::string& extension, uint64_t& size, int& descriptor);
void CloseDescriptor(int& descriptor);
/// Throws FileFormatError naming the file if the open file is now shorter than the
/// `size` bytes mapped: reading a page past its end would kill the process (SIGBUS). Called
/// before each read of a chunk; a file cut during that read still can.
void CheckMappedSize(int descriptor, uint64_t size, const std::string& path);

/// CRC-32 (IEEE 802.3) of a byte range, continuing from `crc`.
uint32_t Crc32(const void* data, std::size_t size, uint32_t crc = 0);

/// The 32 bytes that end .resmr and .resmrp files (Sec. 6.1: written last, so a file whose
/// writing stopped has none): the index's offset, size and CRC, then an 8-byte magic.
constexpr std::size_t IndexTrailerBytes = 32;
std::vector<uint8_t> IndexTrailer(uint64_t indexOffset, const std::vector<uint8_t>& index, const char (&magic)[8]);
/// Checks the trailer of a mapped file of `size` bytes (magic, the index between the header
/// and the trailer, its CRC) and gives the index's offset and size; throws
/// FileFormatError naming `path` and the bytes at fault.
std::pair<uint64_t, uint64_t> ReadIndexTrailer(
  const uint8_t* data, uint64_t size, uint64_t headerBytes, const char (&magic)[8], const std::string& path);

} // namespace resmr
