// The .resmr multiresolution file (paper Sec. 6.1): every region mesh of the diamond hierarchy,
// LZO-compressed one chunk each and concatenated, with an index of offsets, sizes, bounding
// volumes, errors and normal cones, laid out for memory mapping.
//
// Layout (little-endian), version 10 (docs/file-formats.md gives each version's bytes: from 5
// on, the builder seals pinched-out runs when it extracts surfaces and readers must too, see
// RegionMesh.h; from 6 on, each simplified side paints every cell within the region's error of
// its place, SideSurfaceSimplification.h, so viewers may draw it in place of the exact side;
// from 7 on, a wall depth table, WallDepthTable.h; from 8 on, typical errors; from 9 on,
// footprints; from 10 on, layer groups, below):
//   header (256 bytes, CRC-32 at its end): magic, version, grid dimensions, hierarchy box,
//     position lattice, leaf level, Cmax, region and model-chunk counts, perfect-hash sizes,
//     geometry id, then the input's map placement (flags, MAPAXES' 6 values, MAPUNITS and
//     GRIDUNIT in 8 characters each; version 3 has none and reads as no MAPAXES)
//   chunks, in any order: LZO1X-1 compressed, CRC-32 of the stored bytes in the index
//   index: one 192-byte record a region, then one 32-byte record a model chunk
//   trailer (32 bytes): index offset and size, CRC-32 of the index, magic "RESMRIDX"
// Model chunks hold what belongs to the grid, not to a region: the active flags of each
// layer, and the property side of Sec. 5.3-5.4 (perfect spatial hash of the cells the
// extracted faces touch, the cell of each hash slot, top and bottom normals a slot) and the
// wall depth table (every wall's layer interfaces, for the viewer to find a wall pixel's
// layer from its depth). Property
// values never live here (Sec. 5.5): they go to property files (PropertyFile.h) that name
// this file's geometry id, so adding properties never rewrites geometry.
// A file is only trusted once the trailer, the index CRC and every offset and size check out
// against the file; each chunk is checked (CRC, exact decompressed size, every reference in
// range) when read. Any failure throws FileFormatError naming the file and the place.
//
// Ours, from version 10 on: a region's positions, most of its bytes, lie in layer groups of a
// few interfaces, each its own chunk whose prediction restarts, written back to back before
// its mesh chunk (which holds their sizes and CRCs; the record says where they begin), so a
// window of layers (an I/J/K range's, a property filter's) decompresses only the groups it
// reaches. Older versions keep the positions in the mesh chunk and still read.
//
// Positions are stored on one lattice for the whole model (origin + integer * step), so a
// vertex two regions share decodes to the same bits in both, at every level (no cracks);
// steps are 2^-22 of the lateral extent and 2^-20 of the depth range (see ChooseLattice). Topological coordinates are
// stored as floats: integers are exact and rounding never carries a value across one, so no
// coordinate moves into another cell.
//
// Positions keep depth down (Core's convention); the viewer shows z = -depth. They stay in
// grid coordinates: MAPAXES is only recorded, for viewers to apply as the grid readers do.
#pragma once

#include "ByteStream.h"
#include "ChunkStorage.h"
#include "CornerPointModel.h"
#include "PerfectSpatialHash.h"
#include "RegionMesh.h"
#include "WallDepthTable.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace resmr
{

struct MultiresolutionHeader
{
  static constexpr uint32_t Version = 10;
  static constexpr uint32_t OldestVersion = 3; ///< older files are refused
  /// The first version whose simplified sides paint every cell in place (see above).
  static constexpr uint32_t SidesInPlaceVersion = 6;
  /// From this version on a region record carries its typical error (RegionRecord::typicalError).
  static constexpr uint32_t TypicalErrorVersion = 8;
  /// From this version on `resmr build` writes the regions' footprints (ModelChunk::Footprints).
  static constexpr uint32_t FootprintsVersion = 9;
  /// From this version on a mesh chunk's positions lie in chunks of a few layers each
  /// (RegionRecord::layerGroups), so a window of layers decompresses only those it reaches.
  static constexpr uint32_t LayerGroupsVersion = 10;
  uint32_t version = Version; ///< the file's, when read
  std::array<int64_t, 3> dims{};
  std::array<double, 4> box{};           ///< hierarchy box: xmin, ymin, xmax, ymax
  std::array<double, 3> latticeOrigin{}; ///< x, y, depth
  std::array<double, 3> latticeStep{ 1, 1, 1 };
  int32_t leafLevel = 0;
  int32_t cmax = 0;
  uint64_t regionCount = 0;
  uint64_t modelChunkCount = 0;
  /// m: the packed tables hold m0 m1 m2 slots (Sec. 5.4)
  std::array<uint32_t, 3> hashTableSides{ 1, 1, 1 };
  /// r: the offset table holds r0 r1 r2 entries
  std::array<uint32_t, 3> hashOffsetSides{ 1, 1, 1 };
  uint64_t hashedCells = 0; ///< cells the extracted faces touch (filled slots)
  /// Identifies the geometry (a digest of every chunk's checksum): property files name it.
  uint64_t geometryId = 0;
  /// The input's MAPAXES, MAPUNITS and GRIDUNIT (units: 8 characters at most); apply with
  /// CornerPointGeometry::PlacementTransform.
  MapPlacement map;
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
  /// Ours: the typical distance of this region's own surfaces from the original grid's, the
  /// area-weighted root mean square of the quadric distances its ownError is the largest of;
  /// what the view estimates the picture's real error from (ViewSelection.h). Negative:
  /// unknown (files before TypicalErrorVersion).
  float typicalError = -1;
  std::array<float, 4> topCone{}, bottomCone{};
  std::array<ChunkRef, ChunkCount> chunks{};
  /// From LayerGroupsVersion on: the file offset where the mesh's layer-group chunks begin,
  /// back to back (the mesh chunk holds their sizes and checksums); 0 before.
  uint64_t layerGroups = 0;
};

/// A chunk of the grid rather than of a region.
struct ModelChunk
{
  enum Kind : uint32_t
  {
    ActiveLayer = 1, ///< part k: one bit a cell of layer k (i fastest), 1 = active
    HashOffsets = 2, ///< the offset table: r^3 x 3 uint16
    HashCells = 3,   ///< per slot, uint64 natural cell index i + nx (j + ny k); all ones if empty
    CellNormals = 4, ///< per slot, two uint16 (top, bottom face normal, NormalQuantization.h)
    WallDepths = 5,  ///< the wall depth table (WallDepthTable.h), from version 7 on; optional
    /// Per region (the index's order), float32 ti min, ti max, tj min, tj max of the nodes of
    /// the region and its descendants (0, -1, 0, -1: none): a coarse node is an average of the
    /// nodes it merged, so a region's own box may fall short of its leaves'.
    /// From version 9 on; optional; derived from the geometry, so left out of the geometry id.
    Footprints = 6
  };
  uint32_t kind = 0;
  uint32_t part = 0; ///< layer, or piece of a long array (pieces of at most 2^28 bytes)
  ChunkRef chunk;
};

/// The geometry id (MultiresolutionHeader::geometryId): a digest of every chunk's checksum and
/// sizes in index order (not of its offset), so the same geometry gives the same id whatever
/// the chunks' order in the file. Add every region record, then every model chunk.
class GeometryDigest
{
public:
  void Add(const RegionRecord& region);
  void Add(const ModelChunk& chunk);
  uint64_t Id() const { return (static_cast<uint64_t>(this->A) << 32) | this->B; }

private:
  uint32_t A = 0, B = 0x5eed;
};

/// Position lattice for a model of this extent (x, y, depth min and max).
void ChooseLattice(const std::array<double, 6>& extent, MultiresolutionHeader& header);

/// Positions (x, y, depth triples) moved to the nearest points of the header's lattice, the
/// very values ReadRegion() gives back for them; throws std::invalid_argument off the lattice.
void RoundToLattice(std::vector<double>& positions, const MultiresolutionHeader& header);

/// Bytes of one piece of a long model array (HashCells, CellNormals).
constexpr std::size_t ModelPieceBytes = std::size_t(1) << 28;

/// Compressed chunks appended to a scratch file, the body of a .resmr file before it is
/// assembled (AssembleMultiresolutionFile). Offsets are relative to this file. Thread-safe.
/// A build's workers (threads, MPI ranks: one file each) append here, so a killed build keeps
/// what it finished: reopen with `keepBytes`, the size recorded when a level was finished.
class ChunkFile
{
public:
  /// Creates `path`, or with keepBytes >= 0 reopens it cut to that many bytes.
  explicit ChunkFile(const std::string& path, int64_t keepBytes = -1);
  ~ChunkFile();
  ChunkFile(const ChunkFile&) = delete;
  ChunkFile& operator=(const ChunkFile&) = delete;

  /// Compresses and appends `raw`; `what` names it in errors.
  ChunkRef Put(const std::vector<uint8_t>& raw, const std::string& what);
  /// Encodes the region's chunks; fills the record's counts, chunk references and normal
  /// cones (bounds and errors are the caller's).
  void AddRegion(const RegionMesh& mesh, const MultiresolutionHeader& header, RegionRecord& record);
  /// Appends a long array as model chunks of at most ModelPieceBytes each.
  void AddModelArray(uint32_t kind, const void* data, std::size_t bytes, std::vector<ModelChunk>& out);
  /// Flushes to disk; the bytes written so far.
  uint64_t Sync();
  const std::string& Path() const { return this->FilePath; }

private:
  /// A compressed chunk and its reference (offset set once appended).
  using Stored = std::pair<std::vector<uint8_t>, ChunkRef>;
  Stored Compress(const std::vector<uint8_t>& raw, const std::string& what) const;
  /// Appends chunks back to back, others' never in between, and sets their offsets.
  void Append(std::vector<Stored>& run, const std::string& what);

  std::string FilePath;
  int Descriptor = -1;
  std::mutex Lock;
  uint64_t Offset = 0;
};

/// Where a record's chunks lie: which part (ChunkFile) of the assembly.
template<typename Record>
struct PartRecord
{
  int part = 0;
  Record record;
};

/// Writes the .resmr file: header, the parts' bytes in order, the index and trailer, under a
/// temporary name renamed into place (an older file stays untouched until then). Chunk
/// offsets are moved from their part to the file. Sets header.regionCount,
/// modelChunkCount and geometryId.
void AssembleMultiresolutionFile(const std::string& path, MultiresolutionHeader header,
  const std::vector<std::string>& parts, const std::vector<PartRecord<RegionRecord>>& regions,
  const std::vector<PartRecord<ModelChunk>>& model);

/// A ChunkFile mapped for reading back regions before the file is assembled (the builder's
/// last pass over its own output). Checks as MultiresolutionFile does.
class MappedChunkFile
{
public:
  explicit MappedChunkFile(const std::string& path);
  ~MappedChunkFile();
  MappedChunkFile(const MappedChunkFile&) = delete;
  MappedChunkFile& operator=(const MappedChunkFile&) = delete;
  RegionMesh ReadRegion(const RegionRecord& record, const MultiresolutionHeader& header) const;

private:
  std::string FilePath;
  const uint8_t* Data = nullptr;
  uint64_t Size = 0;
};

/// Chooses the layers (first, last; 0-based) of a region to decode from its nodes'
/// topological coordinates (MultiresolutionFile::ReadRegionLayers).
using LayerWindowChooser = std::function<std::array<int32_t, 2>(const std::vector<std::array<float, 2>>& topology)>;

/// A .resmr file opened for reading (memory-mapped).
class MultiresolutionFile
{
public:
  /// Maps and checks the file (header, trailer, index); throws FileFormatError.
  explicit MultiresolutionFile(const std::string& path);
  ~MultiresolutionFile();
  MultiresolutionFile(const MultiresolutionFile&) = delete;
  MultiresolutionFile& operator=(const MultiresolutionFile&) = delete;

  const MultiresolutionHeader& Header() const { return this->Head; }
  const std::vector<RegionRecord>& Regions() const { return this->Records; }
  uint64_t FileSize() const { return this->Size; }
  const std::string& Path() const { return this->FilePath; }

  /// Decodes region `i` of Regions(), checking every chunk; throws FileFormatError.
  /// The side surface comes as triangles (sideTriangles, simplified, Sec. 4.3); side quads
  /// are not stored (ExtractSurfaces() derives them from the mesh).
  RegionMesh ReadRegion(std::size_t i) const;
  /// Decodes the hexahedral mesh of region `i` in layers [first, last] (0-based, clamped to
  /// the model's) and nothing else (a range's cells need no stored surface): its layer 0 is
  /// layer `first` of the model (RegionMesh::firstLayer). Every cell's flags are still
  /// checked against the index. With every layer, ReadRegion().
  RegionMesh ReadRegionLayers(std::size_t i, int32_t first, int32_t last) const;
  /// ReadRegionLayers() with the window (first, last) chosen from the region's nodes'
  /// topological coordinates (ti, tj), which are read first.
  RegionMesh ReadRegionLayers(std::size_t i, const LayerWindowChooser& choose) const;
  /// Decodes only the surfaces and the nodes' topological coordinates (what the property
  /// side needs): positions, corners and cells are left empty.
  RegionMesh ReadRegionSurfaces(std::size_t i) const;

  const std::vector<ModelChunk>& ModelChunks() const { return this->Model; }
  /// Active flags of layer k (one byte a cell, i fastest).
  std::vector<uint8_t> ReadActiveLayer(int64_t k) const;
  /// The concatenated pieces of a long model array (HashOffsets, HashCells, CellNormals).
  std::vector<uint8_t> ReadModelArray(uint32_t kind) const;
  /// The perfect spatial hash of the cells the extracted faces touch (Sec. 5.4).
  PerfectSpatialHash ReadHash() const;
  /// The wall depth table (WallDepthTable.h); empty when the file has none (before version 7,
  /// or a model without walls). Throws FileFormatError for a damaged one.
  WallDepthTable ReadWallDepths() const;
  /// The regions' footprints in (i, j) (ModelChunk::Footprints), one a region; empty when the
  /// file has none. Throws FileFormatError for a damaged table.
  std::vector<std::array<float, 4>> ReadFootprints() const;
  /// The record of (level, index), or nullptr.
  const RegionRecord* Find(int32_t level, int64_t index) const;

private:
  void ReadMapPlacement(ByteReader& head);
  /// Reads and checks the index (every record against the header, the geometry id).
  void ReadIndex(uint64_t indexOffset, uint64_t indexSize);
  std::vector<uint8_t> ReadChunk(const RegionRecord& record, int chunk) const;
  std::vector<uint8_t> ReadChunk(const ChunkRef& ref, const std::string& place) const;
  std::string FilePath;
  const uint8_t* Data = nullptr;
  uint64_t Size = 0;
  int Descriptor = -1; ///< kept open to notice a file cut while mapped
  MultiresolutionHeader Head;
  std::vector<RegionRecord> Records;
  std::vector<ModelChunk> Model;
};

/// Regions (indices into Regions()) whose parent, (level - 1, index / 2), the file lacks: the
/// view reaches a region only through its parent, so these and all below them are never drawn.
/// Files built by earlier versions can hold a few (a triangle whose columns all went to its
/// diamond partner); rebuilding the file removes them.
std::vector<std::size_t> UnreachableRegions(const MultiresolutionFile& file);

} // namespace resmr
