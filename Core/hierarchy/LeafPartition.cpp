// Streaming partition of a corner-point model into tiles of columns (paper Sec. 4.2, 7), kept
// small on disk by predicting each corner and compressing the residuals.
#include "LeafPartition.h"

#include "ByteStream.h"
#include "ChunkStorage.h"
#include "CornerPointGeometry.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <limits>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{
namespace
{
constexpr char StateMagic[8] = { 'R', 'M', 'R', 'T', 'I', 'L', 'E', 'S' };
constexpr uint32_t StateVersion = 1;

void WriteAll(int descriptor, const void* data, std::size_t size, off_t offset, const std::string& path)
{
  const auto* bytes = static_cast<const uint8_t*>(data);
  while (size > 0)
  {
    const ssize_t written = pwrite(descriptor, bytes, size, offset);
    if (written <= 0)
    {
      throw std::runtime_error(
        path + ": scratch write at byte " + std::to_string(offset) + " failed: " + std::strerror(errno));
    }
    bytes += written;
    size -= static_cast<std::size_t>(written);
    offset += written;
  }
}

void ReadAll(int descriptor, void* data, std::size_t size, off_t offset, const std::string& place)
{
  auto* bytes = static_cast<uint8_t*>(data);
  while (size > 0)
  {
    const ssize_t got = pread(descriptor, bytes, size, offset);
    if (got <= 0)
    {
      throw std::runtime_error(place + ": scratch read at byte " + std::to_string(offset) + " failed" +
        (got < 0 ? std::string(": ") + std::strerror(errno) : std::string(" (file shorter than written)")));
    }
    bytes += got;
    size -= static_cast<std::size_t>(got);
    offset += got;
  }
}

double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Residuals are differences of the floats' bit patterns (exact in modular arithmetic), folded
// so that small negative ones have zero high bytes too.
inline uint32_t Zigzag(uint32_t d)
{
  return (d << 1) ^ (0u - (d >> 31));
}

inline uint32_t Unzigzag(uint32_t z)
{
  return (z >> 1) ^ (0u - (z & 1));
}

/// Codes one cell's 8 corners in corner order against a prediction from what a decoder already
/// holds: the corners before, the cell left of it (i - 1) and below it (j - 1) in the tile, and
/// the same cell's bottom corners in the layer above. Top corners repeat the bottom above (no
/// vertical gap); a corner shared with a neighbour at the same pillar repeats it (no fault);
/// the one new pillar of each cell continues the neighbouring thicknesses. Encoding fills
/// the residuals (corner c at residual[c stride]) from `cell`, decoding the other way.
template<bool Decoding>
inline void CodeCell(uint32_t* cell, uint32_t* residual, std::size_t stride, const uint32_t* left, const uint32_t* down,
  const uint32_t* up)
{
  const auto step = [cell, residual, stride](int c, uint32_t prediction) {
    if (Decoding)
    {
      cell[c] = prediction + Unzigzag(residual[c * stride]);
    }
    else
    {
      residual[c * stride] = Zigzag(cell[c] - prediction);
    }
  };
  if (up)
  {
    step(0, up[0]);
    step(1, up[1]);
    step(2, up[2]);
    step(3, up[3]);
  }
  else
  {
    step(0, left ? left[1] : down ? down[2] : 0u);
    step(1, down ? down[3] : cell[0]);
    step(2, left ? left[3] : cell[0]);
    step(3, cell[1] + cell[2] - cell[0]);
  }
  step(4, left ? left[5] : down ? down[6] : cell[0]);
  step(5, down ? down[7] : cell[1] + (cell[4] - cell[0]));
  step(6, left ? left[7] : cell[2] + (cell[4] - cell[0]));
  step(7, cell[3] + (cell[5] - cell[1]) + (cell[6] - cell[2]) - (cell[4] - cell[0]));
}

/// Bytes of a block before compression: the byte planes `planes` keeps, then the flags.
inline std::size_t RawBlockBytes(int64_t cells, uint32_t planes)
{
  return static_cast<std::size_t>(cells) * static_cast<std::size_t>(__builtin_popcount(planes)) +
    static_cast<std::size_t>((cells + 7) / 8);
}

/// One tile's layer as LZO input: the residuals of the w x h cells' 8 corners in byte planes
/// (byte b of corner c of every cell, plane 8 b + c), as LZO finds the runs of zero high bytes
/// only when they lie together, then the active flags, one bit a cell. Planes all zero are
/// left out (bit p of the result says plane p is kept), as even LZO takes time over them.
uint32_t EncodeBlock(uint32_t* cells, const uint32_t* above, const uint8_t* active, int64_t w, int64_t h,
  std::vector<uint32_t>& residuals, std::vector<uint8_t>& raw)
{
  const std::size_t n = static_cast<std::size_t>(w * h);
  residuals.resize(8 * n);
  for (int64_t j = 0; j < h; ++j)
  {
    for (int64_t i = 0; i < w; ++i)
    {
      const std::size_t q = static_cast<std::size_t>(j * w + i);
      uint32_t* cell = cells + 8 * q;
      CodeCell<false>(cell, &residuals[q], n, i > 0 ? cell - 8 : nullptr, j > 0 ? cell - 8 * w : nullptr,
        above ? above + 4 * q : nullptr);
    }
  }
  raw.resize(32 * n + (n + 7) / 8);
  uint32_t planes = 0;
  std::size_t at = 0;
  for (int p = 0; p < 32; ++p)
  {
    const int c = p & 7, shift = 8 * (p >> 3);
    uint32_t any = 0;
    for (std::size_t q = 0; q < n; ++q)
    {
      const uint32_t byte = (residuals[c * n + q] >> shift) & 0xff;
      raw[at + q] = static_cast<uint8_t>(byte);
      any |= byte;
    }
    if (any)
    {
      planes |= 1u << p;
      at += n;
    }
  }
  std::fill(raw.begin() + at, raw.begin() + at + (n + 7) / 8, uint8_t(0));
  for (std::size_t q = 0; q < n; ++q)
  {
    raw[at + (q >> 3)] |= static_cast<uint8_t>((active[q] ? 1u : 0u) << (q & 7));
  }
  raw.resize(at + (n + 7) / 8);
  return planes;
}

/// EncodeBlock undone for the cells i < wUsed, j < hUsed (all that their predictions need);
/// `cells` (8 a cell), `above` (the layer above's cells, 8 a cell) and `active` have the
/// tile's w x h layout.
void DecodeBlock(const std::vector<uint8_t>& raw, uint32_t planes, const uint32_t* above, int64_t w, int64_t h,
  int64_t wUsed, int64_t hUsed, std::vector<uint32_t>& residuals, uint32_t* cells, uint8_t* active)
{
  const std::size_t n = static_cast<std::size_t>(w * h);
  residuals.resize(8 * n);
  for (int c = 0; c < 8; ++c)
  {
    bool written = false; // each residual is set by its first plane kept, or to 0 if none
    for (int b = 0; b < 4; ++b)
    {
      const int p = 8 * b + c;
      if (!(planes >> p & 1))
      {
        continue;
      }
      const uint8_t* plane = raw.data() + static_cast<std::size_t>(__builtin_popcount(planes & ((1u << p) - 1))) * n;
      for (int64_t j = 0; j < hUsed; ++j)
      {
        for (std::size_t q = static_cast<std::size_t>(j * w), end = q + static_cast<std::size_t>(wUsed); q < end; ++q)
        {
          const uint32_t part = uint32_t(plane[q]) << (8 * b);
          residuals[c * n + q] = written ? residuals[c * n + q] | part : part;
        }
      }
      written = true;
    }
    for (int64_t j = 0; j < hUsed && !written; ++j)
    {
      for (std::size_t q = static_cast<std::size_t>(j * w), end = q + static_cast<std::size_t>(wUsed); q < end; ++q)
      {
        residuals[c * n + q] = 0;
      }
    }
  }
  const std::size_t flagsAt = static_cast<std::size_t>(__builtin_popcount(planes)) * n;
  for (int64_t j = 0; j < hUsed; ++j)
  {
    for (int64_t i = 0; i < wUsed; ++i)
    {
      const std::size_t q = static_cast<std::size_t>(j * w + i);
      uint32_t* cell = cells + 8 * q;
      CodeCell<true>(cell, &residuals[q], n, i > 0 ? cell - 8 : nullptr, j > 0 ? cell - 8 * w : nullptr,
        above ? above + 8 * q + 4 : nullptr);
      active[q] = (raw[flagsAt + (q >> 3)] >> (q & 7)) & 1;
    }
  }
}

/// The w x h cells from column (i0, j0) of a layer's ZCORN, 8 corners a cell as bit patterns.
void GatherTile(const std::vector<float>& zcorn, int64_t nx, int64_t ny, int64_t i0, int64_t j0, int64_t w, int64_t h,
  std::vector<uint32_t>& cells)
{
  cells.resize(static_cast<std::size_t>(w * h * 8));
  for (int64_t j = 0; j < h; ++j)
  {
    for (int64_t i = 0; i < w; ++i)
    {
      uint32_t* out = &cells[static_cast<std::size_t>((j * w + i) * 8)];
      for (int c = 0; c < 8; ++c)
      {
        std::memcpy(out + c,
          &zcorn[static_cast<std::size_t>(
            (c >> 2) * 4 * nx * ny + (2 * (j0 + j) + ((c >> 1) & 1)) * 2 * nx + 2 * (i0 + i) + (c & 1))],
          4);
      }
    }
  }
}

/// The bottom corners of a tile's decoded cells, which predict the next layer's top corners.
void KeepBottoms(const std::vector<uint32_t>& cells, std::vector<uint32_t>& above)
{
  above.resize(cells.size() / 2);
  for (std::size_t q = 0; q < cells.size() / 8; ++q)
  {
    std::memcpy(&above[4 * q], &cells[8 * q + 4], 16);
  }
}

/// A file written or read in one pass with the CRC-32 of every byte so far; a failed read or
/// write leaves Ok false (and reads zeros).
class CheckedFile
{
public:
  explicit CheckedFile(std::FILE* file)
    : File(file)
  {
  }
  ~CheckedFile() { this->Close(); }
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;
  void Put(const void* data, std::size_t size)
  {
    this->Ok = this->Ok && std::fwrite(data, 1, size, this->File) == size;
    this->Crc = Crc32(data, size, this->Crc);
  }
  template<typename T>
  void Put(const T& value)
  {
    this->Put(&value, sizeof(T));
  }
  void Get(void* data, std::size_t size)
  {
    this->Ok = this->Ok && std::fread(data, 1, size, this->File) == size;
    if (!this->Ok)
    {
      std::memset(data, 0, size);
    }
    this->Crc = Crc32(data, size, this->Crc);
  }
  template<typename T>
  void Get(T& value)
  {
    this->Get(&value, sizeof(T));
  }
  template<typename T>
  T Get()
  {
    T value{};
    this->Get(&value, sizeof(T));
    return value;
  }
  bool AtEnd() { return std::fgetc(this->File) == EOF; }
  /// Closes the file; false if anything failed.
  bool Close()
  {
    if (this->File)
    {
      this->Ok = (std::fclose(this->File) == 0) && this->Ok;
      this->File = nullptr;
    }
    return this->Ok;
  }
  std::FILE* File;
  uint32_t Crc = 0;
  bool Ok = true;
};

} // namespace

/// A checkpoint as the state file holds it.
struct LeafPartition::State
{
  bool complete = false;
  std::array<int64_t, 3> dims{};
  int64_t tile = 0, layers = 0, activeCount = 0;
  std::array<double, 6> bounds{};
  std::vector<uint8_t> anyActive;
  std::vector<std::vector<Block>> blocks;
  std::vector<uint8_t> note;
};

LeafPartition::LeafPartition(
  LayerSource& source, const std::string& folder, int64_t tileSize, const PartitionHooks& hooks)
  : Dimensions(source.Dims())
  , CoordValues(source.Coord())
  , Tile(std::max<int64_t>(tileSize, 1))
  , Folder(folder)
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  if (static_cast<int64_t>(this->CoordValues.size()) != 6 * (nx + 1) * (ny + 1))
  {
    throw std::invalid_argument(source.Name() + ": COORD holds " + std::to_string(this->CoordValues.size()) +
      " values, " + std::to_string(6 * (nx + 1) * (ny + 1)) + " expected");
  }
  if (mkdir(folder.c_str(), 0755) != 0 && errno != EEXIST)
  {
    throw std::runtime_error(folder + ": cannot create the scratch folder: " + std::strerror(errno));
  }
  this->TilesX = (nx + this->Tile - 1) / this->Tile;
  this->TilesY = (ny + this->Tile - 1) / this->Tile;
  const std::size_t tiles = static_cast<std::size_t>(this->TilesX * this->TilesY);
  this->Readers.assign(tiles, 0);
  this->Removed.assign(tiles, 0);
  const bool resume = this->TakeCheckpoint();
  if (!resume)
  {
    this->StartBounds();
    this->Blocks.assign(tiles, {});
    unlink(this->StatePath().c_str()); // a stale state must never describe the new tiles
    this->SaveCoord();
  }
  std::vector<std::vector<uint32_t>> above(tiles);
  try
  {
    this->OpenTiles(resume);
    if (resume)
    {
      if (hooks.onResume)
      {
        hooks.onResume(this->LayersDone, this->Note);
      }
      this->SkipLayers(source, above);
      if (hooks.progress)
      {
        hooks.progress(static_cast<double>(this->LayersDone) / std::max<int64_t>(this->Dimensions[2], 1));
      }
    }
    this->StreamLayers(source, hooks, above);
  }
  catch (...)
  {
    this->CloseTiles(); // the tiles stay, for a pass that resumes from the last checkpoint
    throw;
  }
}

/// Bounds from COORD alone and no column active: where a pass that starts over begins.
void LeafPartition::StartBounds()
{
  const double inf = std::numeric_limits<double>::infinity();
  this->Bounds = { inf, inf, inf, -inf, -inf, -inf };
  for (std::size_t p = 0; p < this->CoordValues.size(); p += 3)
  {
    for (int d = 0; d < 2; ++d)
    {
      this->Bounds[d] = std::min(this->Bounds[d], this->CoordValues[p + d]);
      this->Bounds[3 + d] = std::max(this->Bounds[3 + d], this->CoordValues[p + d]);
    }
  }
  this->AnyActive.assign(static_cast<std::size_t>(this->Dimensions[0] * this->Dimensions[1]), 0);
  this->ActiveCount = 0;
  this->LayersDone = 0;
}

/// Adopts the unfinished checkpoint in the folder if it is of this grid and its tile files
/// still hold its blocks; false to start over.
bool LeafPartition::TakeCheckpoint()
{
  State state;
  std::string why;
  std::vector<double> coord;
  if (!LoadState(this->StatePath(), state, why) || state.complete || state.dims != this->Dimensions ||
    state.tile != this->Tile || !LoadCoord(this->Folder, state.dims, coord, why) ||
    coord.size() != this->CoordValues.size() ||
    std::memcmp(coord.data(), this->CoordValues.data(), coord.size() * sizeof(double)) != 0)
  {
    return false;
  }
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      struct stat info;
      const std::vector<Block>& blocks = state.blocks[static_cast<std::size_t>(tj * this->TilesX + ti)];
      const uint64_t end = blocks.empty() ? 0 : blocks.back().offset + blocks.back().stored;
      if (stat(this->TilePath(ti, tj).c_str(), &info) != 0 || static_cast<uint64_t>(info.st_size) < end)
      {
        return false;
      }
    }
  }
  this->LayersDone = state.layers;
  this->ActiveCount = state.activeCount;
  this->Bounds = state.bounds;
  this->AnyActive = std::move(state.anyActive);
  this->Blocks = std::move(state.blocks);
  this->Note = std::move(state.note);
  return true;
}

/// Opens every tile file for writing: emptied, or cut back to the checkpoint's blocks.
void LeafPartition::OpenTiles(bool resume)
{
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      const std::string path = this->TilePath(ti, tj);
      const int descriptor = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | (resume ? 0 : O_TRUNC), 0644);
      if (descriptor < 0)
      {
        throw std::runtime_error(path + ": cannot create scratch file: " + std::strerror(errno));
      }
      this->Descriptors.push_back(descriptor);
      const uint64_t end = this->TileEnd(this->Descriptors.size() - 1);
      if (resume && ftruncate(descriptor, static_cast<off_t>(end)) != 0)
      {
        throw std::runtime_error(path + ": cannot cut back to the checkpoint: " + std::strerror(errno));
      }
    }
  }
}

/// Reads the layers a checkpoint already holds and drops them but for the last one's bottom
/// corners, which predict the next layer; that layer must be the one the checkpoint saw.
void LeafPartition::SkipLayers(LayerSource& source, std::vector<std::vector<uint32_t>>& above)
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  std::vector<float> zcorn;
  std::vector<uint8_t> active;
  std::vector<uint32_t> cells;
  for (int64_t k = 0; k < this->LayersDone; ++k)
  {
    if (!source.Next(zcorn, active) || static_cast<int64_t>(zcorn.size()) != 8 * nx * ny ||
      static_cast<int64_t>(active.size()) != nx * ny)
    {
      throw std::runtime_error(
        source.Name() + ": layer " + std::to_string(k + 1) + " is missing or has the wrong size");
    }
    if (k + 2 < this->LayersDone)
    {
      continue;
    }
    // The last layer done must encode to the blocks the tiles hold (the one before it gives
    // the prediction).
    for (int64_t tj = 0; tj < this->TilesY; ++tj)
    {
      for (int64_t ti = 0; ti < this->TilesX; ++ti)
      {
        const std::size_t t = static_cast<std::size_t>(tj * this->TilesX + ti);
        if (k + 1 == this->LayersDone)
        {
          uint32_t planes = 0;
          const std::vector<uint8_t> stored = this->EncodeTile(k, ti, tj, zcorn, active, above, cells, planes);
          if (Crc32(stored.data(), stored.size()) != this->Blocks[t][static_cast<std::size_t>(k)].crc)
          {
            throw std::runtime_error(source.Name() + ": layer " + std::to_string(k + 1) +
              " differs from the one the partition checkpoint in " + this->Folder +
              " was made from; start the build over");
          }
        }
        else
        {
          const int64_t i0 = ti * this->Tile, j0 = tj * this->Tile;
          GatherTile(zcorn, nx, ny, i0, j0, std::min(this->Tile, nx - i0), std::min(this->Tile, ny - j0), cells);
        }
        KeepBottoms(cells, above[t]);
      }
    }
  }
}

/// One tile's block of layer k, compressed (`cells` gets the tile's corners).
std::vector<uint8_t> LeafPartition::EncodeTile(int64_t k, int64_t ti, int64_t tj, const std::vector<float>& zcorn,
  const std::vector<uint8_t>& active, const std::vector<std::vector<uint32_t>>& above, std::vector<uint32_t>& cells,
  uint32_t& planes) const
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  const std::size_t t = static_cast<std::size_t>(tj * this->TilesX + ti);
  const int64_t i0 = ti * this->Tile, j0 = tj * this->Tile;
  const int64_t w = std::min(this->Tile, nx - i0), h = std::min(this->Tile, ny - j0);
  GatherTile(zcorn, nx, ny, i0, j0, w, h, cells);
  std::vector<uint8_t> flags(static_cast<std::size_t>(w * h)), raw;
  std::vector<uint32_t> residuals;
  for (int64_t j = 0; j < h; ++j)
  {
    std::memcpy(&flags[static_cast<std::size_t>(j * w)], &active[static_cast<std::size_t>((j0 + j) * nx + i0)],
      static_cast<std::size_t>(w));
  }
  planes = EncodeBlock(cells.data(), k > 0 ? above[t].data() : nullptr, flags.data(), w, h, residuals, raw);
  return CompressChunk(raw);
}

/// The layers from LayersDone on: statistics, tiles, and a checkpoint whenever the tiles have
/// grown by the checkpoint's own size since the last one (checkpoints cost at most as much
/// disk traffic as the tiles) or checkpointSeconds have passed.
void LeafPartition::StreamLayers(
  LayerSource& source, const PartitionHooks& hooks, std::vector<std::vector<uint32_t>>& above)
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1], nz = this->Dimensions[2];
  std::vector<float> zcorn;
  std::vector<uint8_t> active;
  double last = Now();
  uint64_t grown = 0, checkpointBytes = 0;
  for (int64_t k = this->LayersDone; k < nz; ++k)
  {
    if (!source.Next(zcorn, active) || static_cast<int64_t>(zcorn.size()) != 8 * nx * ny ||
      static_cast<int64_t>(active.size()) != nx * ny)
    {
      throw std::runtime_error(
        source.Name() + ": layer " + std::to_string(k + 1) + " is missing or has the wrong size");
    }
    if (hooks.onLayer)
    {
      hooks.onLayer(k, active);
    }
    try
    {
      this->WriteLayer(k, zcorn, active, above);
    }
    catch (const std::runtime_error&)
    {
      this->CheckpointAfterFailure(hooks);
      throw;
    }
    this->AddLayerStatistics(source, k, zcorn, active);
    this->LayersDone = k + 1;
    for (const std::vector<Block>& blocks : this->Blocks)
    {
      grown += blocks.back().stored;
    }
    if (hooks.progress)
    {
      hooks.progress(static_cast<double>(k + 1) / nz);
    }
    if (k + 1 < nz && (grown >= checkpointBytes || Now() - last >= hooks.checkpointSeconds))
    {
      this->Note = hooks.checkpointNote ? hooks.checkpointNote() : std::vector<uint8_t>();
      this->SaveState();
      struct stat info;
      checkpointBytes = stat(this->StatePath().c_str(), &info) == 0 ? static_cast<uint64_t>(info.st_size) : 0;
      grown = 0;
      last = Now();
    }
  }
  if (this->ActiveCount == 0)
  {
    this->Bounds[2] = this->Bounds[5] = 0;
  }
  this->Complete = true;
  this->Note = hooks.checkpointNote ? hooks.checkpointNote() : std::vector<uint8_t>();
  this->SaveState();
}

/// A write failed (a full disk, most often): the layers done so far are kept as a checkpoint
/// if it can be written, else the last one stays.
void LeafPartition::CheckpointAfterFailure(const PartitionHooks& hooks)
{
  if (this->LayersDone == 0)
  {
    return;
  }
  try
  {
    this->Note = hooks.checkpointNote ? hooks.checkpointNote() : std::vector<uint8_t>();
    this->SaveState();
  }
  catch (const std::exception&)
  {
  }
}

/// Active columns, the active cell count and the depth range of the active cells' corners.
void LeafPartition::AddLayerStatistics(
  const LayerSource& source, int64_t k, const std::vector<float>& zcorn, const std::vector<uint8_t>& active)
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      if (!active[static_cast<std::size_t>(j * nx + i)])
      {
        continue;
      }
      this->AnyActive[static_cast<std::size_t>(j * nx + i)] = 1;
      ++this->ActiveCount;
      for (int c = 0; c < 8; ++c)
      {
        const double z =
          zcorn[static_cast<std::size_t>((c >> 2) * 4 * nx * ny + (2 * j + ((c >> 1) & 1)) * 2 * nx + 2 * i + (c & 1))];
        if (!std::isfinite(z))
        {
          throw std::runtime_error(source.Name() + ": cell (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) +
            ", " + std::to_string(k + 1) + ") has a non-finite corner depth");
        }
        this->Bounds[2] = std::min(this->Bounds[2], z);
        this->Bounds[5] = std::max(this->Bounds[5], z);
      }
    }
  }
}

/// Appends layer k's block to every tile file.
void LeafPartition::WriteLayer(int64_t k, const std::vector<float>& zcorn, const std::vector<uint8_t>& active,
  std::vector<std::vector<uint32_t>>& above)
{
  std::vector<uint32_t> cells;
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      const std::size_t t = static_cast<std::size_t>(tj * this->TilesX + ti);
      Block block;
      const std::vector<uint8_t> stored = this->EncodeTile(k, ti, tj, zcorn, active, above, cells, block.planes);
      block.offset = this->TileEnd(t);
      block.stored = static_cast<uint32_t>(stored.size());
      block.crc = Crc32(stored.data(), stored.size());
      WriteAll(
        this->Descriptors[t], stored.data(), stored.size(), static_cast<off_t>(block.offset), this->TilePath(ti, tj));
      this->Blocks[t].push_back(block);
      KeepBottoms(cells, above[t]);
    }
  }
}

uint64_t LeafPartition::TileEnd(std::size_t t) const
{
  const std::vector<Block>& blocks = this->Blocks[t];
  return blocks.empty() ? 0 : blocks.back().offset + blocks.back().stored;
}

void LeafPartition::CloseTiles()
{
  std::lock_guard<std::mutex> guard(this->Lock);
  for (int& descriptor : this->Descriptors)
  {
    if (descriptor >= 0)
    {
      close(descriptor);
      descriptor = -1;
    }
  }
}

LeafPartition::~LeafPartition()
{
  this->CloseTiles();
  if (!this->Owner)
  {
    return;
  }
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      unlink(this->TilePath(ti, tj).c_str());
    }
  }
  unlink(this->StatePath().c_str());
  unlink((this->Folder + "/coord.bin").c_str());
  rmdir(this->Folder.c_str());
}

/// COORD, written once a pass (checkpoints would rewrite it: it is the largest part of the
/// state), under a temporary name renamed into place, with its CRC-32.
void LeafPartition::SaveCoord() const
{
  const std::string path = this->Folder + "/coord.bin";
  const std::string temporary = path + ".part";
  CheckedFile out(std::fopen(temporary.c_str(), "wb"));
  if (!out.File)
  {
    throw std::runtime_error(temporary + ": cannot create: " + std::strerror(errno));
  }
  out.Put(static_cast<uint64_t>(this->CoordValues.size()));
  out.Put(this->CoordValues.data(), this->CoordValues.size() * sizeof(double));
  const uint32_t crc = out.Crc;
  out.Put(crc);
  if (!out.Close() || std::rename(temporary.c_str(), path.c_str()) != 0)
  {
    unlink(temporary.c_str());
    throw std::runtime_error(path + ": write failed (disk full?)");
  }
}

/// COORD as SaveCoord wrote it for `dims`; false with the reason in `why`.
bool LeafPartition::LoadCoord(
  const std::string& folder, const std::array<int64_t, 3>& dims, std::vector<double>& coord, std::string& why)
{
  CheckedFile in(std::fopen((folder + "/coord.bin").c_str(), "rb"));
  if (!in.File)
  {
    why = "coord.bin: cannot open: " + std::string(std::strerror(errno));
    return false;
  }
  const uint64_t count = static_cast<uint64_t>(6 * (dims[0] + 1) * (dims[1] + 1));
  struct stat info;
  if (in.Get<uint64_t>() != count || fstat(fileno(in.File), &info) != 0 ||
    static_cast<uint64_t>(info.st_size) != 12 + 8 * count)
  {
    why = "coord.bin: truncated, or not of these dimensions";
    return false;
  }
  coord.resize(count);
  in.Get(coord.data(), coord.size() * sizeof(double));
  const uint32_t crc = in.Crc;
  if (!in.Ok || in.Get<uint32_t>() != crc)
  {
    why = "coord.bin: truncated or corrupt";
    return false;
  }
  return true;
}

/// The state file, whole, then renamed over the last one, so a reader finds the old
/// checkpoint or the new one and never a part.
void LeafPartition::SaveState() const
{
  const std::string path = this->StatePath();
  const std::string temporary = path + ".part";
  CheckedFile out(std::fopen(temporary.c_str(), "wb"));
  if (!out.File)
  {
    throw std::runtime_error(temporary + ": cannot create: " + std::strerror(errno));
  }
  out.Put(StateMagic, sizeof(StateMagic));
  out.Put(StateVersion);
  out.Put(static_cast<uint8_t>(this->Complete ? 1 : 0));
  out.Put(this->Dimensions);
  out.Put(this->Tile);
  out.Put(this->LayersDone);
  out.Put(this->ActiveCount);
  out.Put(this->Bounds);
  out.Put(static_cast<uint64_t>(this->AnyActive.size()));
  out.Put(this->AnyActive.data(), this->AnyActive.size());
  out.Put(static_cast<uint64_t>(this->Blocks.size()));
  ByteWriter index;
  for (const std::vector<Block>& blocks : this->Blocks)
  {
    index.Bytes.clear();
    for (int64_t k = 0; k < this->LayersDone; ++k)
    {
      const Block& block = blocks[static_cast<std::size_t>(k)];
      index.Put(block.offset);
      index.Put(block.stored);
      index.Put(block.crc);
      index.Put(block.planes);
    }
    out.Put(index.Bytes.data(), index.Bytes.size());
  }
  out.Put(static_cast<uint64_t>(this->Note.size()));
  out.Put(this->Note.data(), this->Note.size());
  const uint32_t crc = out.Crc;
  out.Put(crc);
  if (!out.Close() || std::rename(temporary.c_str(), path.c_str()) != 0)
  {
    unlink(temporary.c_str());
    throw std::runtime_error(path + ": write failed (disk full?)");
  }
}

/// Reads and checks a state file; false with the reason in `why` if it is missing or
/// cannot be trusted.
bool LeafPartition::LoadState(const std::string& path, State& state, std::string& why)
{
  CheckedFile in(std::fopen(path.c_str(), "rb"));
  if (!in.File)
  {
    why = std::string("cannot open: ") + std::strerror(errno);
    return false;
  }
  char magic[sizeof(StateMagic)] = {};
  uint32_t version = 0;
  uint8_t complete = 0;
  in.Get(magic, sizeof(magic));
  in.Get(version);
  in.Get(complete);
  in.Get(state.dims);
  in.Get(state.tile);
  in.Get(state.layers);
  in.Get(state.activeCount);
  in.Get(state.bounds);
  state.complete = complete != 0;
  const int64_t nx = state.dims[0], ny = state.dims[1], nz = state.dims[2];
  if (!in.Ok || std::memcmp(magic, StateMagic, sizeof(magic)) != 0 || version != StateVersion || nx <= 0 || ny <= 0 ||
    nz < 0 || nx > (int64_t(1) << 24) || ny > (int64_t(1) << 24) || state.tile <= 0 || state.layers < 0 ||
    state.layers > nz || (state.complete && state.layers != nz))
  {
    why = "not a partition state of this version, or truncated or corrupt";
    return false;
  }
  // The sizes the dimensions imply, checked against the file's before anything is allocated.
  const uint64_t tiles =
    static_cast<uint64_t>(((nx + state.tile - 1) / state.tile) * ((ny + state.tile - 1) / state.tile));
  const uint64_t columns = static_cast<uint64_t>(nx * ny);
  struct stat info;
  if (fstat(fileno(in.File), &info) != 0 ||
    double(info.st_size) < double(columns) + 20.0 * double(tiles) * double(state.layers))
  {
    why = "shorter than its dimensions imply";
    return false;
  }
  state.anyActive.resize(columns);
  bool sizes = in.Get<uint64_t>() == state.anyActive.size();
  in.Get(state.anyActive.data(), state.anyActive.size());
  sizes = sizes && in.Get<uint64_t>() == tiles;
  if (!sizes || !in.Ok)
  {
    why = "truncated, or its sizes do not match its dimensions";
    return false;
  }
  state.blocks.assign(tiles, std::vector<Block>(static_cast<std::size_t>(state.layers)));
  bool ordered = true;
  for (std::vector<Block>& blocks : state.blocks)
  {
    uint64_t end = 0;
    for (Block& block : blocks)
    {
      in.Get(block.offset);
      in.Get(block.stored);
      in.Get(block.crc);
      in.Get(block.planes);
      ordered = ordered && block.offset == end;
      end += block.stored;
    }
  }
  const uint64_t noteBytes = in.Get<uint64_t>();
  state.note.resize(static_cast<std::size_t>(in.Ok && noteBytes < (uint64_t(1) << 32) ? noteBytes : 0));
  in.Get(state.note.data(), state.note.size());
  const uint32_t crc = in.Crc;
  if (!in.Ok || !ordered || noteBytes != state.note.size() || in.Get<uint32_t>() != crc || !in.AtEnd())
  {
    why = "truncated or corrupt (checksum, block index or size)";
    return false;
  }
  return true;
}

bool LeafPartition::HasCheckpoint(const std::string& folder, bool* complete)
{
  State state;
  std::string why;
  const bool found = LoadState(folder + "/partition.state", state, why);
  if (complete)
  {
    *complete = found && state.complete;
  }
  return found;
}

LeafPartition::LeafPartition(const std::string& folder)
  : Folder(folder)
  , Owner(false)
{
  const std::string path = this->StatePath();
  State state;
  std::string why;
  if (!LoadState(path, state, why))
  {
    throw std::runtime_error(path + ": cannot read the partition written by rank 0: " + why);
  }
  if (!state.complete)
  {
    throw std::runtime_error(path + ": the partition pass stopped after " + std::to_string(state.layers) + " of " +
      std::to_string(state.dims[2]) + " layers; only a finished one can be opened for reading");
  }
  this->Dimensions = state.dims;
  this->Tile = state.tile;
  this->LayersDone = state.layers;
  this->ActiveCount = state.activeCount;
  this->Bounds = state.bounds;
  if (!LoadCoord(folder, state.dims, this->CoordValues, why))
  {
    throw std::runtime_error(folder + "/" + why);
  }
  this->AnyActive = std::move(state.anyActive);
  this->Blocks = std::move(state.blocks);
  this->Note = std::move(state.note);
  this->Complete = true;
  this->TilesX = (this->Dimensions[0] + this->Tile - 1) / this->Tile;
  this->TilesY = (this->Dimensions[1] + this->Tile - 1) / this->Tile;
  const std::size_t tiles = static_cast<std::size_t>(this->TilesX * this->TilesY);
  this->Readers.assign(tiles, 0);
  this->Removed.assign(tiles, 0);
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      const std::string tile = this->TilePath(ti, tj);
      const int descriptor = open(tile.c_str(), O_RDONLY | O_CLOEXEC);
      if (descriptor < 0 && errno != ENOENT)
      {
        const int error = errno;
        this->CloseTiles();
        throw std::runtime_error(tile + ": cannot open a partition tile: " + std::strerror(error));
      }
      this->Removed[this->Descriptors.size()] = descriptor < 0; // freed by a resumed build
      this->Descriptors.push_back(descriptor);
    }
  }
}

std::string LeafPartition::TilePath(int64_t ti, int64_t tj) const
{
  return this->Folder + "/tile-" + std::to_string(ti) + "-" + std::to_string(tj) + ".bin";
}

std::array<double, 2> LeafPartition::ColumnCentre(int64_t i, int64_t j) const
{
  const int64_t nx = this->Dimensions[0];
  double x = 0, y = 0;
  for (int64_t pj = j; pj <= j + 1; ++pj)
  {
    for (int64_t pi = i; pi <= i + 1; ++pi)
    {
      const double* p = &this->CoordValues[static_cast<std::size_t>(6 * (pj * (nx + 1) + pi))];
      x += 0.125 * (p[0] + p[3]);
      y += 0.125 * (p[1] + p[4]);
    }
  }
  return { x, y };
}

void LeafPartition::PillarPoint(int64_t pi, int64_t pj, double depth, double xyz[3]) const
{
  PointOnPillar(&this->CoordValues[static_cast<std::size_t>(6 * (pj * (this->Dimensions[0] + 1) + pi))], depth, xyz);
}

/// The tiles [ti0, ti1] x [tj0, tj1] a box of columns overlaps; throws for a box outside the grid.
std::array<int64_t, 4> LeafPartition::TileRange(int64_t i0, int64_t i1, int64_t j0, int64_t j1) const
{
  if (i0 < 0 || j0 < 0 || i1 > this->Dimensions[0] || j1 > this->Dimensions[1] || i0 >= i1 || j0 >= j1)
  {
    throw std::out_of_range("leaf partition: box outside the grid");
  }
  return { i0 / this->Tile, (i1 - 1) / this->Tile, j0 / this->Tile, (j1 - 1) / this->Tile };
}

void LeafPartition::Retain(int64_t i0, int64_t i1, int64_t j0, int64_t j1)
{
  const std::array<int64_t, 4> range = this->TileRange(i0, i1, j0, j1);
  std::lock_guard<std::mutex> guard(this->Lock);
  for (int64_t tj = range[2]; tj <= range[3]; ++tj)
  {
    for (int64_t ti = range[0]; ti <= range[1]; ++ti)
    {
      ++this->Readers[static_cast<std::size_t>(tj * this->TilesX + ti)];
    }
  }
}

void LeafPartition::Release(int64_t i0, int64_t i1, int64_t j0, int64_t j1)
{
  const std::array<int64_t, 4> range = this->TileRange(i0, i1, j0, j1);
  std::lock_guard<std::mutex> guard(this->Lock);
  for (int64_t tj = range[2]; tj <= range[3]; ++tj)
  {
    for (int64_t ti = range[0]; ti <= range[1]; ++ti)
    {
      const std::size_t t = static_cast<std::size_t>(tj * this->TilesX + ti);
      if (this->Readers[t] <= 0 || --this->Readers[t] > 0 || !this->Owner || this->Removed[t])
      {
        continue;
      }
      if (this->Descriptors[t] >= 0)
      {
        close(this->Descriptors[t]);
        this->Descriptors[t] = -1;
      }
      unlink(this->TilePath(ti, tj).c_str());
      this->Removed[t] = 1;
    }
  }
}

uint64_t LeafPartition::TileBytes() const
{
  std::lock_guard<std::mutex> guard(this->Lock);
  uint64_t bytes = 0;
  for (std::size_t t = 0; t < this->Blocks.size(); ++t)
  {
    bytes += this->Removed[t] ? 0 : this->TileEnd(t);
  }
  return bytes;
}

void LeafPartition::ReadBox(
  int64_t i0, int64_t i1, int64_t j0, int64_t j1, std::vector<float>& zcorn, std::vector<uint8_t>& active) const
{
  const std::array<int64_t, 4> range = this->TileRange(i0, i1, j0, j1);
  const int64_t w = i1 - i0, h = j1 - j0, nz = this->Dimensions[2];
  zcorn.resize(static_cast<std::size_t>(w * h * nz * 8)); // every value is set below
  active.resize(static_cast<std::size_t>(w * h * nz));
  for (int64_t tj = range[2]; tj <= range[3]; ++tj)
  {
    for (int64_t ti = range[0]; ti <= range[1]; ++ti)
    {
      this->ReadTile(ti, tj, i0, i1, j0, j1, zcorn, active);
    }
  }
}

/// The part of the box in tile (ti, tj), every layer: each block read, checked and
/// decompressed once, decoded as far as the box reaches into the tile.
void LeafPartition::ReadTile(int64_t ti, int64_t tj, int64_t i0, int64_t i1, int64_t j0, int64_t j1,
  std::vector<float>& zcorn, std::vector<uint8_t>& active) const
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1], nz = this->Dimensions[2];
  const int64_t w = i1 - i0, h = j1 - j0;
  const int64_t ti0 = ti * this->Tile, tj0 = tj * this->Tile;
  const int64_t tw = std::min(this->Tile, nx - ti0), th = std::min(this->Tile, ny - tj0);
  const int64_t a0 = std::max(i0, ti0), a1 = std::min(i1, ti0 + tw);
  const int64_t b0 = std::max(j0, tj0), b1 = std::min(j1, tj0 + th);
  const std::size_t t = static_cast<std::size_t>(tj * this->TilesX + ti);
  const std::string path = this->TilePath(ti, tj);
  int descriptor = -1;
  {
    std::lock_guard<std::mutex> guard(this->Lock);
    descriptor = this->Descriptors[t];
  }
  if (descriptor < 0)
  {
    throw std::runtime_error(path + ": the partition tile is gone (released once its leaves were built, or removed)");
  }
  std::vector<uint32_t> layers[2], residuals; // this layer's cells and the one above's
  layers[0].resize(static_cast<std::size_t>(tw * th * 8));
  layers[1].resize(layers[0].size());
  std::vector<uint8_t> stored, flags(static_cast<std::size_t>(tw * th));
  for (int64_t k = 0; k < nz; ++k)
  {
    const Block& block = this->Blocks[t][static_cast<std::size_t>(k)];
    const std::string place = path + ", layer " + std::to_string(k + 1);
    stored.resize(block.stored);
    ReadAll(descriptor, stored.data(), stored.size(), static_cast<off_t>(block.offset), place);
    ChunkRef ref;
    ref.stored = block.stored;
    ref.raw = static_cast<uint32_t>(RawBlockBytes(tw * th, block.planes));
    ref.crc = block.crc;
    const std::vector<uint8_t> raw = DecompressChunk(stored.data(), stored.size(), ref, place);
    std::vector<uint32_t>& cells = layers[k & 1];
    DecodeBlock(raw, block.planes, k > 0 ? layers[(k + 1) & 1].data() : nullptr, tw, th, a1 - ti0, b1 - tj0, residuals,
      cells.data(), flags.data());
    for (int64_t j = b0; j < b1; ++j)
    {
      const std::size_t from = static_cast<std::size_t>((j - tj0) * tw + (a0 - ti0));
      const std::size_t to = static_cast<std::size_t>((k * h + (j - j0)) * w + (a0 - i0));
      std::memcpy(&zcorn[to * 8], &cells[from * 8], static_cast<std::size_t>(a1 - a0) * 32);
      std::memcpy(&active[to], &flags[from], static_cast<std::size_t>(a1 - a0));
    }
  }
}

} // namespace resmr
