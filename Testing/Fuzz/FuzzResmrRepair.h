// Shared by the fuzz targets of this project's own files (.resmr, .resmrp): after libFuzzer
// has mutated an input, every checksum is made right again (chunk CRCs, index CRC, trailer,
// the geometry id, header CRC), so that the mutations reach the parsers instead of stopping
// at the first CRC. Chunks may come unpacked (a reference whose stored and raw sizes agree
// is taken to point at raw bytes, which are LZO-compressed and appended before the index),
// so that mutations of a chunk's contents reach the decoders rather than LZO's (unless the
// bytes are an LZO stream of that size); other chunks stay as they are, with their CRC
// recomputed. UnpackChunks() turns a valid file into that form (how the unpacked seeds are
// made).
#pragma once

#include "ByteStream.h"
#include "FuzzReplay.h"
#include "MultiresolutionFile.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace resmr_fuzz
{

/// Where a format keeps what the repair needs.
struct FileLayout
{
  std::size_t headerBytes = 0;
  char trailerMagic[8] = {};
  /// The index size the header's counts call for (0 if they make no sense).
  std::function<uint64_t(const std::vector<uint8_t>& file)> indexBytes;
  /// Byte positions, inside an index of `size` bytes, of every 20-byte chunk reference
  /// (offset u64, stored u32, raw u32, crc u32).
  std::function<std::vector<std::size_t>(const std::vector<uint8_t>& file, uint64_t size)> references;
  /// Called with the repaired index before the header CRC is written (the .resmr geometry id).
  std::function<void(std::vector<uint8_t>& file, const std::vector<uint8_t>& index)> beforeHeaderCrc;
};

template<typename T>
T Load(const std::vector<uint8_t>& bytes, std::size_t at)
{
  T value{};
  if (at <= bytes.size() && sizeof(T) <= bytes.size() - at)
  {
    std::memcpy(&value, bytes.data() + at, sizeof(T));
  }
  return value;
}

template<typename T>
void Store(std::vector<uint8_t>& bytes, std::size_t at, const T& value)
{
  if (at <= bytes.size() && sizeof(T) <= bytes.size() - at)
  {
    std::memcpy(bytes.data() + at, &value, sizeof(T));
  }
}

/// Where the index lies: the trailer's offset and size when they fit the file exactly (so a
/// mutated count in the header still meets the index it disagrees with), else the end of the
/// file less the trailer and the size the header's counts call for. False if neither fits.
inline bool LocateIndex(const std::vector<uint8_t>& file, const FileLayout& layout, uint64_t& offset, uint64_t& size)
{
  if (file.size() < layout.headerBytes + resmr::IndexTrailerBytes)
  {
    return false;
  }
  const uint64_t end = file.size() - resmr::IndexTrailerBytes;
  offset = Load<uint64_t>(file, end);
  size = Load<uint64_t>(file, end + 8);
  if (offset >= layout.headerBytes && offset <= end && size == end - offset)
  {
    return true;
  }
  size = layout.indexBytes(file);
  if (size == 0 || size > end - layout.headerBytes)
  {
    return false;
  }
  offset = end - size;
  return true;
}

/// Whether the `stored` bytes at `offset` are an LZO stream of `raw` bytes (a packed chunk
/// that happens to be as long as its contents, not an unpacked one).
inline bool Decompresses(const std::vector<uint8_t>& file, uint64_t offset, uint32_t stored, uint32_t raw)
{
  resmr::ChunkRef ref;
  ref.offset = offset;
  ref.stored = stored;
  ref.raw = raw;
  ref.crc = resmr::Crc32(file.data() + offset, stored);
  try
  {
    resmr::DecompressChunk(file.data(), file.size(), ref, "repair");
    return true;
  }
  catch (const resmr::FileFormatError&)
  {
    return false;
  }
}

/// The mutated file with every checksum right again (see above). Inputs too short or without
/// a place for the index get only their header CRC (when they have a header). With `pack`
/// false, no chunk is taken for unpacked (only CRCs are recomputed).
inline std::vector<uint8_t> Repair(const uint8_t* data, std::size_t size, const FileLayout& layout, bool pack = true)
{
  std::vector<uint8_t> file(data, data + size);
  uint64_t indexOffset = 0, indexSize = 0;
  if (LocateIndex(file, layout, indexOffset, indexSize))
  {
    std::vector<uint8_t> index(file.begin() + static_cast<std::ptrdiff_t>(indexOffset),
      file.begin() + static_cast<std::ptrdiff_t>(indexOffset + indexSize));
    std::vector<uint8_t> packed; // compressed unpacked chunks, to go before the index
    for (std::size_t at : layout.references(file, indexSize))
    {
      const uint64_t offset = Load<uint64_t>(index, at);
      const uint32_t stored = Load<uint32_t>(index, at + 8), raw = Load<uint32_t>(index, at + 12);
      if (offset > indexOffset || stored > indexOffset - offset)
      {
        continue; // outside the data part: the reader must say so
      }
      const uint8_t* bytes = file.data() + offset;
      if (pack && stored == raw && stored > 0 && !Decompresses(file, offset, stored, raw))
      {
        const auto compressed = resmr::CompressChunk(std::vector<uint8_t>(bytes, bytes + stored));
        Store<uint64_t>(index, at, indexOffset + packed.size());
        Store<uint32_t>(index, at + 8, static_cast<uint32_t>(compressed.size()));
        Store<uint32_t>(index, at + 16, resmr::Crc32(compressed.data(), compressed.size()));
        packed.insert(packed.end(), compressed.begin(), compressed.end());
      }
      else
      {
        Store<uint32_t>(index, at + 16, resmr::Crc32(bytes, stored));
      }
    }
    file.resize(static_cast<std::size_t>(indexOffset));
    file.insert(file.end(), packed.begin(), packed.end());
    const uint64_t newOffset = file.size();
    file.insert(file.end(), index.begin(), index.end());
    const auto trailer = resmr::IndexTrailer(newOffset, index, layout.trailerMagic);
    file.insert(file.end(), trailer.begin(), trailer.end());
    if (layout.beforeHeaderCrc)
    {
      layout.beforeHeaderCrc(file, index);
    }
  }
  if (file.size() >= layout.headerBytes)
  {
    Store<uint32_t>(file, layout.headerBytes - 4, resmr::Crc32(file.data(), layout.headerBytes - 4));
  }
  return file;
}

/// A valid file with every chunk stored raw (stored = raw = its decompressed size), appended
/// after the data part; the form the repair packs again. Throws for a file that is not valid.
inline std::vector<uint8_t> UnpackChunks(const std::vector<uint8_t>& valid, const FileLayout& layout)
{
  std::vector<uint8_t> file = valid;
  uint64_t indexOffset = 0, indexSize = 0;
  if (!LocateIndex(file, layout, indexOffset, indexSize))
  {
    throw resmr::FileFormatError("unpack: no index");
  }
  std::vector<uint8_t> index(file.begin() + static_cast<std::ptrdiff_t>(indexOffset),
    file.begin() + static_cast<std::ptrdiff_t>(indexOffset + indexSize));
  file.resize(static_cast<std::size_t>(indexOffset));
  std::vector<uint8_t> raws;
  for (std::size_t at : layout.references(valid, indexSize))
  {
    resmr::ChunkRef ref;
    ref.offset = Load<uint64_t>(index, at);
    ref.stored = Load<uint32_t>(index, at + 8);
    ref.raw = Load<uint32_t>(index, at + 12);
    ref.crc = Load<uint32_t>(index, at + 16);
    const auto raw = resmr::DecompressChunk(valid.data(), valid.size(), ref, "unpack");
    Store<uint64_t>(index, at, file.size() + raws.size());
    Store<uint32_t>(index, at + 8, ref.raw);
    raws.insert(raws.end(), raw.begin(), raw.end());
  }
  file.insert(file.end(), raws.begin(), raws.end());
  const auto trailer = resmr::IndexTrailer(file.size(), index, layout.trailerMagic);
  file.insert(file.end(), index.begin(), index.end());
  file.insert(file.end(), trailer.begin(), trailer.end());
  return file;
}

/// The .resmr layout (MultiresolutionFile.cpp): 256-byte header with the region count at byte
/// 128, the model chunk count at 136 and the geometry id at 176; 192-byte region records with
/// their four chunk references from byte 104; 32-byte model chunk records (kind, part, then
/// the reference).
inline FileLayout ResmrLayout()
{
  constexpr std::size_t Header = 256, Record = 192, ModelRecord = 32, RegionsAt = 128, ModelAt = 136, IdAt = 176;
  FileLayout layout;
  layout.headerBytes = Header;
  std::memcpy(layout.trailerMagic, "RESMRIDX", 8);
  layout.indexBytes = [=](const std::vector<uint8_t>& file) -> uint64_t {
    const uint64_t regions = Load<uint64_t>(file, RegionsAt), model = Load<uint64_t>(file, ModelAt);
    return regions < (uint64_t(1) << 32) && model < (uint64_t(1) << 32) ? regions * Record + model * ModelRecord : 0;
  };
  // Records that fit in the index, as many as the header's counts say.
  const auto counts = [=](const std::vector<uint8_t>& file, uint64_t size, uint64_t& regions, uint64_t& model) {
    regions = std::min<uint64_t>(Load<uint64_t>(file, RegionsAt), size / Record);
    model = std::min<uint64_t>(Load<uint64_t>(file, ModelAt), (size - regions * Record) / ModelRecord);
  };
  layout.references = [=](const std::vector<uint8_t>& file, uint64_t size) {
    uint64_t regions = 0, model = 0;
    counts(file, size, regions, model);
    std::vector<std::size_t> at;
    for (uint64_t r = 0; r < regions; ++r)
    {
      for (std::size_t c = 0; c < 4; ++c)
      {
        at.push_back(static_cast<std::size_t>(r * Record + 104 + 20 * c));
      }
    }
    for (uint64_t m = 0; m < model; ++m)
    {
      at.push_back(static_cast<std::size_t>(regions * Record + m * ModelRecord + 8));
    }
    return at;
  };
  layout.beforeHeaderCrc = [=](std::vector<uint8_t>& file, const std::vector<uint8_t>& index) {
    uint64_t regions = 0, model = 0;
    counts(file, index.size(), regions, model);
    resmr::GeometryDigest digest;
    for (uint64_t r = 0; r < regions; ++r)
    {
      resmr::RegionRecord record;
      for (std::size_t c = 0; c < 4; ++c)
      {
        const std::size_t at = static_cast<std::size_t>(r * Record + 104 + 20 * c);
        record.chunks[c].stored = Load<uint32_t>(index, at + 8);
        record.chunks[c].raw = Load<uint32_t>(index, at + 12);
        record.chunks[c].crc = Load<uint32_t>(index, at + 16);
      }
      digest.Add(record);
    }
    for (uint64_t m = 0; m < model; ++m)
    {
      const std::size_t at = static_cast<std::size_t>(regions * Record + m * ModelRecord);
      resmr::ModelChunk chunk;
      chunk.kind = Load<uint32_t>(index, at);
      chunk.part = Load<uint32_t>(index, at + 4);
      chunk.chunk.stored = Load<uint32_t>(index, at + 16);
      chunk.chunk.raw = Load<uint32_t>(index, at + 20);
      chunk.chunk.crc = Load<uint32_t>(index, at + 24);
      digest.Add(chunk);
    }
    Store<uint64_t>(file, IdAt, digest.Id());
  };
  return layout;
}

/// The .resmrp layout (PropertyFile.cpp): 128-byte header with the version at byte 8, ny at 28,
/// nz at 36, the table count at 56 and (version 3) the rows a band at 60; per table 56 bytes
/// (name, step, report, days, range), then the packed table's reference and one a band of
/// every layer (version 2: one a layer).
inline FileLayout ResmrpLayout()
{
  constexpr std::size_t Header = 128, VersionAt = 8, ColumnsAt = 20, RowsAt = 28, LayersAt = 36, TablesAt = 56,
                        BandRowsAt = 60, BandColumnsAt = 64, TableHead = 56;
  FileLayout layout;
  layout.headerBytes = Header;
  std::memcpy(layout.trailerMagic, "RESMRPIX", 8);
  const auto tableBytes = [=](const std::vector<uint8_t>& file) -> uint64_t {
    const int64_t limit = int64_t(1) << 24;
    const int64_t layers = Load<int64_t>(file, LayersAt), rows = Load<int64_t>(file, RowsAt);
    const int64_t columns = Load<int64_t>(file, ColumnsAt);
    const uint32_t version = Load<uint32_t>(file, VersionAt);
    const int64_t bandRows = version >= 3 ? Load<uint32_t>(file, BandRowsAt) : rows;
    const int64_t bandColumns = version >= 5 ? Load<uint32_t>(file, BandColumnsAt) : columns;
    if (layers <= 0 || layers > limit || rows <= 0 || rows > limit || bandRows <= 0 || bandRows > rows ||
      columns <= 0 || columns > limit || bandColumns <= 0 || bandColumns > columns)
    {
      return 0;
    }
    // Bands are tiles of bandRows x bandColumns (version 5 on; whole rows before).
    const uint64_t bands = static_cast<uint64_t>((rows + bandRows - 1) / bandRows) *
      static_cast<uint64_t>((columns + bandColumns - 1) / bandColumns);
    // The packed table's chunk, the block ranges' and layer blocks' (version 4 on), then the
    // layers' bands.
    const uint64_t blocks = Load<uint32_t>(file, VersionAt) >= 4 ? 2 : 0;
    return TableHead + 20 * (static_cast<uint64_t>(layers) * bands + 1 + blocks);
  };
  layout.indexBytes = [=](const std::vector<uint8_t>& file) -> uint64_t {
    return Load<uint32_t>(file, TablesAt) * tableBytes(file);
  };
  layout.references = [=](const std::vector<uint8_t>& file, uint64_t size) {
    std::vector<std::size_t> at;
    const uint64_t bytes = tableBytes(file);
    if (bytes == 0)
    {
      return at;
    }
    const uint64_t tables = std::min<uint64_t>(Load<uint32_t>(file, TablesAt), size / bytes);
    for (uint64_t t = 0; t < tables; ++t)
    {
      for (uint64_t c = 0; c * 20 + TableHead < bytes; ++c)
      {
        at.push_back(static_cast<std::size_t>(t * bytes + TableHead + 20 * c));
      }
    }
    return at;
  };
  return layout;
}

/// The standalone main of a .resmr/.resmrp target: `--unpack IN OUT` writes IN with its chunks
/// stored uncompressed (how the unpacked seeds are made); otherwise every file named is
/// replayed through `test`, which must accept it whole when its name starts with "valid".
inline int ResmrReplayMain(const char* tool, int argc, char** argv, const FileLayout& layout, bool& mustBeValid,
  std::string& lastOutcome, int (*test)(const uint8_t*, std::size_t))
{
  LimitAddressSpace(2);
  if (argc == 4 && std::string(argv[1]) == "--unpack")
  {
    std::string contents;
    if (!ReadWholeFile(argv[2], contents))
    {
      std::fprintf(stderr, "cannot read %s\n", argv[2]);
      return 1;
    }
    const auto unpacked = UnpackChunks(std::vector<uint8_t>(contents.begin(), contents.end()), layout);
    std::FILE* out = std::fopen(argv[3], "wb");
    const bool ok = out && std::fwrite(unpacked.data(), 1, unpacked.size(), out) == unpacked.size();
    return out && std::fclose(out) == 0 && ok ? 0 : 1;
  }
  long count = 0;
  return ReplayMain(tool, argc, argv, count, [&](const std::string& path, const std::string& contents) {
    std::printf("%s (%zu bytes): ", path.c_str(), contents.size());
    std::fflush(stdout); // the name is out before a crash
    lastOutcome.clear();
    mustBeValid = path.substr(path.find_last_of('/') + 1).rfind("valid", 0) == 0;
    test(reinterpret_cast<const uint8_t*>(contents.data()), contents.size());
    std::printf("%s\n", lastOutcome.substr(0, 400).c_str());
    ++count;
  });
}

} // namespace resmr_fuzz
