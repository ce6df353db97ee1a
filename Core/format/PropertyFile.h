// Property tables kept apart from geometry (paper Sec. 5.2, 5.4 and 5.5): one .resmrp file
// holds any number of properties and time steps of one simulation, for the geometry of one
// .resmr file, so adding a property, a step or another simulation of the same grid never
// rewrites the geometry.
//
// Contract:
// - A table is one value a cell, float32 (integer arrays are exact up to 2^24), NaN where the
//   cell is inactive in the geometry or has no value. Each table is stored twice, LZO-
//   compressed with a CRC-32 a chunk: packed through the geometry's perfect spatial hash
//   (m^3 values, slot s holding the cell the geometry's HashCells names; the whole-model
//   view's 3D texture, Sec. 5.4) and layer by layer (nx ny values, i fastest; the single-
//   layer view's 2D texture, Sec. 5.2), each layer cut into bands, a chunk a band (ours): from
//   version 5 tiles of LayerTileSide x LayerTileSide columns (a property filter's leaf region
//   reads its own columns' tiles, not whole rows of the model), before it whole rows. Reading
//   one cell's value (a pick) decodes one band, not a layer. From version 4, each table also keeps the value range of
//   each block of ColumnBlockSide^2 columns over all layers, and of each block of
//   LayerBlockSide^2 columns in each layer with its mean (ours: PropertyFilter.h).
// - Layout (little-endian): header (128 bytes, CRC-32 at its end: magic, version, the
//   geometry id of the .resmr file, grid dimensions, hash table side, table count, rows a
//   band, columns a band (version 5 on)), chunks, index (per table: name, step, report
//   number, days, value range, packed chunk, block ranges and layer blocks chunks (version 4
//   on), then nz times the bands of a layer), trailer (index offset and size, index CRC, magic
//   "RESMRPIX"). Version 2 files (a chunk a layer, no band rows) are read as one band.
// - The bands' chunk references are read from the mapped index when a band is read, not held
//   (a table of the 1.26-billion-cell model has 300,000 bands): opening checks them all.
// - A file is written under a temporary name and renamed; one that names another geometry
//   is refused (CheckGeometry). Every header and index field is checked when the file is
//   opened (dimensions, sides, the table count against the index size, names, steps, value
//   ranges, every chunk inside the file and of the size its table calls for); failures throw
//   FileFormatError naming the file and the field or place.
#pragma once

#include "MultiresolutionFile.h"

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace resmr
{

class AtomicOutputFile;

struct PropertyTable
{
  std::string name;  ///< at most 31 bytes
  int32_t step = -1; ///< index of the report step; -1 for a static array
  int32_t reportNumber = 0;
  double days = 0;                ///< simulated time of the step
  float minimum = 0, maximum = 0; ///< over the cells with a value (NaN if none)
  ChunkRef packed;
  /// Value ranges of blocks of ColumnBlockSide x ColumnBlockSide columns over all layers
  /// (ColumnBlockRanges); raw 0 in files before version 4.
  ChunkRef blockRanges;
  /// Summaries of blocks of LayerBlockSide x LayerBlockSide columns, layer by layer
  /// (ReadLayerBlocks); raw 0 in files before version 4.
  ChunkRef layerBlocks;
  /// nz times the bands of a layer (layer k's band b at k * bands + b): the writer's; a file
  /// opened for reading leaves it empty and reads each from its index (LayerBand).
  std::vector<ChunkRef> layerBands;
};

/// Columns a side of the blocks whose value ranges a table keeps (ours: a property filter,
/// PropertyFilter.h, tells from them which regions it leaves whole or removes whole).
constexpr int64_t ColumnBlockSide = 8;

/// The range of a table's values over the active cells of a block of columns, all layers:
/// low > high when no active cell has a value; low is -infinity when an active cell has none
/// (NaN), so such a block never passes a filter whole.
struct ValueRange
{
  float low = 0, high = 0;
};

/// Columns a side of the blocks a table summarises layer by layer (ours: coarse regions a
/// property filter crosses are masked and painted from them, PropertyFilter.h).
constexpr int64_t LayerBlockSide = 16;

/// A block of columns in one layer: the range of its active cells' values (as ValueRange)
/// and their mean (NaN when none has a value).
struct BlockSummary
{
  float low = 0, high = 0, mean = 0;
};

/// Columns a side of the bands (tiles) of a layer files are written with: 16 KB of values; a
/// leaf region's box of about 80 x 80 columns decodes about twice its own cells.
constexpr int64_t LayerTileSide = 64;

/// A .resmrp file opened for reading (memory-mapped).
class PropertyFile
{
public:
  explicit PropertyFile(const std::string& path);
  ~PropertyFile();
  PropertyFile(const PropertyFile&) = delete;
  PropertyFile& operator=(const PropertyFile&) = delete;

  const std::string& Path() const { return this->FilePath; }
  uint64_t GeometryId() const { return this->Geometry; }
  /// Grid dimensions and hash table sides of the geometry the file was made for.
  const std::array<int64_t, 3>& Dimensions() const { return this->Dims; }
  const std::array<uint32_t, 3>& HashTableSides() const { return this->TableSides; }
  /// Rows and columns of each band of a layer (the last along i and j may hold fewer), bands
  /// along i and j, and bands in a layer (band (bi, bj) of a layer at bi + BandsAlongI() bj).
  int64_t BandRows() const { return this->RowsInBand; }
  int64_t BandColumns() const { return this->ColumnsInBand; }
  int64_t BandsAlongI() const { return (this->Dims[0] + this->ColumnsInBand - 1) / this->ColumnsInBand; }
  int64_t BandsAlongJ() const { return (this->Dims[1] + this->RowsInBand - 1) / this->RowsInBand; }
  int64_t Bands() const { return this->BandsAlongI() * this->BandsAlongJ(); }
  /// The chunk of band `band` of layer k of table `table`, from the index.
  ChunkRef LayerBand(std::size_t table, int64_t k, int64_t band) const;
  const std::vector<PropertyTable>& Tables() const { return this->Entries; }
  /// Index of table (name, step) or -1.
  int Find(const std::string& name, int32_t step) const;
  /// Throws FileFormatError if this file was not made for `geometry`.
  void CheckGeometry(const MultiresolutionFile& geometry) const;

  /// Whether the tables carry block ranges (version 4 on).
  bool HasBlockRanges() const { return this->FormatVersion >= 4; }
  /// Blocks along i and j: ceil(nx / ColumnBlockSide), ceil(ny / ColumnBlockSide).
  std::array<int64_t, 2> BlockCounts() const;
  /// The table's block ranges, block (bi, bj) at bi + bx * bj; empty before version 4.
  std::vector<ValueRange> ReadBlockRanges(std::size_t table) const;
  /// Layer blocks along i and j: ceil(nx / LayerBlockSide), ceil(ny / LayerBlockSide).
  std::array<int64_t, 2> LayerBlockCounts() const;
  /// The table's layer block summaries, block (bi, bj) of layer k at bi + bx (bj + by k); empty
  /// before version 4.
  std::vector<BlockSummary> ReadLayerBlocks(std::size_t table) const;
  /// The values of a box of cells, [lo, hi] inclusive and 0-based, i fastest, then j, then k:
  /// each band the box reaches in each layer, decoded up to the box's last row (its CRC
  /// checked the first time a band is read, as ReadCell).
  std::vector<float> ReadBox(
    std::size_t table, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) const;
  /// The packed table (m0 m1 m2 values, Sec. 5.4).
  std::vector<float> ReadPacked(std::size_t table) const;
  /// Layer k of the table (nx ny values).
  std::vector<float> ReadLayer(std::size_t table, int64_t k) const;
  /// A plane of cells of the table with one index fixed: `axis` 0, I = `index` (ny nz values,
  /// j fastest); 1, J = `index` (nx nz values, i fastest); 2, a layer (ReadLayer). Each decodes
  /// the bands the plane crosses (ours: the cut faces of an I/J/K range, CellRange.h).
  std::vector<float> ReadPlane(std::size_t table, int axis, int64_t index) const;
  /// The value of cell (i, j, k) in the table: the band of its layer that holds it decoded up to
  /// it only, the band's CRC checked the first time it is read (later reads of it, a cursor
  /// resting on one place, decode only).
  float ReadCell(std::size_t table, const std::array<int64_t, 3>& cell) const;
  /// Asks the system to start reading the band ReadCell will decode (a cold file's pages come
  /// from the disk all at once, not one table after the other); returns at once.
  void PrefetchCell(std::size_t table, const std::array<int64_t, 3>& cell) const;
  /// The stored bytes of a chunk (for copying into a new file).
  const uint8_t* ChunkBytes(const ChunkRef& ref) const { return this->Data + ref.offset; }

private:
  void CheckHeader(uint32_t tables, uint64_t indexSize, uint32_t version, uint32_t bandRows, uint32_t bandColumns);
  /// Rows of the bands in band row `bj`, columns of those in band column `bi`.
  int64_t RowsIn(int64_t bj) const;
  int64_t ColumnsIn(int64_t bi) const;
  /// Band (bi, bj) of layer k of table t, and where it lies, in words for errors.
  ChunkRef Band(std::size_t t, int64_t k, int64_t bi, int64_t bj, std::string& place) const;
  /// Decodes band (bi, bj) of layer k of table t up to its row `lastRow` (band rows from 0),
  /// its CRC checked the first time the band is read.
  std::vector<uint8_t> DecodeBand(std::size_t t, int64_t k, int64_t bi, int64_t bj, int64_t lastRow) const;
  PropertyTable ReadTable(ByteReader& index, uint32_t t, uint64_t indexOffset) const;
  std::vector<float> ReadValues(const ChunkRef& ref, uint64_t count, const std::string& place) const;
  std::string FilePath;
  const uint8_t* Data = nullptr;
  uint64_t Size = 0;
  int Descriptor = -1; ///< kept open to notice a file cut while mapped
  uint64_t Geometry = 0;
  std::array<int64_t, 3> Dims{};
  std::array<uint32_t, 3> TableSides{};
  int64_t RowsInBand = 1, ColumnsInBand = 1;
  uint32_t FormatVersion = 0;
  std::vector<PropertyTable> Entries;
  std::vector<uint64_t> BandRefsAt; ///< per table, where its first band reference lies in the file
  mutable std::mutex VerifiedLock;
  /// Per table, a bit a band whose CRC held (DecodeBand).
  mutable std::unordered_map<std::size_t, std::vector<uint64_t>> Verified;
};

/// Writes a .resmrp file for `geometry` under a temporary name; Commit() puts it in place.
class PropertyFileWriter
{
public:
  /// `bandRows`, `bandColumns`: a band's rows and columns (0: LayerTileSide, what files are
  /// written with; with only rows given, whole rows).
  PropertyFileWriter(
    const std::string& path, const MultiresolutionFile& geometry, int64_t bandRows = 0, int64_t bandColumns = 0);
  ~PropertyFileWriter();

  /// Adds a table from one value a cell (nx ny nz, ECLIPSE order; NaN: no value); cells
  /// inactive in the geometry get NaN in the layer tables, and in the packed table the value
  /// of the nearest active cell of their layer (coarse faces reach over them). Replaces an
  /// earlier table of the same name and step.
  void Add(PropertyTable table, const std::vector<float>& cellValues);
  /// The same for values that come a layer at a time (a generator's stream), so that no
  /// whole array is held: BeginTable, then AddLayer for k = 0 .. nz-1 in order, then EndTable
  /// stores what Add would store from the same values. Several tables may be open at once
  /// (their layer chunks interleave in the file); each holds its packed table (m0 m1 m2
  /// values, 4 bytes each) until EndTable. BeginTable returns the table's handle.
  std::size_t BeginTable(PropertyTable table);
  /// The next layer of open table `handle`: nx ny values, i fastest.
  void AddLayer(std::size_t handle, const float* layerValues);
  void EndTable(std::size_t handle);
  /// Copies every table of `older` (same geometry) that this writer does not hold yet; the
  /// layers of a file cut into other bands (an older version's) are cut into this file's.
  void CopyFrom(const PropertyFile& older);
  /// Writes the index and trailer and renames the file into place.
  void Commit();
  std::size_t TableCount() const { return this->Entries.size(); }

private:
  struct OpenTable
  {
    PropertyTable table;
    std::vector<uint8_t> packed;           ///< m0 m1 m2 floats, filled as the layers come
    float low = 0, high = 0;               ///< value range so far
    std::vector<ValueRange> blocks;        ///< block ranges so far (BlockCounts)
    std::vector<BlockSummary> layerBlocks; ///< layer block summaries of the layers so far
    int64_t layers = 0;                    ///< layers added so far
    bool open = false;
  };
  OpenTable& Opened(std::size_t handle);
  ChunkRef PutChunk(const std::vector<uint8_t>& raw, const std::string& what);
  ChunkRef CopyChunk(const PropertyFile& from, const ChunkRef& ref);
  /// Stores block ranges as the table's chunk.
  ChunkRef PutBlockRanges(const std::vector<ValueRange>& blocks, const PropertyTable& table);
  /// Widens `blocks` by layer k's values (nx ny, NaN where inactive) and active flags.
  void AddToBlockRanges(std::vector<ValueRange>& blocks, const float* values, int64_t k) const;
  /// Appends layer k's block summaries of its values (nx ny, NaN where inactive).
  void AddLayerBlocks(std::vector<BlockSummary>& summaries, const float* values, int64_t k) const;
  ChunkRef PutLayerBlocks(const std::vector<BlockSummary>& summaries, const PropertyTable& table);
  /// Layer values (nx ny floats as bytes) stored as this file's bands.
  void PutLayerBands(PropertyTable& table, const std::vector<uint8_t>& raw, int64_t k);
  void Write(const void* data, std::size_t size, const std::string& what);
  std::unique_ptr<AtomicOutputFile> Output;
  uint64_t Offset = 0;
  uint64_t Geometry = 0;
  std::array<int64_t, 3> Dims{};
  std::array<uint32_t, 3> TableSides{};
  int64_t RowsInBand = 1, ColumnsInBand = 1;
  uint64_t SlotCount = 0;                    ///< of the packed tables
  std::vector<std::vector<uint64_t>> Active; ///< per layer, a bit a cell
  std::vector<uint64_t> LayerSlotStart;      ///< nz + 1: where each layer's slots start below
  /// Slots with a source (the cell whose value the slot holds, see Add), by their source's
  /// layer: (slot, the source's place in its layer).
  std::vector<std::pair<uint32_t, uint32_t>> LayerSlots;
  std::vector<OpenTable> Open;
  std::vector<PropertyTable> Entries;
};

} // namespace resmr
