// The .resmr file: compressed region meshes, index and checks (paper Sec. 6.1). Ours: the
// checks, and the positions' layer groups (version 10; MultiresolutionFile.h).
#include "MultiresolutionFile.h"

#include "AtomicOutputFile.h"
#include "CornerPointGeometry.h"
#include "DiamondHierarchy.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{
namespace
{
constexpr char HeaderMagic[8] = { 'R', 'E', 'S', 'M', 'R', '\r', '\n', '\x1a' };
constexpr char TrailerMagic[8] = { 'R', 'E', 'S', 'M', 'R', 'I', 'D', 'X' };
constexpr std::size_t HeaderBytes = 256;
constexpr std::size_t RecordBytes = 192;
constexpr std::size_t ModelRecordBytes = 32;
constexpr uint32_t MapAxesFlag = 1;             // header: MAPAXES given
constexpr uint32_t GridInMapFlag = 2;           // header: GRIDUNIT says COORD is in map coordinates
constexpr std::size_t UnitBytes = 8;            // header: MAPUNITS, GRIDUNIT
constexpr uint32_t MeshMagic = 0x4853454d;      // "MESH"
constexpr uint32_t SurfaceMagic = 0x46525553;   // "SURF"
constexpr uint32_t TrianglesMagic = 0x53495254; // "TRIS"
/// No chunk of a sane file comes near this (a region holds Cmax columns).
constexpr const char* ChunkNames[4] = { "mesh", "top surface", "bottom surface", "side surface" };

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

} // namespace

void RoundToLattice(std::vector<double>& positions, const MultiresolutionHeader& header)
{
  for (std::size_t i = 0; i < positions.size(); ++i)
  {
    const int axis = static_cast<int>(i % 3);
    // As the decoder computes it, so the builder sees the bits every reader sees.
    positions[i] = header.latticeOrigin[axis] +
      Quantise(positions[i], header.latticeOrigin[axis], header.latticeStep[axis]) * header.latticeStep[axis];
  }
}

namespace
{

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

/// Interfaces [from, from + count) of every node, node by node, each value its difference from
/// the prediction, zig-zagged, in four byte planes. A layer group restarts the prediction (its
/// first interface predicted by the node before's), so it decodes without the groups above.
void PutPositions(
  ByteWriter& out, const RegionMesh& mesh, const MultiresolutionHeader& header, std::size_t from, std::size_t count)
{
  const std::size_t interfaces = static_cast<std::size_t>(mesh.layers) + 1;
  const std::size_t nodes = static_cast<std::size_t>(mesh.NodeCount());
  const std::size_t values = nodes * count * 3;
  std::vector<uint32_t> coded(values);
  std::array<int32_t, 3> previousFirst{ 0, 0, 0 };
  for (std::size_t node = 0; node < nodes; ++node)
  {
    std::array<int32_t, 3> above = previousFirst, twoAbove = previousFirst;
    for (std::size_t k = 0; k < count; ++k)
    {
      const std::size_t at = (node * interfaces + from + k) * 3;
      std::array<int32_t, 3> q;
      for (int axis = 0; axis < 3; ++axis)
      {
        q[axis] = Quantise(mesh.positions[at + axis], header.latticeOrigin[axis], header.latticeStep[axis]);
        const int32_t predicted = Predict(axis, k, above, twoAbove);
        coded[(node * count + k) * 3 + axis] =
          ZigZag(static_cast<int32_t>(static_cast<uint32_t>(q[axis]) - static_cast<uint32_t>(predicted)));
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
  out.Bytes.resize(start + values * 4);
  for (int plane = 0; plane < 4; ++plane)
  {
    uint8_t* bytes = &out.Bytes[start + plane * values];
    for (std::size_t i = 0; i < values; ++i)
    {
      bytes[i] = static_cast<uint8_t>(coded[i] >> (8 * plane));
    }
  }
}

/// Decodes interfaces [from, from + count) of every node from a group's byte planes (`planes`,
/// PutPositions' layout), keeping those of the window [mesh.firstLayer, mesh.firstLayer +
/// mesh.layers]: the group's interfaces above the window are decoded (each is predicted from
/// the two above it) but not kept, those below are skipped.
void GetPositions(
  const uint8_t* planes, RegionMesh& mesh, const MultiresolutionHeader& header, std::size_t from, std::size_t count)
{
  const std::size_t nodes = static_cast<std::size_t>(mesh.NodeCount());
  const std::size_t values = nodes * count * 3;
  const std::size_t first = static_cast<std::size_t>(mesh.firstLayer);
  const std::size_t kept = static_cast<std::size_t>(mesh.layers) + 1;
  // The first interface of the next node is predicted from this one's: always decoded.
  const std::size_t end = std::clamp<std::size_t>(first + kept, from + 1, from + count) - from;
  std::array<int32_t, 3> previousFirst{ 0, 0, 0 };
  for (std::size_t node = 0; node < nodes; ++node)
  {
    std::array<int32_t, 3> above = previousFirst, twoAbove = previousFirst;
    for (std::size_t k = 0; k < end; ++k)
    {
      const std::size_t at = (node * count + k) * 3;
      std::array<int32_t, 3> q;
      for (int axis = 0; axis < 3; ++axis)
      {
        const std::size_t i = at + axis;
        const uint32_t coded = uint32_t(planes[i]) | uint32_t(planes[values + i]) << 8 |
          uint32_t(planes[2 * values + i]) << 16 | uint32_t(planes[3 * values + i]) << 24;
        q[axis] = static_cast<int32_t>(
          static_cast<uint32_t>(Predict(axis, k, above, twoAbove)) + static_cast<uint32_t>(UnZigZag(coded)));
      }
      if (from + k >= first && from + k - first < kept)
      {
        double* out = &mesh.positions[(node * kept + (from + k - first)) * 3];
        for (int axis = 0; axis < 3; ++axis)
        {
          out[axis] = header.latticeOrigin[axis] + q[axis] * header.latticeStep[axis];
        }
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

/// Interfaces a layer group of a mesh chunk holds (LayerGroupsVersion): a window of a few
/// layers decompresses an eighth or so of a 100-layer region's positions, most of its bytes.
constexpr uint32_t GroupInterfaces = 8;

/// Layer groups of a mesh of `interfaces` interfaces a node, `each` a group.
std::size_t GroupCount(std::size_t interfaces, std::size_t each)
{
  return (interfaces + each - 1) / each;
}

/// The positions' layer groups, top down, each to be its own chunk.
std::vector<std::vector<uint8_t>> EncodeLayerGroups(const RegionMesh& mesh, const MultiresolutionHeader& header)
{
  const std::size_t interfaces = static_cast<std::size_t>(mesh.layers) + 1;
  std::vector<std::vector<uint8_t>> groups(GroupCount(interfaces, GroupInterfaces));
  for (std::size_t g = 0; g < groups.size(); ++g)
  {
    ByteWriter out;
    const std::size_t from = g * GroupInterfaces;
    PutPositions(out, mesh, header, from, std::min<std::size_t>(GroupInterfaces, interfaces - from));
    groups[g] = std::move(out.Bytes);
  }
  return groups;
}

/// The mesh chunk; its layer groups' chunks (`groups`: stored bytes, raw bytes, CRC) lie back
/// to back from the record's layerGroups.
std::vector<uint8_t> EncodeMesh(const RegionMesh& mesh, const std::vector<ChunkRef>& groups)
{
  ByteWriter out;
  out.Put(MeshMagic);
  out.Put(static_cast<uint32_t>(mesh.layers));
  out.Put(static_cast<uint32_t>(mesh.NodeCount()));
  out.Put(static_cast<uint32_t>(mesh.ColumnCount()));
  out.Put(GroupInterfaces);
  out.Put(static_cast<uint32_t>(groups.size()));
  for (const ChunkRef& group : groups)
  {
    out.Put(group.stored);
    out.Put(group.raw);
    out.Put(group.crc);
  }
  out.PutBytes(mesh.topology.data(), mesh.topology.size() * sizeof(mesh.topology[0]));
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

/// Every index of `polygons` is below `limit`; else the chunk is corrupt ("<what> 12 of 10").
template<typename Polygon>
void CheckIndices(const ByteReader& in, const std::vector<Polygon>& polygons, uint64_t limit, const char* what)
{
  for (const Polygon& polygon : polygons)
  {
    for (uint32_t index : polygon)
    {
      if (index >= limit)
      {
        throw FileFormatError(in.Where() + ": " + what + " " + std::to_string(index) + " of " + std::to_string(limit));
      }
    }
  }
}

/// Reads a layer group's chunk (DecodeRegion: decompressed and checked, errors naming it).
using LayerGroupReader = std::function<std::vector<uint8_t>(const ChunkRef&, std::size_t group)>;

/// The layer groups' table of a mesh chunk (LayerGroupsVersion): where each group's chunk lies
/// (back to back from the record's layerGroups) and its sizes, checked against the counts.
std::vector<ChunkRef> GetLayerGroups(
  ByteReader& in, const RegionRecord& record, std::size_t interfaces, uint32_t nodes, uint32_t& each)
{
  each = in.Get<uint32_t>();
  const uint32_t count = in.Get<uint32_t>();
  if (each < 1 || count != GroupCount(interfaces, each) || uint64_t(count) * 12 > in.Left())
  {
    throw FileFormatError(in.Where() + ": " + std::to_string(count) + " layer groups of " + std::to_string(each) +
      " interfaces for " + std::to_string(interfaces) + " interfaces a node");
  }
  std::vector<ChunkRef> groups(count);
  uint64_t offset = record.layerGroups;
  for (std::size_t g = 0; g < groups.size(); ++g)
  {
    ChunkRef& group = groups[g];
    group.offset = offset;
    group.stored = in.Get<uint32_t>();
    group.raw = in.Get<uint32_t>();
    group.crc = in.Get<uint32_t>();
    const uint64_t raw = uint64_t(nodes) * std::min<uint64_t>(each, interfaces - g * each) * 12;
    if (group.raw != raw)
    {
      throw FileFormatError(in.Where() + ": layer group " + std::to_string(g) + " of " + std::to_string(group.raw) +
        " bytes, not the " + std::to_string(raw) + " of its interfaces");
    }
    offset += group.stored;
  }
  return groups;
}

/// The positions of the mesh's window of layers (mesh.firstLayer, mesh.layers), from the layer
/// `groups` it reaches (of `each` interfaces), or without groups (before LayerGroupsVersion)
/// from the chunk's one plane set, next in `in`.
void GetWindowPositions(ByteReader& in, RegionMesh& mesh, const MultiresolutionHeader& header,
  const std::vector<ChunkRef>& groups, uint32_t each, std::size_t interfaces, const LayerGroupReader& readGroup)
{
  const std::size_t nodes = static_cast<std::size_t>(mesh.NodeCount());
  const std::size_t first = static_cast<std::size_t>(mesh.firstLayer);
  const std::size_t kept = static_cast<std::size_t>(mesh.layers) + 1;
  if (groups.empty() && nodes * interfaces * 12 > in.Left())
  {
    throw FileFormatError(in.Where() + ": " + std::to_string(nodes) + " nodes do not fit in the chunk");
  }
  mesh.positions.resize(nodes * kept * 3);
  if (groups.empty())
  {
    GetPositions(in.Skip(nodes * interfaces * 12), mesh, header, 0, interfaces);
    return;
  }
  for (std::size_t g = 0; g < groups.size(); ++g)
  {
    const std::size_t from = g * each, count = std::min<std::size_t>(each, interfaces - from);
    if (from < first + kept && from + count > first)
    {
      const std::vector<uint8_t> raw = readGroup(groups[g], g);
      GetPositions(raw.data(), mesh, header, from, count);
    }
  }
}

/// Decodes a mesh chunk, keeping the layers `choose` gives from the nodes' topological
/// coordinates (clamped to the model's; null: every layer).
void DecodeMesh(ByteReader& in, RegionMesh& mesh, const MultiresolutionHeader& header, const RegionRecord& record,
  const LayerWindowChooser* choose, const LayerGroupReader& readGroup)
{
  const uint32_t magic = in.Get<uint32_t>();
  const uint32_t layers = in.Get<uint32_t>(), nodes = in.Get<uint32_t>(), columns = in.Get<uint32_t>();
  if (magic != MeshMagic)
  {
    throw FileFormatError(in.Where() + ": not a mesh chunk");
  }
  if (static_cast<int64_t>(layers) != header.dims[2] || columns != static_cast<uint64_t>(record.columns) ||
    static_cast<uint64_t>(nodes) * (layers + 1) != static_cast<uint64_t>(record.vertices))
  {
    throw FileFormatError(in.Where() + ": " + std::to_string(layers) + " layers, " + std::to_string(nodes) +
      " nodes, " + std::to_string(columns) + " columns disagree with the index");
  }
  // The stored surfaces were extracted with this rule; readers extract them again.
  mesh.sealedPinchThickness = header.version >= 5 && record.level != header.leafLevel ? record.ownError : 0;
  uint32_t each = 0;
  const std::vector<ChunkRef> groups = header.version >= MultiresolutionHeader::LayerGroupsVersion
    ? GetLayerGroups(in, record, static_cast<std::size_t>(layers) + 1, nodes, each)
    : std::vector<ChunkRef>{};
  if (static_cast<uint64_t>(nodes) * 8 > in.Left())
  {
    throw FileFormatError(in.Where() + ": " + std::to_string(nodes) + " nodes do not fit in the chunk");
  }
  mesh.topology.resize(nodes);
  in.GetBytes(mesh.topology.data(), mesh.topology.size() * sizeof(mesh.topology[0]));
  for (const auto& t : mesh.topology)
  {
    if (!std::isfinite(t[0]) || !std::isfinite(t[1]) || t[0] < 0 || t[1] < 0 || t[0] > header.dims[0] ||
      t[1] > header.dims[1])
    {
      throw FileFormatError(in.Where() + ": a topological coordinate lies outside the grid");
    }
  }
  const std::array<int32_t, 2> window =
    choose ? (*choose)(mesh.topology) : std::array<int32_t, 2>{ 0, static_cast<int32_t>(layers) - 1 };
  const int32_t first = std::clamp<int32_t>(window[0], 0, static_cast<int32_t>(layers));
  const int32_t last = std::clamp<int32_t>(window[1], first - 1, static_cast<int32_t>(layers) - 1);
  mesh.firstLayer = first;
  mesh.layers = last - first + 1;
  GetWindowPositions(in, mesh, header, groups, each, static_cast<std::size_t>(layers) + 1, readGroup);
  if (static_cast<uint64_t>(columns) * (16 + layers + 1) != in.Left())
  {
    throw FileFormatError(in.Where() + ": column data of " + std::to_string(in.Left()) + " bytes for " +
      std::to_string(columns) + " columns");
  }
  mesh.corners.resize(columns);
  in.GetBytes(mesh.corners.data(), mesh.corners.size() * sizeof(mesh.corners[0]));
  CheckIndices(in, mesh.corners, nodes, "a column refers to node");
  // Every cell's flags are checked and counted against the index; the window's are kept.
  const uint8_t* flags = in.Skip(static_cast<std::size_t>(columns) * layers);
  const std::size_t kept = static_cast<std::size_t>(mesh.layers);
  mesh.active.resize(static_cast<std::size_t>(columns) * kept);
  mesh.openSides.resize(mesh.active.size());
  int64_t activeCells = 0;
  for (std::size_t c = 0; c < columns; ++c)
  {
    for (std::size_t k = 0; k < layers; ++k)
    {
      const std::size_t i = c * layers + k;
      if (flags[i] >> 5)
      {
        throw FileFormatError(
          in.Where() + ": cell flags " + std::to_string(flags[i]) + " of cell " + std::to_string(i) + " are not valid");
      }
      activeCells += flags[i] & 1;
      if (k >= static_cast<std::size_t>(first) && k - first < kept)
      {
        const std::size_t at = c * kept + (k - first);
        mesh.openSides[at] = flags[i] >> 1;
        mesh.active[at] = flags[i] & 1;
      }
    }
  }
  if (activeCells != record.activeCells)
  {
    throw FileFormatError(in.Where() + ": " + std::to_string(activeCells) + " active cells, the index says " +
      std::to_string(record.activeCells));
  }
  mesh.cutEdges.resize(columns);
  in.GetBytes(mesh.cutEdges.data(), mesh.cutEdges.size());
  for (std::size_t c = 0; c < mesh.cutEdges.size(); ++c)
  {
    if (mesh.cutEdges[c] >> 4)
    {
      throw FileFormatError(in.Where() + ": cut edges " + std::to_string(mesh.cutEdges[c]) + " of column " +
        std::to_string(c) + " name an edge beyond the column's four");
    }
  }
}

std::vector<uint8_t> EncodeSurface(const RegionSurface& surface)
{
  ByteWriter out;
  out.Put(SurfaceMagic);
  out.Put(static_cast<uint32_t>(surface.quads.size()));
  out.PutBytes(surface.cone.data(), sizeof(surface.cone));
  out.PutBytes(surface.quads.data(), surface.quads.size() * sizeof(surface.quads[0]));
  return std::move(out.Bytes);
}

void DecodeSurface(ByteReader& in, RegionSurface& surface, uint64_t vertices)
{
  const uint32_t magic = in.Get<uint32_t>();
  const uint32_t count = in.Get<uint32_t>();
  if (magic != SurfaceMagic)
  {
    throw FileFormatError(in.Where() + ": not a surface chunk");
  }
  in.GetBytes(surface.cone.data(), sizeof(surface.cone));
  if (static_cast<uint64_t>(count) * 16 != in.Left())
  {
    throw FileFormatError(
      in.Where() + ": " + std::to_string(count) + " quads in " + std::to_string(in.Left()) + " bytes");
  }
  surface.quads.resize(count);
  in.GetBytes(surface.quads.data(), surface.quads.size() * sizeof(surface.quads[0]));
  CheckIndices(in, surface.quads, vertices, "a quad refers to vertex");
}

std::vector<uint8_t> EncodeTriangles(const std::vector<std::array<uint32_t, 3>>& triangles)
{
  ByteWriter out;
  out.Put(TrianglesMagic);
  out.Put(static_cast<uint32_t>(triangles.size()));
  out.PutBytes(triangles.data(), triangles.size() * sizeof(triangles[0]));
  return std::move(out.Bytes);
}

void DecodeTriangles(ByteReader& in, std::vector<std::array<uint32_t, 3>>& triangles, uint64_t vertices)
{
  const uint32_t magic = in.Get<uint32_t>();
  const uint32_t count = in.Get<uint32_t>();
  if (magic != TrianglesMagic)
  {
    throw FileFormatError(in.Where() + ": not a triangle chunk");
  }
  if (static_cast<uint64_t>(count) * 12 != in.Left())
  {
    throw FileFormatError(
      in.Where() + ": " + std::to_string(count) + " triangles in " + std::to_string(in.Left()) + " bytes");
  }
  triangles.resize(count);
  in.GetBytes(triangles.data(), triangles.size() * sizeof(triangles[0]));
  CheckIndices(in, triangles, vertices, "a triangle refers to vertex");
}

void PutHeader(ByteWriter& out, const MultiresolutionHeader& h)
{
  out.PutBytes(HeaderMagic, 8);
  out.Put(MultiresolutionHeader::Version);
  out.Put(static_cast<uint32_t>(HeaderBytes));
  out.Put(h.dims);
  out.Put(h.box);
  out.Put(h.latticeOrigin);
  out.Put(h.latticeStep);
  out.Put(h.leafLevel);
  out.Put(h.cmax);
  out.Put(h.regionCount);
  out.Put(h.modelChunkCount);
  out.Put(h.hashTableSides);
  out.Put(h.hashOffsetSides);
  out.Put(h.hashedCells);
  out.Put(h.geometryId);
  out.Put(static_cast<uint32_t>((h.map.hasMapAxes ? MapAxesFlag : 0) | (h.map.gridUnitIsMap ? GridInMapFlag : 0)));
  out.Put(h.map.mapAxes.yAxisPoint);
  out.Put(h.map.mapAxes.origin);
  out.Put(h.map.mapAxes.xAxisPoint);
  for (const std::string* unit : { &h.map.mapUnits, &h.map.gridUnit })
  {
    char text[UnitBytes] = {}; // printable ASCII, NUL-padded (other characters become '?')
    for (std::size_t c = 0; c < std::min(unit->size(), UnitBytes); ++c)
    {
      const char u = (*unit)[c];
      text[c] = u >= 0x20 && u <= 0x7e ? u : '?';
    }
    out.PutBytes(text, UnitBytes);
  }
  out.Bytes.resize(HeaderBytes - 4, 0);
  out.Put(Crc32(out.Bytes.data(), out.Bytes.size()));
}

void PutRecord(ByteWriter& out, const RegionRecord& r)
{
  const std::size_t start = out.Bytes.size();
  out.Put(r.level);
  out.Put(std::max(r.typicalError, 0.f));
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
  out.Put(r.layerGroups);
  out.Bytes.resize(start + RecordBytes, 0);
}

/// A record as PutRecord wrote it; `reservedZero` tells whether its unused bytes are zero.
/// Before TypicalErrorVersion the typical error's four bytes were reserved too.
RegionRecord GetRecord(ByteReader& in, uint32_t version, bool& reservedZero)
{
  RegionRecord r;
  r.level = in.Get<int32_t>();
  int32_t reserved = 0;
  if (version >= MultiresolutionHeader::TypicalErrorVersion)
  {
    r.typicalError = in.Get<float>();
  }
  else
  {
    reserved = in.Get<int32_t>();
  }
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
  static_assert(RecordBytes == 4 + 4 + 8 * 4 + 24 + 8 + 32 + 4 * 20 + 8, "a record ends with its layer groups' offset");
  r.layerGroups = in.Get<uint64_t>();
  if (version < MultiresolutionHeader::LayerGroupsVersion)
  {
    reserved |= r.layerGroups != 0;
    r.layerGroups = 0;
  }
  reservedZero = reserved == 0;
  return r;
}
} // namespace

namespace
{

/// Decodes a region; with a window of layers narrower than the model's (`choose`), only its
/// mesh chunk, for those layers (MultiresolutionFile::ReadRegionLayers).
RegionMesh DecodeRegion(const uint8_t* data, uint64_t size, const std::string& path, const RegionRecord& record,
  const MultiresolutionHeader& header, const LayerWindowChooser* choose = nullptr)
{
  RegionMesh mesh;
  const std::string region =
    path + ": region (level " + std::to_string(record.level) + ", index " + std::to_string(record.index) + ") ";
  const auto chunk = [&](int c) {
    return DecompressChunk(
      data, size, record.chunks[c], region + ChunkNames[c] + " at byte " + std::to_string(record.chunks[c].offset));
  };
  {
    const auto raw = chunk(RegionRecord::Mesh);
    ByteReader in(raw.data(), raw.size(), region + ChunkNames[0]);
    DecodeMesh(in, mesh, header, record, choose, [&](const ChunkRef& group, std::size_t g) {
      return DecompressChunk(data, size, group,
        region + "mesh layer group " + std::to_string(g) + " at byte " + std::to_string(group.offset));
    });
  }
  if (mesh.layers < header.dims[2])
  {
    return mesh; // the stored surfaces number the whole mesh's vertices
  }
  RegionSurface* surfaces[2] = { &mesh.top, &mesh.bottom };
  for (int c = RegionRecord::Top; c <= RegionRecord::Bottom; ++c)
  {
    const auto raw = chunk(c);
    ByteReader in(raw.data(), raw.size(), region + ChunkNames[c]);
    DecodeSurface(in, *surfaces[c - 1], static_cast<uint64_t>(mesh.VertexCount()));
  }
  const auto raw = chunk(RegionRecord::Side);
  ByteReader in(raw.data(), raw.size(), region + ChunkNames[RegionRecord::Side]);
  DecodeTriangles(in, mesh.sideTriangles, static_cast<uint64_t>(mesh.VertexCount()));
  return mesh;
}

/// Model chunks a long array of `bytes` takes (ChunkFile::AddModelArray; one if empty).
uint64_t ModelPieces(uint64_t bytes)
{
  return std::max<uint64_t>(1, (bytes + ModelPieceBytes - 1) / ModelPieceBytes);
}

/// Throws naming the header field and what it must be.
[[noreturn]] void BadField(
  const std::string& path, const std::string& field, const std::string& value, const std::string& must)
{
  throw FileFormatError(path + ": header field '" + field + "' is " + value + ", must be " + must + " (corrupt)");
}

std::string Number(double value)
{
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

/// Every header field against what it must be (the map placement is checked as it is read).
void CheckHeader(const MultiresolutionHeader& h, const std::string& path)
{
  const char* const axes[3] = { "x", "y", "depth" };
  const int64_t maxDim = int64_t(1) << 24;
  for (int a = 0; a < 3; ++a)
  {
    if (h.dims[a] <= 0 || h.dims[a] > maxDim)
    {
      BadField(path, std::string("dimensions (n") + "xyz"[a] + ")", std::to_string(h.dims[a]),
        "1 to " + std::to_string(maxDim));
    }
  }
  if (h.dims[0] * h.dims[1] > (int64_t(1) << 40) / h.dims[2])
  {
    BadField(path, "dimensions",
      std::to_string(h.dims[0]) + " x " + std::to_string(h.dims[1]) + " x " + std::to_string(h.dims[2]),
      "at most 2^40 cells");
  }
  for (int a = 0; a < 2; ++a)
  {
    if (!std::isfinite(h.box[a]) || !std::isfinite(h.box[a + 2]) || !(h.box[a] < h.box[a + 2]))
    {
      BadField(path, std::string("hierarchy box (") + axes[a] + ")", Number(h.box[a]) + " to " + Number(h.box[a + 2]),
        "finite with a positive extent");
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(h.latticeOrigin[a]))
    {
      BadField(path, std::string("lattice origin (") + axes[a] + ")", Number(h.latticeOrigin[a]), "finite");
    }
    if (!std::isfinite(h.latticeStep[a]) || !(h.latticeStep[a] > 0))
    {
      BadField(path, std::string("lattice step (") + axes[a] + ")", Number(h.latticeStep[a]), "positive and finite");
    }
  }
  // The lattice's integers (int32) reach the whole box, and it resolves the box (the builder
  // takes 2^-22 of the larger lateral extent, at least 1): a coarser lattice would put every
  // position on a handful of points, or at infinity.
  const double lateral = std::max({ h.box[2] - h.box[0], h.box[3] - h.box[1], 1.0 });
  for (int a = 0; a < 2; ++a)
  {
    const double reach = std::ldexp(h.latticeStep[a], 31);
    if (std::fabs(h.box[a] - h.latticeOrigin[a]) >= reach || std::fabs(h.box[a + 2] - h.latticeOrigin[a]) >= reach)
    {
      BadField(path, std::string("lattice step (") + axes[a] + ")", Number(h.latticeStep[a]),
        "large enough for the lattice to reach the hierarchy box");
    }
    if (h.latticeStep[a] > lateral)
    {
      BadField(path, std::string("lattice step (") + axes[a] + ")", Number(h.latticeStep[a]),
        "at most the hierarchy box's extent " + Number(lateral));
    }
  }
  if (h.leafLevel < 0 || h.leafLevel > DiamondHierarchy::MaxDepth)
  {
    BadField(path, "leaf level", std::to_string(h.leafLevel), "0 to " + std::to_string(DiamondHierarchy::MaxDepth));
  }
  if (h.cmax < 1)
  {
    BadField(path, "Cmax", std::to_string(h.cmax), "at least 1");
  }
  // Each level holds at most 2^(level + 1) regions.
  const uint64_t maxRegions = h.leafLevel >= 38 ? uint64_t(1) << 40 : (uint64_t(4) << h.leafLevel) - 2;
  if (h.regionCount < static_cast<uint64_t>(h.leafLevel) + 1 || h.regionCount > maxRegions)
  {
    BadField(path, "region count", std::to_string(h.regionCount),
      std::to_string(h.leafLevel + 1) + " to " + std::to_string(maxRegions) + " for leaf level " +
        std::to_string(h.leafLevel));
  }
  for (int a = 0; a < 3; ++a)
  {
    if (h.hashTableSides[a] < 1 || h.hashTableSides[a] > PerfectSpatialHash::MaxSide)
    {
      BadField(path, "hash table sides", std::to_string(h.hashTableSides[a]),
        "1 to " + std::to_string(PerfectSpatialHash::MaxSide));
    }
    if (h.hashOffsetSides[a] < 1 || h.hashOffsetSides[a] > PerfectSpatialHash::MaxSide)
    {
      BadField(path, "hash offset sides", std::to_string(h.hashOffsetSides[a]),
        "1 to " + std::to_string(PerfectSpatialHash::MaxSide));
    }
  }
  // Active flags of every layer, then the offset, cell and normal tables in pieces of at most
  // ModelPieceBytes; then the pieces of a wall depth table, if any (from version 7 on).
  const uint64_t slots = uint64_t(h.hashTableSides[0]) * h.hashTableSides[1] * h.hashTableSides[2];
  const uint64_t offsets = uint64_t(h.hashOffsetSides[0]) * h.hashOffsetSides[1] * h.hashOffsetSides[2];
  const uint64_t chunks =
    static_cast<uint64_t>(h.dims[2]) + ModelPieces(offsets * 6) + ModelPieces(slots * 8) + ModelPieces(slots * 4);
  if (h.modelChunkCount < chunks)
  {
    BadField(path, "model chunk count", std::to_string(h.modelChunkCount),
      "at least " + std::to_string(chunks) + " for " + std::to_string(h.dims[2]) + " layers and the hash's sides");
  }
  const uint64_t cells = static_cast<uint64_t>(h.dims[0] * h.dims[1] * h.dims[2]);
  if (h.hashedCells < 1 || h.hashedCells > slots || h.hashedCells > cells)
  {
    BadField(path, "hashed cells", std::to_string(h.hashedCells),
      "1 to the table's " + std::to_string(slots) + " slots and the grid's " + std::to_string(cells) + " cells");
  }
}

/// One region record's fields against the header (chunks are checked by the caller).
void CheckRecord(const RegionRecord& r, const MultiresolutionHeader& h, const std::string& place)
{
  const auto fail = [&](const std::string& what) { throw FileFormatError(place + ": " + what + " (corrupt)"); };
  if (r.level < 0 || r.level > h.leafLevel || r.index < 0 || r.index >= (int64_t(2) << r.level))
  {
    fail("level or region index outside the hierarchy of leaf level " + std::to_string(h.leafLevel));
  }
  const int64_t layers = h.dims[2];
  if (r.columns < 1 || r.columns > h.dims[0] * h.dims[1])
  {
    fail(std::to_string(r.columns) + " columns in a grid of " + std::to_string(h.dims[0] * h.dims[1]));
  }
  if (r.activeCells < 0 || r.activeCells > r.columns * layers)
  {
    fail(std::to_string(r.activeCells) + " active cells in " + std::to_string(r.columns) + " columns");
  }
  // Each column has four corner nodes, each node a vertex at every layer interface.
  if (r.vertices < layers + 1 || r.vertices % (layers + 1) != 0 || r.vertices / (layers + 1) > 4 * r.columns)
  {
    fail(std::to_string(r.vertices) + " vertices for " + std::to_string(r.columns) + " columns of " +
      std::to_string(layers) + " layers");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(r.bounds[a]) || !std::isfinite(r.bounds[a + 3]) || r.bounds[a] > r.bounds[a + 3])
    {
      fail("bounding volume is not finite or empty");
    }
  }
  if (!std::isfinite(r.error) || !std::isfinite(r.ownError) || r.error < 0 || r.ownError < 0)
  {
    fail("error " + Number(r.error) + " or own error " + Number(r.ownError) + " is not finite and non-negative");
  }
  // A mean never passes the largest (a float's rounding aside).
  if (h.version >= MultiresolutionHeader::TypicalErrorVersion &&
    !(r.typicalError >= 0 && r.typicalError <= r.ownError * (1 + 1e-5f) + 1e-30f))
  {
    fail("typical error " + Number(r.typicalError) + " is not between 0 and the own error " + Number(r.ownError));
  }
  for (const auto* cone : { &r.topCone, &r.bottomCone })
  {
    const auto& c = *cone;
    const bool finite = std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]) && std::isfinite(c[3]);
    const double length = std::sqrt(double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2]);
    if (!finite || !(c[3] == -2 || (c[3] >= -1 && c[3] <= 1 && std::fabs(length - 1) < 1e-3)))
    {
      fail("normal cone is not finite, its axis not of unit length or its cosine not in [-1, 1] (nor -2, empty)");
    }
  }
}

/// Model chunks against the header: every layer's active flags once, of nx ny bits; the hash
/// arrays in whole pieces, of the sizes the hash's sides call for.
void CheckModelChunks(const std::vector<ModelChunk>& model, const MultiresolutionHeader& h, const std::string& path)
{
  const uint64_t layer = static_cast<uint64_t>(h.dims[0] * h.dims[1]);
  const uint64_t slots = uint64_t(h.hashTableSides[0]) * h.hashTableSides[1] * h.hashTableSides[2];
  const uint64_t offsets = uint64_t(h.hashOffsetSides[0]) * h.hashOffsetSides[1] * h.hashOffsetSides[2];
  const uint64_t expected[7] = { 0, (layer + 7) / 8, offsets * 6, slots * 8, slots * 4, 0, h.regionCount * 16 };
  const char* const names[7] = { "", "active flags", "hash offset table", "hash cell table", "cell normal table",
    "wall depth table", "region footprints" };
  std::vector<uint8_t> layerSeen(static_cast<std::size_t>(h.dims[2]), 0);
  uint64_t total[7] = {}, pieces[7] = {};
  for (const ModelChunk& m : model)
  {
    const std::string place = path + ": model chunk " + names[m.kind] + " part " + std::to_string(m.part);
    if (m.kind == ModelChunk::ActiveLayer)
    {
      if (m.part >= layerSeen.size() || layerSeen[m.part]++ != 0)
      {
        throw FileFormatError(place + ": no such layer, or a second chunk for it (corrupt)");
      }
      if (m.chunk.raw != expected[m.kind])
      {
        throw FileFormatError(
          place + ": " + std::to_string(m.chunk.raw) + " bytes for " + std::to_string(layer) + " cells (corrupt)");
      }
      continue;
    }
    total[m.kind] += m.chunk.raw;
    ++pieces[m.kind];
  }
  for (std::size_t k = 0; k < layerSeen.size(); ++k)
  {
    if (!layerSeen[k])
    {
      throw FileFormatError(path + ": no active flags for layer " + std::to_string(k + 1) + " (corrupt)");
    }
  }
  for (uint32_t kind = ModelChunk::HashOffsets; kind <= ModelChunk::CellNormals; ++kind)
  {
    if (total[kind] != expected[kind] || pieces[kind] != ModelPieces(expected[kind]))
    {
      throw FileFormatError(path + ": " + names[kind] + " of " + std::to_string(total[kind]) + " bytes in " +
        std::to_string(pieces[kind]) + " chunks, " + std::to_string(expected[kind]) +
        " expected from the header's hash sides (corrupt)");
    }
  }
  if (pieces[ModelChunk::WallDepths] > 0 &&
    pieces[ModelChunk::WallDepths] != ModelPieces(total[ModelChunk::WallDepths]))
  {
    throw FileFormatError(path + ": wall depth table of " + std::to_string(total[ModelChunk::WallDepths]) +
      " bytes in " + std::to_string(pieces[ModelChunk::WallDepths]) + " chunks (corrupt)");
  }
  const uint32_t footprints = ModelChunk::Footprints;
  if (pieces[footprints] > 0 &&
    (total[footprints] != expected[footprints] || pieces[footprints] != ModelPieces(expected[footprints])))
  {
    throw FileFormatError(path + ": region footprints of " + std::to_string(total[footprints]) + " bytes in " +
      std::to_string(pieces[footprints]) + " chunks, " + std::to_string(expected[footprints]) + " expected for " +
      std::to_string(h.regionCount) + " regions (corrupt)");
  }
}

} // namespace

void GeometryDigest::Add(const RegionRecord& region)
{
  for (const ChunkRef& c : region.chunks)
  {
    this->A = Crc32(&c.crc, 4, Crc32(&c.raw, 4, this->A));
    this->B = Crc32(&c.stored, 4, Crc32(&c.crc, 4, this->B));
  }
}

void GeometryDigest::Add(const ModelChunk& chunk)
{
  if (chunk.kind == ModelChunk::Footprints)
  {
    return; // derived from the regions, which the id covers
  }
  this->A = Crc32(&chunk.chunk.crc, 4, Crc32(&chunk.kind, 4, this->A));
  this->B = Crc32(&chunk.chunk.raw, 4, Crc32(&chunk.part, 4, this->B));
}

void ChooseLattice(const std::array<double, 6>& extent, MultiresolutionHeader& header)
{
  const double lateral = std::max({ extent[3] - extent[0], extent[4] - extent[1], 1.0 });
  const double vertical = std::max(extent[5] - extent[2], 1.0);
  // Centred, with 2^9 times the extent spare on each side for inactive corners outside it.
  // 2^-22 of the lateral extent (2.4 mm over 10 km) and 2^-20 of the depth range (0.3 mm
  // over 300 m): finer than any cell, coarse enough that differences pack into few bytes.
  header.latticeOrigin = { 0.5 * (extent[0] + extent[3]), 0.5 * (extent[1] + extent[4]),
    0.5 * (extent[2] + extent[5]) };
  header.latticeStep = { std::ldexp(lateral, -22), std::ldexp(lateral, -22), std::ldexp(vertical, -20) };
}

ChunkFile::ChunkFile(const std::string& path, int64_t keepBytes)
  : FilePath(path)
{
  this->Descriptor = keepBytes < 0 ? open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC, 0644) : open(path.c_str(), O_RDWR);
  if (this->Descriptor < 0)
  {
    throw FileFormatError(path + ": cannot open the chunk file: " + std::strerror(errno));
  }
  if (keepBytes >= 0)
  {
    struct stat info;
    if (fstat(this->Descriptor, &info) != 0 || info.st_size < keepBytes || ftruncate(this->Descriptor, keepBytes) != 0)
    {
      close(this->Descriptor);
      throw FileFormatError(
        path + ": shorter than the " + std::to_string(keepBytes) + " bytes its manifest records (cannot resume)");
    }
    this->Offset = static_cast<uint64_t>(keepBytes);
  }
}

ChunkFile::~ChunkFile()
{
  if (this->Descriptor >= 0)
  {
    close(this->Descriptor);
  }
}

ChunkFile::Stored ChunkFile::Compress(const std::vector<uint8_t>& raw, const std::string& what) const
{
  if (raw.size() >= MaxChunkBytes)
  {
    throw FileFormatError(
      this->FilePath + ": " + what + " of " + std::to_string(raw.size()) + " bytes is too big for a chunk");
  }
  Stored chunk{ CompressChunk(raw), ChunkRef{} };
  chunk.second.stored = static_cast<uint32_t>(chunk.first.size());
  chunk.second.raw = static_cast<uint32_t>(raw.size());
  chunk.second.crc = Crc32(chunk.first.data(), chunk.first.size());
  return chunk;
}

void ChunkFile::Append(std::vector<Stored>& run, const std::string& what)
{
  std::lock_guard<std::mutex> guard(this->Lock);
  for (Stored& chunk : run)
  {
    chunk.second.offset = this->Offset;
    const std::size_t length = chunk.first.size();
    std::size_t done = 0;
    while (done < length)
    {
      const ssize_t written =
        pwrite(this->Descriptor, chunk.first.data() + done, length - done, static_cast<off_t>(this->Offset + done));
      if (written <= 0)
      {
        throw FileFormatError(this->FilePath + ": writing the " + what + " at byte " +
          std::to_string(this->Offset + done) + " failed: " + std::strerror(errno));
      }
      done += static_cast<std::size_t>(written);
    }
    this->Offset += length;
  }
}

ChunkRef ChunkFile::Put(const std::vector<uint8_t>& raw, const std::string& what)
{
  std::vector<Stored> run{ this->Compress(raw, what) };
  this->Append(run, what);
  return run.front().second;
}

void ChunkFile::AddRegion(const RegionMesh& mesh, const MultiresolutionHeader& header, RegionRecord& record)
{
  const std::string region =
    "region (level " + std::to_string(record.level) + ", index " + std::to_string(record.index) + ") ";
  // The layer groups are compressed first, for the mesh chunk to hold their sizes and CRCs,
  // and written back to back before it.
  std::vector<Stored> run;
  std::vector<ChunkRef> groups;
  for (const std::vector<uint8_t>& raw : EncodeLayerGroups(mesh, header))
  {
    run.push_back(this->Compress(raw, region + "mesh layer group"));
    groups.push_back(run.back().second);
  }
  run.push_back(this->Compress(EncodeMesh(mesh, groups), region + ChunkNames[RegionRecord::Mesh]));
  this->Append(run, region + ChunkNames[RegionRecord::Mesh]);
  record.layerGroups = run.front().second.offset;
  record.chunks[RegionRecord::Mesh] = run.back().second;
  const std::vector<uint8_t> raw[RegionRecord::ChunkCount] = { {}, EncodeSurface(mesh.top), EncodeSurface(mesh.bottom),
    EncodeTriangles(mesh.sideTriangles) };
  for (int c = RegionRecord::Top; c < RegionRecord::ChunkCount; ++c)
  {
    record.chunks[c] = this->Put(raw[c], region + ChunkNames[c]);
  }
  record.columns = mesh.ColumnCount();
  record.vertices = mesh.VertexCount();
  record.activeCells = std::count(mesh.active.begin(), mesh.active.end(), uint8_t(1));
  record.topCone = mesh.top.cone;
  record.bottomCone = mesh.bottom.cone;
}

void ChunkFile::AddModelArray(uint32_t kind, const void* data, std::size_t bytes, std::vector<ModelChunk>& out)
{
  const auto* begin = static_cast<const uint8_t*>(data);
  uint32_t part = 0;
  for (std::size_t at = 0; at < bytes || (bytes == 0 && part == 0); at += ModelPieceBytes, ++part)
  {
    const std::size_t size = std::min(ModelPieceBytes, bytes - at);
    ModelChunk chunk;
    chunk.kind = kind;
    chunk.part = part;
    chunk.chunk = this->Put(std::vector<uint8_t>(begin + at, begin + at + size),
      "model array " + std::to_string(kind) + " piece " + std::to_string(part));
    out.push_back(chunk);
    if (bytes == 0)
    {
      break;
    }
  }
}

uint64_t ChunkFile::Sync()
{
  std::lock_guard<std::mutex> guard(this->Lock);
  if (fsync(this->Descriptor) != 0)
  {
    throw FileFormatError(this->FilePath + ": cannot flush to disk: " + std::strerror(errno));
  }
  return this->Offset;
}

void AssembleMultiresolutionFile(const std::string& path, MultiresolutionHeader header,
  const std::vector<std::string>& parts, const std::vector<PartRecord<RegionRecord>>& regions,
  const std::vector<PartRecord<ModelChunk>>& model)
{
  AtomicOutputFile output(path);
  uint64_t offset = 0;
  const auto write = [&](const void* data, std::size_t size, const std::string& what) {
    if (!output.Write(data, size))
    {
      throw FileFormatError(
        path + ": writing the " + what + " at byte " + std::to_string(offset) + " failed: " + std::strerror(errno));
    }
    offset += size;
  };
  GeometryDigest digest;
  for (const auto& r : regions)
  {
    digest.Add(r.record);
  }
  for (const auto& m : model)
  {
    digest.Add(m.record);
  }
  header.regionCount = regions.size();
  header.modelChunkCount = model.size();
  header.geometryId = digest.Id();
  ByteWriter head;
  PutHeader(head, header);
  write(head.Bytes.data(), head.Bytes.size(), "header");
  std::vector<uint64_t> base(parts.size());
  // Copied in blocks of 4 MiB, or of the largest part if smaller (no memory to zero for nothing).
  std::size_t blockSize = 1;
  for (const std::string& part : parts)
  {
    struct stat status;
    blockSize =
      std::max<std::size_t>(blockSize, stat(part.c_str(), &status) == 0 ? static_cast<std::size_t>(status.st_size) : 0);
  }
  blockSize = std::min<std::size_t>(blockSize, std::size_t(1) << 22);
  std::unique_ptr<uint8_t[]> block(new uint8_t[blockSize]);
  for (std::size_t p = 0; p < parts.size(); ++p)
  {
    base[p] = offset;
    std::FILE* in = std::fopen(parts[p].c_str(), "rb");
    if (!in)
    {
      throw FileFormatError(parts[p] + ": cannot open the chunk file: " + std::strerror(errno));
    }
    std::size_t got = 0;
    while ((got = std::fread(block.get(), 1, blockSize, in)) > 0)
    {
      write(block.get(), got, "chunks of " + parts[p]);
    }
    const bool failed = std::ferror(in) != 0;
    std::fclose(in);
    if (failed)
    {
      throw FileFormatError(parts[p] + ": read failed: " + std::strerror(errno));
    }
  }
  const auto moved = [&](int part, ChunkRef ref) {
    if (part < 0 || static_cast<std::size_t>(part) >= parts.size())
    {
      throw std::invalid_argument("AssembleMultiresolutionFile: no part " + std::to_string(part));
    }
    ref.offset += base[static_cast<std::size_t>(part)];
    return ref;
  };
  ByteWriter index;
  for (const auto& r : regions)
  {
    RegionRecord record = r.record;
    for (ChunkRef& c : record.chunks)
    {
      c = moved(r.part, c);
    }
    record.layerGroups = moved(r.part, ChunkRef{ record.layerGroups }).offset;
    PutRecord(index, record);
  }
  for (const auto& m : model)
  {
    const ChunkRef c = moved(m.part, m.record.chunk);
    index.Put(m.record.kind);
    index.Put(m.record.part);
    index.Put(c.offset);
    index.Put(c.stored);
    index.Put(c.raw);
    index.Put(c.crc);
    index.Put(static_cast<uint32_t>(0));
  }
  const uint64_t indexOffset = offset;
  write(index.Bytes.data(), index.Bytes.size(), "index");
  const auto trailer = IndexTrailer(indexOffset, index.Bytes, TrailerMagic);
  write(trailer.data(), trailer.size(), "trailer");
  output.Commit();
}

MultiresolutionFile::MultiresolutionFile(const std::string& path)
  : FilePath(path)
{
  this->Data = MapOwnFile(
    path, HeaderBytes + IndexTrailerBytes, HeaderMagic, "multiresolution", ".resmr", this->Size, this->Descriptor);
  try
  {
    ByteReader head(this->Data, HeaderBytes, path + ": header");
    uint8_t magic[8];
    head.GetBytes(magic, 8);
    const uint32_t version = head.Get<uint32_t>();
    if (version < MultiresolutionHeader::OldestVersion || version > MultiresolutionHeader::Version)
    {
      throw FileFormatError(path + ": format version " + std::to_string(version) +
        " at byte 8; this build reads versions " + std::to_string(MultiresolutionHeader::OldestVersion) + " to " +
        std::to_string(MultiresolutionHeader::Version) +
        (version < MultiresolutionHeader::OldestVersion ? " (build the file again with resmr build)"
                                                        : " (a newer build wrote it)"));
    }
    this->Head.version = version;
    uint32_t storedCrc;
    std::memcpy(&storedCrc, this->Data + HeaderBytes - 4, 4);
    if (Crc32(this->Data, HeaderBytes - 4) != storedCrc)
    {
      throw FileFormatError(
        path + ": header checksum mismatch (bytes 0-" + std::to_string(HeaderBytes - 5) + " are corrupt)");
    }
    const uint32_t headerSize = head.Get<uint32_t>();
    if (headerSize != HeaderBytes)
    {
      throw FileFormatError(path + ": header field 'header size' at byte 12 is " + std::to_string(headerSize) +
        ", must be " + std::to_string(HeaderBytes) + " (corrupt)");
    }
    head.Get(this->Head.dims);
    head.Get(this->Head.box);
    head.Get(this->Head.latticeOrigin);
    head.Get(this->Head.latticeStep);
    head.Get(this->Head.leafLevel);
    head.Get(this->Head.cmax);
    head.Get(this->Head.regionCount);
    head.Get(this->Head.modelChunkCount);
    head.Get(this->Head.hashTableSides);
    head.Get(this->Head.hashOffsetSides);
    this->Head.hashedCells = head.Get<uint64_t>();
    this->Head.geometryId = head.Get<uint64_t>();
    if (version >= 4)
    {
      this->ReadMapPlacement(head);
    }
    CheckHeader(this->Head, path);

    const auto [indexOffset, indexSize] = ReadIndexTrailer(this->Data, this->Size, HeaderBytes, TrailerMagic, path);
    if (indexSize != this->Head.regionCount * RecordBytes + this->Head.modelChunkCount * ModelRecordBytes)
    {
      throw FileFormatError(path + ": index of " + std::to_string(indexSize) + " bytes at byte " +
        std::to_string(indexOffset) + " does not hold the header's " + std::to_string(this->Head.regionCount) +
        " regions and " + std::to_string(this->Head.modelChunkCount) +
        " model chunks (header field 'region count' or " + "'model chunk count' corrupt)");
    }
    this->ReadIndex(indexOffset, indexSize);
  }
  catch (...)
  {
    UnmapFile(this->Data, this->Size);
    CloseDescriptor(this->Descriptor);
    throw;
  }
}

void MultiresolutionFile::ReadIndex(uint64_t indexOffset, uint64_t indexSize)
{
  const std::string& path = this->FilePath;
  ByteReader index(this->Data + indexOffset, indexSize, path + ": index");
  const auto checkChunk = [&](const ChunkRef& chunk, const std::string& what) {
    if (chunk.offset < HeaderBytes || chunk.offset > indexOffset || chunk.stored > indexOffset - chunk.offset)
    {
      throw FileFormatError(what + " at byte " + std::to_string(chunk.offset) + " of " + std::to_string(chunk.stored) +
        " bytes lies outside the data part of the file (corrupt)");
    }
    if (chunk.raw >= MaxChunkBytes || chunk.raw > MaxDecompressedBytes(chunk.stored))
    {
      throw FileFormatError(what + " at byte " + std::to_string(chunk.offset) + ": " + std::to_string(chunk.stored) +
        " bytes cannot decompress to " + std::to_string(chunk.raw) + " (corrupt)");
    }
  };
  GeometryDigest digest;
  std::set<std::pair<int32_t, int64_t>> seen;
  int32_t deepest = -1;
  this->Records.reserve(this->Head.regionCount);
  for (uint64_t i = 0; i < this->Head.regionCount; ++i)
  {
    bool reservedZero = false;
    RegionRecord r = GetRecord(index, this->Head.version, reservedZero);
    const std::string place = path + ": index record " + std::to_string(i) + " (level " + std::to_string(r.level) +
      ", region " + std::to_string(r.index) + ")";
    if (!reservedZero)
    {
      throw FileFormatError(place + ": reserved bytes are not zero (corrupt)");
    }
    CheckRecord(r, this->Head, place);
    if (!seen.insert({ r.level, r.index }).second)
    {
      throw FileFormatError(place + ": a second record of the same region (corrupt)");
    }
    for (int c = 0; c < RegionRecord::ChunkCount; ++c)
    {
      checkChunk(r.chunks[c], place + ": " + ChunkNames[c]);
    }
    if (this->Head.version >= MultiresolutionHeader::LayerGroupsVersion &&
      (r.layerGroups < HeaderBytes || r.layerGroups > indexOffset))
    {
      throw FileFormatError(place + ": layer groups at byte " + std::to_string(r.layerGroups) +
        " lie outside the data part of the file (corrupt)");
    }
    deepest = std::max(deepest, r.level);
    digest.Add(r);
    this->Records.push_back(r);
  }
  // The depth step resolves the regions' depth range as the lateral steps do the box.
  float top = std::numeric_limits<float>::infinity(), bottom = -top;
  for (const RegionRecord& r : this->Records)
  {
    top = std::min(top, r.bounds[2]);
    bottom = std::max(bottom, r.bounds[5]);
  }
  const double vertical = std::max(double(bottom) - double(top), 1.0);
  if (this->Head.latticeStep[2] > vertical)
  {
    BadField(path, "lattice step (depth)", Number(this->Head.latticeStep[2]),
      "at most the regions' depth range " + Number(vertical));
  }
  if (deepest != this->Head.leafLevel)
  {
    throw FileFormatError(path + ": header field 'leaf level' is " + std::to_string(this->Head.leafLevel) +
      " but the deepest region of the index is at level " + std::to_string(deepest) + " (corrupt)");
  }
  for (uint64_t i = 0; i < this->Head.modelChunkCount; ++i)
  {
    ModelChunk m;
    m.kind = index.Get<uint32_t>();
    m.part = index.Get<uint32_t>();
    m.chunk.offset = index.Get<uint64_t>();
    m.chunk.stored = index.Get<uint32_t>();
    m.chunk.raw = index.Get<uint32_t>();
    m.chunk.crc = index.Get<uint32_t>();
    const uint32_t reserved = index.Get<uint32_t>();
    const std::string place = path + ": model chunk record " + std::to_string(i) + " (kind " + std::to_string(m.kind) +
      ", part " + std::to_string(m.part) + ")";
    if (m.kind < ModelChunk::ActiveLayer || m.kind > ModelChunk::Footprints || reserved != 0)
    {
      throw FileFormatError(place + ": unknown kind or reserved bytes set (corrupt)");
    }
    checkChunk(m.chunk, place);
    digest.Add(m);
    this->Model.push_back(m);
  }
  CheckModelChunks(this->Model, this->Head, path);
  if (digest.Id() != this->Head.geometryId)
  {
    throw FileFormatError(path + ": header field 'geometry id' does not match the chunks of the index (corrupt)");
  }
}

void MultiresolutionFile::ReadMapPlacement(ByteReader& head)
{
  MapPlacement& map = this->Head.map;
  const std::size_t at = HeaderBytes - 4 - 4 - 6 * 8 - 2 * UnitBytes;
  const uint32_t flags = head.Get<uint32_t>();
  head.Get(map.mapAxes.yAxisPoint);
  head.Get(map.mapAxes.origin);
  head.Get(map.mapAxes.xAxisPoint);
  char text[2][UnitBytes];
  head.GetBytes(text[0], UnitBytes);
  head.GetBytes(text[1], UnitBytes);
  const auto fail = [&](const std::string& what) {
    throw FileFormatError(this->FilePath + ": header bytes " + std::to_string(at) + "-" +
      std::to_string(HeaderBytes - 5) + " (map placement): " + what + " (corrupt)");
  };
  if (flags > (MapAxesFlag | GridInMapFlag))
  {
    fail("unknown flags " + std::to_string(flags));
  }
  map.hasMapAxes = (flags & MapAxesFlag) != 0;
  map.gridUnitIsMap = (flags & GridInMapFlag) != 0;
  std::array<double, 6> transform;
  if (map.hasMapAxes && !map.gridUnitIsMap && !CornerPointGeometry::MapTransformOf(map.mapAxes, transform))
  {
    fail("MAPAXES axis points coincide with the origin or are not finite");
  }
  std::string* units[2] = { &map.mapUnits, &map.gridUnit };
  for (int u = 0; u < 2; ++u)
  {
    const std::size_t length = std::find(text[u], text[u] + UnitBytes, '\0') - text[u];
    units[u]->assign(text[u], length);
    if (std::any_of(units[u]->begin(), units[u]->end(), [](char c) { return c < 0x20 || c > 0x7e; }) ||
      std::any_of(text[u] + length, text[u] + UnitBytes, [](char c) { return c != '\0'; }))
    {
      fail(std::string(u == 0 ? "MAPUNITS" : "GRIDUNIT") + " is not text");
    }
    while (!units[u]->empty() && units[u]->back() == ' ')
    {
      units[u]->pop_back();
    }
  }
}

MultiresolutionFile::~MultiresolutionFile()
{
  UnmapFile(this->Data, this->Size);
  CloseDescriptor(this->Descriptor);
}

std::vector<std::size_t> UnreachableRegions(const MultiresolutionFile& file)
{
  std::set<std::pair<int32_t, int64_t>> present;
  for (const RegionRecord& r : file.Regions())
  {
    present.insert({ r.level, r.index });
  }
  std::vector<std::size_t> out;
  for (std::size_t n = 0; n < file.Regions().size(); ++n)
  {
    const RegionRecord& r = file.Regions()[n];
    if (r.level > 0 && !present.count({ r.level - 1, r.index / 2 }))
    {
      out.push_back(n);
    }
  }
  return out;
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
  return this->ReadChunk(record.chunks[chunk],
    this->FilePath + ": region (level " + std::to_string(record.level) + ", index " + std::to_string(record.index) +
      ") " + ChunkNames[chunk] + " at byte " + std::to_string(record.chunks[chunk].offset));
}

std::vector<uint8_t> MultiresolutionFile::ReadChunk(const ChunkRef& ref, const std::string& place) const
{
  CheckMappedSize(this->Descriptor, this->Size, this->FilePath);
  return DecompressChunk(this->Data, this->Size, ref, place);
}

std::vector<uint8_t> MultiresolutionFile::ReadActiveLayer(int64_t k) const
{
  const int64_t cells = this->Head.dims[0] * this->Head.dims[1];
  for (const ModelChunk& m : this->Model)
  {
    if (m.kind == ModelChunk::ActiveLayer && static_cast<int64_t>(m.part) == k)
    {
      const std::string place = this->FilePath + ": active flags of layer " + std::to_string(k + 1) + " at byte " +
        std::to_string(m.chunk.offset);
      const auto bits = this->ReadChunk(m.chunk, place);
      if (static_cast<int64_t>(bits.size()) != (cells + 7) / 8)
      {
        throw FileFormatError(
          place + ": " + std::to_string(bits.size()) + " bytes for " + std::to_string(cells) + " cells");
      }
      std::vector<uint8_t> flags(static_cast<std::size_t>(cells));
      for (int64_t c = 0; c < cells; ++c)
      {
        flags[static_cast<std::size_t>(c)] = (bits[static_cast<std::size_t>(c >> 3)] >> (c & 7)) & 1;
      }
      return flags;
    }
  }
  throw FileFormatError(this->FilePath + ": no active flags for layer " + std::to_string(k + 1));
}

PerfectSpatialHash MultiresolutionFile::ReadHash() const
{
  PerfectSpatialHash hash;
  hash.tableSides = this->Head.hashTableSides;
  hash.offsetSides = this->Head.hashOffsetSides;
  const auto raw = this->ReadModelArray(ModelChunk::HashOffsets);
  if (raw.size() != hash.OffsetTableSize() * 6)
  {
    throw FileFormatError(this->FilePath + ": hash offsets hold " + std::to_string(raw.size()) +
      " bytes for an offset table of " + std::to_string(hash.OffsetTableSize()) + " entries");
  }
  hash.offsets.resize(static_cast<std::size_t>(hash.OffsetTableSize()));
  std::memcpy(hash.offsets.data(), raw.data(), raw.size());
  for (const auto& o : hash.offsets)
  {
    if (o[0] >= hash.tableSides[0] || o[1] >= hash.tableSides[1] || o[2] >= hash.tableSides[2])
    {
      throw FileFormatError(this->FilePath + ": a hash offset lies outside the table (corrupt)");
    }
  }
  return hash;
}

std::vector<uint8_t> MultiresolutionFile::ReadModelArray(uint32_t kind) const
{
  std::vector<const ModelChunk*> pieces;
  for (const ModelChunk& m : this->Model)
  {
    if (m.kind == kind)
    {
      pieces.push_back(&m);
    }
  }
  std::sort(pieces.begin(), pieces.end(), [](const ModelChunk* a, const ModelChunk* b) { return a->part < b->part; });
  std::vector<uint8_t> out;
  const char* const names[] = { "model array", "active flags", "hash offset table", "hash cell table",
    "cell normal table", "wall depth table", "region footprints" };
  const std::string name = names[kind <= ModelChunk::Footprints ? kind : 0];
  for (std::size_t p = 0; p < pieces.size(); ++p)
  {
    const std::string place = this->FilePath + ": " + name + " (model chunk kind " + std::to_string(kind) + ") piece " +
      std::to_string(p) + " at byte " + std::to_string(pieces[p]->chunk.offset);
    if (pieces[p]->part != p || (p + 1 < pieces.size() && pieces[p]->chunk.raw != ModelPieceBytes))
    {
      throw FileFormatError(place + ": pieces missing or out of order");
    }
    const auto raw = this->ReadChunk(pieces[p]->chunk, place);
    out.insert(out.end(), raw.begin(), raw.end());
  }
  return out;
}

WallDepthTable MultiresolutionFile::ReadWallDepths() const
{
  const auto bytes = this->ReadModelArray(ModelChunk::WallDepths);
  if (bytes.empty())
  {
    return WallDepthTable{};
  }
  return DecodeWallDepthTable(bytes, this->Head.dims, this->FilePath + ": wall depth table");
}

std::vector<std::array<float, 4>> MultiresolutionFile::ReadFootprints() const
{
  const auto bytes = this->ReadModelArray(ModelChunk::Footprints);
  std::vector<std::array<float, 4>> footprints(bytes.size() / 16);
  if (!footprints.empty())
  {
    std::memcpy(footprints.data(), bytes.data(), footprints.size() * 16);
  }
  const float most = float(std::max(this->Head.dims[0], this->Head.dims[1]));
  for (std::size_t r = 0; r < footprints.size(); ++r)
  {
    const auto& f = footprints[r];
    const bool none = f[0] == 0 && f[1] == -1 && f[2] == 0 && f[3] == -1;
    const bool box = f[0] >= 0 && f[0] <= f[1] && f[1] <= most && f[2] >= 0 && f[2] <= f[3] && f[3] <= most;
    if (!none && !box)
    {
      throw FileFormatError(this->FilePath + ": region footprints: region " + std::to_string(r) + " spans i " +
        std::to_string(f[0]) + " to " + std::to_string(f[1]) + ", j " + std::to_string(f[2]) + " to " +
        std::to_string(f[3]) + ", not within the grid (corrupt)");
    }
  }
  return footprints;
}

RegionMesh MultiresolutionFile::ReadRegion(std::size_t i) const
{
  if (i >= this->Records.size())
  {
    throw std::out_of_range("multiresolution file: no region " + std::to_string(i));
  }
  CheckMappedSize(this->Descriptor, this->Size, this->FilePath);
  return DecodeRegion(this->Data, this->Size, this->FilePath, this->Records[i], this->Head);
}

RegionMesh MultiresolutionFile::ReadRegionLayers(std::size_t i, int32_t first, int32_t last) const
{
  return this->ReadRegionLayers(i, [first, last](const auto&) { return std::array<int32_t, 2>{ first, last }; });
}

RegionMesh MultiresolutionFile::ReadRegionLayers(std::size_t i, const LayerWindowChooser& choose) const
{
  if (i >= this->Records.size())
  {
    throw std::out_of_range("multiresolution file: no region " + std::to_string(i));
  }
  CheckMappedSize(this->Descriptor, this->Size, this->FilePath);
  return DecodeRegion(this->Data, this->Size, this->FilePath, this->Records[i], this->Head, &choose);
}

MappedChunkFile::MappedChunkFile(const std::string& path)
  : FilePath(path)
{
  this->Data = MapReadOnlyFile(path, this->Size);
}

MappedChunkFile::~MappedChunkFile()
{
  UnmapFile(this->Data, this->Size);
}

RegionMesh MappedChunkFile::ReadRegion(const RegionRecord& record, const MultiresolutionHeader& header) const
{
  return DecodeRegion(this->Data, this->Size, this->FilePath, record, header);
}

RegionMesh MultiresolutionFile::ReadRegionSurfaces(std::size_t i) const
{
  RegionMesh mesh = this->ReadRegion(i);
  mesh.positions.clear();
  mesh.positions.shrink_to_fit();
  return mesh;
}

} // namespace resmr
