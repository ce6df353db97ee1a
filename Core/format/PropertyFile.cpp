// Property tables apart from geometry, packed through the perfect spatial hash (paper Sec.
// 5.2, 5.4, 5.5).
#include "PropertyFile.h"

#include "AtomicOutputFile.h"
#include "PerfectSpatialHash.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <stdexcept>
#include <sys/mman.h>
#include <unistd.h>

namespace resmr
{
namespace
{
constexpr char Magic[8] = { 'R', 'E', 'S', 'M', 'R', 'P', 'R', 'P' };
constexpr char TrailerMagic[8] = { 'R', 'E', 'S', 'M', 'R', 'P', 'I', 'X' };
constexpr uint32_t Version = 5;
constexpr uint32_t OldestVersion = 2; ///< a chunk a layer: read as one band a layer
constexpr std::size_t HeaderBytes = 128;
constexpr std::size_t NameBytes = 32;

void PutRef(ByteWriter& out, const ChunkRef& c)
{
  out.Put(c.offset);
  out.Put(c.stored);
  out.Put(c.raw);
  out.Put(c.crc);
}

ChunkRef GetRef(ByteReader& in)
{
  ChunkRef c;
  c.offset = in.Get<uint64_t>();
  c.stored = in.Get<uint32_t>();
  c.raw = in.Get<uint32_t>();
  c.crc = in.Get<uint32_t>();
  return c;
}

std::vector<uint8_t> HeaderOf(uint64_t geometry, const std::array<int64_t, 3>& dims,
  const std::array<uint32_t, 3>& tableSides, uint32_t tables, int64_t bandRows, int64_t bandColumns)
{
  ByteWriter head;
  head.PutBytes(Magic, 8);
  head.Put(Version);
  head.Put(geometry);
  head.Put(dims);
  head.Put(tableSides);
  head.Put(tables);
  head.Put(static_cast<uint32_t>(bandRows));
  head.Put(static_cast<uint32_t>(bandColumns));
  head.Bytes.resize(HeaderBytes - 4, 0);
  head.Put(Crc32(head.Bytes.data(), head.Bytes.size()));
  return std::move(head.Bytes);
}

/// Whether cell c of a layer is active, from the layer's flags as bits.
bool Bit(const std::vector<uint64_t>& bits, uint64_t c)
{
  return bits[c >> 6] >> (c & 63) & 1;
}

/// Replaces the cell of each hash slot by the cell whose value it holds: its own cell when
/// active, else the nearest active cell of the same layer (fewest i/j steps; ~0 if the layer
/// has none). Coarse levels' faces reach over inactive cells (Sec. 4.1 simplifies them with
/// the rest); padding their slots the way texture atlases pad charts paints them like their
/// surroundings instead of in the NaN colour. Finest-level faces belong to active cells only,
/// so exact views are unchanged.
void NearestActiveSources(std::vector<uint64_t>& slotCells, const std::vector<std::vector<uint64_t>>& active,
  const std::array<int64_t, 3>& dims)
{
  const uint64_t nx = static_cast<uint64_t>(dims[0]), ny = static_cast<uint64_t>(dims[1]);
  const uint64_t layer = nx * ny;
  std::vector<std::vector<uint32_t>> inactiveSlotsByLayer(active.size());
  for (std::size_t s = 0; s < slotCells.size(); ++s)
  {
    const uint64_t cell = slotCells[s];
    if (cell != ~uint64_t(0) && !Bit(active[cell / layer], cell % layer))
    {
      inactiveSlotsByLayer[cell / layer].push_back(static_cast<uint32_t>(s));
    }
  }
  std::vector<uint32_t> nearest;
  std::vector<uint32_t> queue;
  for (std::size_t k = 0; k < active.size(); ++k)
  {
    if (inactiveSlotsByLayer[k].empty())
    {
      continue;
    }
    // Breadth-first from every active column at once: each column learns its nearest one.
    const uint32_t unknown = ~uint32_t(0);
    nearest.assign(layer, unknown);
    queue.clear();
    for (uint64_t c = 0; c < layer; ++c)
    {
      if (Bit(active[k], c))
      {
        nearest[c] = static_cast<uint32_t>(c);
        queue.push_back(static_cast<uint32_t>(c));
      }
    }
    for (std::size_t head = 0; head < queue.size(); ++head)
    {
      const uint32_t c = queue[head];
      const uint64_t i = c % nx, j = c / nx;
      const uint64_t next[4] = { i > 0 ? c - 1 : layer, i + 1 < nx ? c + 1 : layer, j > 0 ? c - nx : layer,
        j + 1 < ny ? c + nx : layer };
      for (uint64_t n : next)
      {
        if (n < layer && nearest[n] == unknown)
        {
          nearest[n] = nearest[c];
          queue.push_back(static_cast<uint32_t>(n));
        }
      }
    }
    for (uint32_t s : inactiveSlotsByLayer[k])
    {
      const uint32_t source = nearest[slotCells[s] % layer];
      slotCells[s] = source == unknown ? ~uint64_t(0) : k * layer + source;
    }
    std::vector<uint32_t>().swap(inactiveSlotsByLayer[k]);
  }
}

/// Index bytes a table takes: name, step, report, days, range, then the packed table's chunk
/// and one chunk a band of every layer.
uint64_t TableRecordBytes(uint64_t layerBands, uint32_t version)
{
  return NameBytes + 4 + 4 + 8 + 4 + 4 + 20 * (layerBands + 1) + (version >= 4 ? 40 : 0);
}

int64_t BlocksAlong(int64_t cells, int64_t side = ColumnBlockSide)
{
  return (cells + side - 1) / side;
}

std::string TableName(const PropertyTable& t)
{
  return t.step < 0
    ? t.name
    : t.name + " of step " + std::to_string(t.step) + " (report " + std::to_string(t.reportNumber) + ")";
}
} // namespace

PropertyFile::PropertyFile(const std::string& path)
  : FilePath(path)
{
  this->Data =
    MapOwnFile(path, HeaderBytes + IndexTrailerBytes, Magic, "property", ".resmrp", this->Size, this->Descriptor);
  try
  {
    uint32_t crc;
    std::memcpy(&crc, this->Data + HeaderBytes - 4, 4);
    if (Crc32(this->Data, HeaderBytes - 4) != crc)
    {
      throw FileFormatError(path + ": header checksum mismatch (bytes 0-127 are corrupt)");
    }
    ByteReader head(this->Data + 8, HeaderBytes - 12, path + ": header");
    const uint32_t version = head.Get<uint32_t>();
    if (version < OldestVersion || version > Version)
    {
      throw FileFormatError(path + ": format version " + std::to_string(version) + "; this build reads versions " +
        std::to_string(OldestVersion) + " to " + std::to_string(Version));
    }
    this->Geometry = head.Get<uint64_t>();
    head.Get(this->Dims);
    head.Get(this->TableSides);
    const uint32_t tables = head.Get<uint32_t>();
    const uint32_t bandRows = version >= 3 ? head.Get<uint32_t>() : 0;
    const uint32_t bandColumns = version >= 5 ? head.Get<uint32_t>() : 0;
    this->FormatVersion = version;
    const auto [indexOffset, indexSize] = ReadIndexTrailer(this->Data, this->Size, HeaderBytes, TrailerMagic, path);
    this->CheckHeader(tables, indexSize, version, bandRows, bandColumns);
    ByteReader index(this->Data + indexOffset, indexSize, path + ": index");
    std::set<std::pair<std::string, int32_t>> seen;
    for (uint32_t t = 0; t < tables; ++t)
    {
      const uint64_t record = static_cast<uint64_t>(index.Skip(0) - this->Data);
      PropertyTable table = this->ReadTable(index, t, indexOffset);
      this->BandRefsAt.push_back(record + TableRecordBytes(0, version));
      if (!seen.insert({ table.name, table.step }).second)
      {
        throw FileFormatError(path + ": index table " + std::to_string(t) + " (" + TableName(table) +
          "): a second table of the same name and step (corrupt)");
      }
      this->Entries.push_back(std::move(table));
    }
  }
  catch (...)
  {
    UnmapFile(this->Data, this->Size);
    CloseDescriptor(this->Descriptor);
    throw;
  }
}

void PropertyFile::CheckHeader(
  uint32_t tables, uint64_t indexSize, uint32_t version, uint32_t bandRows, uint32_t bandColumns)
{
  // Sets RowsInBand and ColumnsInBand, which the index's size depends on.
  const auto bad = [&](const std::string& field, const std::string& value, const std::string& must) {
    throw FileFormatError(
      this->FilePath + ": header field '" + field + "' is " + value + ", must be " + must + " (corrupt)");
  };
  const int64_t maxDim = int64_t(1) << 24;
  for (int a = 0; a < 3; ++a)
  {
    if (this->Dims[a] <= 0 || this->Dims[a] > maxDim)
    {
      bad(
        std::string("dimensions (n") + "xyz"[a] + ")", std::to_string(this->Dims[a]), "1 to " + std::to_string(maxDim));
    }
    if (this->TableSides[a] < 1 || this->TableSides[a] > PerfectSpatialHash::MaxSide)
    {
      bad(
        "hash table sides", std::to_string(this->TableSides[a]), "1 to " + std::to_string(PerfectSpatialHash::MaxSide));
    }
  }
  // A layer's and the packed table's values fit one chunk (their sizes are 32-bit).
  const uint64_t layer = static_cast<uint64_t>(this->Dims[0] * this->Dims[1]);
  if (layer * 4 > std::numeric_limits<uint32_t>::max())
  {
    bad("dimensions", std::to_string(this->Dims[0]) + " x " + std::to_string(this->Dims[1]),
      "at most 2^30 cells a layer");
  }
  if (uint64_t(this->TableSides[0]) * this->TableSides[1] * this->TableSides[2] * 4 >
    std::numeric_limits<uint32_t>::max())
  {
    bad("hash table sides",
      std::to_string(this->TableSides[0]) + " x " + std::to_string(this->TableSides[1]) + " x " +
        std::to_string(this->TableSides[2]),
      "at most 2^30 slots");
  }
  if (version >= 3 && (bandRows < 1 || bandRows > this->Dims[1]))
  {
    bad("rows a band", std::to_string(bandRows), "1 to ny (" + std::to_string(this->Dims[1]) + ")");
  }
  if (version >= 5 && (bandColumns < 1 || bandColumns > this->Dims[0]))
  {
    bad("columns a band", std::to_string(bandColumns), "1 to nx (" + std::to_string(this->Dims[0]) + ")");
  }
  this->RowsInBand = version >= 3 ? static_cast<int64_t>(bandRows) : this->Dims[1];
  this->ColumnsInBand = version >= 5 ? static_cast<int64_t>(bandColumns) : this->Dims[0];
  for (std::size_t at = version >= 5 ? 68 : version >= 3 ? 64 : 60; at < HeaderBytes - 4; ++at)
  {
    if (this->Data[at] != 0)
    {
      bad("reserved bytes", "byte " + std::to_string(at) + " = " + std::to_string(this->Data[at]), "zero");
    }
  }
  const uint64_t recordBytes = TableRecordBytes(static_cast<uint64_t>(this->Dims[2] * this->Bands()), version);
  if (indexSize % recordBytes != 0 || indexSize / recordBytes != tables)
  {
    bad("table count", std::to_string(tables),
      "what the index of " + std::to_string(indexSize) + " bytes holds (" + std::to_string(recordBytes) +
        " bytes a table)");
  }
}

PropertyTable PropertyFile::ReadTable(ByteReader& index, uint32_t t, uint64_t indexOffset) const
{
  PropertyTable table;
  char name[NameBytes];
  index.GetBytes(name, NameBytes);
  table.name.assign(name, strnlen(name, NameBytes));
  table.step = index.Get<int32_t>();
  table.reportNumber = index.Get<int32_t>();
  table.days = index.Get<double>();
  table.minimum = index.Get<float>();
  table.maximum = index.Get<float>();
  table.packed = GetRef(index);
  if (this->FormatVersion >= 4)
  {
    table.blockRanges = GetRef(index);
    table.layerBlocks = GetRef(index);
  }
  // The bands' references stay in the mapped index (LayerBand); each is checked below.
  const int64_t bands = this->Bands();
  const uint64_t bandCount = static_cast<uint64_t>(this->Dims[2] * bands);
  const uint8_t* bandRefs = index.Skip(static_cast<std::size_t>(bandCount * 20));
  const std::string place = this->FilePath + ": index table " + std::to_string(t) + " (" + TableName(table) + ")";
  const auto fail = [&](const std::string& what) { throw FileFormatError(place + ": " + what + " (corrupt)"); };
  const bool text = std::all_of(table.name.begin(), table.name.end(), [](char c) { return c >= 0x20 && c <= 0x7e; });
  const bool padded =
    std::all_of(name + std::min(table.name.size(), NameBytes), name + NameBytes, [](char c) { return c == 0; });
  if (table.name.empty() || table.name.size() >= NameBytes || !text || !padded)
  {
    fail("the name is not 1 to 31 printable characters, NUL-padded");
  }
  if (table.step < -1 || table.reportNumber < 0 || !std::isfinite(table.days) ||
    (table.step < 0 && (table.reportNumber != 0 || table.days != 0)))
  {
    fail("step " + std::to_string(table.step) + ", report " + std::to_string(table.reportNumber) + " or day " +
      std::to_string(table.days) + " impossible");
  }
  // NaN both when no cell has a value, else an ordered range.
  const bool none = std::isnan(table.minimum) && std::isnan(table.maximum);
  if (!none && !(table.minimum <= table.maximum))
  {
    fail("value range " + std::to_string(table.minimum) + " to " + std::to_string(table.maximum) + " impossible");
  }
  const uint64_t slots = uint64_t(this->TableSides[0]) * this->TableSides[1] * this->TableSides[2];
  for (int64_t n = -1; n < static_cast<int64_t>(bandCount); ++n)
  {
    ChunkRef band;
    if (n >= 0)
    {
      ByteReader at(bandRefs + 20 * n, 20, place);
      band = GetRef(at);
    }
    const ChunkRef& c = n < 0 ? table.packed : band;
    const int64_t b = n < 0 ? 0 : n % bands, bi = b % this->BandsAlongI(), bj = b / this->BandsAlongI();
    const std::string what = n < 0
      ? std::string("packed table")
      : "layer " + std::to_string(n / bands + 1) + (bands > 1 ? " band " + std::to_string(b + 1) : "");
    if (c.offset < HeaderBytes || c.offset > indexOffset || c.stored > indexOffset - c.offset)
    {
      fail(what + " at byte " + std::to_string(c.offset) + " of " + std::to_string(c.stored) +
        " bytes lies outside the file");
    }
    const uint64_t values = n < 0 ? slots : static_cast<uint64_t>(this->ColumnsIn(bi) * this->RowsIn(bj));
    if (c.raw != values * 4)
    {
      fail(what + " of " + std::to_string(c.raw) + " bytes for " + std::to_string(values) + " values");
    }
  }
  if (this->FormatVersion >= 4)
  {
    const ChunkRef& c = table.blockRanges;
    const auto blocks = this->BlockCounts();
    const uint64_t bytes = static_cast<uint64_t>(blocks[0] * blocks[1]) * sizeof(ValueRange);
    if (c.offset < HeaderBytes || c.offset > indexOffset || c.stored > indexOffset - c.offset || c.raw != bytes)
    {
      fail("block ranges at byte " + std::to_string(c.offset) + " (" + std::to_string(c.stored) + " bytes stored, " +
        std::to_string(c.raw) + " raw) lie outside the file or are not " + std::to_string(bytes) + " bytes");
    }
    const ChunkRef& l = table.layerBlocks;
    const auto layerBlocks = this->LayerBlockCounts();
    const uint64_t summaries =
      static_cast<uint64_t>(layerBlocks[0] * layerBlocks[1] * this->Dims[2]) * sizeof(BlockSummary);
    if (l.offset < HeaderBytes || l.offset > indexOffset || l.stored > indexOffset - l.offset || l.raw != summaries)
    {
      fail("layer blocks at byte " + std::to_string(l.offset) + " (" + std::to_string(l.stored) + " bytes stored, " +
        std::to_string(l.raw) + " raw) lie outside the file or are not " + std::to_string(summaries) + " bytes");
    }
  }
  return table;
}

PropertyFile::~PropertyFile()
{
  UnmapFile(this->Data, this->Size);
  CloseDescriptor(this->Descriptor);
}

int PropertyFile::Find(const std::string& name, int32_t step) const
{
  for (std::size_t t = 0; t < this->Entries.size(); ++t)
  {
    if (this->Entries[t].name == name && this->Entries[t].step == step)
    {
      return static_cast<int>(t);
    }
  }
  return -1;
}

void PropertyFile::CheckGeometry(const MultiresolutionFile& geometry) const
{
  if (geometry.Header().geometryId != this->Geometry || geometry.Header().dims != this->Dims ||
    geometry.Header().hashTableSides != this->TableSides)
  {
    throw FileFormatError(this->FilePath + ": made for another geometry than " + geometry.Path() +
      " (geometry id or grid differs; was the .resmr built again?): write its properties anew with resmr "
      "add-properties, to another file (-o) or after removing this one");
  }
}

std::vector<float> PropertyFile::ReadValues(const ChunkRef& ref, uint64_t count, const std::string& place) const
{
  CheckMappedSize(this->Descriptor, this->Size, this->FilePath);
  const auto raw = DecompressChunk(this->Data, this->Size, ref, place);
  if (raw.size() != count * 4)
  {
    throw FileFormatError(
      place + ": " + std::to_string(raw.size()) + " bytes, " + std::to_string(count * 4) + " expected");
  }
  std::vector<float> values(count);
  std::memcpy(values.data(), raw.data(), raw.size());
  return values;
}

std::vector<float> PropertyFile::ReadPacked(std::size_t table) const
{
  const PropertyTable& t = this->Entries.at(table);
  const uint64_t slots = uint64_t(this->TableSides[0]) * this->TableSides[1] * this->TableSides[2];
  return this->ReadValues(t.packed, slots,
    this->FilePath + ": packed table of " + TableName(t) + " at byte " + std::to_string(t.packed.offset));
}

std::array<int64_t, 2> PropertyFile::BlockCounts() const
{
  return { BlocksAlong(this->Dims[0]), BlocksAlong(this->Dims[1]) };
}

std::vector<ValueRange> PropertyFile::ReadBlockRanges(std::size_t table) const
{
  const PropertyTable& t = this->Entries.at(table);
  if (!this->HasBlockRanges())
  {
    return {};
  }
  const auto blocks = this->BlockCounts();
  const std::string place =
    this->FilePath + ": block ranges of " + TableName(t) + " at byte " + std::to_string(t.blockRanges.offset);
  const auto floats = this->ReadValues(t.blockRanges, static_cast<uint64_t>(blocks[0] * blocks[1]) * 2, place);
  std::vector<ValueRange> ranges(floats.size() / 2);
  for (std::size_t b = 0; b < ranges.size(); ++b)
  {
    ranges[b] = { floats[2 * b], floats[2 * b + 1] };
    if (std::isnan(ranges[b].low) || std::isnan(ranges[b].high))
    {
      throw FileFormatError(place + ": block " + std::to_string(b) + " has a NaN bound (corrupt)");
    }
  }
  return ranges;
}

std::array<int64_t, 2> PropertyFile::LayerBlockCounts() const
{
  return { BlocksAlong(this->Dims[0], LayerBlockSide), BlocksAlong(this->Dims[1], LayerBlockSide) };
}

std::vector<BlockSummary> PropertyFile::ReadLayerBlocks(std::size_t table) const
{
  const PropertyTable& t = this->Entries.at(table);
  if (!this->HasBlockRanges())
  {
    return {};
  }
  const auto blocks = this->LayerBlockCounts();
  const std::string place =
    this->FilePath + ": layer blocks of " + TableName(t) + " at byte " + std::to_string(t.layerBlocks.offset);
  const uint64_t count = static_cast<uint64_t>(blocks[0] * blocks[1] * this->Dims[2]);
  const auto floats = this->ReadValues(t.layerBlocks, count * 3, place);
  std::vector<BlockSummary> summaries(count);
  for (std::size_t b = 0; b < summaries.size(); ++b)
  {
    summaries[b] = { floats[3 * b], floats[3 * b + 1], floats[3 * b + 2] };
  }
  for (std::size_t b = 0; b < summaries.size(); ++b)
  {
    const BlockSummary& s = summaries[b];
    const bool none = s.low > s.high && std::isnan(s.mean);
    if (std::isnan(s.low) || std::isnan(s.high) || (!none && !(s.low <= s.high)))
    {
      throw FileFormatError(place + ": block " + std::to_string(b) + " has an impossible range (corrupt)");
    }
  }
  return summaries;
}

std::vector<float> PropertyFile::ReadBox(
  std::size_t table, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi) const
{
  static_cast<void>(this->Entries.at(table)); // throws for a table the file lacks
  for (int a = 0; a < 3; ++a)
  {
    if (lo[a] < 0 || hi[a] >= this->Dims[a] || lo[a] > hi[a])
    {
      throw std::out_of_range(this->FilePath + ": box " + std::to_string(lo[a] + 1) + "-" + std::to_string(hi[a] + 1) +
        " along " + "IJK"[a] + " lies outside the grid");
    }
  }
  const int64_t width = hi[0] - lo[0] + 1, rows = hi[1] - lo[1] + 1;
  std::vector<float> box(static_cast<std::size_t>(width * rows * (hi[2] - lo[2] + 1)));
  const int64_t cols = this->ColumnsInBand, bandRows = this->RowsInBand;
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
  {
    float* slab = box.data() + (k - lo[2]) * width * rows;
    for (int64_t bj = lo[1] / bandRows; bj <= hi[1] / bandRows; ++bj)
    {
      const int64_t first = std::max(lo[1], bj * bandRows),
                    last = std::min(hi[1], bj * bandRows + this->RowsIn(bj) - 1);
      for (int64_t bi = lo[0] / cols; bi <= hi[0] / cols; ++bi)
      {
        // The band decoded up to the box's last row only: a leaf region's box is a few rows
        // of a band.
        const auto raw = this->DecodeBand(table, k, bi, bj, last - bj * bandRows);
        const int64_t left = std::max(lo[0], bi * cols), right = std::min(hi[0], bi * cols + this->ColumnsIn(bi) - 1);
        for (int64_t j = first; j <= last; ++j)
        {
          const std::size_t at =
            static_cast<std::size_t>(((j - bj * bandRows) * this->ColumnsIn(bi) + left - bi * cols) * 4);
          std::memcpy(slab + (j - lo[1]) * width + (left - lo[0]), raw.data() + at,
            static_cast<std::size_t>(right - left + 1) * 4);
        }
      }
    }
  }
  return box;
}

int64_t PropertyFile::RowsIn(int64_t bj) const
{
  return std::min(this->RowsInBand, this->Dims[1] - bj * this->RowsInBand);
}

int64_t PropertyFile::ColumnsIn(int64_t bi) const
{
  return std::min(this->ColumnsInBand, this->Dims[0] - bi * this->ColumnsInBand);
}

ChunkRef PropertyFile::LayerBand(std::size_t table, int64_t k, int64_t band) const
{
  static_cast<void>(this->Entries.at(table)); // throws for a table the file lacks
  if (k < 0 || k >= this->Dims[2] || band < 0 || band >= this->Bands())
  {
    throw std::out_of_range(
      this->FilePath + ": no band " + std::to_string(band + 1) + " of layer " + std::to_string(k + 1));
  }
  ByteReader at(this->Data + this->BandRefsAt[table] + 20 * static_cast<uint64_t>(k * this->Bands() + band), 20,
    this->FilePath + ": index");
  return GetRef(at);
}

ChunkRef PropertyFile::Band(std::size_t t, int64_t k, int64_t bi, int64_t bj, std::string& place) const
{
  const int64_t band = bj * this->BandsAlongI() + bi;
  const ChunkRef ref = this->LayerBand(t, k, band);
  place = this->FilePath + ": layer " + std::to_string(k + 1) + " of " + TableName(this->Entries[t]) +
    (this->Bands() > 1 ? " (band " + std::to_string(band + 1) + ")" : std::string()) + " at byte " +
    std::to_string(ref.offset);
  return ref;
}

std::vector<uint8_t> PropertyFile::DecodeBand(std::size_t t, int64_t k, int64_t bi, int64_t bj, int64_t lastRow) const
{
  std::string place;
  const ChunkRef ref = this->Band(t, k, bi, bj, place);
  CheckMappedSize(this->Descriptor, this->Size, this->FilePath);
  const uint64_t band = static_cast<uint64_t>(k * this->Bands() + bj * this->BandsAlongI() + bi);
  bool verified = false;
  {
    const std::lock_guard<std::mutex> lock(this->VerifiedLock);
    std::vector<uint64_t>& bits = this->Verified[t];
    bits.resize(static_cast<std::size_t>((this->Dims[2] * this->Bands() + 63) / 64), 0);
    verified = bits[band >> 6] >> (band & 63) & 1;
  }
  const uint64_t bytes = static_cast<uint64_t>((lastRow + 1) * this->ColumnsIn(bi)) * 4;
  auto raw = DecompressChunkPrefix(this->Data, this->Size, ref, bytes, place, !verified);
  if (!verified)
  {
    const std::lock_guard<std::mutex> lock(this->VerifiedLock);
    this->Verified[t][band >> 6] |= uint64_t(1) << (band & 63);
  }
  return raw;
}

std::vector<float> PropertyFile::ReadLayer(std::size_t table, int64_t k) const
{
  if (k < 0 || k >= this->Dims[2])
  {
    throw std::out_of_range(this->FilePath + ": no layer " + std::to_string(k + 1));
  }
  return this->ReadBox(table, { 0, 0, k }, { this->Dims[0] - 1, this->Dims[1] - 1, k });
}

std::vector<float> PropertyFile::ReadPlane(std::size_t table, int axis, int64_t index) const
{
  if (axis == 2)
  {
    return this->ReadLayer(table, index);
  }
  if (axis < 0 || axis > 2 || index < 0 || index >= this->Dims[axis])
  {
    const char* names[3] = { "I", "J", "K" };
    throw std::out_of_range(this->FilePath + ": no plane " +
      (axis >= 0 && axis <= 2 ? std::string(names[axis]) + " = " : "along axis " + std::to_string(axis) + ", ") +
      std::to_string(index + 1));
  }
  const int64_t nx = this->Dims[0], ny = this->Dims[1], nz = this->Dims[2];
  std::array<int64_t, 3> lo{ 0, 0, 0 }, hi{ nx - 1, ny - 1, nz - 1 };
  lo[axis] = hi[axis] = index;
  // A box one cell thick: i fastest, then j, then k, which is the plane's order either way.
  return this->ReadBox(table, lo, hi);
}

float PropertyFile::ReadCell(std::size_t table, const std::array<int64_t, 3>& cell) const
{
  static_cast<void>(this->Entries.at(table)); // throws for a table the file lacks
  for (int a = 0; a < 3; ++a)
  {
    if (cell[a] < 0 || cell[a] >= this->Dims[a])
    {
      throw std::out_of_range(this->FilePath + ": no cell (" + std::to_string(cell[0] + 1) + ", " +
        std::to_string(cell[1] + 1) + ", " + std::to_string(cell[2] + 1) + ")");
    }
  }
  const int64_t bi = cell[0] / this->ColumnsInBand, bj = cell[1] / this->RowsInBand;
  const int64_t row = cell[1] - bj * this->RowsInBand;
  const auto raw = this->DecodeBand(table, cell[2], bi, bj, row);
  const std::size_t at = static_cast<std::size_t>(row * this->ColumnsIn(bi) + cell[0] - bi * this->ColumnsInBand);
  float value = 0;
  std::memcpy(&value, raw.data() + at * 4, 4);
  return value;
}

void PropertyFile::PrefetchCell(std::size_t table, const std::array<int64_t, 3>& cell) const
{
  if (table >= this->Entries.size() || cell[0] < 0 || cell[1] < 0 || cell[2] < 0 || cell[0] >= this->Dims[0] ||
    cell[1] >= this->Dims[1] || cell[2] >= this->Dims[2])
  {
    return;
  }
  const int64_t band = (cell[1] / this->RowsInBand) * this->BandsAlongI() + cell[0] / this->ColumnsInBand;
  const ChunkRef ref = this->LayerBand(table, cell[2], band);
  if (ref.offset > this->Size || ref.stored > this->Size - ref.offset)
  {
    return; // ReadCell names it
  }
  const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
  const uintptr_t begin = reinterpret_cast<uintptr_t>(this->Data + ref.offset) & ~(page - 1);
  const uintptr_t end = reinterpret_cast<uintptr_t>(this->Data + ref.offset + ref.stored);
  posix_madvise(reinterpret_cast<void*>(begin), end - begin, POSIX_MADV_WILLNEED);
}

PropertyFileWriter::PropertyFileWriter(
  const std::string& path, const MultiresolutionFile& geometry, int64_t bandRows, int64_t bandColumns)
  : Output(new AtomicOutputFile(path))
  , Geometry(geometry.Header().geometryId)
  , Dims(geometry.Header().dims)
  , TableSides(geometry.Header().hashTableSides)
  , RowsInBand(std::clamp<int64_t>(bandRows > 0 ? bandRows : LayerTileSide, 1, std::max<int64_t>(Dims[1], 1)))
  , ColumnsInBand(std::clamp<int64_t>(bandColumns > 0 ? bandColumns
        : bandRows > 0                                ? Dims[0]
                                                      : LayerTileSide,
      1, std::max<int64_t>(Dims[0], 1)))
{
  const uint64_t slots = uint64_t(this->TableSides[0]) * this->TableSides[1] * this->TableSides[2];
  const uint64_t layer = static_cast<uint64_t>(this->Dims[0] * this->Dims[1]);
  if (layer > UINT32_MAX)
  {
    throw FileFormatError(geometry.Path() + ": layers of " + std::to_string(layer) + " cells are too large");
  }
  std::vector<uint64_t> slotCells;
  {
    const auto cells = geometry.ReadModelArray(ModelChunk::HashCells);
    if (cells.size() != slots * 8)
    {
      throw FileFormatError(geometry.Path() + ": hash cells hold " + std::to_string(cells.size()) +
        " bytes for a table of " + std::to_string(slots) + " slots");
    }
    slotCells.resize(cells.size() / 8);
    std::memcpy(slotCells.data(), cells.data(), cells.size());
  }
  const uint64_t total = layer * static_cast<uint64_t>(this->Dims[2]);
  for (uint64_t cell : slotCells)
  {
    if (cell != ~uint64_t(0) && cell >= total)
    {
      throw FileFormatError(
        geometry.Path() + ": a hash slot names cell " + std::to_string(cell) + " of " + std::to_string(total));
    }
  }
  // Active flags as bits (a whole model's bytes would be its largest array), a layer each.
  for (int64_t k = 0; k < this->Dims[2]; ++k)
  {
    const std::vector<uint8_t> flags = geometry.ReadActiveLayer(k);
    std::vector<uint64_t> bits((layer + 63) / 64, 0);
    for (uint64_t c = 0; c < layer && c < flags.size(); ++c)
    {
      bits[c >> 6] |= uint64_t(flags[c] != 0) << (c & 63);
    }
    this->Active.push_back(std::move(bits));
  }
  this->SlotCount = slots;
  NearestActiveSources(slotCells, this->Active, this->Dims);
  // The slots each layer fills (those whose source lies in it) with their source's place in
  // the layer, for tables given by layers.
  this->LayerSlotStart.assign(static_cast<std::size_t>(this->Dims[2]) + 1, 0);
  for (uint64_t source : slotCells)
  {
    if (source != ~uint64_t(0))
    {
      ++this->LayerSlotStart[source / layer + 1];
    }
  }
  for (std::size_t k = 1; k < this->LayerSlotStart.size(); ++k)
  {
    this->LayerSlotStart[k] += this->LayerSlotStart[k - 1];
  }
  this->LayerSlots.resize(this->LayerSlotStart.back());
  std::vector<uint64_t> next(this->LayerSlotStart.begin(), this->LayerSlotStart.end() - 1);
  for (uint64_t s = 0; s < slotCells.size(); ++s)
  {
    if (slotCells[s] != ~uint64_t(0))
    {
      this->LayerSlots[next[slotCells[s] / layer]++] = { static_cast<uint32_t>(s),
        static_cast<uint32_t>(slotCells[s] % layer) };
    }
  }
  // The table count is patched in at Commit.
  const auto head = HeaderOf(this->Geometry, this->Dims, this->TableSides, 0, this->RowsInBand, this->ColumnsInBand);
  this->Write(head.data(), head.size(), "header");
}

PropertyFileWriter::~PropertyFileWriter() = default;

void PropertyFileWriter::Write(const void* data, std::size_t size, const std::string& what)
{
  if (!this->Output->Write(data, size))
  {
    throw FileFormatError(this->Output->Path() + ": writing the " + what + " at byte " + std::to_string(this->Offset) +
      " failed: " + std::strerror(errno));
  }
  this->Offset += size;
}

ChunkRef PropertyFileWriter::PutChunk(const std::vector<uint8_t>& raw, const std::string& what)
{
  const std::vector<uint8_t> stored = CompressChunk(raw);
  ChunkRef ref;
  ref.offset = this->Offset;
  ref.stored = static_cast<uint32_t>(stored.size());
  ref.raw = static_cast<uint32_t>(raw.size());
  ref.crc = Crc32(stored.data(), stored.size());
  this->Write(stored.data(), stored.size(), what);
  return ref;
}

void PropertyFileWriter::PutLayerBands(PropertyTable& table, const std::vector<uint8_t>& raw, int64_t k)
{
  const int64_t nx = this->Dims[0], ny = this->Dims[1];
  std::vector<uint8_t> band;
  int64_t number = 0;
  for (int64_t j0 = 0; j0 < ny; j0 += this->RowsInBand)
  {
    const int64_t rows = std::min(this->RowsInBand, ny - j0);
    for (int64_t i0 = 0; i0 < nx; i0 += this->ColumnsInBand)
    {
      const std::size_t rowBytes = static_cast<std::size_t>(std::min(this->ColumnsInBand, nx - i0)) * 4;
      band.resize(static_cast<std::size_t>(rows) * rowBytes);
      for (int64_t j = 0; j < rows; ++j)
      {
        std::memcpy(band.data() + static_cast<std::size_t>(j) * rowBytes,
          raw.data() + static_cast<std::size_t>(((j0 + j) * nx + i0) * 4), rowBytes);
      }
      table.layerBands.push_back(this->PutChunk(
        band, TableName(table) + " layer " + std::to_string(k + 1) + " band " + std::to_string(++number)));
    }
  }
}

ChunkRef PropertyFileWriter::CopyChunk(const PropertyFile& from, const ChunkRef& ref)
{
  if (Crc32(from.ChunkBytes(ref), ref.stored) != ref.crc)
  {
    throw FileFormatError(
      from.Path() + ": chunk at byte " + std::to_string(ref.offset) + ": checksum mismatch (corrupt data)");
  }
  ChunkRef moved = ref;
  moved.offset = this->Offset;
  this->Write(from.ChunkBytes(ref), ref.stored, "copied table");
  return moved;
}

ChunkRef PropertyFileWriter::PutBlockRanges(const std::vector<ValueRange>& blocks, const PropertyTable& table)
{
  std::vector<uint8_t> raw(blocks.size() * sizeof(ValueRange));
  std::memcpy(raw.data(), blocks.data(), raw.size());
  return this->PutChunk(raw, TableName(table) + " block ranges");
}

void PropertyFileWriter::AddToBlockRanges(std::vector<ValueRange>& blocks, const float* values, int64_t k) const
{
  const int64_t nx = this->Dims[0], ny = this->Dims[1], bx = BlocksAlong(nx);
  const std::vector<uint64_t>& active = this->Active[static_cast<std::size_t>(k)];
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      const uint64_t c = static_cast<uint64_t>(j * nx + i);
      if (!Bit(active, c))
      {
        continue;
      }
      ValueRange& block = blocks[static_cast<std::size_t>((j / ColumnBlockSide) * bx + i / ColumnBlockSide)];
      const float v = values[c];
      block.low = std::isnan(v) ? -std::numeric_limits<float>::infinity() : std::min(block.low, v);
      block.high = std::isnan(v) ? block.high : std::max(block.high, v);
    }
  }
}

void PropertyFileWriter::AddLayerBlocks(std::vector<BlockSummary>& summaries, const float* values, int64_t k) const
{
  const int64_t nx = this->Dims[0], ny = this->Dims[1];
  const int64_t bx = BlocksAlong(nx, LayerBlockSide), by = BlocksAlong(ny, LayerBlockSide);
  const std::vector<uint64_t>& active = this->Active[static_cast<std::size_t>(k)];
  const float infinity = std::numeric_limits<float>::infinity();
  const std::size_t first = summaries.size();
  summaries.resize(first + static_cast<std::size_t>(bx * by), BlockSummary{ infinity, -infinity, 0.f });
  std::vector<double> sums(static_cast<std::size_t>(bx * by), 0.0);
  std::vector<int64_t> counts(sums.size(), 0);
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      const uint64_t c = static_cast<uint64_t>(j * nx + i);
      if (!Bit(active, c))
      {
        continue;
      }
      const std::size_t b = static_cast<std::size_t>((j / LayerBlockSide) * bx + i / LayerBlockSide);
      BlockSummary& s = summaries[first + b];
      const float v = values[c];
      s.low = std::isnan(v) ? -infinity : std::min(s.low, v);
      s.high = std::isnan(v) ? s.high : std::max(s.high, v);
      sums[b] += std::isnan(v) ? 0.0 : double(v);
      counts[b] += std::isnan(v) ? 0 : 1;
    }
  }
  for (std::size_t b = 0; b < sums.size(); ++b)
  {
    summaries[first + b].mean =
      counts[b] ? static_cast<float>(sums[b] / double(counts[b])) : std::numeric_limits<float>::quiet_NaN();
  }
}

ChunkRef PropertyFileWriter::PutLayerBlocks(const std::vector<BlockSummary>& summaries, const PropertyTable& table)
{
  std::vector<uint8_t> raw(summaries.size() * sizeof(BlockSummary));
  std::memcpy(raw.data(), summaries.data(), raw.size());
  return this->PutChunk(raw, TableName(table) + " layer blocks");
}

void PropertyFileWriter::Add(PropertyTable table, const std::vector<float>& cellValues)
{
  const int64_t layer = this->Dims[0] * this->Dims[1];
  if (static_cast<int64_t>(cellValues.size()) != layer * this->Dims[2])
  {
    throw std::invalid_argument(this->Output->Path() + ": " + TableName(table) + " has " +
      std::to_string(cellValues.size()) + " values for " + std::to_string(layer * this->Dims[2]) + " cells");
  }
  const std::size_t handle = this->BeginTable(std::move(table));
  for (int64_t k = 0; k < this->Dims[2]; ++k)
  {
    this->AddLayer(handle, cellValues.data() + k * layer);
  }
  this->EndTable(handle);
}

std::size_t PropertyFileWriter::BeginTable(PropertyTable table)
{
  // What PropertyFile accepts back.
  const bool text = std::all_of(table.name.begin(), table.name.end(), [](char c) { return c >= 0x20 && c <= 0x7e; });
  if (table.name.empty() || table.name.size() >= NameBytes || !text)
  {
    throw std::invalid_argument(
      this->Output->Path() + ": property name '" + table.name + "' must hold 1 to 31 printable characters");
  }
  if (table.step < -1 || table.reportNumber < 0 || !std::isfinite(table.days) ||
    (table.step < 0 && (table.reportNumber != 0 || table.days != 0)))
  {
    throw std::invalid_argument(
      this->Output->Path() + ": " + TableName(table) + ": step, report number or days impossible");
  }
  OpenTable opened;
  opened.table = std::move(table);
  opened.table.layerBands.clear();
  opened.low = std::numeric_limits<float>::infinity();
  opened.high = -opened.low;
  opened.blocks.assign(static_cast<std::size_t>(BlocksAlong(this->Dims[0]) * BlocksAlong(this->Dims[1])),
    ValueRange{ opened.low, opened.high });
  // Slots without a source (empty, or inactive in a layer with no active cell) stay NaN.
  const float none = std::numeric_limits<float>::quiet_NaN();
  opened.packed.resize(static_cast<std::size_t>(this->SlotCount) * 4);
  for (std::size_t s = 0; s < this->SlotCount; ++s)
  {
    std::memcpy(&opened.packed[s * 4], &none, 4);
  }
  opened.open = true;
  for (std::size_t handle = 0; handle < this->Open.size(); ++handle)
  {
    if (!this->Open[handle].open)
    {
      this->Open[handle] = std::move(opened);
      return handle;
    }
  }
  this->Open.push_back(std::move(opened));
  return this->Open.size() - 1;
}

PropertyFileWriter::OpenTable& PropertyFileWriter::Opened(std::size_t handle)
{
  if (handle >= this->Open.size() || !this->Open[handle].open)
  {
    throw std::invalid_argument(this->Output->Path() + ": no open table " + std::to_string(handle));
  }
  return this->Open[handle];
}

void PropertyFileWriter::AddLayer(std::size_t handle, const float* layerValues)
{
  OpenTable& t = this->Opened(handle);
  const int64_t k = t.layers;
  if (k >= this->Dims[2])
  {
    throw std::invalid_argument(this->Output->Path() + ": " + TableName(t.table) + " given more than its " +
      std::to_string(this->Dims[2]) + " layers");
  }
  const uint64_t layer = static_cast<uint64_t>(this->Dims[0] * this->Dims[1]);
  const std::vector<uint64_t>& active = this->Active[static_cast<std::size_t>(k)];
  const float none = std::numeric_limits<float>::quiet_NaN();
  std::vector<uint8_t> raw(static_cast<std::size_t>(layer) * 4);
  for (uint64_t c = 0; c < layer; ++c)
  {
    const float v = Bit(active, c) ? layerValues[c] : none;
    if (!std::isnan(v))
    {
      t.low = std::min(t.low, v);
      t.high = std::max(t.high, v);
    }
    std::memcpy(&raw[static_cast<std::size_t>(c) * 4], &v, 4);
  }
  this->PutLayerBands(t.table, raw, k);
  this->AddToBlockRanges(t.blocks, reinterpret_cast<const float*>(raw.data()), k);
  this->AddLayerBlocks(t.layerBlocks, reinterpret_cast<const float*>(raw.data()), k);
  ++t.layers;
  for (uint64_t at = this->LayerSlotStart[static_cast<std::size_t>(k)];
       at < this->LayerSlotStart[static_cast<std::size_t>(k) + 1]; ++at)
  {
    const auto [s, c] = this->LayerSlots[at];
    const float v = Bit(active, c) ? layerValues[c] : none;
    std::memcpy(&t.packed[std::size_t(s) * 4], &v, 4);
  }
}

void PropertyFileWriter::EndTable(std::size_t handle)
{
  OpenTable& t = this->Opened(handle);
  if (t.layers != this->Dims[2])
  {
    throw std::invalid_argument(this->Output->Path() + ": " + TableName(t.table) + " ended after " +
      std::to_string(t.layers) + " of its " + std::to_string(this->Dims[2]) + " layers");
  }
  const float none = std::numeric_limits<float>::quiet_NaN();
  PropertyTable table = std::move(t.table);
  table.minimum = t.low <= t.high ? t.low : none;
  table.maximum = t.low <= t.high ? t.high : none;
  table.packed = this->PutChunk(t.packed, TableName(table) + " packed table");
  table.blockRanges = this->PutBlockRanges(t.blocks, table);
  table.layerBlocks = this->PutLayerBlocks(t.layerBlocks, table);
  t.packed = std::vector<uint8_t>();
  t.blocks = std::vector<ValueRange>();
  t.layerBlocks = std::vector<BlockSummary>();
  t.open = false;
  for (auto& old : this->Entries)
  {
    if (old.name == table.name && old.step == table.step)
    {
      old = std::move(table); // replaced: the older chunks stay unreferenced in this file
      return;
    }
  }
  this->Entries.push_back(std::move(table));
}

void PropertyFileWriter::CopyFrom(const PropertyFile& older)
{
  if (older.GeometryId() != this->Geometry)
  {
    throw FileFormatError(older.Path() + ": made for another geometry; not merged");
  }
  for (const PropertyTable& table : older.Tables())
  {
    const bool held = std::any_of(this->Entries.begin(), this->Entries.end(),
      [&](const PropertyTable& t) { return t.name == table.name && t.step == table.step; });
    if (held)
    {
      continue;
    }
    PropertyTable copy = table;
    const std::size_t t = static_cast<std::size_t>(&table - older.Tables().data());
    copy.packed = this->CopyChunk(older, table.packed);
    if (older.HasBlockRanges())
    {
      copy.blockRanges = this->CopyChunk(older, table.blockRanges);
      copy.layerBlocks = this->CopyChunk(older, table.layerBlocks);
    }
    else // an older version's table: its block ranges and summaries from its layers
    {
      std::vector<ValueRange> blocks(static_cast<std::size_t>(BlocksAlong(this->Dims[0]) * BlocksAlong(this->Dims[1])),
        ValueRange{ std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity() });
      std::vector<BlockSummary> summaries;
      for (int64_t k = 0; k < this->Dims[2]; ++k)
      {
        const std::vector<float> layer = older.ReadLayer(t, k);
        this->AddToBlockRanges(blocks, layer.data(), k);
        this->AddLayerBlocks(summaries, layer.data(), k);
      }
      copy.blockRanges = this->PutBlockRanges(blocks, copy);
      copy.layerBlocks = this->PutLayerBlocks(summaries, copy);
    }
    copy.layerBands.clear();
    if (older.BandRows() == this->RowsInBand && older.BandColumns() == this->ColumnsInBand)
    {
      for (int64_t n = 0; n < this->Dims[2] * older.Bands(); ++n)
      {
        copy.layerBands.push_back(this->CopyChunk(older, older.LayerBand(t, n / older.Bands(), n % older.Bands())));
      }
    }
    else // an older version's layers: cut into this file's bands
    {
      for (int64_t k = 0; k < this->Dims[2]; ++k)
      {
        const std::vector<float> layer = older.ReadLayer(t, k);
        std::vector<uint8_t> raw(layer.size() * 4);
        std::memcpy(raw.data(), layer.data(), raw.size());
        this->PutLayerBands(copy, raw, k);
      }
    }
    this->Entries.push_back(std::move(copy));
  }
}

void PropertyFileWriter::Commit()
{
  for (const OpenTable& t : this->Open)
  {
    if (t.open)
    {
      throw std::invalid_argument(this->Output->Path() + ": " + TableName(t.table) + " was never ended");
    }
  }
  ByteWriter index;
  for (const PropertyTable& t : this->Entries)
  {
    char name[NameBytes] = {};
    std::memcpy(name, t.name.data(), std::min(t.name.size(), NameBytes - 1));
    index.PutBytes(name, NameBytes);
    index.Put(t.step);
    index.Put(t.reportNumber);
    index.Put(t.days);
    index.Put(t.minimum);
    index.Put(t.maximum);
    PutRef(index, t.packed);
    PutRef(index, t.blockRanges);
    PutRef(index, t.layerBlocks);
    for (const ChunkRef& band : t.layerBands)
    {
      PutRef(index, band);
    }
  }
  const uint64_t indexOffset = this->Offset;
  this->Write(index.Bytes.data(), index.Bytes.size(), "index");
  const auto trailer = IndexTrailer(indexOffset, index.Bytes, TrailerMagic);
  this->Write(trailer.data(), trailer.size(), "trailer");
  // The table count goes in the header, which was written first: rewrite it in place.
  const auto head = HeaderOf(this->Geometry, this->Dims, this->TableSides, static_cast<uint32_t>(this->Entries.size()),
    this->RowsInBand, this->ColumnsInBand);
  if (!this->Output->WriteAt(head.data(), head.size(), 0))
  {
    throw FileFormatError(this->Output->Path() + ": rewriting the header failed: " + std::strerror(errno));
  }
  this->Output->Commit();
}

} // namespace resmr
