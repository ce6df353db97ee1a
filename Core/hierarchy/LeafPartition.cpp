// Streaming partition of a corner-point model into tiles of columns (paper Sec. 4.2, 7).
#include "LeafPartition.h"

#include "CornerPointGeometry.h"

#include <algorithm>
#include <cerrno>
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

void ReadAll(int descriptor, void* data, std::size_t size, off_t offset, const std::string& path)
{
  auto* bytes = static_cast<uint8_t*>(data);
  while (size > 0)
  {
    const ssize_t got = pread(descriptor, bytes, size, offset);
    if (got <= 0)
    {
      throw std::runtime_error(path + ": scratch read at byte " + std::to_string(offset) + " failed" +
        (got < 0 ? std::string(": ") + std::strerror(errno) : std::string(" (file shorter than written)")));
    }
    bytes += got;
    size -= static_cast<std::size_t>(got);
    offset += got;
  }
}
} // namespace

LeafPartition::LeafPartition(LayerSource& source, const std::string& folder, int64_t tileSize,
  const std::function<void(double)>& progress,
  const std::function<void(int64_t k, const std::vector<uint8_t>& active)>& onLayer)
  : Dimensions(source.Dims())
  , CoordValues(source.Coord())
  , Tile(std::max<int64_t>(tileSize, 1))
  , Folder(folder)
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1], nz = this->Dimensions[2];
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
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      const std::string path = this->TilePath(ti, tj);
      const int descriptor = open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644);
      if (descriptor < 0)
      {
        for (int d : this->Descriptors)
        {
          close(d);
        }
        throw std::runtime_error(path + ": cannot create scratch file: " + std::strerror(errno));
      }
      this->Descriptors.push_back(descriptor);
    }
  }
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
  this->AnyActive.assign(static_cast<std::size_t>(nx * ny), 0);
  std::vector<float> zcorn, tileZ;
  std::vector<uint8_t> active, tileActive;
  for (int64_t k = 0; k < nz; ++k)
  {
    if (!source.Next(zcorn, active) || static_cast<int64_t>(zcorn.size()) != 8 * nx * ny ||
      static_cast<int64_t>(active.size()) != nx * ny)
    {
      throw std::runtime_error(
        source.Name() + ": layer " + std::to_string(k + 1) + " is missing or has the wrong size");
    }
    if (onLayer)
    {
      onLayer(k, active);
    }
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
          const double z = zcorn[static_cast<std::size_t>(
            (c >> 2) * 4 * nx * ny + (2 * j + ((c >> 1) & 1)) * 2 * nx + 2 * i + (c & 1))];
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
    for (int64_t tj = 0; tj < this->TilesY; ++tj)
    {
      for (int64_t ti = 0; ti < this->TilesX; ++ti)
      {
        const int64_t i0 = ti * this->Tile, j0 = tj * this->Tile;
        const int64_t w = std::min(this->Tile, nx - i0), h = std::min(this->Tile, ny - j0);
        tileZ.resize(static_cast<std::size_t>(w * h * 8));
        tileActive.resize(static_cast<std::size_t>(w * h));
        for (int64_t j = 0; j < h; ++j)
        {
          for (int64_t i = 0; i < w; ++i)
          {
            const int64_t gi = i0 + i, gj = j0 + j;
            float* out = &tileZ[static_cast<std::size_t>((j * w + i) * 8)];
            for (int c = 0; c < 8; ++c)
            {
              out[c] = zcorn[static_cast<std::size_t>(
                (c >> 2) * 4 * nx * ny + (2 * gj + ((c >> 1) & 1)) * 2 * nx + 2 * gi + (c & 1))];
            }
            tileActive[static_cast<std::size_t>(j * w + i)] = active[static_cast<std::size_t>(gj * nx + gi)];
          }
        }
        const std::size_t layerBytes = static_cast<std::size_t>(w * h) * 33;
        std::vector<uint8_t> bytes(layerBytes);
        std::memcpy(bytes.data(), tileZ.data(), tileZ.size() * 4);
        std::memcpy(bytes.data() + tileZ.size() * 4, tileActive.data(), tileActive.size());
        const int descriptor = this->Descriptors[static_cast<std::size_t>(tj * this->TilesX + ti)];
        WriteAll(descriptor, bytes.data(), bytes.size(), static_cast<off_t>(k * layerBytes), this->TilePath(ti, tj));
      }
    }
    if (progress)
    {
      progress(static_cast<double>(k + 1) / nz);
    }
  }
  if (this->ActiveCount == 0)
  {
    this->Bounds[2] = this->Bounds[5] = 0;
  }
}

LeafPartition::~LeafPartition()
{
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      const std::size_t t = static_cast<std::size_t>(tj * this->TilesX + ti);
      if (t < this->Descriptors.size())
      {
        close(this->Descriptors[t]);
      }
      if (this->Owner)
      {
        unlink(this->TilePath(ti, tj).c_str());
      }
    }
  }
  if (this->Owner)
  {
    unlink((this->Folder + "/partition.state").c_str());
    rmdir(this->Folder.c_str());
  }
}

void LeafPartition::SaveState() const
{
  const std::string path = this->Folder + "/partition.state";
  const std::string temporary = path + ".part";
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (!file)
  {
    throw std::runtime_error(temporary + ": cannot create: " + std::strerror(errno));
  }
  const uint64_t coordCount = this->CoordValues.size(), columnCount = this->AnyActive.size();
  bool ok = std::fwrite(this->Dimensions.data(), sizeof(int64_t), 3, file) == 3;
  ok = ok && std::fwrite(&this->Tile, sizeof(int64_t), 1, file) == 1;
  ok = ok && std::fwrite(&this->ActiveCount, sizeof(int64_t), 1, file) == 1;
  ok = ok && std::fwrite(this->Bounds.data(), sizeof(double), 6, file) == 6;
  ok = ok && std::fwrite(&coordCount, sizeof(uint64_t), 1, file) == 1;
  ok = ok && std::fwrite(this->CoordValues.data(), sizeof(double), coordCount, file) == coordCount;
  ok = ok && std::fwrite(&columnCount, sizeof(uint64_t), 1, file) == 1;
  ok = ok && std::fwrite(this->AnyActive.data(), 1, columnCount, file) == columnCount;
  ok = (std::fclose(file) == 0) && ok;
  if (!ok || std::rename(temporary.c_str(), path.c_str()) != 0)
  {
    unlink(temporary.c_str());
    throw std::runtime_error(path + ": write failed (disk full?)");
  }
}

LeafPartition::LeafPartition(const std::string& folder)
  : Folder(folder)
  , Owner(false)
{
  const std::string path = folder + "/partition.state";
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file)
  {
    throw std::runtime_error(path + ": cannot open the partition written by rank 0: " + std::strerror(errno));
  }
  uint64_t coordCount = 0, columnCount = 0;
  bool ok = std::fread(this->Dimensions.data(), sizeof(int64_t), 3, file) == 3;
  ok = ok && std::fread(&this->Tile, sizeof(int64_t), 1, file) == 1 && this->Tile > 0;
  ok = ok && std::fread(&this->ActiveCount, sizeof(int64_t), 1, file) == 1;
  ok = ok && std::fread(this->Bounds.data(), sizeof(double), 6, file) == 6;
  ok = ok && std::fread(&coordCount, sizeof(uint64_t), 1, file) == 1 && coordCount < (uint64_t(1) << 40);
  if (ok)
  {
    this->CoordValues.resize(coordCount);
    ok = std::fread(this->CoordValues.data(), sizeof(double), coordCount, file) == coordCount;
  }
  ok = ok && std::fread(&columnCount, sizeof(uint64_t), 1, file) == 1 && columnCount < (uint64_t(1) << 40);
  if (ok)
  {
    this->AnyActive.resize(columnCount);
    ok = std::fread(this->AnyActive.data(), 1, columnCount, file) == columnCount;
  }
  std::fclose(file);
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  if (!ok || nx <= 0 || ny <= 0 || static_cast<int64_t>(columnCount) != nx * ny)
  {
    throw std::runtime_error(path + ": truncated or corrupt");
  }
  this->TilesX = (nx + this->Tile - 1) / this->Tile;
  this->TilesY = (ny + this->Tile - 1) / this->Tile;
  for (int64_t tj = 0; tj < this->TilesY; ++tj)
  {
    for (int64_t ti = 0; ti < this->TilesX; ++ti)
    {
      const std::string tile = this->TilePath(ti, tj);
      const int descriptor = open(tile.c_str(), O_RDONLY);
      if (descriptor < 0)
      {
        throw std::runtime_error(tile + ": cannot open a partition tile: " + std::strerror(errno));
      }
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

void LeafPartition::ReadBox(
  int64_t i0, int64_t i1, int64_t j0, int64_t j1, std::vector<float>& zcorn, std::vector<uint8_t>& active) const
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1], nz = this->Dimensions[2];
  if (i0 < 0 || j0 < 0 || i1 > nx || j1 > ny || i0 >= i1 || j0 >= j1)
  {
    throw std::out_of_range("leaf partition: box outside the grid");
  }
  const int64_t w = i1 - i0, h = j1 - j0;
  zcorn.assign(static_cast<std::size_t>(w * h * nz * 8), 0.f);
  active.assign(static_cast<std::size_t>(w * h * nz), 0);
  std::vector<uint8_t> row;
  for (int64_t tj = j0 / this->Tile; tj <= (j1 - 1) / this->Tile; ++tj)
  {
    for (int64_t ti = i0 / this->Tile; ti <= (i1 - 1) / this->Tile; ++ti)
    {
      const int64_t ti0 = ti * this->Tile, tj0 = tj * this->Tile;
      const int64_t tw = std::min(this->Tile, nx - ti0), th = std::min(this->Tile, ny - tj0);
      const int64_t a0 = std::max(i0, ti0), a1 = std::min(i1, ti0 + tw);
      const int64_t b0 = std::max(j0, tj0), b1 = std::min(j1, tj0 + th);
      const std::size_t layerBytes = static_cast<std::size_t>(tw * th) * 33;
      const int descriptor = this->Descriptors[static_cast<std::size_t>(tj * this->TilesX + ti)];
      const std::string path = this->TilePath(ti, tj);
      // Whole rows of the tile between b0 and b1, one read a layer.
      const std::size_t rowsBytes = static_cast<std::size_t>((b1 - b0) * tw);
      row.resize(rowsBytes * 32);
      std::vector<uint8_t> flags(rowsBytes);
      for (int64_t k = 0; k < nz; ++k)
      {
        const off_t base = static_cast<off_t>(k * layerBytes);
        ReadAll(descriptor, row.data(), row.size(), base + static_cast<off_t>((b0 - tj0) * tw * 32), path);
        ReadAll(
          descriptor, flags.data(), flags.size(), base + static_cast<off_t>(tw * th * 32 + (b0 - tj0) * tw), path);
        for (int64_t j = b0; j < b1; ++j)
        {
          for (int64_t i = a0; i < a1; ++i)
          {
            const std::size_t from = static_cast<std::size_t>((j - b0) * tw + (i - ti0));
            const std::size_t to = static_cast<std::size_t>((k * h + (j - j0)) * w + (i - i0));
            std::memcpy(&zcorn[to * 8], &row[from * 32], 32);
            active[to] = flags[from];
          }
        }
      }
    }
  }
}

} // namespace resmr
