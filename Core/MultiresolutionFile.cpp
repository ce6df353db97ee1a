// The .resmr file: compressed region meshes, index and checks (paper Sec. 6.1).
#include "MultiresolutionFile.h"

#include "AtomicOutputFile.h"

#include <lzo/lzo1x.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <limits>
#include <mutex>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{
namespace
{
constexpr char HeaderMagic[8] = { 'R', 'E', 'S', 'M', 'R', '\r', '\n', '\x1a' };
constexpr char TrailerMagic[8] = { 'R', 'E', 'S', 'M', 'R', 'I', 'D', 'X' };
constexpr std::size_t HeaderBytes = 160;
constexpr std::size_t RecordBytes = 192;
constexpr std::size_t TrailerBytes = 32;
constexpr uint32_t MeshMagic = 0x4853454d;    // "MESH"
constexpr uint32_t SurfaceMagic = 0x46525553; // "SURF"
/// No chunk of a sane file comes near this (a region holds Cmax columns).
constexpr uint64_t MaxRawChunk = uint64_t(1) << 31;
constexpr const char* ChunkNames[4] = { "mesh", "top surface", "bottom surface", "side surface" };

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

/// Little-endian byte buffer.
class Buffer
{
public:
  template <typename T>
  void Put(const T& value)
  {
    const auto* bytes = reinterpret_cast<const uint8_t*>(&value);
    this->Bytes.insert(this->Bytes.end(), bytes, bytes + sizeof(T));
  }
  void PutBytes(const void* data, std::size_t size)
  {
    const auto* bytes = static_cast<const uint8_t*>(data);
    this->Bytes.insert(this->Bytes.end(), bytes, bytes + size);
  }
  std::vector<uint8_t> Bytes;
};

/// Reads what Buffer wrote, refusing to run past the end.
class Reader
{
public:
  Reader(const uint8_t* data, std::size_t size, std::string place)
    : Data(data)
    , Size(size)
    , Place(std::move(place))
  {
  }
  template <typename T>
  T Get()
  {
    T value;
    this->GetBytes(&value, sizeof(T));
    return value;
  }
  void GetBytes(void* out, std::size_t size)
  {
    if (size > this->Size - this->At)
    {
      throw MultiresolutionFileError(this->Place + ": ends early (needs " + std::to_string(size) + " more bytes at byte " +
        std::to_string(this->At) + " of " + std::to_string(this->Size) + ")");
    }
    std::memcpy(out, this->Data + this->At, size);
    this->At += size;
  }
  std::size_t Left() const { return this->Size - this->At; }
  const std::string& Where() const { return this->Place; }

private:
  const uint8_t* Data;
  std::size_t Size;
  std::size_t At = 0;
  std::string Place;
};

uint32_t ZigZag(int32_t v)
{
  return (static_cast<uint32_t>(v) << 1) ^ static_cast<uint32_t>(v >> 31);
}
int32_t UnZigZag(uint32_t v)
{
  return static_cast<int32_t>(v >> 1) ^ -static_cast<int32_t>(v & 1);
}

int32_t Quantise(double value, double origin, double step)
{
  const double q = std::nearbyint((value - origin) / step);
  if (!(q >= std::numeric_limits<int32_t>::min() && q <= std::numeric_limits<int32_t>::max()))
  {
    throw std::invalid_argument("multiresolution file: a position lies outside the model lattice");
  }
  return static_cast<int32_t>(q);
}

/// Positions as lattice integers, each stored as its difference from a prediction: x and y
/// continue the straight line of the two vertices above (pillars are straight lines, so the
/// difference is 0 or +-1), depth repeats the one above (the difference is the layer's
/// thickness); the first vertex of a node is predicted by the first of the node before.
/// Differences are zig-zagged and split into byte planes, which LZO packs well.
int32_t Predict(int axis, std::size_t k, const std::array<int32_t, 3>& above, const std::array<int32_t, 3>& twoAbove)
{
  if (axis < 2 && k >= 2)
  {
    return static_cast<int32_t>(2 * static_cast<uint32_t>(above[axis]) - static_cast<uint32_t>(twoAbove[axis]));
  }
  return above[axis];
}

void PutPositions(Buffer& out, const RegionMesh& mesh, const MultiresolutionHeader& header)
{
  const std::size_t interfaces = static_cast<std::size_t>(mesh.layers) + 1;
  const std::size_t count = mesh.positions.size();
  std::vector<uint32_t> coded(count);
  std::array<int32_t, 3> previousFirst{ 0, 0, 0 };
  for (std::size_t node = 0; node < static_cast<std::size_t>(mesh.NodeCount()); ++node)
  {
    std::array<int32_t, 3> above = previousFirst, twoAbove = previousFirst;
    for (std::size_t k = 0; k < interfaces; ++k)
    {
      const std::size_t at = (node * interfaces + k) * 3;
      std::array<int32_t, 3> q;
      for (int axis = 0; axis < 3; ++axis)
      {
        q[axis] = Quantise(mesh.positions[at + axis], header.latticeOrigin[axis], header.latticeStep[axis]);
        const int32_t predicted = Predict(axis, k, above, twoAbove);
        coded[at + axis] = ZigZag(static_cast<int32_t>(static_cast<uint32_t>(q[axis]) - static_cast<uint32_t>(predicted)));
      }
      if (k == 0)
      {
        previousFirst = q;
      }
      twoAbove = above;
      above = q;
    }
  }
  const std::size_t start = out.Bytes.size();
  out.Bytes.resize(start + count * 4);
  for (int plane = 0; plane < 4; ++plane)
  {
    uint8_t* bytes = &out.Bytes[start + plane * count];
    for (std::size_t i = 0; i < count; ++i)
    {
      bytes[i] = static_cast<uint8_t>(coded[i] >> (8 * plane));
    }
  }
}

void GetPositions(Reader& in, RegionMesh& mesh, const MultiresolutionHeader& header)
{
  const std::size_t interfaces = static_cast<std::size_t>(mesh.layers) + 1;
  const std::size_t count = static_cast<std::size_t>(mesh.NodeCount()) * interfaces * 3;
  if (count * 4 > in.Left())
  {
    throw MultiresolutionFileError(in.Where() + ": " + std::to_string(mesh.NodeCount()) + " nodes do not fit in the chunk");
  }
  std::vector<uint8_t> planes(count * 4);
  in.GetBytes(planes.data(), planes.size());
  mesh.positions.resize(count);
  std::array<int32_t, 3> previousFirst{ 0, 0, 0 };
  for (std::size_t node = 0; node < static_cast<std::size_t>(mesh.NodeCount()); ++node)
  {
    std::array<int32_t, 3> above = previousFirst, twoAbove = previousFirst;
    for (std::size_t k = 0; k < interfaces; ++k)
    {
      const std::size_t at = (node * interfaces + k) * 3;
      std::array<int32_t, 3> q;
      for (int axis = 0; axis < 3; ++axis)
      {
        const std::size_t i = at + axis;
        const uint32_t coded = uint32_t(planes[i]) | uint32_t(planes[count + i]) << 8 |
          uint32_t(planes[2 * count + i]) << 16 | uint32_t(planes[3 * count + i]) << 24;
        q[axis] = static_cast<int32_t>(
          static_cast<uint32_t>(Predict(axis, k, above, twoAbove)) + static_cast<uint32_t>(UnZigZag(coded)));
        mesh.positions[i] = header.latticeOrigin[axis] + q[axis] * header.latticeStep[axis];
      }
      if (k == 0)
      {
        previousFirst = q;
      }
      twoAbove = above;
      above = q;
    }
  }
}

std::vector<uint8_t> EncodeMesh(const RegionMesh& mesh, const MultiresolutionHeader& header)
{
  Buffer out;
  out.Put(MeshMagic);
  out.Put(static_cast<uint32_t>(mesh.layers));
  out.Put(static_cast<uint32_t>(mesh.NodeCount()));
  out.Put(static_cast<uint32_t>(mesh.ColumnCount()));
  out.PutBytes(mesh.topology.data(), mesh.topology.size() * sizeof(mesh.topology[0]));
  PutPositions(out, mesh, header);
  out.PutBytes(mesh.corners.data(), mesh.corners.size() * sizeof(mesh.corners[0]));
  // One byte a cell: bit 0 active, bits 1-4 open sides.
  std::vector<uint8_t> cells(mesh.active.size());
  for (std::size_t i = 0; i < cells.size(); ++i)
  {
    cells[i] = static_cast<uint8_t>((mesh.active[i] ? 1 : 0) | (mesh.openSides[i] & 0xF) << 1);
  }
  out.PutBytes(cells.data(), cells.size());
  out.PutBytes(mesh.cutEdges.data(), mesh.cutEdges.size());
  return std::move(out.Bytes);
}

void DecodeMesh(Reader& in, RegionMesh& mesh, const MultiresolutionHeader& header, const RegionRecord& record)
{
  const uint32_t magic = in.Get<uint32_t>();
  const uint32_t layers = in.Get<uint32_t>(), nodes = in.Get<uint32_t>(), columns = in.Get<uint32_t>();
  if (magic != MeshMagic)
  {
    throw MultiresolutionFileError(in.Where() + ": not a mesh chunk");
  }
  if (static_cast<int64_t>(layers) != header.dims[2] || columns != static_cast<uint64_t>(record.columns) ||
    static_cast<uint64_t>(nodes) * (layers + 1) != static_cast<uint64_t>(record.vertices))
  {
    throw MultiresolutionFileError(in.Where() + ": " + std::to_string(layers) + " layers, " + std::to_string(nodes) +
      " nodes, " + std::to_string(columns) + " columns disagree with the index");
  }
  mesh.layers = static_cast<int32_t>(layers);
  if (static_cast<uint64_t>(nodes) * 8 > in.Left())
  {
    throw MultiresolutionFileError(in.Where() + ": " + std::to_string(nodes) + " nodes do not fit in the chunk");
  }
  mesh.topology.resize(nodes);
  in.GetBytes(mesh.topology.data(), mesh.topology.size() * sizeof(mesh.topology[0]));
  for (const auto& t : mesh.topology)
  {
    if (!std::isfinite(t[0]) || !std::isfinite(t[1]) || t[0] < 0 || t[1] < 0 || t[0] > header.dims[0] ||
      t[1] > header.dims[1])
    {
      throw MultiresolutionFileError(in.Where() + ": a topological coordinate lies outside the grid");
    }
  }
  GetPositions(in, mesh, header);
  if (static_cast<uint64_t>(columns) * (16 + layers + 1) != in.Left())
  {
    throw MultiresolutionFileError(in.Where() + ": column data of " + std::to_string(in.Left()) + " bytes for " +
      std::to_string(columns) + " columns");
  }
  mesh.corners.resize(columns);
  in.GetBytes(mesh.corners.data(), mesh.corners.size() * sizeof(mesh.corners[0]));
  for (const auto& q : mesh.corners)
  {
    for (uint32_t node : q)
    {
      if (node >= nodes)
      {
        throw MultiresolutionFileError(in.Where() + ": a column refers to node " + std::to_string(node) + " of " +
          std::to_string(nodes));
      }
    }
  }
  mesh.active.resize(static_cast<std::size_t>(columns) * layers);
  in.GetBytes(mesh.active.data(), mesh.active.size());
  mesh.openSides.resize(mesh.active.size());
  for (std::size_t i = 0; i < mesh.active.size(); ++i)
  {
    if (mesh.active[i] >> 5)
    {
      throw MultiresolutionFileError(in.Where() + ": cell flags " + std::to_string(mesh.active[i]) + " of cell " +
        std::to_string(i) + " are not valid");
    }
    mesh.openSides[i] = mesh.active[i] >> 1;
    mesh.active[i] &= 1;
  }
  mesh.cutEdges.resize(columns);
  in.GetBytes(mesh.cutEdges.data(), mesh.cutEdges.size());
}

std::vector<uint8_t> EncodeSurface(const RegionSurface& surface)
{
  Buffer out;
  out.Put(SurfaceMagic);
  out.Put(static_cast<uint32_t>(surface.quads.size()));
  out.PutBytes(surface.cone.data(), sizeof(surface.cone));
  out.PutBytes(surface.quads.data(), surface.quads.size() * sizeof(surface.quads[0]));
  return std::move(out.Bytes);
}

void DecodeSurface(Reader& in, RegionSurface& surface, uint64_t vertices)
{
  const uint32_t magic = in.Get<uint32_t>();
  const uint32_t count = in.Get<uint32_t>();
  if (magic != SurfaceMagic)
  {
    throw MultiresolutionFileError(in.Where() + ": not a surface chunk");
  }
  in.GetBytes(surface.cone.data(), sizeof(surface.cone));
  if (static_cast<uint64_t>(count) * 16 != in.Left())
  {
    throw MultiresolutionFileError(in.Where() + ": " + std::to_string(count) + " quads in " + std::to_string(in.Left()) + " bytes");
  }
  surface.quads.resize(count);
  in.GetBytes(surface.quads.data(), surface.quads.size() * sizeof(surface.quads[0]));
  for (const auto& q : surface.quads)
  {
    for (uint32_t v : q)
    {
      if (v >= vertices)
      {
        throw MultiresolutionFileError(in.Where() + ": a quad refers to vertex " + std::to_string(v) + " of " +
          std::to_string(vertices));
      }
    }
  }
}

void PutHeader(Buffer& out, const MultiresolutionHeader& h)
{
  out.PutBytes(HeaderMagic, 8);
  out.Put(MultiresolutionHeader::Version);
  out.Put(static_cast<uint32_t>(HeaderBytes));
  for (int64_t d : h.dims)
  {
    out.Put(d);
  }
  for (double v : h.box)
  {
    out.Put(v);
  }
  for (double v : h.latticeOrigin)
  {
    out.Put(v);
  }
  for (double v : h.latticeStep)
  {
    out.Put(v);
  }
  out.Put(h.leafLevel);
  out.Put(h.cmax);
  out.Put(static_cast<uint64_t>(0)); // reserved; the region count is the index's (trailer)
  out.Bytes.resize(HeaderBytes - 4, 0);
  out.Put(Crc32(out.Bytes.data(), out.Bytes.size()));
}

void PutRecord(Buffer& out, const RegionRecord& r)
{
  const std::size_t start = out.Bytes.size();
  out.Put(r.level);
  out.Put(static_cast<int32_t>(0));
  out.Put(r.index);
  out.Put(r.columns);
  out.Put(r.activeCells);
  out.Put(r.vertices);
  out.PutBytes(r.bounds.data(), sizeof(r.bounds));
  out.Put(r.error);
  out.Put(r.ownError);
  out.PutBytes(r.topCone.data(), sizeof(r.topCone));
  out.PutBytes(r.bottomCone.data(), sizeof(r.bottomCone));
  for (const ChunkRef& c : r.chunks)
  {
    out.Put(c.offset);
    out.Put(c.stored);
    out.Put(c.raw);
    out.Put(c.crc);
  }
  out.Bytes.resize(start + RecordBytes, 0);
}

RegionRecord GetRecord(Reader& in)
{
  RegionRecord r;
  r.level = in.Get<int32_t>();
  in.Get<int32_t>();
  r.index = in.Get<int64_t>();
  r.columns = in.Get<int64_t>();
  r.activeCells = in.Get<int64_t>();
  r.vertices = in.Get<int64_t>();
  in.GetBytes(r.bounds.data(), sizeof(r.bounds));
  r.error = in.Get<float>();
  r.ownError = in.Get<float>();
  in.GetBytes(r.topCone.data(), sizeof(r.topCone));
  in.GetBytes(r.bottomCone.data(), sizeof(r.bottomCone));
  for (ChunkRef& c : r.chunks)
  {
    c.offset = in.Get<uint64_t>();
    c.stored = in.Get<uint32_t>();
    c.raw = in.Get<uint32_t>();
    c.crc = in.Get<uint32_t>();
  }
  uint8_t padding[RecordBytes - 4 - 4 - 8 * 4 - 24 - 8 - 32 - 4 * 20];
  in.GetBytes(padding, sizeof(padding));
  return r;
}
} // namespace

uint32_t Crc32(const void* data, std::size_t size, uint32_t crc)
{
  static const auto table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i)
    {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k)
      {
        c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      }
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  const auto* bytes = static_cast<const uint8_t*>(data);
  for (std::size_t i = 0; i < size; ++i)
  {
    crc = table[(crc ^ bytes[i]) & 0xFF] ^ (crc >> 8);
  }
  return ~crc;
}

void ChooseLattice(const std::array<double, 6>& extent, MultiresolutionHeader& header)
{
  const double lateral = std::max({ extent[3] - extent[0], extent[4] - extent[1], 1.0 });
  const double vertical = std::max(extent[5] - extent[2], 1.0);
  // Centred, with 2^9 times the extent spare on each side for inactive corners outside it.
  // 2^-22 of the lateral extent (2.4 mm over 10 km) and 2^-20 of the depth range (0.3 mm
  // over 300 m): finer than any cell, coarse enough that differences pack into few bytes.
  header.latticeOrigin = { 0.5 * (extent[0] + extent[3]), 0.5 * (extent[1] + extent[4]), 0.5 * (extent[2] + extent[5]) };
  header.latticeStep = { std::ldexp(lateral, -22), std::ldexp(lateral, -22), std::ldexp(vertical, -20) };
}

MultiresolutionWriter::MultiresolutionWriter(const std::string& path, const MultiresolutionHeader& header)
  : Output(new AtomicOutputFile(path))
  , Header(header)
{
  InitialiseLzo();
  Buffer head;
  PutHeader(head, header);
  this->WriteOrThrow(head.Bytes.data(), head.Bytes.size(), "header");
}

MultiresolutionWriter::~MultiresolutionWriter() = default;

const std::string& MultiresolutionWriter::Path() const
{
  return this->Output->Path();
}

void MultiresolutionWriter::WriteOrThrow(const void* data, std::size_t size, const char* what)
{
  if (!this->Output->Write(data, size))
  {
    throw MultiresolutionFileError(this->Output->Path() + ": writing the " + what + " at byte " +
      std::to_string(this->Offset) + " failed: " + std::strerror(errno));
  }
  this->Offset += size;
}

void MultiresolutionWriter::AddRegion(const RegionMesh& mesh, RegionRecord& record)
{
  std::vector<uint8_t> raw[RegionRecord::ChunkCount] = { EncodeMesh(mesh, this->Header), EncodeSurface(mesh.top),
    EncodeSurface(mesh.bottom), EncodeSurface(mesh.side) };
  std::vector<uint8_t> stored[RegionRecord::ChunkCount];
  std::vector<uint8_t> work(LZO1X_1_MEM_COMPRESS);
  for (int c = 0; c < RegionRecord::ChunkCount; ++c)
  {
    if (raw[c].size() >= MaxRawChunk)
    {
      throw MultiresolutionFileError(this->Output->Path() + ": region (level " + std::to_string(record.level) + ", index " +
        std::to_string(record.index) + ") " + ChunkNames[c] + " of " + std::to_string(raw[c].size()) +
        " bytes is too big for a chunk");
    }
    stored[c].resize(raw[c].size() + raw[c].size() / 16 + 64 + 3);
    lzo_uint length = 0;
    lzo1x_1_compress(raw[c].data(), raw[c].size(), stored[c].data(), &length, work.data());
    stored[c].resize(length);
    record.chunks[c].stored = static_cast<uint32_t>(length);
    record.chunks[c].raw = static_cast<uint32_t>(raw[c].size());
    record.chunks[c].crc = Crc32(stored[c].data(), length);
  }
  record.columns = mesh.ColumnCount();
  record.vertices = mesh.VertexCount();
  record.activeCells = std::count(mesh.active.begin(), mesh.active.end(), uint8_t(1));
  record.topCone = mesh.top.cone;
  record.bottomCone = mesh.bottom.cone;
  std::lock_guard<std::mutex> guard(this->Lock);
  for (int c = 0; c < RegionRecord::ChunkCount; ++c)
  {
    record.chunks[c].offset = this->Offset;
    this->WriteOrThrow(stored[c].data(), stored[c].size(), ChunkNames[c]);
  }
}

void MultiresolutionWriter::Commit(const std::vector<RegionRecord>& records)
{
  std::lock_guard<std::mutex> guard(this->Lock);
  Buffer index;
  for (const RegionRecord& r : records)
  {
    PutRecord(index, r);
  }
  const uint64_t indexOffset = this->Offset;
  this->WriteOrThrow(index.Bytes.data(), index.Bytes.size(), "index");
  Buffer trailer;
  trailer.Put(indexOffset);
  trailer.Put(static_cast<uint64_t>(index.Bytes.size()));
  trailer.Put(Crc32(index.Bytes.data(), index.Bytes.size()));
  trailer.Put(static_cast<uint32_t>(0));
  trailer.PutBytes(TrailerMagic, 8);
  this->WriteOrThrow(trailer.Bytes.data(), trailer.Bytes.size(), "trailer");
  this->Output->Commit();
}

MultiresolutionFile::MultiresolutionFile(const std::string& path)
  : FilePath(path)
{
  InitialiseLzo();
  const int descriptor = open(path.c_str(), O_RDONLY);
  if (descriptor < 0)
  {
    throw MultiresolutionFileError(path + ": cannot open: " + std::strerror(errno));
  }
  struct stat info;
  if (fstat(descriptor, &info) != 0 || !S_ISREG(info.st_mode))
  {
    close(descriptor);
    throw MultiresolutionFileError(path + ": not a regular file");
  }
  this->Size = static_cast<uint64_t>(info.st_size);
  if (this->Size < HeaderBytes + TrailerBytes)
  {
    close(descriptor);
    throw MultiresolutionFileError(path + ": " + std::to_string(this->Size) +
      " bytes, too short for a multiresolution file (truncated?)");
  }
  void* map = mmap(nullptr, this->Size, PROT_READ, MAP_SHARED, descriptor, 0);
  close(descriptor);
  if (map == MAP_FAILED)
  {
    throw MultiresolutionFileError(path + ": cannot map: " + std::strerror(errno));
  }
  this->Data = static_cast<const uint8_t*>(map);
  try
  {
    if (std::memcmp(this->Data, HeaderMagic, 8) != 0)
    {
      throw MultiresolutionFileError(path + ": not a multiresolution (.resmr) file (bad magic at byte 0)");
    }
    Reader head(this->Data, HeaderBytes, path + ": header");
    uint8_t magic[8];
    head.GetBytes(magic, 8);
    const uint32_t version = head.Get<uint32_t>();
    if (version != MultiresolutionHeader::Version)
    {
      throw MultiresolutionFileError(path + ": format version " + std::to_string(version) + "; this build reads version " +
        std::to_string(MultiresolutionHeader::Version));
    }
    uint32_t storedCrc;
    std::memcpy(&storedCrc, this->Data + HeaderBytes - 4, 4);
    if (Crc32(this->Data, HeaderBytes - 4) != storedCrc)
    {
      throw MultiresolutionFileError(path + ": header checksum mismatch (bytes 0-159 are corrupt)");
    }
    head.Get<uint32_t>();
    for (int64_t& d : this->Head.dims)
    {
      d = head.Get<int64_t>();
    }
    for (double& v : this->Head.box)
    {
      v = head.Get<double>();
    }
    for (double& v : this->Head.latticeOrigin)
    {
      v = head.Get<double>();
    }
    for (double& v : this->Head.latticeStep)
    {
      v = head.Get<double>();
    }
    this->Head.leafLevel = head.Get<int32_t>();
    this->Head.cmax = head.Get<int32_t>();
    head.Get<uint64_t>();

    Reader tail(this->Data + this->Size - TrailerBytes, TrailerBytes, path + ": trailer");
    const uint64_t indexOffset = tail.Get<uint64_t>(), indexSize = tail.Get<uint64_t>();
    const uint32_t indexCrc = tail.Get<uint32_t>();
    tail.Get<uint32_t>();
    tail.GetBytes(magic, 8);
    if (std::memcmp(magic, TrailerMagic, 8) != 0)
    {
      throw MultiresolutionFileError(path + ": no index trailer at the end of the file (truncated or unfinished)");
    }
    const uint64_t indexEnd = this->Size - TrailerBytes;
    if (indexOffset < HeaderBytes || indexOffset > indexEnd || indexSize != indexEnd - indexOffset ||
      indexSize % RecordBytes != 0)
    {
      throw MultiresolutionFileError(path + ": index at byte " + std::to_string(indexOffset) + " of " +
        std::to_string(indexSize) + " bytes does not fit a file of " + std::to_string(this->Size) +
        " bytes (truncated or corrupt)");
    }
    this->Head.regionCount = indexSize / RecordBytes;
    if (Crc32(this->Data + indexOffset, indexSize) != indexCrc)
    {
      throw MultiresolutionFileError(path + ": index checksum mismatch (bytes " + std::to_string(indexOffset) + "-" +
        std::to_string(indexEnd) + " are corrupt)");
    }
    Reader index(this->Data + indexOffset, indexSize, path + ": index");
    this->Records.reserve(this->Head.regionCount);
    for (uint64_t i = 0; i < this->Head.regionCount; ++i)
    {
      RegionRecord r = GetRecord(index);
      const std::string place = path + ": index record " + std::to_string(i) + " (level " + std::to_string(r.level) +
        ", region " + std::to_string(r.index) + ")";
      if (r.level < 0 || r.level > this->Head.leafLevel || r.index < 0 || r.index >= (int64_t(2) << r.level) ||
        r.columns < 0 || r.vertices < 0 || !std::isfinite(r.error))
      {
        throw MultiresolutionFileError(place + ": impossible level, region, counts or error");
      }
      for (int c = 0; c < RegionRecord::ChunkCount; ++c)
      {
        const ChunkRef& chunk = r.chunks[c];
        if (chunk.offset < HeaderBytes || chunk.offset > indexOffset || chunk.stored > indexOffset - chunk.offset ||
          chunk.raw >= MaxRawChunk)
        {
          throw MultiresolutionFileError(place + ": " + ChunkNames[c] + " at byte " + std::to_string(chunk.offset) +
            " of " + std::to_string(chunk.stored) + " bytes lies outside the data part of the file");
        }
      }
      this->Records.push_back(r);
    }
  }
  catch (...)
  {
    munmap(const_cast<uint8_t*>(this->Data), this->Size);
    throw;
  }
}

MultiresolutionFile::~MultiresolutionFile()
{
  munmap(const_cast<uint8_t*>(this->Data), this->Size);
}

const RegionRecord* MultiresolutionFile::Find(int32_t level, int64_t index) const
{
  for (const RegionRecord& r : this->Records)
  {
    if (r.level == level && r.index == index)
    {
      return &r;
    }
  }
  return nullptr;
}

std::vector<uint8_t> MultiresolutionFile::ReadChunk(const RegionRecord& record, int chunk) const
{
  const ChunkRef& ref = record.chunks[chunk];
  const std::string place = this->FilePath + ": region (level " + std::to_string(record.level) + ", index " +
    std::to_string(record.index) + ") " + ChunkNames[chunk] + " at byte " + std::to_string(ref.offset);
  if (Crc32(this->Data + ref.offset, ref.stored) != ref.crc)
  {
    throw MultiresolutionFileError(place + ": checksum mismatch (corrupt data)");
  }
  std::vector<uint8_t> raw(ref.raw);
  lzo_uint length = ref.raw;
  const int status = lzo1x_decompress_safe(this->Data + ref.offset, ref.stored, raw.data(), &length, nullptr);
  if (status != LZO_E_OK || length != ref.raw)
  {
    throw MultiresolutionFileError(place + ": does not decompress to its " + std::to_string(ref.raw) + " bytes");
  }
  return raw;
}

RegionMesh MultiresolutionFile::ReadRegion(std::size_t i) const
{
  if (i >= this->Records.size())
  {
    throw std::out_of_range("multiresolution file: no region " + std::to_string(i));
  }
  const RegionRecord& record = this->Records[i];
  RegionMesh mesh;
  const std::string region = this->FilePath + ": region (level " + std::to_string(record.level) + ", index " +
    std::to_string(record.index) + ") ";
  {
    const auto raw = this->ReadChunk(record, RegionRecord::Mesh);
    Reader in(raw.data(), raw.size(), region + ChunkNames[0]);
    DecodeMesh(in, mesh, this->Head, record);
  }
  RegionSurface* surfaces[3] = { &mesh.top, &mesh.bottom, &mesh.side };
  for (int c = RegionRecord::Top; c <= RegionRecord::Side; ++c)
  {
    const auto raw = this->ReadChunk(record, c);
    Reader in(raw.data(), raw.size(), region + ChunkNames[c]);
    DecodeSurface(in, *surfaces[c - 1], static_cast<uint64_t>(mesh.VertexCount()));
  }
  return mesh;
}

} // namespace resmr
