// The .resmr multiresolution file (paper Sec. 6.1): every region mesh of the diamond hierarchy,
// LZO-compressed one chunk each and concatenated, with an index of offsets, sizes, bounding
// volumes, errors and normal cones, laid out for memory mapping.
//
// Layout (little-endian):
//   header (160 bytes, CRC-32 at its end): magic, version, grid dimensions, hierarchy box,
//     position lattice, leaf level, Cmax
//   chunks, in any order: LZO1X-1 compressed, CRC-32 of the stored bytes in the index
//   index: one 192-byte record a region
//   trailer (32 bytes): index offset and size, CRC-32 of the index, magic "RESMRIDX"
// A file is only trusted once the trailer, the index CRC and every offset and size check out
// against the file; each chunk is checked (CRC, exact decompressed size, every reference in
// range) when read. Any failure throws MultiresolutionFileError naming the file and the place.
//
// Positions are stored on one lattice for the whole model (origin + integer * step), so a
// vertex two regions share decodes to the same bits in both, at every level (no cracks);
// steps are 2^-22 of the lateral extent and 2^-20 of the depth range (see ChooseLattice). Topological coordinates are
// stored as floats: integers are exact and rounding never carries a value across one, so no
// coordinate moves into another cell.
//
// Positions keep depth down (Core's convention); the viewer shows z = -depth.
#pragma once

#include "RegionMesh.h"

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace resmr
{

class AtomicOutputFile;

class MultiresolutionFileError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

struct MultiresolutionHeader
{
  static constexpr uint32_t Version = 1;
  std::array<int64_t, 3> dims{};
  std::array<double, 4> box{};          ///< hierarchy box: xmin, ymin, xmax, ymax
  std::array<double, 3> latticeOrigin{}; ///< x, y, depth
  std::array<double, 3> latticeStep{ 1, 1, 1 };
  int32_t leafLevel = 0;
  int32_t cmax = 0;
  uint64_t regionCount = 0; ///< read from the index (the header is written before it is known)
};

/// Where one compressed chunk lies.
struct ChunkRef
{
  uint64_t offset = 0;
  uint32_t stored = 0; ///< compressed bytes
  uint32_t raw = 0;    ///< bytes once decompressed
  uint32_t crc = 0;    ///< CRC-32 of the stored bytes
};

struct RegionRecord
{
  enum Chunk
  {
    Mesh = 0,
    Top = 1,
    Bottom = 2,
    Side = 3,
    ChunkCount = 4
  };
  int32_t level = 0;
  int64_t index = 0;
  int64_t columns = 0, activeCells = 0, vertices = 0;
  /// Bounding volume (x, y, depth min then max), enclosing both regions of the diamond and
  /// every descendant (Sec. 6.2).
  std::array<float, 6> bounds{};
  /// Model-space error, units of distance: the square root of the largest quadric error of
  /// the diamond's or any descendant's simplification (Lindstrom; Sec. 6.2); the same for
  /// both regions of a diamond and never smaller than a child's.
  float error = 0;
  float ownError = 0; ///< the same for this region's own simplification only
  std::array<float, 4> topCone{}, bottomCone{};
  std::array<ChunkRef, ChunkCount> chunks{};
};

/// Position lattice for a model of this extent (x, y, depth min and max).
void ChooseLattice(const std::array<double, 6>& extent, MultiresolutionHeader& header);

/// Writes a .resmr file under a temporary name; Commit() writes the index and renames it.
/// AddRegion may be called from several threads at once.
class MultiresolutionWriter
{
public:
  MultiresolutionWriter(const std::string& path, const MultiresolutionHeader& header);
  ~MultiresolutionWriter();

  /// Compresses and appends the region's chunks; fills the record's sizes, counts, chunk
  /// references and normal cones (bounds and errors are the caller's).
  void AddRegion(const RegionMesh& mesh, RegionRecord& record);
  /// Writes the index of `records` and the trailer and puts the file in place.
  void Commit(const std::vector<RegionRecord>& records);

  const std::string& Path() const;
  uint64_t BytesWritten() const { return this->Offset; }

private:
  void WriteOrThrow(const void* data, std::size_t size, const char* what);
  std::unique_ptr<AtomicOutputFile> Output;
  MultiresolutionHeader Header;
  std::mutex Lock;
  uint64_t Offset = 0;
};

/// A .resmr file opened for reading (memory-mapped).
class MultiresolutionFile
{
public:
  /// Maps and checks the file (header, trailer, index); throws MultiresolutionFileError.
  explicit MultiresolutionFile(const std::string& path);
  ~MultiresolutionFile();
  MultiresolutionFile(const MultiresolutionFile&) = delete;
  MultiresolutionFile& operator=(const MultiresolutionFile&) = delete;

  const MultiresolutionHeader& Header() const { return this->Head; }
  const std::vector<RegionRecord>& Regions() const { return this->Records; }
  uint64_t FileSize() const { return this->Size; }
  const std::string& Path() const { return this->FilePath; }

  /// Decodes region `i` of Regions(), checking every chunk; throws MultiresolutionFileError.
  RegionMesh ReadRegion(std::size_t i) const;
  /// The record of (level, index), or nullptr.
  const RegionRecord* Find(int32_t level, int64_t index) const;

private:
  std::vector<uint8_t> ReadChunk(const RegionRecord& record, int chunk) const;
  std::string FilePath;
  const uint8_t* Data = nullptr;
  uint64_t Size = 0;
  MultiresolutionHeader Head;
  std::vector<RegionRecord> Records;
};

/// CRC-32 (IEEE 802.3) of a byte range, continuing from `crc`.
uint32_t Crc32(const void* data, std::size_t size, uint32_t crc = 0);

} // namespace resmr
