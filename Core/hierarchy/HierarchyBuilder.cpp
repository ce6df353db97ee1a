// Out-of-core, multi-threaded build of the diamond hierarchy, paper Sec. 4.2 (with 4.3 and 6.2).
#include "HierarchyBuilder.h"

#include "BuildJournal.h"
#include "BuildSchedule.h"
#include "ByteStream.h"
#include "ColumnCollapse.h"
#include "ColumnMesh.h"
#include "DiamondHierarchy.h"
#include "DiskUse.h"
#include "FaultWelding.h"
#include "HashMix.h"
#include "LeafPartition.h"
#include "MemoryBudget.h"
#include "MultiresolutionFile.h"
#include "NormalQuantization.h"
#include "PerfectSpatialHash.h"
#include "RegionMesh.h"
#include "SideSurfaceSimplification.h"
#include "ThreadGroup.h"
#include "WallDepthTable.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <exception>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>
#include <unordered_map>

namespace resmr
{
namespace
{
/// A region's mesh between levels: the column mesh with quadrics, which edges border another
/// region and which side faces are external.
struct ScratchRegion
{
  ColumnMeshData mesh;
  std::vector<uint8_t> cutEdges;  ///< per column, bit e
  std::vector<uint8_t> openSides; ///< per cell, bit e: side face e is external (see RegionMesh)
  /// Error the region has beyond its quadrics' (faults welded at its level); not saved: the
  /// levels above take it as their descendants' error.
  double weldError = 0;
};

std::string RegionPath(const std::string& folder, int level, int64_t index)
{
  return folder + "/region-" + std::to_string(level) + "-" + std::to_string(index) + ".bin";
}

template<typename T>
void PutVector(ByteWriter& out, const std::vector<T>& values)
{
  out.Put(static_cast<uint64_t>(values.size()));
  out.PutBytes(values.data(), values.size() * sizeof(T));
}

template<typename T>
void GetVector(ByteReader& in, std::vector<T>& values)
{
  const uint64_t count = std::min<uint64_t>(in.Get<uint64_t>(), in.Left() / sizeof(T) + 1);
  const uint8_t* bytes = in.Skip(static_cast<std::size_t>(count * sizeof(T)));
  values.resize(static_cast<std::size_t>(count));
  if (count > 0)
  {
    std::memcpy(values.data(), bytes, static_cast<std::size_t>(count * sizeof(T)));
  }
}

/// Scratch files are LZO-compressed in pieces (chunks hold at most MaxChunkBytes), written
/// under a temporary name, synced and renamed: a scratch file is there whole or not at all.
void SaveCompressed(const std::string& path, const std::vector<uint8_t>& raw)
{
  constexpr std::size_t piece = std::size_t(1) << 30;
  const std::string temporary = path + ".part";
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (!file)
  {
    throw std::runtime_error(path + ": cannot create scratch file: " + std::strerror(errno));
  }
  const uint64_t size = raw.size();
  bool ok = std::fwrite(&size, sizeof(size), 1, file) == 1;
  for (std::size_t at = 0; ok && at < raw.size(); at += piece)
  {
    const std::vector<uint8_t> part(raw.begin() + static_cast<std::ptrdiff_t>(at),
      raw.begin() + static_cast<std::ptrdiff_t>(std::min(raw.size(), at + piece)));
    const std::vector<uint8_t> stored = CompressChunk(part);
    const uint32_t head[3] = { static_cast<uint32_t>(stored.size()), static_cast<uint32_t>(part.size()),
      Crc32(stored.data(), stored.size()) };
    ok = std::fwrite(head, sizeof(head), 1, file) == 1 &&
      std::fwrite(stored.data(), 1, stored.size(), file) == stored.size();
  }
  ok = (std::fflush(file) == 0) && (fsync(fileno(file)) == 0) && ok;
  ok = (std::fclose(file) == 0) && ok;
  if (!ok || std::rename(temporary.c_str(), path.c_str()) != 0)
  {
    unlink(temporary.c_str());
    throw std::runtime_error(path + ": scratch write failed (disk full?)");
  }
}

/// False if the file is absent; throws naming it if it is damaged.
bool LoadCompressed(const std::string& path, std::vector<uint8_t>& raw)
{
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file)
  {
    return false;
  }
  std::vector<uint8_t> stored;
  uint8_t block[65536];
  std::size_t got = 0;
  while ((got = std::fread(block, 1, sizeof(block), file)) > 0)
  {
    stored.insert(stored.end(), block, block + got);
  }
  std::fclose(file);
  uint64_t size = 0;
  bool ok = stored.size() >= sizeof(size);
  if (ok)
  {
    std::memcpy(&size, stored.data(), sizeof(size));
  }
  raw.clear();
  std::size_t at = sizeof(size);
  while (ok && raw.size() < size)
  {
    uint32_t head[3];
    ok = at + sizeof(head) <= stored.size();
    if (!ok)
    {
      break;
    }
    std::memcpy(head, stored.data() + at, sizeof(head));
    ChunkRef ref;
    ref.offset = at + sizeof(head);
    ref.stored = head[0];
    ref.raw = head[1];
    ref.crc = head[2];
    try
    {
      const std::vector<uint8_t> part = DecompressChunk(stored.data(), stored.size(), ref, path);
      raw.insert(raw.end(), part.begin(), part.end());
    }
    catch (const std::exception&)
    {
      ok = false;
    }
    at = ref.offset + ref.stored;
  }
  if (!ok || raw.size() != size || at != stored.size())
  {
    throw std::runtime_error(path + ": scratch file is truncated or corrupt");
  }
  return true;
}

/// Every array of a scratch region, in the order its file holds them.
template<typename Region, typename Visit>
void EachArray(Region& region, Visit&& visit)
{
  visit(region.mesh.positions);
  visit(region.mesh.quadrics);
  visit(region.mesh.topology);
  visit(region.mesh.corners);
  visit(region.mesh.activeCells);
  visit(region.mesh.origin);
  visit(region.cutEdges);
  visit(region.openSides);
}

void SaveRegion(const std::string& path, const ScratchRegion& region)
{
  ByteWriter out;
  out.Put(region.mesh.layers);
  EachArray(region, [&](const auto& values) { PutVector(out, values); });
  SaveCompressed(path, out.Bytes);
}

bool LoadRegion(const std::string& path, ScratchRegion& region)
{
  std::vector<uint8_t> raw;
  if (!LoadCompressed(path, raw))
  {
    return false; // an empty region saves nothing
  }
  try
  {
    ByteReader in(raw.data(), raw.size(), path);
    region.mesh.layers = in.Get<int32_t>();
    EachArray(region, [&](auto& values) { GetVector(in, values); });
  }
  catch (const std::exception&)
  {
    throw std::runtime_error(path + ": scratch file is truncated or corrupt");
  }
  return true;
}

/// The column across edge e (corner e to e + 1) of a column, or -1.
int32_t Across(const ColumnMesh& mesh, int32_t column, int e)
{
  const auto& q = mesh.ColumnCorners(column);
  const int32_t a = q[e], b = q[(e + 1) % 4];
  for (int32_t other : mesh.NodeColumns(a))
  {
    if (other == column || !mesh.IsColumnAlive(other))
    {
      continue;
    }
    const auto& o = mesh.ColumnCorners(other);
    for (int f = 0; f < 4; ++f)
    {
      if (o[f] == b && o[(f + 1) % 4] == a)
      {
        return other;
      }
    }
  }
  return -1;
}

/// The columns across the model's faults (ours, not the paper's): a boundary edge whose two
/// pillars, as topological coordinates, another boundary edge of the mesh runs between the
/// other way round is the other side of a fault. Regions are cut along column edges, and
/// where a cut follows a fault its two sides land in different regions: the edge must be
/// cut there (locked, as every edge between regions) or each region simplifies its side of
/// the fault on its own and the two part.
class FaultSides
{
public:
  explicit FaultSides(const ColumnMesh& mesh)
  {
    for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
    {
      for (int e = 0; mesh.IsColumnAlive(c) && e < 4; ++e)
      {
        if (mesh.IsBoundaryEdge(c, e))
        {
          this->Edges.emplace(Key(mesh, c, e, false), c);
        }
      }
    }
  }

  /// The column across the fault from edge e of `column`, or -1 (no fault there).
  int32_t Across(const ColumnMesh& mesh, int32_t column, int e) const
  {
    const auto found = this->Edges.find(Key(mesh, column, e, true));
    return found == this->Edges.end() || found->second == column ? -1 : found->second;
  }

private:
  static std::array<double, 4> Key(const ColumnMesh& mesh, int32_t column, int e, bool reversed)
  {
    const auto& q = mesh.ColumnCorners(column);
    const auto& a = mesh.TopologicalCoordinate(q[reversed ? (e + 1) % 4 : e]);
    const auto& b = mesh.TopologicalCoordinate(q[reversed ? e : (e + 1) % 4]);
    return { a[0], a[1], b[0], b[1] };
  }
  std::map<std::array<double, 4>, int32_t> Edges;
};

/// Open sides of every alive column's cells, from the columns across; edges flagged in `cut`
/// (one mask a column slot) keep the flags in `openSides` (one byte a cell slot), since the
/// cells across them lie in another region.
void UpdateOpenSides(const ColumnMesh& mesh, const std::vector<uint8_t>& cut, std::vector<uint8_t>& openSides)
{
  const std::size_t layers = static_cast<std::size_t>(mesh.Layers());
  openSides.resize(static_cast<std::size_t>(mesh.ColumnSlots()) * layers, 0);
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (!mesh.IsColumnAlive(c))
    {
      continue;
    }
    for (int e = 0; e < 4; ++e)
    {
      if (cut[c] & (1u << e))
      {
        continue;
      }
      const int32_t other = Across(mesh, c, e);
      for (std::size_t k = 0; k < layers; ++k)
      {
        uint8_t& flags = openSides[c * layers + k];
        const bool open = other < 0 || !mesh.IsCellActive(other, static_cast<int32_t>(k));
        flags = static_cast<uint8_t>(open ? flags | (1u << e) : flags & ~(1u << e));
      }
    }
  }
}

/// The cells of the columns flagged in `keep`, in order.
std::vector<uint8_t> KeptCells(
  const std::vector<uint8_t>& perCell, const std::vector<uint8_t>& keep, std::size_t layers)
{
  std::vector<uint8_t> out;
  for (std::size_t c = 0; c < keep.size(); ++c)
  {
    if (keep[c])
    {
      out.insert(out.end(), perCell.begin() + c * layers, perCell.begin() + (c + 1) * layers);
    }
  }
  return out;
}

RegionMesh ToRegionMesh(
  const ScratchRegion& region, const MultiresolutionHeader& header, float ownError, double sideError)
{
  RegionMesh out;
  out.layers = region.mesh.layers;
  out.positions = region.mesh.positions;
  // What readers will decode: pinch-outs are sealed by thickness, and a run the builder seals
  // must be the one every reader seals.
  RoundToLattice(out.positions, header);
  out.topology.resize(region.mesh.topology.size());
  for (std::size_t n = 0; n < out.topology.size(); ++n)
  {
    out.topology[n] = { static_cast<float>(region.mesh.topology[n][0]),
      static_cast<float>(region.mesh.topology[n][1]) };
  }
  out.corners.resize(region.mesh.corners.size());
  for (std::size_t c = 0; c < out.corners.size(); ++c)
  {
    for (int q = 0; q < 4; ++q)
    {
      out.corners[c][q] = static_cast<uint32_t>(region.mesh.corners[c][q]);
    }
  }
  out.active = region.mesh.activeCells;
  out.cutEdges = region.cutEdges;
  out.openSides = region.openSides;
  out.sealedPinchThickness = ownError;
  ExtractSurfaces(out);
  // Sec. 4.3: side faces simplified up to the error of the hexahedral mesh they bound.
  out.sideTriangles = SimplifySideSurface(out, sideError);
  return out;
}

std::array<double, 6> BoxOf(const std::vector<double>& positions)
{
  const double inf = std::numeric_limits<double>::infinity();
  std::array<double, 6> box{ inf, inf, inf, -inf, -inf, -inf };
  for (std::size_t p = 0; p < positions.size(); p += 3)
  {
    for (int d = 0; d < 3; ++d)
    {
      box[d] = std::min(box[d], positions[p + d]);
      box[3 + d] = std::max(box[3 + d], positions[p + d]);
    }
  }
  return box;
}

/// Model-space error of a region mesh in units of distance (Sec. 6.2): over its vertices, the
/// largest root-mean-square distance to the original faces merged into the vertex. A quadric
/// sums weight x squared distance and the trace of its 3 x 3 part sums the weights (unit
/// normals), so their ratio is the weighted mean squared distance; the raw quadric error
/// would grow with the number of faces merged, not with the distance.
double QuadricDistance(const ColumnMeshData& mesh)
{
  double largest = 0;
  for (std::size_t v = 0; v < mesh.quadrics.size(); ++v)
  {
    const Quadric& q = mesh.quadrics[v];
    const double weight = q.q[0] + q.q[4] + q.q[7];
    if (weight > 0)
    {
      const glm::dvec3 p(mesh.positions[v * 3], mesh.positions[v * 3 + 1], mesh.positions[v * 3 + 2]);
      largest = std::max(largest, q.Error(p) / weight);
    }
  }
  return std::sqrt(largest);
}

/// The typical quadric distance (ours): the root mean square over the surfaces, weighted by
/// the area each vertex's quadric stands for, of what QuadricDistance takes the largest of.
double TypicalQuadricDistance(const ColumnMeshData& mesh)
{
  double error = 0, weights = 0;
  for (std::size_t v = 0; v < mesh.quadrics.size(); ++v)
  {
    const Quadric& q = mesh.quadrics[v];
    const double weight = q.q[0] + q.q[4] + q.q[7];
    if (weight > 0)
    {
      const glm::dvec3 p(mesh.positions[v * 3], mesh.positions[v * 3 + 1], mesh.positions[v * 3 + 2]);
      error += std::max(q.Error(p), 0.0);
      weights += weight;
    }
  }
  return weights > 0 ? std::sqrt(error / weights) : 0;
}

/// Columns of a full-size region: a 64 x 64 patch, top and bottom surfaces of about 16k
/// triangles, the batch size at which GPUs reach full speed, while a diamond's merged mesh
/// stays a few hundred MB for 100 layers.
constexpr int64_t FullRegionColumns = 4096;

/// Default Cmax: a full-size region, but at most a 32nd of the model's columns (and at least
/// 256), so that small models get five or more levels, not a single one.

int64_t AutomaticCmax(int64_t columns)
{
  return std::max<int64_t>(256, std::min<int64_t>(FullRegionColumns, columns / 32));
}

/// Runs task(i) for i in [0, count) on `threads` threads; rethrows the first failure.
void ParallelFor(int64_t count, int threads, const std::function<void(int64_t)>& task)
{
  std::atomic<int64_t> next{ 0 };
  std::exception_ptr failure;
  std::mutex failureLock;
  auto work = [&] {
    for (;;)
    {
      const int64_t i = next++;
      if (i >= count)
      {
        return;
      }
      try
      {
        task(i);
      }
      catch (...)
      {
        std::lock_guard<std::mutex> guard(failureLock);
        if (!failure)
        {
          failure = std::current_exception();
        }
        next = count;
      }
    }
  };
  RunOnThreads(threads, work);
  if (failure)
  {
    std::rethrow_exception(failure);
  }
}

/// SplitMix64's step and finaliser: the seeds of each diamond's simplification.
uint64_t Mix(uint64_t x)
{
  return HashMix(x + GoldenGamma);
}

/// Little binary files that record a build's progress (resuming, MPI ranks).
class ManifestOut : public ByteWriter
{
public:
  /// Written under a temporary name and renamed: a manifest is there whole or not at all.
  void Save(const std::string& path) const
  {
    const std::string temporary = path + ".part";
    std::FILE* file = std::fopen(temporary.c_str(), "wb");
    bool ok = file && std::fwrite(this->Bytes.data(), 1, this->Bytes.size(), file) == this->Bytes.size();
    ok = file && (std::fflush(file) == 0) && (fsync(fileno(file)) == 0) && ok;
    ok = file && (std::fclose(file) == 0) && ok;
    if (!ok || std::rename(temporary.c_str(), path.c_str()) != 0)
    {
      unlink(temporary.c_str());
      throw std::runtime_error(path + ": cannot write the build manifest: " + std::strerror(errno));
    }
  }
};

class ManifestIn : public ByteReader
{
public:
  /// False if the file is absent.
  bool Load(const std::string& path)
  {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    if (!file)
    {
      return false;
    }
    uint8_t block[65536];
    std::size_t got = 0;
    while ((got = std::fread(block, 1, sizeof(block), file)) > 0)
    {
      this->Bytes.insert(this->Bytes.end(), block, block + got);
    }
    std::fclose(file);
    this->Path = path;
    this->Reset(this->Bytes.data(), this->Bytes.size(), path + ": build manifest");
    return true;
  }
  std::vector<uint8_t> Bytes;
  std::string Path;
};

constexpr uint64_t BuildManifestMagic = 0x31444c4252534552ull; // "RESRBLD1"

bool Exists(const std::string& path)
{
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

void RemoveTree(const std::string& path)
{
  DIR* folder = opendir(path.c_str());
  if (!folder)
  {
    unlink(path.c_str());
    return;
  }
  while (const dirent* entry = readdir(folder))
  {
    const std::string name = entry->d_name;
    if (name != "." && name != "..")
    {
      RemoveTree(path + "/" + name);
    }
  }
  closedir(folder);
  rmdir(path.c_str());
}

/// Whether triangle (a, b, c) meets the cell [lo, lo + 1]^3 grown by `margin` on every side
/// (the separating-axis test of Akenine-Moller, "Fast 3D triangle-box overlap testing", 2001).
bool TriangleMeetsCell(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, const glm::dvec3& lo, double margin)
{
  const glm::dvec3 centre = lo + 0.5;
  const double h = 0.5 + margin;
  a -= centre;
  b -= centre;
  c -= centre;
  const auto apart = [&](const glm::dvec3& axis) {
    const double pa = glm::dot(a, axis), pb = glm::dot(b, axis), pc = glm::dot(c, axis);
    const double r = h * (std::fabs(axis.x) + std::fabs(axis.y) + std::fabs(axis.z));
    return std::min({ pa, pb, pc }) > r || std::max({ pa, pb, pc }) < -r;
  };
  const glm::dvec3 units[3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  const glm::dvec3 edges[3] = { b - a, c - b, a - c };
  if (apart(units[0]) || apart(units[1]) || apart(units[2]) || apart(glm::cross(edges[0], edges[1])))
  {
    return false;
  }
  for (const auto& edge : edges)
  {
    for (const auto& unit : units)
    {
      if (apart(glm::cross(edge, unit)))
      {
        return false;
      }
    }
  }
  return true;
}

/// How far (cells) past a drawn triangle a fragment's interpolated cell coordinate may land: the
/// GPU interpolates it in single precision (half a thousandth of a cell apart at coordinates
/// near 4,096), so a fragment on a triangle's edge along a cell boundary can name the cell
/// beyond it, which must be hashed too (else a pixel in the NaN colour, or in another cell's).
constexpr double NamingMargin = 0.001;

/// The triangles a face is drawn as, each moved as the view moves its cell coordinate
/// (RegionCache): a top quad half a cell down into its cell (k + 0.5), a bottom one half a cell
/// up, both split q0-q1-q2, q0-q2-q3; a side triangle half a cell along its topological
/// normal's largest axis, either way (the side depends on the file's handedness). Empty for a
/// side quad, the exact unit face, whose box is already exact.
/// At most two drawn triangles of one face, without a heap allocation a face.
struct Drawn
{
  std::array<std::array<glm::dvec3, 3>, 2> triangles;
  int count = 0;
  const std::array<glm::dvec3, 3>* begin() const { return this->triangles.data(); }
  const std::array<glm::dvec3, 3>* end() const { return this->triangles.data() + this->count; }
  bool empty() const { return this->count == 0; }
};

Drawn DrawnTriangles(const std::array<glm::dvec3, 4>& t, int count, int kind)
{
  Drawn out;
  if (kind < 2)
  {
    const glm::dvec3 shift(0, 0, kind == 0 ? 0.5 : -0.5);
    out.triangles[0] = { t[0] + shift, t[1] + shift, t[2] + shift };
    out.triangles[1] = { t[0] + shift, t[2] + shift, t[3] + shift };
    out.count = 2;
  }
  else if (count == 3)
  {
    const glm::dvec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);
    int axis = std::fabs(n.y) > std::fabs(n.x) ? 1 : 0;
    axis = std::fabs(n.z) > std::fabs(n[axis]) ? 2 : axis;
    glm::dvec3 shift(0.0);
    shift[axis] = 0.5;
    out.triangles[0] = { t[0] + shift, t[1] + shift, t[2] + shift };
    out.triangles[1] = { t[0] - shift, t[1] - shift, t[2] - shift };
    out.count = 2;
  }
  return out;
}

/// The box of cells a face may name: every cell its drawn triangles' box reaches, on the
/// inner side of a top or bottom face and on both sides of a side quad.
void CellBox(const std::array<glm::dvec3, 4>& t, int count, const Drawn& drawn, const std::array<int64_t, 3>& dims,
  std::array<int64_t, 3>& first, std::array<int64_t, 3>& last)
{
  for (int a = 0; a < 3; ++a)
  {
    double low = 1e300, high = -1e300;
    for (int v = 0; v < count; ++v)
    {
      low = std::min(low, t[v][a]);
      high = std::max(high, t[v][a]);
    }
    for (const auto& triangle : drawn)
    {
      for (const auto& p : triangle)
      {
        low = std::min(low, p[a]);
        high = std::max(high, p[a]);
      }
    }
    if (drawn.empty() && high - low < 1e-6)
    {
      // A side quad's constant coordinate: the cells either side of it.
      const int64_t plane = static_cast<int64_t>(std::llround(low));
      first[a] = plane - 1;
      last[a] = plane;
    }
    else
    {
      first[a] = static_cast<int64_t>(std::floor(low - NamingMargin));
      last[a] = static_cast<int64_t>(std::floor(high + NamingMargin));
    }
    first[a] = std::max<int64_t>(first[a], 0);
    last[a] = std::min<int64_t>(last[a], dims[a] - 1);
  }
}

/// The cells (natural index) an extracted face of the region may sample through its
/// interpolated topological coordinates (Sec. 5.2): exactly the cells its drawn triangles
/// (DrawnTriangles) meet; for a side quad, the two cells either side of it. A coarse face is
/// large and slanted in (i, j, k): its box held many cells it never names (a long sliver
/// along a fault), and a simplified side triangle names cells half a cell beyond its box.
void MarkTouchedCells(
  const RegionMesh& mesh, const std::array<int64_t, 3>& dims, std::vector<std::atomic<uint64_t>>& bits)
{
  const uint32_t interfaces = static_cast<uint32_t>(mesh.layers + 1);
  const auto mark = [&](const uint32_t* vertices, int count, int kind) {
    std::array<glm::dvec3, 4> t;
    for (int v = 0; v < count; ++v)
    {
      const uint32_t node = vertices[v] / interfaces;
      t[v] = glm::dvec3(mesh.topology[node][0], mesh.topology[node][1], double(vertices[v] % interfaces));
    }
    const auto drawn = DrawnTriangles(t, count, kind);
    std::array<int64_t, 3> first{}, last{};
    CellBox(t, count, drawn, dims, first, last);
    for (int64_t k = first[2]; k <= last[2]; ++k)
    {
      for (int64_t j = first[1]; j <= last[1]; ++j)
      {
        for (int64_t i = first[0]; i <= last[0]; ++i)
        {
          const glm::dvec3 cell{ double(i), double(j), double(k) };
          const bool named = drawn.empty() || std::any_of(drawn.begin(), drawn.end(), [&](const auto& triangle) {
            return TriangleMeetsCell(triangle[0], triangle[1], triangle[2], cell, NamingMargin);
          });
          if (named)
          {
            const uint64_t n = static_cast<uint64_t>(i + dims[0] * (j + dims[1] * k));
            bits[n >> 6].fetch_or(uint64_t(1) << (n & 63), std::memory_order_relaxed);
          }
        }
      }
    }
  };
  for (const auto& q : mesh.top.quads)
  {
    mark(q.data(), 4, 0);
  }
  for (const auto& q : mesh.bottom.quads)
  {
    mark(q.data(), 4, 1);
  }
  for (const auto& t : mesh.sideTriangles)
  {
    mark(t.data(), 3, 2);
  }
  for (const auto& q : mesh.side.quads)
  {
    mark(q.data(), 4, 2);
  }
}

/// Merges sibling regions into one column mesh (with their cut edges, open sides and
/// column count): nodes the children share (never moved since they were split apart) are
/// bitwise equal, topological coordinate and whole vertex stack. Only nodes of different
/// children are joined: one child may hold two distinct nodes with equal data (where faults
/// cross, the diagonal columns at a pillar can agree while their edge neighbours do not).
ColumnMesh MergeRegions(const std::vector<ScratchRegion>& children, std::vector<uint8_t>& childCut,
  std::vector<uint8_t>& openSides, int64_t& inputColumns)
{
  const int32_t layers = children.front().mesh.layers;
  const std::size_t interfaces = static_cast<std::size_t>(layers) + 1;
  ColumnMeshData merged;
  merged.layers = layers;
  std::unordered_multimap<uint64_t, int32_t> nodeByKey;
  std::vector<int> nodeChild; // the last child a merged node was taken from
  inputColumns = 0;
  for (std::size_t which = 0; which < children.size(); ++which)
  {
    const ColumnMeshData& m = children[which].mesh;
    const ScratchRegion& child = children[which];
    std::vector<int32_t> map(m.topology.size());
    for (std::size_t n = 0; n < m.topology.size(); ++n)
    {
      const double* stack = &m.positions[n * interfaces * 3];
      uint64_t key = Mix(std::hash<double>()(m.topology[n][0]) ^ Mix(std::hash<double>()(m.topology[n][1])));
      key = Mix(key ^ std::hash<double>()(stack[0]) ^ Mix(std::hash<double>()(stack[interfaces * 3 - 1])));
      int32_t found = -1;
      const auto range = nodeByKey.equal_range(key);
      for (auto it = range.first; it != range.second && found < 0; ++it)
      {
        const int32_t candidate = it->second;
        if (nodeChild[candidate] != static_cast<int>(which) && merged.topology[candidate] == m.topology[n] &&
          std::equal(
            stack, stack + interfaces * 3, &merged.positions[static_cast<std::size_t>(candidate) * interfaces * 3]))
        {
          found = candidate;
        }
      }
      if (found < 0)
      {
        found = static_cast<int32_t>(merged.topology.size());
        merged.topology.push_back(m.topology[n]);
        merged.positions.insert(merged.positions.end(), stack, stack + interfaces * 3);
        merged.quadrics.insert(
          merged.quadrics.end(), m.quadrics.begin() + n * interfaces, m.quadrics.begin() + (n + 1) * interfaces);
        nodeByKey.emplace(key, found);
        nodeChild.push_back(-1);
      }
      nodeChild[found] = static_cast<int>(which);
      map[n] = found;
    }
    for (std::size_t c = 0; c < m.corners.size(); ++c)
    {
      merged.corners.push_back(
        { map[m.corners[c][0]], map[m.corners[c][1]], map[m.corners[c][2]], map[m.corners[c][3]] });
    }
    merged.activeCells.insert(merged.activeCells.end(), m.activeCells.begin(), m.activeCells.end());
    merged.origin.insert(merged.origin.end(), m.origin.begin(), m.origin.end());
    childCut.insert(childCut.end(), child.cutEdges.begin(), child.cutEdges.end());
    openSides.insert(openSides.end(), child.openSides.begin(), child.openSides.end());
    inputColumns += m.ColumnCount();
  }
  return ColumnMesh::FromData(std::move(merged));
}

/// Cut edges stay cut only where the merged mesh has no column across, on either side of a
/// fault; their nodes border another diamond and must not move, so every column touching one
/// is locked.
void LockCutColumns(ColumnMesh& mesh, std::vector<uint8_t>& childCut)
{
  const int32_t slots = mesh.ColumnSlots();
  const FaultSides faults(mesh);
  std::vector<uint8_t> external(static_cast<std::size_t>(mesh.NodeCount()), 0);
  for (int32_t c = 0; c < slots; ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      if ((childCut[c] & (1u << e)) && (!mesh.IsBoundaryEdge(c, e) || faults.Across(mesh, c, e) >= 0))
      {
        childCut[c] &= static_cast<uint8_t>(~(1u << e));
      }
      if (childCut[c] & (1u << e))
      {
        external[mesh.ColumnCorners(c)[e]] = 1;
        external[mesh.ColumnCorners(c)[(e + 1) % 4]] = 1;
      }
    }
  }
  for (int32_t c = 0; c < slots; ++c)
  {
    const auto& q = mesh.ColumnCorners(c);
    if (external[q[0]] || external[q[1]] || external[q[2]] || external[q[3]])
    {
      mesh.SetLocked(c, true);
    }
  }
}

/// Locks every column touching a fault node (ours, not the paper's), when they fit: a fault
/// node is a boundary node whose topological coordinate another node of the mesh shares, the
/// two sides of a fault at one pillar. The column collapse simplifies each fault block's
/// outline on its own, so the two traces of a fault that bends (a staircase across I and J, a
/// junction of faults) part and open a gap one sees through. Kept whole, the columns on both
/// sides keep the original trace and their cells, and the blocks meet as they do in the
/// grid. (Pinning the fault nodes alone, letting the columns beside them collapse into them,
/// kept as many columns and still left gaps.) The faults' columns are kept only while they
/// and the columns locked already number no more than `limit`, a full-size region's columns
/// a triangle of the diamond: regions stay within the size memory budgets plan for (though a
/// level may then not halve the one below, and a small model's regions grow past its small
/// cmax), and where the faults are longer than that (the coarsest levels of a large model)
/// they are simplified as before. Returns whether they were locked.
bool LockFaultColumns(ColumnMesh& mesh, int64_t limit)
{
  std::map<std::array<double, 2>, int> sharing;
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    if (mesh.IsNodeAlive(node) && mesh.IsBoundaryNode(node))
    {
      ++sharing[mesh.TopologicalCoordinate(node)];
    }
  }
  std::vector<uint8_t> lock(static_cast<std::size_t>(mesh.ColumnSlots()), 0);
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    if (mesh.IsNodeAlive(node) && mesh.IsBoundaryNode(node) && sharing[mesh.TopologicalCoordinate(node)] > 1)
    {
      for (const int32_t column : mesh.NodeColumns(node))
      {
        lock[column] = 1;
      }
    }
  }
  int64_t kept = 0;
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    kept += mesh.IsColumnAlive(c) && (lock[c] || mesh.IsLocked(c));
  }
  if (kept > limit)
  {
    return false;
  }
  for (int32_t c = 0; c < mesh.ColumnSlots(); ++c)
  {
    if (lock[c])
    {
      mesh.SetLocked(c, true);
    }
  }
  return true;
}

/// The seed as a resumed build must match it: with the fault options folded in, so a build is
/// never resumed under another choice.
uint64_t ResumeSeed(const HierarchyOptions& options)
{
  return options.seed ^ (options.keepFaults ? 0 : GoldenGamma) ^
    (options.faultColumns > 0 ? Mix(static_cast<uint64_t>(options.faultColumns)) : 0);
}

class Builder
{
public:
  Builder(
    LayerSource& source, const std::string& output, const HierarchyOptions& options, const BuildProgress& progress)
    : Source(source)
    , Output(output)
    , Options(options)
    , Progress(progress)
    , Scratch(ScratchFolder(output, options))
  {
    if (this->Options.cmax != 0 && this->Options.cmax < 16)
    {
      throw std::invalid_argument("--cmax must be at least 16 columns (or 0: chosen from the model)");
    }
    if (this->Options.ranks < 1 || this->Options.rank < 0 || this->Options.rank >= this->Options.ranks ||
      (this->Options.ranks > 1 && !this->Options.barrier))
    {
      throw std::invalid_argument("hierarchy build: rank " + std::to_string(this->Options.rank) + " of " +
        std::to_string(this->Options.ranks) + " (several ranks need a barrier)");
    }
  }

  HierarchyReport Run();

private:
  /// One leaf of the hierarchy and its columns (i + j nx).
  using Leaf = std::pair<int64_t, std::vector<int64_t>>;
  /// Scratch bytes a vertex of a column mesh costs while a region is built.
  static constexpr int64_t VertexBytes = 24 + 80 + 40;
  int PrepareScratch(MultiresolutionHeader& header, HierarchyReport& report, bool& partitioned);
  void Resume(int finished, const MultiresolutionHeader& header);
  void PartitionInput(HierarchyReport& report);
  void ReopenPartition();
  void CheckFreeDisk() const;
  std::vector<Leaf> PlanLeaves(MultiresolutionHeader& header, HierarchyReport& report);
  void BuildLeaves(const std::vector<Leaf>& leaves, int leafLevel, HierarchyReport& report);
  std::vector<std::size_t> Share(std::size_t count) const;
  void SimplifyLevels(int finished, HierarchyReport& report);
  void WriteFile(MultiresolutionHeader& header, HierarchyReport& report);
  void Report(const char* phase, double fraction)
  {
    if (this->Progress)
    {
      std::lock_guard<std::mutex> guard(this->ProgressLock);
      this->Progress(phase, fraction);
    }
  }
  /// A finished region on its way to the chunk file.
  struct Emitted
  {
    RegionMesh mesh;
    RegionRecord record;
    std::array<double, 6> box{};
  };
  void BuildLeaf(int64_t leaf, const std::vector<int64_t>& columns, std::vector<Emitted>& out);
  void BuildDiamond(const DiamondHierarchy::Diamond& diamond, std::vector<Emitted>& out);
  /// `owners`: for each child, the triangle of the diamond it is a child of (1: first, 2: second).
  std::vector<ScratchRegion> LoadChildren(const DiamondHierarchy::Diamond& diamond, std::vector<uint8_t>& owners) const;
  void SplitAndEmit(const DiamondHierarchy::Diamond& diamond, const ColumnMesh& mesh,
    const std::vector<uint8_t>& origin, const std::vector<uint8_t>& childCut, const std::vector<uint8_t>& openSides,
    double weldError, std::vector<Emitted>& out);
  /// Saves the region's scratch file (for the level above) and encodes it.
  void Prepare(int level, int64_t index, const ScratchRegion& region, bool keepScratch, std::vector<Emitted>& out);
  /// Appends a task's regions to the chunk file and records them; with `task` (a one-process
  /// build), also in the journal.
  void Commit(std::vector<Emitted>& out, const BuildSchedule::Task* task);
  /// A leaf's box of columns with its halo: i0, i1, j0, j1.
  std::array<int64_t, 4> LeafBox(const std::vector<int64_t>& columns) const;
  void BuildDepthFirst(const std::vector<Leaf>& leaves, HierarchyReport& report);
  std::vector<uint8_t> ReadJournal(const BuildSchedule& schedule, HierarchyReport& report);
  int ThreadsFor(int64_t bytesPerTask) const;
  void Barrier()
  {
    if (this->Options.ranks > 1)
    {
      this->Options.barrier();
    }
  }
  /// Runs `work` on every rank; if it fails on any, every rank throws (no rank is left
  /// waiting at a barrier for one that failed).
  void Collective(const std::function<void()>& work);
  std::string LevelManifest(int level, int rank) const
  {
    return this->Scratch + "/level-" + std::to_string(level) + ".rank-" + std::to_string(rank);
  }
  std::string ChunkPath(int rank) const { return this->Scratch + "/chunks-" + std::to_string(rank) + ".bin"; }
  std::string NormalsPath(int64_t leaf) const { return this->Scratch + "/normals-" + std::to_string(leaf) + ".bin"; }
  void SaveLevel(int level);
  void LoadLevel(int level);
  bool ReadBuildManifest(MultiresolutionHeader& header, HierarchyReport& report);
  void WriteBuildManifest(const MultiresolutionHeader& header, const HierarchyReport& report) const;
  void FinishBoundsAndErrors(int leafLevel);
  void BuildPropertySide(MultiresolutionHeader& header, HierarchyReport& report, std::vector<ModelChunk>& model);
  /// The regions' footprints (ModelChunk::Footprints) from each region's own topology box
  /// (`hulls`, of `keys`), added to `model`.
  void AddFootprints(const std::vector<std::pair<int, int64_t>>& keys, const std::vector<std::array<float, 4>>& hulls,
    int leafLevel, std::vector<ModelChunk>& model);
  /// The wall depth table of the leaves' wall faces (emptied), or why it was left out.
  void AddWallDepths(std::vector<WallFace>& walls, const MultiresolutionHeader& header, HierarchyReport& report,
    std::vector<ModelChunk>& model);

  LayerSource& Source;
  std::string Output;
  HierarchyOptions Options;
  BuildProgress Progress;
  std::string Scratch;
  std::mutex ProgressLock;
  std::unique_ptr<LeafPartition> Partition;
  uint64_t PartitionChunkBytes = 0; ///< rank 0's chunk file once the partition pass is done
  std::unique_ptr<DiskMeter> Meter; ///< rank 0's
  DiamondHierarchy Tree;
  MultiresolutionHeader Header;
  std::unique_ptr<ChunkFile> Chunks;
  std::vector<ModelChunk> ActiveLayers; ///< rank 0's
  std::mutex RecordLock, CommitLock;
  std::unique_ptr<BuildJournal> Journal; ///< one-process builds
  std::map<std::pair<int, int64_t>, RegionRecord> Records;
  std::map<std::pair<int, int64_t>, int> Parts; ///< the rank whose chunk file holds a region
  std::map<std::pair<int, int64_t>, std::array<double, 6>> OwnBoxes;
  std::atomic<int64_t> WorkDone{ 0 };
  int64_t WorkTotal = 1;
  double WorkStart = 0, WorkSpan = 1;
  const char* Phase = "";
  int64_t CellCount = 0;
};

int Builder::ThreadsFor(int64_t bytesPerTask) const
{
  constexpr int64_t cellsPerThread = 16384;
  int threads = this->Options.threads > 0 ? this->Options.threads
                                          : static_cast<int>(std::min<int64_t>(std::thread::hardware_concurrency(),
                                              (this->CellCount + cellsPerThread - 1) / cellsPerThread));
  threads = std::max(threads, 1);
  const int64_t budget = this->Options.memoryBytes > 0 ? this->Options.memoryBytes : DefaultBuildMemoryBytes();
  const int64_t fit = std::max<int64_t>(1, budget / std::max<int64_t>(bytesPerTask, 1));
  return static_cast<int>(std::min<int64_t>(threads, fit));
}

void Builder::Collective(const std::function<void()>& work)
{
  std::string failure;
  try
  {
    work();
  }
  catch (const std::exception& error)
  {
    failure = error.what();
    if (this->Options.ranks == 1)
    {
      throw;
    }
    ManifestOut note;
    note.PutString(failure);
    try
    {
      note.Save(this->Scratch + "/failed.rank-" + std::to_string(this->Options.rank));
    }
    catch (const std::exception&)
    {
    }
  }
  this->Barrier();
  if (!failure.empty())
  {
    throw std::runtime_error(failure);
  }
  for (int r = 0; r < this->Options.ranks; ++r)
  {
    ManifestIn note;
    if (note.Load(this->Scratch + "/failed.rank-" + std::to_string(r)))
    {
      throw std::runtime_error("rank " + std::to_string(r) + " failed: " + note.GetString());
    }
  }
}

void Builder::Prepare(
  int level, int64_t index, const ScratchRegion& region, bool keepScratch, std::vector<Emitted>& out)
{
  if (keepScratch)
  {
    SaveRegion(RegionPath(this->Scratch, level, index), region);
  }
  Emitted emitted;
  emitted.record.level = level;
  emitted.record.index = index;
  const double ownError = std::max(QuadricDistance(region.mesh), region.weldError);
  emitted.record.ownError = static_cast<float>(ownError);
  emitted.record.typicalError =
    std::min(static_cast<float>(TypicalQuadricDistance(region.mesh)), emitted.record.ownError);
  // The file rounds positions to its lattice after simplification: allow one step more.
  const auto& step = this->Header.latticeStep;
  emitted.mesh = ToRegionMesh(region, this->Header, level == this->Header.leafLevel ? 0.f : emitted.record.ownError,
    ownError + std::sqrt(step[0] * step[0] + step[1] * step[1] + step[2] * step[2]));
  emitted.box = BoxOf(region.mesh.positions);
  out.push_back(std::move(emitted));
}

void Builder::Commit(std::vector<Emitted>& out, const BuildSchedule::Task* task)
{
  // One task's chunks lie together and its journal record follows them, so a resumed build
  // cuts the chunk file back to the end of its last recorded task.
  std::unique_lock<std::mutex> commit(this->CommitLock, std::defer_lock);
  if (task)
  {
    commit.lock();
  }
  for (Emitted& emitted : out)
  {
    this->Chunks->AddRegion(emitted.mesh, this->Header, emitted.record);
    emitted.mesh = RegionMesh();
  }
  if (task)
  {
    ByteWriter record;
    record.Put(static_cast<int32_t>(task->level));
    record.Put(task->first);
    record.Put(this->Chunks->Sync());
    record.Put(static_cast<uint64_t>(out.size()));
    for (const Emitted& emitted : out)
    {
      record.Put(emitted.record);
      record.Put(emitted.box);
    }
    this->Journal->Append(record.Bytes);
  }
  std::lock_guard<std::mutex> guard(this->RecordLock);
  for (const Emitted& emitted : out)
  {
    const std::pair<int, int64_t> key{ emitted.record.level, emitted.record.index };
    this->Records[key] = emitted.record;
    this->Parts[key] = this->Options.rank;
    this->OwnBoxes[key] = emitted.box;
  }
}

void Builder::SaveLevel(int level)
{
  ManifestOut out;
  out.Put(BuildManifestMagic);
  out.Put(static_cast<int32_t>(level));
  out.Put(static_cast<int32_t>(this->Options.rank));
  out.Put(this->Chunks->Sync());
  std::vector<std::pair<int, int64_t>> mine;
  for (const auto& entry : this->Parts)
  {
    if (entry.first.first == level && entry.second == this->Options.rank)
    {
      mine.push_back(entry.first);
    }
  }
  out.Put(static_cast<uint64_t>(mine.size()));
  for (const auto& key : mine)
  {
    out.Put(this->Records[key]);
    out.Put(this->OwnBoxes[key]);
  }
  out.Save(this->LevelManifest(level, this->Options.rank));
}

void Builder::LoadLevel(int level)
{
  for (int r = 0; r < this->Options.ranks; ++r)
  {
    ManifestIn in;
    if (!in.Load(this->LevelManifest(level, r)))
    {
      throw std::runtime_error(this->LevelManifest(level, r) + ": missing (rank " + std::to_string(r) +
        " did not finish level " + std::to_string(level) + ")");
    }
    if (in.Get<uint64_t>() != BuildManifestMagic || in.Get<int32_t>() != level || in.Get<int32_t>() != r)
    {
      throw std::runtime_error(in.Path + ": not the manifest of this level and rank");
    }
    in.Get<uint64_t>();
    const uint64_t count = in.Get<uint64_t>();
    for (uint64_t n = 0; n < count; ++n)
    {
      const RegionRecord record = in.Get<RegionRecord>();
      const auto box = in.Get<std::array<double, 6>>();
      const std::pair<int, int64_t> key{ record.level, record.index };
      this->Records[key] = record;
      this->Parts[key] = r;
      this->OwnBoxes[key] = box;
    }
  }
}

void Builder::WriteBuildManifest(const MultiresolutionHeader& header, const HierarchyReport& report) const
{
  ManifestOut out;
  out.Put(BuildManifestMagic);
  out.PutString(this->Source.Name());
  out.Put(this->Source.Dims());
  out.Put(this->Options.cmax);
  out.Put(ResumeSeed(this->Options));
  out.Put(static_cast<int32_t>(this->Options.ranks));
  out.Put(header.dims);
  out.Put(header.box);
  out.Put(header.latticeOrigin);
  out.Put(header.latticeStep);
  out.Put(header.leafLevel);
  out.Put(header.cmax);
  out.Put(report.cells);
  out.Put(report.activeCells);
  out.Put(report.columns);
  out.Put(static_cast<uint64_t>(this->ActiveLayers.size()));
  for (const ModelChunk& m : this->ActiveLayers)
  {
    out.Put(m);
  }
  out.Put(this->PartitionChunkBytes);
  out.Save(this->Scratch + "/build.manifest");
}

/// True if the scratch folder holds a build of the same input and options to resume.
bool Builder::ReadBuildManifest(MultiresolutionHeader& header, HierarchyReport& report)
{
  ManifestIn in;
  if (!this->Options.resume || !in.Load(this->Scratch + "/build.manifest"))
  {
    return false;
  }
  try
  {
    if (in.Get<uint64_t>() != BuildManifestMagic || in.GetString() != this->Source.Name() ||
      in.Get<std::array<int64_t, 3>>() != this->Source.Dims() || in.Get<int64_t>() != this->Options.cmax ||
      in.Get<uint64_t>() != ResumeSeed(this->Options) || in.Get<int32_t>() != this->Options.ranks)
    {
      return false;
    }
    header.dims = in.Get<std::array<int64_t, 3>>();
    header.box = in.Get<std::array<double, 4>>();
    header.latticeOrigin = in.Get<std::array<double, 3>>();
    header.latticeStep = in.Get<std::array<double, 3>>();
    header.leafLevel = in.Get<int32_t>();
    header.cmax = in.Get<int32_t>();
    report.cells = in.Get<int64_t>();
    report.activeCells = in.Get<int64_t>();
    report.columns = in.Get<int64_t>();
    const uint64_t layers = in.Get<uint64_t>();
    this->ActiveLayers.clear();
    for (uint64_t k = 0; k < layers; ++k)
    {
      this->ActiveLayers.push_back(in.Get<ModelChunk>());
    }
    this->PartitionChunkBytes = in.Get<uint64_t>();
  }
  catch (const std::runtime_error&)
  {
    return false;
  }
  return true;
}

std::array<int64_t, 4> Builder::LeafBox(const std::vector<int64_t>& columns) const
{
  const auto& dims = this->Partition->Dims();
  const int64_t nx = dims[0], ny = dims[1];
  int64_t i0 = nx, i1 = 0, j0 = ny, j1 = 0;
  for (int64_t column : columns)
  {
    const int64_t i = column % nx, j = column / nx;
    i0 = std::min(i0, i);
    i1 = std::max(i1, i + 1);
    j0 = std::min(j0, j);
    j1 = std::max(j1, j + 1);
  }
  // One column of halo all round: the nodes and quadrics of the leaf's border come out as in
  // the whole model, and edges shared with the halo are the leaf's cut edges.
  return { std::max<int64_t>(i0 - 1, 0), std::min(i1 + 1, nx), std::max<int64_t>(j0 - 1, 0), std::min(j1 + 1, ny) };
}

void Builder::BuildLeaf(int64_t leaf, const std::vector<int64_t>& columns, std::vector<Emitted>& out)
{
  const auto& dims = this->Partition->Dims();
  const int64_t nx = dims[0], nz = dims[2];
  const auto box = this->LeafBox(columns);
  const int64_t i0 = box[0], i1 = box[1], j0 = box[2], j1 = box[3];
  const int64_t w = i1 - i0, h = j1 - j0;
  std::vector<uint8_t> selected(static_cast<std::size_t>(w * h), 0);
  const auto& hasActive = this->Partition->ColumnHasActive();
  for (int64_t column : columns)
  {
    const int64_t i = column % nx - i0, j = column / nx - j0;
    selected[static_cast<std::size_t>(j * w + i)] = 2;
  }
  for (int64_t column : columns)
  {
    const int64_t ci = column % nx, cj = column / nx;
    for (int64_t dj = -1; dj <= 1; ++dj)
    {
      for (int64_t di = -1; di <= 1; ++di)
      {
        const int64_t i = ci + di, j = cj + dj;
        if (i < i0 || j < j0 || i >= i1 || j >= j1 || !hasActive[static_cast<std::size_t>(j * nx + i)])
        {
          continue;
        }
        uint8_t& flag = selected[static_cast<std::size_t>((j - j0) * w + (i - i0))];
        flag = std::max<uint8_t>(flag, 1);
      }
    }
  }
  std::vector<float> zcorn;
  std::vector<uint8_t> activeBytes;
  this->Partition->ReadBox(i0, i1, j0, j1, zcorn, activeBytes);
  std::vector<bool> active(activeBytes.size());
  for (std::size_t c = 0; c < activeBytes.size(); ++c)
  {
    active[c] = activeBytes[c] != 0;
  }
  const LeafPartition& partition = *this->Partition;
  const auto corners = [&](int64_t i, int64_t j, int64_t k, double out[8][3]) {
    const float* z = &zcorn[static_cast<std::size_t>(((k * h + j) * w + i) * 8)];
    for (int c = 0; c < 8; ++c)
    {
      partition.PillarPoint(i0 + i + (c & 1), j0 + j + ((c >> 1) & 1), z[c], out[c]);
    }
  };
  // Sec. 5.3: the original top and bottom face normals of every cell (z up), 2 bytes each.
  {
    ManifestOut normals;
    normals.Put(static_cast<uint64_t>(columns.size()));
    double p[8][3];
    for (int64_t column : columns)
    {
      normals.Put(column);
      for (int64_t k = 0; k < nz; ++k)
      {
        corners(column % nx - i0, column / nx - j0, k, p);
        for (int face = 0; face < 2; ++face)
        {
          const auto at = [&](
                            int c) { return glm::dvec3(p[4 * face + c][0], p[4 * face + c][1], -p[4 * face + c][2]); };
          glm::dvec3 n = glm::cross(at(1) - at(0) + at(3) - at(2), at(2) - at(0) + at(3) - at(1));
          if ((face == 0 && n.z < 0) || (face == 1 && n.z > 0))
          {
            n = -n; // top faces look up, bottom faces down, whichever way the grid turns
          }
          if (!(glm::length(n) > 0))
          {
            n = glm::dvec3(0, 0, face == 0 ? 1 : -1); // a face of no area: level
          }
          normals.Put(EncodeUnitNormal(n.x, n.y, n.z));
        }
      }
    }
    SaveCompressed(this->NormalsPath(leaf), normals.Bytes);
  }
  const ColumnMesh halo = ColumnMesh::FromCells({ w, h, nz }, corners, active, 0, w, 0, h, &selected);
  std::vector<uint8_t> keep(static_cast<std::size_t>(halo.ColumnSlots()), 0);
  for (int32_t c = 0; c < halo.ColumnSlots(); ++c)
  {
    const auto& origin = halo.ColumnOrigin(c);
    keep[c] = selected[static_cast<std::size_t>(origin[1] * w + origin[0])] == 2;
  }
  ScratchRegion region;
  region.mesh = halo.Export(&keep);
  std::vector<uint8_t> openSides;
  UpdateOpenSides(halo, std::vector<uint8_t>(static_cast<std::size_t>(halo.ColumnSlots()), 0), openSides);
  region.openSides = KeptCells(openSides, keep, static_cast<std::size_t>(nz));
  const FaultSides faults(halo);
  for (int32_t c = 0; c < halo.ColumnSlots(); ++c)
  {
    if (!keep[c])
    {
      continue;
    }
    uint8_t cut = 0;
    for (int e = 0; e < 4; ++e)
    {
      int32_t other = Across(halo, c, e);
      other = other >= 0 ? other : faults.Across(halo, c, e);
      if (other >= 0 && !keep[other])
      {
        cut |= static_cast<uint8_t>(1u << e);
      }
    }
    region.cutEdges.push_back(cut);
  }
  for (auto& t : region.mesh.topology)
  {
    t[0] += static_cast<double>(i0);
    t[1] += static_cast<double>(j0);
  }
  for (auto& o : region.mesh.origin)
  {
    o[0] += static_cast<int32_t>(i0);
    o[1] += static_cast<int32_t>(j0);
  }
  this->Prepare(this->Tree.LeafLevel(), leaf, region, this->Tree.LeafLevel() > 0, out);
  this->WorkDone += static_cast<int64_t>(columns.size());
  this->Report(this->Phase, this->WorkStart + this->WorkSpan * static_cast<double>(this->WorkDone) / this->WorkTotal);
}

/// The finished regions of a diamond's children (level + 1), read back from scratch.
std::vector<ScratchRegion> Builder::LoadChildren(
  const DiamondHierarchy::Diamond& diamond, std::vector<uint8_t>& owners) const
{
  const int childLevel = diamond.level + 1;
  std::vector<ScratchRegion> children;
  owners.clear();
  for (int64_t triangle : { diamond.first, diamond.second })
  {
    if (triangle < 0)
    {
      continue;
    }
    for (int64_t child : { 2 * triangle, 2 * triangle + 1 })
    {
      ScratchRegion region;
      const std::string path = RegionPath(this->Scratch, childLevel, child);
      if (LoadRegion(path, region)) // removed once the level is finished (resuming needs it)
      {
        children.push_back(std::move(region));
        owners.push_back(triangle == diamond.first ? 1 : 2);
      }
    }
  }
  return children;
}

/// Ours: split by column centre alone, a simplified diamond's columns can all fall on one side
/// of its hypotenuse (the other triangle's collapsed into columns centred across it). That
/// triangle would have no region, and the view, which reaches a region only through its
/// parent, could never draw its children: a hole in every finer cut. So a triangle whose
/// children hold columns (`origin`: per column slot, the triangle whose children it came
/// from) takes back the columns that came from them, or else the column centred nearest its
/// own centre, as long as the other triangle keeps one if it needs one. `side`: per slot, 0
/// (not alive), 1 or 2.
void KeepEveryTriangleFed(const std::vector<uint8_t>& origin, const std::vector<glm::dvec2>& centres,
  const std::array<glm::dvec2, 2>& triangleCentres, std::vector<uint8_t>& side)
{
  std::array<int64_t, 3> count{ 0, 0, 0 };
  std::array<bool, 3> fed{ false, false, false };
  for (std::size_t c = 0; c < side.size(); ++c)
  {
    ++count[side[c]];
    fed[origin[c]] = true;
  }
  for (uint8_t which : { uint8_t(1), uint8_t(2) })
  {
    const uint8_t other = static_cast<uint8_t>(3 - which);
    if (count[which] > 0 || !fed[which])
    {
      continue;
    }
    const int64_t keep = fed[other] ? 1 : 0;
    for (std::size_t c = 0; c < side.size() && count[other] > keep; ++c)
    {
      if (side[c] == other && origin[c] == which)
      {
        side[c] = which;
        --count[other];
        ++count[which];
      }
    }
    std::size_t nearest = side.size();
    for (std::size_t c = 0; c < side.size() && count[which] == 0 && count[other] > keep; ++c)
    {
      const auto distance = [&](std::size_t n) { return glm::length(centres[n] - triangleCentres[which - 1]); };
      if (side[c] == other && (nearest == side.size() || distance(c) < distance(nearest)))
      {
        nearest = c;
      }
    }
    if (nearest < side.size())
    {
      side[nearest] = which;
      --count[other];
      ++count[which];
    }
  }
}

/// Splits the simplified diamond along its hypotenuse by column centre and emits each
/// triangle's region with the edges cut towards the other triangle and other diamonds.
void Builder::SplitAndEmit(const DiamondHierarchy::Diamond& diamond, const ColumnMesh& mesh,
  const std::vector<uint8_t>& origin, const std::vector<uint8_t>& childCut, const std::vector<uint8_t>& openSides,
  double weldError, std::vector<Emitted>& out)
{
  const int32_t slots = mesh.ColumnSlots();
  const int32_t layers = mesh.Layers();
  const std::size_t interfaces = static_cast<std::size_t>(layers) + 1;
  const int triangles = diamond.second >= 0 ? 2 : 1;
  std::vector<uint8_t> side(static_cast<std::size_t>(slots), 0);
  std::vector<glm::dvec2> centres(static_cast<std::size_t>(slots), glm::dvec2(0.0));
  for (int32_t c = 0; c < slots; ++c)
  {
    if (!mesh.IsColumnAlive(c))
    {
      continue;
    }
    for (int32_t node : mesh.ColumnCorners(c))
    {
      for (int32_t k : { 0, layers })
      {
        const glm::dvec3 p = mesh.Position(node, k);
        centres[c] += glm::dvec2(p.x, p.y) / 8.0;
      }
    }
    side[c] = this->Tree.OnFirstSide(diamond, centres[c].x, centres[c].y) ? 1 : 2;
  }
  if (triangles == 2)
  {
    std::array<glm::dvec2, 2> triangleCentres;
    for (int which = 0; which < 2; ++which)
    {
      const auto t = this->Tree.ModelTriangle(diamond.level, which == 0 ? diamond.first : diamond.second);
      triangleCentres[which] = glm::dvec2(t.apex[0] + t.left[0] + t.right[0], t.apex[1] + t.left[1] + t.right[1]) / 3.0;
    }
    std::vector<uint8_t> from = origin;
    from.resize(side.size(), 0); // columns made after the merge (none today) came from no child
    KeepEveryTriangleFed(from, centres, triangleCentres, side);
  }
  const FaultSides faults(mesh);
  for (int which = 1; which <= triangles; ++which)
  {
    std::vector<uint8_t> keep(static_cast<std::size_t>(slots), 0);
    bool any = false;
    for (int32_t c = 0; c < slots; ++c)
    {
      keep[c] = side[c] == which;
      any = any || keep[c];
    }
    if (!any)
    {
      continue;
    }
    ScratchRegion region;
    region.mesh = mesh.Export(&keep);
    region.openSides = KeptCells(openSides, keep, interfaces - 1);
    region.weldError = weldError;
    for (int32_t c = 0; c < slots; ++c)
    {
      if (!keep[c])
      {
        continue;
      }
      // Locked columns keep their corners, so their cut edges are still cut; the rest have
      // none but those facing the other triangle.
      uint8_t cut = mesh.IsLocked(c) ? childCut[c] : 0;
      for (int e = 0; e < 4; ++e)
      {
        int32_t other = Across(mesh, c, e);
        other = other >= 0 ? other : faults.Across(mesh, c, e);
        if (other >= 0 && side[other] != which)
        {
          cut |= static_cast<uint8_t>(1u << e);
        }
      }
      region.cutEdges.push_back(cut);
    }
    const int64_t index = which == 1 ? diamond.first : diamond.second;
    this->Prepare(diamond.level, index, region, diamond.level > 0, out);
  }
}

void Builder::BuildDiamond(const DiamondHierarchy::Diamond& diamond, std::vector<Emitted>& out)
{
  std::vector<uint8_t> owners;
  const std::vector<ScratchRegion> children = this->LoadChildren(diamond, owners);
  if (children.empty())
  {
    return;
  }
  // Per column slot of the merged mesh (the children's columns in order), the triangle whose
  // children it came from.
  std::vector<uint8_t> origin;
  for (std::size_t n = 0; n < children.size(); ++n)
  {
    origin.insert(origin.end(), children[n].mesh.corners.size(), owners[n]);
  }
  const bool bothFed = std::find(owners.begin(), owners.end(), 1) != owners.end() &&
    std::find(owners.begin(), owners.end(), 2) != owners.end();
  std::vector<uint8_t> childCut, openSides;
  int64_t inputColumns = 0;
  ColumnMesh mesh = MergeRegions(children, childCut, openSides, inputColumns);
  LockCutColumns(mesh, childCut);
  const int triangles = diamond.second >= 0 ? 2 : 1;
  // At least a column for each triangle whose children have some (KeepEveryTriangleFed).
  const int64_t target =
    std::max<int64_t>(std::min<int64_t>(this->Options.cmax * triangles, (inputColumns + 1) / 2), bothFed ? 2 : 1);
  // Faults too long to keep whole here weld instead of parting (FaultWelding.h).
  double weldError = 0;
  const int64_t faultColumns =
    this->Options.faultColumns > 0 ? this->Options.faultColumns : std::max(this->Options.cmax, FullRegionColumns);
  if (this->Options.keepFaults && !LockFaultColumns(mesh, faultColumns * triangles))
  {
    weldError = WeldFaults(mesh).largestMove;
    // What could not weld (a side's node on a locked border) stays whole until it can.
    LockFaultColumns(mesh, std::numeric_limits<int64_t>::max());
  }
  if (mesh.AliveColumns() > target)
  {
    ColumnCollapse collapse(mesh,
      Mix(this->Options.seed ^ Mix(static_cast<uint64_t>(diamond.level) << 48 ^ static_cast<uint64_t>(diamond.first))));
    collapse.Simplify(target);
  }
  // Cut edges left are on the diamond's boundary, where columns are locked and unchanged.
  UpdateOpenSides(mesh, childCut, openSides);
  this->SplitAndEmit(diamond, mesh, origin, childCut, openSides, weldError, out);
  this->WorkDone += inputColumns;
  this->Report(this->Phase, this->WorkStart + this->WorkSpan * static_cast<double>(this->WorkDone) / this->WorkTotal);
}

double Seconds()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void Builder::FinishBoundsAndErrors(int leafLevel)
{
  // Bounding volumes and errors: equal within a diamond, monotone up the tree (Sec. 6.2).
  std::map<std::pair<int, int64_t>, std::array<double, 6>> boxes;
  std::map<std::pair<int, int64_t>, double> errors;
  for (int level = leafLevel; level >= 0; --level)
  {
    for (const auto& d : this->Tree.Diamonds(level))
    {
      const double inf = std::numeric_limits<double>::infinity();
      std::array<double, 6> box{ inf, inf, inf, -inf, -inf, -inf };
      double error = 0;
      bool any = false;
      for (int64_t triangle : { d.first, d.second })
      {
        if (triangle < 0 || !this->Records.count({ level, triangle }))
        {
          continue;
        }
        any = true;
        const auto& own = this->OwnBoxes[{ level, triangle }];
        error = std::max<double>(error, this->Records[{ level, triangle }].ownError);
        for (int axis = 0; axis < 3; ++axis)
        {
          box[axis] = std::min(box[axis], own[axis]);
          box[3 + axis] = std::max(box[3 + axis], own[3 + axis]);
        }
        if (level < leafLevel)
        {
          for (int64_t child : { 2 * triangle, 2 * triangle + 1 })
          {
            const auto found = boxes.find({ level + 1, child });
            if (found == boxes.end())
            {
              continue;
            }
            error = std::max(error, errors[{ level + 1, child }]);
            for (int axis = 0; axis < 3; ++axis)
            {
              box[axis] = std::min(box[axis], found->second[axis]);
              box[3 + axis] = std::max(box[3 + axis], found->second[3 + axis]);
            }
          }
        }
      }
      if (!any)
      {
        continue;
      }
      for (int64_t triangle : { d.first, d.second })
      {
        if (triangle < 0 || !this->Records.count({ level, triangle }))
        {
          continue;
        }
        boxes[{ level, triangle }] = box;
        errors[{ level, triangle }] = error;
        RegionRecord& record = this->Records[{ level, triangle }];
        record.error = static_cast<float>(error);
        for (int i = 0; i < 6; ++i)
        {
          // Rounded outward, so the float box still encloses the double one.
          record.bounds[i] = static_cast<float>(box[i]);
          record.bounds[i] = i < 3 ? std::nextafter(record.bounds[i], -std::numeric_limits<float>::infinity())
                                   : std::nextafter(record.bounds[i], std::numeric_limits<float>::infinity());
        }
      }
    }
  }
}

void Builder::AddFootprints(const std::vector<std::pair<int, int64_t>>& keys,
  const std::vector<std::array<float, 4>>& hulls, int leafLevel, std::vector<ModelChunk>& model)
{
  // A region's footprint (ours, for the view's I/J/K ranges, CellRange.h) is its own and its
  // descendants' node boxes together: a coarse column's topology is an average of the nodes
  // it merged, so its own box may fall short of what it stands for. The deepest level first.
  std::map<std::pair<int, int64_t>, std::array<float, 4>> footprint;
  for (std::size_t n = 0; n < keys.size(); ++n)
  {
    footprint[keys[n]] = hulls[n];
  }
  const std::array<float, 4> none{ 0.f, -1.f, 0.f, -1.f };
  const auto unite = [&](std::array<float, 4>& into, const std::array<float, 4>& box) {
    if (box[1] < box[0])
    {
      return;
    }
    into = into[1] < into[0] ? box
                             : std::array<float, 4>{ std::min(into[0], box[0]), std::max(into[1], box[1]),
                                 std::min(into[2], box[2]), std::max(into[3], box[3]) };
  };
  for (int level = leafLevel - 1; level >= 0; --level)
  {
    for (auto& entry : footprint)
    {
      if (entry.first.first != level)
      {
        continue;
      }
      for (const int64_t child : { 2 * entry.first.second, 2 * entry.first.second + 1 })
      {
        const auto found = footprint.find({ level + 1, child });
        if (found != footprint.end())
        {
          unite(entry.second, found->second);
        }
      }
    }
  }
  std::vector<float> table;
  table.reserve(this->Records.size() * 4);
  for (const auto& entry : this->Records) // the index's order
  {
    const auto found = footprint.find(entry.first);
    const auto& box = found != footprint.end() ? found->second : none;
    table.insert(table.end(), box.begin(), box.end());
  }
  this->Chunks->AddModelArray(ModelChunk::Footprints, table.data(), table.size() * 4, model);
}

void Builder::BuildPropertySide(MultiresolutionHeader& header, HierarchyReport& report, std::vector<ModelChunk>& model)
{
  const auto& dims = header.dims;
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  const uint64_t cells = static_cast<uint64_t>(nx * ny * nz);

  // The cells that any extracted face of any level may sample (Sec. 5.4): read back from
  // the chunk files, one region a task.
  std::vector<std::atomic<uint64_t>> touched((cells + 63) / 64);
  std::vector<std::unique_ptr<MappedChunkFile>> parts;
  for (int r = 0; r < this->Options.ranks; ++r)
  {
    parts.emplace_back(new MappedChunkFile(this->ChunkPath(r)));
  }
  std::vector<std::pair<int, int64_t>> keys;
  for (const auto& entry : this->Records)
  {
    if (entry.second.columns > 0)
    {
      keys.push_back(entry.first);
    }
  }
  const int threads = this->ThreadsFor(4 * this->Options.cmax * (nz + 1) * 64);
  this->Phase = "property side";
  std::vector<WallFace> walls; // the leaves' wall faces, for the wall depth table
  std::mutex wallsMutex;
  std::vector<std::array<float, 4>> hulls(keys.size()); // each region's own nodes' box in (i, j)
  ParallelFor(static_cast<int64_t>(keys.size()), threads, [&](int64_t n) {
    const auto& key = keys[static_cast<std::size_t>(n)];
    RegionMesh mesh = parts[static_cast<std::size_t>(this->Parts[key])]->ReadRegion(this->Records[key], header);
    hulls[static_cast<std::size_t>(n)] = TopologyBox(mesh);
    ExtractSurfaces(mesh); // the exact side faces, which views draw for regions of small error
    MarkTouchedCells(mesh, dims, touched);
    if (key.first == header.leafLevel)
    {
      std::vector<WallFace> faces;
      CollectWallFaces(mesh, nx, faces);
      std::lock_guard<std::mutex> lock(wallsMutex);
      std::move(faces.begin(), faces.end(), std::back_inserter(walls));
    }
    this->Report(this->Phase, 0.95 + 0.03 * static_cast<double>(n + 1) / static_cast<double>(keys.size()));
  });
  parts.clear();
  this->AddFootprints(keys, hulls, header.leafLevel, model);

  // Perfect spatial hash over them (Lefebvre and Hoppe), the cell of each slot. The cell
  // list is the largest array of the build: made exactly once, freed before the tables.
  const uint64_t layer = static_cast<uint64_t>(nx * ny);
  const auto eachTouched = [&](auto&& visit) {
    for (uint64_t word = 0; word < touched.size(); ++word)
    {
      for (uint64_t bits = touched[word].load(std::memory_order_relaxed); bits; bits &= bits - 1)
      {
        const uint64_t n = word * 64 + static_cast<uint64_t>(__builtin_ctzll(bits));
        visit(n,
          std::array<uint32_t, 3>{ static_cast<uint32_t>(n % layer % static_cast<uint64_t>(nx)),
            static_cast<uint32_t>(n % layer / static_cast<uint64_t>(nx)), static_cast<uint32_t>(n / layer) });
      }
    }
  };
  PerfectSpatialHash hash;
  {
    std::vector<std::array<uint32_t, 3>> hashed;
    uint64_t count = 0;
    for (const auto& word : touched)
    {
      count += static_cast<uint64_t>(__builtin_popcountll(word.load(std::memory_order_relaxed)));
    }
    hashed.reserve(static_cast<std::size_t>(count));
    eachTouched([&](uint64_t, const std::array<uint32_t, 3>& p) { hashed.push_back(p); });
    hash = BuildPerfectSpatialHash(hashed);
    header.hashedCells = hashed.size();
  }
  header.hashTableSides = hash.tableSides;
  header.hashOffsetSides = hash.offsetSides;
  report.hashedCells = header.hashedCells;
  report.hashSlots = hash.TableSize();
  report.hashOffsets = static_cast<uint64_t>(hash.offsets.size());
  std::vector<uint16_t> offsets;
  for (const auto& o : hash.offsets)
  {
    offsets.insert(offsets.end(), o.begin(), o.end());
  }
  this->Chunks->AddModelArray(ModelChunk::HashOffsets, offsets.data(), offsets.size() * 2, model);
  // Each table is written and freed before the next is made.
  const std::size_t slots = static_cast<std::size_t>(hash.TableSize());
  {
    std::vector<uint64_t> slotCell(slots, ~uint64_t(0));
    eachTouched([&](uint64_t n, const std::array<uint32_t, 3>& p) {
      slotCell[static_cast<std::size_t>(hash.Slot(p[0], p[1], p[2]))] = n;
    });
    this->Chunks->AddModelArray(ModelChunk::HashCells, slotCell.data(), slotCell.size() * 8, model);
  }
  // The normals of the hashed cells (those `touched` flags), leaf by leaf.
  std::vector<std::array<uint16_t, 2>> slotNormals(slots, { 0, 0 });
  for (const auto& entry : this->Records)
  {
    if (entry.first.first != header.leafLevel || entry.second.columns == 0)
    {
      continue;
    }
    std::vector<uint8_t> raw;
    if (!LoadCompressed(this->NormalsPath(entry.first.second), raw))
    {
      throw std::runtime_error(this->NormalsPath(entry.first.second) + ": missing scratch file of cell normals");
    }
    ByteReader in(raw.data(), raw.size(), this->NormalsPath(entry.first.second));
    const uint64_t columns = in.Get<uint64_t>();
    for (uint64_t c = 0; c < columns; ++c)
    {
      const uint64_t column = static_cast<uint64_t>(in.Get<int64_t>());
      const uint8_t* stack = in.Skip(static_cast<std::size_t>(nz) * 4);
      for (uint64_t k = 0; k < static_cast<uint64_t>(nz) && column < layer; ++k)
      {
        const uint64_t n = column + layer * k;
        if (touched[n >> 6].load(std::memory_order_relaxed) >> (n & 63) & 1)
        {
          const uint64_t slot = hash.Slot(static_cast<uint32_t>(column % static_cast<uint64_t>(nx)),
            static_cast<uint32_t>(column / static_cast<uint64_t>(nx)), static_cast<uint32_t>(k));
          std::memcpy(slotNormals[static_cast<std::size_t>(slot)].data(), stack + k * 4, 4);
        }
      }
    }
  }
  std::vector<std::atomic<uint64_t>>().swap(touched);
  this->Chunks->AddModelArray(ModelChunk::CellNormals, slotNormals.data(), slotNormals.size() * 4, model);
  std::vector<std::array<uint16_t, 2>>().swap(slotNormals);
  this->AddWallDepths(walls, header, report, model);
}

void Builder::AddWallDepths(std::vector<WallFace>& walls, const MultiresolutionHeader& header, HierarchyReport& report,
  std::vector<ModelChunk>& model)
{
  const int64_t nx = header.dims[0], ny = header.dims[1], nz = header.dims[2];
  // Wall depths (ours, WallDepthTable.h), in a fixed order whatever the threads did; keys of
  // (j nx + i) 4 + face + 1 fit 32 bits below 2^30 columns.
  // The table is an aid to painting: a model it cannot be made for keeps the rest of the build.
  if (walls.empty())
  {
    return;
  }
  if (static_cast<uint64_t>(nx * ny) >= (uint64_t(1) << 30))
  {
    report.wallsLeftOut = "2^30 columns or more: wall face keys would not fit 32 bits";
    return;
  }
  std::sort(walls.begin(), walls.end(), [](const WallFace& a, const WallFace& b) { return a.key < b.key; });
  std::vector<uint8_t> bytes;
  try
  {
    bytes = EncodeWallDepthTable(BuildWallDepthTable(walls, static_cast<int32_t>(nz), nx));
  }
  catch (const std::invalid_argument& e)
  {
    report.wallsLeftOut = e.what(); // no perfect hash within the texture limits
    return;
  }
  report.wallFaces = walls.size();
  std::vector<WallFace>().swap(walls);
  this->Chunks->AddModelArray(ModelChunk::WallDepths, bytes.data(), bytes.size(), model);
}

/// Creates the scratch folder, or finds in it the last level every rank finished (-1: none)
/// and clears what an unfinished level left. `partitioned`: no level is finished but the
/// partition pass is, so the build resumes with the leaves.
int Builder::PrepareScratch(MultiresolutionHeader& header, HierarchyReport& report, bool& partitioned)
{
  const bool lead = this->Options.rank == 0;
  if (mkdir(this->Scratch.c_str(), 0755) != 0 && errno != EEXIST)
  {
    throw std::runtime_error(this->Scratch + ": cannot create the scratch folder: " + std::strerror(errno));
  }
  int finished = -1;
  partitioned = false;
  bool complete = false;
  const bool checkpoint = LeafPartition::HasCheckpoint(this->Scratch + "/tiles", &complete);
  // A partition pass stopped part-way resumes from its checkpoint (LeafPartition checks that
  // it is of the same input); the rest of the build starts over from it.
  const bool partial = this->Options.resume && checkpoint && !complete;
  if (this->ReadBuildManifest(header, report))
  {
    partitioned = checkpoint && complete;
    for (int level = header.leafLevel; level >= 0; --level)
    {
      bool all = true;
      for (int r = 0; r < this->Options.ranks; ++r)
      {
        all = all && Exists(this->LevelManifest(level, r));
      }
      if (!all)
      {
        break;
      }
      finished = level;
    }
  }
  if (finished < 0 && !partitioned && !partial && this->Options.checkDisk)
  {
    try
    {
      this->CheckFreeDisk(); // every rank: they see the same disks, so all refuse or none
    }
    catch (const std::runtime_error&)
    {
      rmdir(this->Scratch.c_str()); // the folder just made, if nothing else is in it
      throw;
    }
  }
  this->Barrier();
  if (lead)
  {
    // Start over, or clear what the unfinished level left (other ranks wait below).
    if (finished < 0 && !partitioned && !partial)
    {
      RemoveTree(this->Scratch);
      if (mkdir(this->Scratch.c_str(), 0755) != 0 && errno != EEXIST)
      {
        throw std::runtime_error(this->Scratch + ": cannot create the scratch folder: " + std::strerror(errno));
      }
    }
    for (int r = 0; r < this->Options.ranks; ++r)
    {
      unlink((this->Scratch + "/failed.rank-" + std::to_string(r)).c_str());
    }
  }
  this->Barrier();
  return finished;
}

/// Refuses a build the disks cannot hold (BuildDiskNeed), before any work, with what it needs.
void Builder::CheckFreeDisk() const
{
  const BuildDiskNeed need(this->Source.Dims(), this->Options.ranks);
  const uint64_t scratchFree = FreeDiskBytes(this->Scratch), outputFree = FreeDiskBytes(this->Output);
  const bool shared = SameFilesystem(this->Scratch, this->Output);
  const auto gb = [](uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.1f GB", double(bytes) / 1e9);
    return std::string(text);
  };
  const std::string what = std::to_string(this->CellCount) + " cells need about " + gb(need.scratch) +
    " of scratch and " + gb(need.file) + " for the file (" + std::to_string(need.FileBytesPerCell) +
    " bytes a cell for the file, " +
    (this->Options.ranks > 1 ? std::to_string(need.LevelScratchBytesPerCell) + " for the scratch of MPI ranks"
                             : std::to_string(need.ScratchBytesPerCell) + " and " +
          std::to_string(need.ScratchBytesPerColumn) + " a column for the scratch") +
    ", and a few hundred MB)";
  std::string problem;
  if (shared && scratchFree < need.scratch + need.file)
  {
    problem = this->Scratch + " and " + this->Output + " share a disk with " + gb(scratchFree) + " free";
  }
  else if (!shared && scratchFree < need.scratch)
  {
    problem = "the scratch folder " + this->Scratch + " has " + gb(scratchFree) + " free";
  }
  else if (!shared && outputFree < need.file)
  {
    problem = "the output " + this->Output + " has " + gb(outputFree) + " free";
  }
  if (!problem.empty())
  {
    throw std::runtime_error("not enough free disk: " + what + "; " + problem +
      ". Put the scratch folder on a disk with room (--scratch DIR), or free some space (--no-disk-check "
      "starts anyway; a build stopped by a full disk keeps its finished work and resumes)");
  }
}

/// Reloads the levels a killed build finished and reopens this rank's chunk file at the
/// size it had then.
void Builder::Resume(int finished, const MultiresolutionHeader& header)
{
  this->Tree = DiamondHierarchy(header.box[0], header.box[1], header.box[2], header.box[3], header.leafLevel);
  this->Options.cmax = header.cmax;
  for (int level = header.leafLevel; level >= finished; --level)
  {
    this->LoadLevel(level);
  }
  ManifestIn own;
  own.Load(this->LevelManifest(finished, this->Options.rank));
  own.Get<uint64_t>();
  own.Get<int32_t>();
  own.Get<int32_t>();
  this->Header = header;
  this->Chunks.reset(new ChunkFile(this->ChunkPath(this->Options.rank), static_cast<int64_t>(own.Get<uint64_t>())));
}

/// The streaming pass (Sec. 4.2 and 7, "partitioning"): rank 0 reads the input once, layer by
/// layer, into scratch tiles and stores each layer's active flags; the other ranks open its
/// tiles.
void Builder::PartitionInput(HierarchyReport& report)
{
  const bool lead = this->Options.rank == 0;
  const auto dims = this->Source.Dims();
  // Tiles of about 64 x 64 columns, fewer and bigger for very wide grids (at most ~1000
  // files).
  const int64_t tile =
    std::max<int64_t>(64, static_cast<int64_t>(std::ceil(std::sqrt(double(dims[0]) * dims[1] / 1000.0))));
  this->Collective([&] {
    if (!lead)
    {
      this->Chunks.reset(new ChunkFile(this->ChunkPath(this->Options.rank)));
      return;
    }
    this->ActiveLayers.clear(); // onResume gives back those of a pass stopped part-way
    std::vector<uint8_t> bits;
    PartitionHooks hooks;
    hooks.progress = [this](double f) { this->Report("partition", 0.1 * f); };
    hooks.onLayer = [&](int64_t k, const std::vector<uint8_t>& active) {
      if (!this->Chunks) // a pass that starts over (one that resumes has it from onResume)
      {
        this->Chunks.reset(new ChunkFile(this->ChunkPath(0)));
      }
      bits.assign((active.size() + 7) / 8, 0);
      for (std::size_t c = 0; c < active.size(); ++c)
      {
        bits[c >> 3] |= static_cast<uint8_t>((active[c] ? 1 : 0) << (c & 7));
      }
      ModelChunk chunk;
      chunk.kind = ModelChunk::ActiveLayer;
      chunk.part = static_cast<uint32_t>(k);
      chunk.chunk = this->Chunks->Put(bits, "active flags of layer " + std::to_string(k + 1));
      this->ActiveLayers.push_back(chunk);
    };
    // A checkpoint keeps the layers' active flags in the chunk file (synced) and their list.
    hooks.checkpointNote = [this] {
      ByteWriter note;
      note.Put(this->Chunks ? this->Chunks->Sync() : uint64_t(0));
      note.Put(static_cast<uint64_t>(this->ActiveLayers.size()));
      for (const ModelChunk& chunk : this->ActiveLayers)
      {
        note.Put(chunk);
      }
      return note.Bytes;
    };
    hooks.onResume = [&](int64_t layers, const std::vector<uint8_t>& note) {
      ByteReader in(note.data(), note.size(), this->Scratch + "/tiles: partition checkpoint");
      in.Get<uint64_t>();
      const uint64_t count = in.Get<uint64_t>();
      this->ActiveLayers.clear();
      for (uint64_t k = 0; k < count && static_cast<int64_t>(k) < layers; ++k)
      {
        this->ActiveLayers.push_back(in.Get<ModelChunk>());
      }
      if (static_cast<int64_t>(this->ActiveLayers.size()) != layers)
      {
        throw std::runtime_error(this->Scratch + "/tiles: the partition checkpoint lacks layers' active flags");
      }
      // The flags of the layers done, and none of those to stream again.
      const ChunkRef last = layers > 0 ? this->ActiveLayers.back().chunk : ChunkRef();
      this->Chunks.reset(new ChunkFile(this->ChunkPath(0), static_cast<int64_t>(last.offset + last.stored)));
      report.resumedLayers = layers;
    };
    this->Partition.reset(new LeafPartition(this->Source, this->Scratch + "/tiles", tile, hooks));
    this->Partition->SaveState();
    this->PartitionChunkBytes = this->Chunks->Sync();
  });
  if (!lead)
  {
    this->Partition.reset(new LeafPartition(this->Scratch + "/tiles"));
  }
}

/// The partition pass of a killed build, reopened from its tiles; rank 0 takes the tiles over
/// (removed once the leaves are built) and its chunk file is cut back to the active flags.
void Builder::ReopenPartition()
{
  const bool lead = this->Options.rank == 0;
  if (this->Options.ranks > 1) // one process: ReadJournal reopens it at the end of its last task
  {
    this->Chunks.reset(
      new ChunkFile(this->ChunkPath(this->Options.rank), lead ? static_cast<int64_t>(this->PartitionChunkBytes) : 0));
  }
  this->Partition.reset(new LeafPartition(this->Scratch + "/tiles"));
  this->Partition->SetRemoveOnDestroy(lead);
}

/// The hierarchy over the pillars' extent, its leaf level chosen for Cmax columns a leaf, and
/// the columns of each leaf (by column centre); fills the header and writes the build
/// manifest.
std::vector<Builder::Leaf> Builder::PlanLeaves(MultiresolutionHeader& header, HierarchyReport& report)
{
  const auto dims = this->Source.Dims();
  const int64_t nx = dims[0], ny = dims[1];
  const auto& extent = this->Partition->Extent();
  const auto& hasActive = this->Partition->ColumnHasActive();
  std::vector<int64_t> columns;
  for (int64_t c = 0; c < nx * ny; ++c)
  {
    if (hasActive[static_cast<std::size_t>(c)])
    {
      columns.push_back(c);
    }
  }
  if (columns.empty())
  {
    throw std::runtime_error(this->Source.Name() + ": the model has no active cell");
  }
  report.columns = static_cast<int64_t>(columns.size());
  DiamondHierarchy locator(extent[0], extent[1], extent[3], extent[4], 0);
  std::vector<std::pair<uint64_t, int64_t>> coded(columns.size());
  std::vector<uint64_t> codes(columns.size());
  for (std::size_t n = 0; n < columns.size(); ++n)
  {
    const auto centre = this->Partition->ColumnCentre(columns[n] % nx, columns[n] / nx);
    codes[n] = locator.Code(centre[0], centre[1]);
    coded[n] = { codes[n], columns[n] };
  }
  const int64_t cmax = this->Options.cmax == 0 ? AutomaticCmax(report.columns) : this->Options.cmax;
  const int leafLevel = DiamondHierarchy::ChooseLeafLevel(codes, cmax);
  this->Tree = DiamondHierarchy(extent[0], extent[1], extent[3], extent[4], leafLevel);
  std::sort(coded.begin(), coded.end());
  std::vector<Leaf> leaves;
  for (const auto& entry : coded)
  {
    const int64_t leaf = static_cast<int64_t>(entry.first >> (DiamondHierarchy::MaxDepth - leafLevel));
    if (leaves.empty() || leaves.back().first != leaf)
    {
      leaves.push_back({ leaf, {} });
    }
    leaves.back().second.push_back(entry.second);
  }

  header.dims = dims;
  header.box = { extent[0], extent[1], extent[3], extent[4] };
  ChooseLattice(extent, header);
  header.leafLevel = leafLevel;
  header.cmax = static_cast<int32_t>(cmax);
  this->Header = header;
  if (this->Options.rank == 0)
  {
    this->WriteBuildManifest(header, report);
  }
  this->Options.cmax = cmax;
  return leaves;
}

/// Leaf meshes (Sec. 4.2's finest level), this rank's share on worker threads, then the
/// partition's tiles are removed.
void Builder::BuildLeaves(const std::vector<Leaf>& leaves, int leafLevel, HierarchyReport& report)
{
  const int64_t nz = this->Source.Dims()[2];
  const int64_t cmax = this->Options.cmax;
  // Work: leaf columns once, then the columns merged at each level (about halving).
  this->WorkTotal = std::max<int64_t>(1, report.columns / this->Options.ranks);
  this->WorkStart = 0.1;
  this->WorkSpan = 0.1;
  this->Phase = "leaves";
  const double leafStart = Seconds();
  const int64_t leafTask = (cmax * 2) * (nz + 1) * VertexBytes * 2 + cmax * 2 * nz * 40;
  const int leafThreads = this->ThreadsFor(leafTask);
  report.threadsUsed = leafThreads;
  const std::vector<std::size_t> mine = this->Share(leaves.size());
  this->Collective([&] {
    ParallelFor(static_cast<int64_t>(mine.size()), leafThreads, [&](int64_t n) {
      const auto& leaf = leaves[mine[static_cast<std::size_t>(n)]];
      std::vector<Emitted> out;
      this->BuildLeaf(leaf.first, leaf.second, out);
      this->Commit(out, nullptr);
    });
    this->SaveLevel(leafLevel);
  });
  this->LoadLevel(leafLevel);
  report.leafSeconds = Seconds() - leafStart;
  // Tiles are no longer needed: other ranks close theirs before rank 0 removes them.
  if (this->Options.rank != 0)
  {
    this->Partition.reset();
  }
  this->Barrier();
  this->Partition.reset();
}

/// The items of `count` this rank builds (round robin over ranks).
std::vector<std::size_t> Builder::Share(std::size_t count) const
{
  std::vector<std::size_t> mine;
  for (std::size_t n = 0; n < count; ++n)
  {
    if (static_cast<int>(n % static_cast<std::size_t>(this->Options.ranks)) == this->Options.rank)
    {
      mine.push_back(n);
    }
  }
  return mine;
}

/// Sec. 4.1-4.3 bottom-up: each level's diamonds merge and simplify their children's meshes;
/// a level's scratch regions are removed once the next level holds them.
void Builder::SimplifyLevels(int finished, HierarchyReport& report)
{
  const int64_t nz = this->Source.Dims()[2];
  const double simplifyStart = Seconds();
  this->Phase = "simplify";
  this->WorkDone = 0;
  this->WorkTotal = std::max<int64_t>(1, 2 * report.columns / this->Options.ranks);
  this->WorkStart = 0.2;
  this->WorkSpan = 0.75;
  const int64_t diamondTask = 4 * this->Options.cmax * (nz + 1) * VertexBytes * 3;
  const int diamondThreads = this->ThreadsFor(diamondTask);
  report.threadsUsed = std::max(report.threadsUsed, diamondThreads);
  for (int level = finished - 1; level >= 0; --level)
  {
    std::vector<DiamondHierarchy::Diamond> busy;
    for (const auto& d : this->Tree.Diamonds(level))
    {
      const int64_t children[4] = { 2 * d.first, 2 * d.first + 1, d.second >= 0 ? 2 * d.second : -1,
        d.second >= 0 ? 2 * d.second + 1 : -1 };
      for (int64_t child : children)
      {
        if (child >= 0 && this->Records.count({ level + 1, child }))
        {
          busy.push_back(d);
          break;
        }
      }
    }
    const std::vector<std::size_t> mine = this->Share(busy.size());
    this->Collective([&] {
      ParallelFor(static_cast<int64_t>(mine.size()), diamondThreads, [&](int64_t n) {
        std::vector<Emitted> out;
        this->BuildDiamond(busy[mine[static_cast<std::size_t>(n)]], out);
        this->Commit(out, nullptr);
      });
      this->SaveLevel(level);
    });
    this->LoadLevel(level);
    if (this->Options.rank == 0)
    {
      for (const auto& entry : this->Records)
      {
        if (entry.first.first == level + 1)
        {
          unlink(RegionPath(this->Scratch, level + 1, entry.first.second).c_str());
        }
      }
    }
  }
  report.simplifySeconds = Seconds() - simplifyStart;
}

/// The tasks a killed one-process build finished, from its journal: their regions are
/// recorded again, the chunk file is cut back to the end of the last one, and the children
/// of finished diamonds are removed (a kill may have come between the two).
std::vector<uint8_t> Builder::ReadJournal(const BuildSchedule& schedule, HierarchyReport& report)
{
  const auto& tasks = schedule.Tasks();
  std::map<std::pair<int, int64_t>, int32_t> index;
  for (std::size_t t = 0; t < tasks.size(); ++t)
  {
    index[{ tasks[t].level, tasks[t].first }] = static_cast<int32_t>(t);
  }
  const std::string path = this->Scratch + "/build.journal";
  std::vector<std::vector<uint8_t>> records;
  this->Journal.reset(new BuildJournal(path, records));
  std::vector<uint8_t> done(tasks.size(), 0);
  uint64_t chunkEnd = this->PartitionChunkBytes;
  for (const auto& bytes : records)
  {
    ByteReader in(bytes.data(), bytes.size(), path);
    const int level = in.Get<int32_t>();
    const int64_t first = in.Get<int64_t>();
    const auto found = index.find({ level, first });
    if (found == index.end() || done[static_cast<std::size_t>(found->second)])
    {
      throw std::runtime_error(path + ": records a task this build does not have (build with --fresh)");
    }
    done[static_cast<std::size_t>(found->second)] = 1;
    chunkEnd = std::max(chunkEnd, in.Get<uint64_t>());
    const uint64_t count = in.Get<uint64_t>();
    // Records are this build's structs: a journal of another resmr version has other sizes.
    if (count > 2 || bytes.size() != 28 + count * (sizeof(RegionRecord) + sizeof(std::array<double, 6>)))
    {
      throw std::runtime_error(path + ": written by another version of resmr (build with --fresh)");
    }
    std::vector<Emitted> regions(count);
    for (auto& emitted : regions)
    {
      emitted.record = in.Get<RegionRecord>();
      emitted.box = in.Get<std::array<double, 6>>();
      const std::pair<int, int64_t> key{ emitted.record.level, emitted.record.index };
      this->Records[key] = emitted.record;
      this->Parts[key] = 0;
      this->OwnBoxes[key] = emitted.box;
    }
    ++report.resumedTasks;
  }
  this->Chunks.reset();
  this->Chunks.reset(new ChunkFile(this->ChunkPath(0), static_cast<int64_t>(chunkEnd)));
  for (std::size_t t = 0; t < tasks.size(); ++t)
  {
    for (int64_t child : done[t] ? BuildSchedule::Children(tasks[t]) : std::vector<int64_t>())
    {
      unlink(RegionPath(this->Scratch, tasks[t].level + 1, child).c_str());
    }
  }
  return done;
}

/// One process (ours): leaves and diamonds as one schedule, depth first (BuildSchedule), so
/// that only regions made but not yet merged lie in scratch; each finished task goes to the
/// journal, and the same build run again skips them.
void Builder::BuildDepthFirst(const std::vector<Leaf>& leaves, HierarchyReport& report)
{
  const int64_t nz = this->Source.Dims()[2];
  const int64_t cmax = this->Options.cmax;
  std::vector<int64_t> triangles;
  for (const Leaf& leaf : leaves)
  {
    triangles.push_back(leaf.first);
  }
  const BuildSchedule schedule(this->Tree, triangles);
  const auto& tasks = schedule.Tasks();
  report.tasks = static_cast<int64_t>(tasks.size());
  const std::vector<uint8_t> done = this->ReadJournal(schedule, report);
  // A tile of the partition is freed once no leaf still to build reads it.
  for (std::size_t t = 0; t < tasks.size(); ++t)
  {
    if (tasks[t].leaf && !done[t])
    {
      const auto box = this->LeafBox(leaves[static_cast<std::size_t>(tasks[t].leafIndex)].second);
      this->Partition->Retain(box[0], box[1], box[2], box[3]);
    }
  }
  // Work: leaf columns once, then the columns merged at each level (about halving).
  this->WorkDone = 0;
  this->WorkTotal = std::max<int64_t>(1, 3 * report.columns);
  this->WorkStart = 0.1;
  this->WorkSpan = 0.85;
  this->Phase = "hierarchy";
  const int64_t leafTask = (cmax * 2) * (nz + 1) * VertexBytes * 2 + cmax * 2 * nz * 40;
  const int64_t diamondTask = 4 * cmax * (nz + 1) * VertexBytes * 3;
  const int threads = this->ThreadsFor(std::max(leafTask, diamondTask));
  report.threadsUsed = threads;
  std::atomic<int64_t> leafMicros{ 0 }, diamondMicros{ 0 };
  const double start = Seconds();
  schedule.Run(threads, done, [&](int32_t t) {
    const BuildSchedule::Task& task = tasks[static_cast<std::size_t>(t)];
    const double begin = Seconds();
    std::vector<Emitted> out;
    if (task.leaf)
    {
      const Leaf& leaf = leaves[static_cast<std::size_t>(task.leafIndex)];
      this->BuildLeaf(leaf.first, leaf.second, out);
      this->Commit(out, &task);
      const auto box = this->LeafBox(leaf.second);
      this->Partition->Release(box[0], box[1], box[2], box[3]);
      leafMicros += static_cast<int64_t>(1e6 * (Seconds() - begin));
      return;
    }
    this->BuildDiamond({ task.level, task.first, task.second }, out);
    this->Commit(out, &task);
    for (int64_t child : BuildSchedule::Children(task))
    {
      unlink(RegionPath(this->Scratch, task.level + 1, child).c_str());
    }
    diamondMicros += static_cast<int64_t>(1e6 * (Seconds() - begin));
  });
  // The phases interleave: the wall time is shared out by the time the tasks of each took.
  const double wall = Seconds() - start, busy = std::max<double>(1, double(leafMicros + diamondMicros));
  report.leafSeconds = wall * double(leafMicros) / busy;
  report.simplifySeconds = wall * double(diamondMicros) / busy;
  this->Journal.reset();
  // Every tile is freed; the partition's state stays until the file is written, for a build
  // that stops after this and resumes (its leaves are planned from it).
  this->Partition->SetRemoveOnDestroy(false);
  this->Partition.reset();
}

/// Rank 0: errors and bounds, the property side, then the file from every rank's chunks.
void Builder::WriteFile(MultiresolutionHeader& header, HierarchyReport& report)
{
  this->Collective([&] {
    if (this->Options.rank != 0)
    {
      return;
    }
    this->FinishBoundsAndErrors(header.leafLevel);
    std::vector<ModelChunk> model = this->ActiveLayers;
    this->BuildPropertySide(header, report, model);
    this->Chunks->Sync();
    std::vector<std::string> paths;
    for (int r = 0; r < this->Options.ranks; ++r)
    {
      paths.push_back(this->ChunkPath(r));
    }
    std::vector<PartRecord<RegionRecord>> regions;
    for (const auto& entry : this->Records)
    {
      regions.push_back({ this->Parts[entry.first], entry.second });
      report.nonEmptyRegions += entry.second.columns > 0 ? 1 : 0;
    }
    std::vector<PartRecord<ModelChunk>> modelParts;
    for (const ModelChunk& m : model)
    {
      modelParts.push_back({ 0, m });
    }
    report.regions = static_cast<int64_t>(regions.size());
    header.map = this->Source.Placement(); // recorded only: positions stay in grid coordinates
    this->Report("writing", 0.99);
    AssembleMultiresolutionFile(this->Output, header, paths, regions, modelParts);
    struct stat info;
    report.fileBytes = stat(this->Output.c_str(), &info) == 0 ? static_cast<uint64_t>(info.st_size) : 0;
    // The file is whole beside the scratch it was made from: the build's last peak.
    this->Meter->Sample(uint64_t(info.st_blocks) * 512);
    report.peakScratchBytes = this->Meter->PeakScratchBytes();
    report.peakDiskBytes = this->Meter->PeakTotalBytes();
  });
}

HierarchyReport Builder::Run()
{
  HierarchyReport report;
  const double start = Seconds();
  const auto dims = this->Source.Dims();
  report.cells = dims[0] * dims[1] * dims[2];
  this->CellCount = report.cells;
  MultiresolutionHeader header;
  bool partitioned = false;
  if (this->Options.rank == 0)
  {
    this->Meter.reset(new DiskMeter(this->Scratch, this->Output));
  }
  int finished = this->PrepareScratch(header, report, partitioned);
  bool keepScratch = false;
  try
  {
    if (finished >= 0)
    {
      report.resumedFromLevel = finished;
      this->Resume(finished, header);
      keepScratch = true;
      this->SimplifyLevels(finished, report);
    }
    else
    {
      if (partitioned)
      {
        report.resumedFromPartition = true;
        this->ReopenPartition();
      }
      else
      {
        this->PartitionInput(report);
        report.partitionSeconds = Seconds() - start;
      }
      report.activeCells = this->Partition->ActiveCells();
      this->Source.Finished(); // the tiles hold the model now
      const std::vector<Leaf> leaves = this->PlanLeaves(header, report);
      keepScratch = true; // the partition is finished: a failure from here keeps it
      if (this->Options.ranks == 1)
      {
        this->BuildDepthFirst(leaves, report);
      }
      else
      {
        this->BuildLeaves(leaves, header.leafLevel, report);
        this->SimplifyLevels(header.leafLevel, report);
      }
    }
    report.leafLevel = header.leafLevel;
    this->WriteFile(header, report);
  }
  catch (const std::exception& error)
  {
    this->Chunks.reset();
    // A partition pass stopped part-way keeps its last checkpoint.
    bool complete = false;
    keepScratch = keepScratch || LeafPartition::HasCheckpoint(this->Scratch + "/tiles", &complete);
    if (this->Partition)
    {
      this->Partition->SetRemoveOnDestroy(!keepScratch && this->Options.rank == 0);
    }
    this->Partition.reset();
    if (!keepScratch)
    {
      if (this->Options.rank == 0)
      {
        RemoveTree(this->Scratch);
      }
      throw;
    }
    throw std::runtime_error(std::string(error.what()) + " (the finished work is kept in " + this->Scratch +
      ": run the same build again to resume)");
  }
  this->Chunks.reset();
  this->Meter.reset();
  this->Barrier();
  if (this->Options.rank == 0)
  {
    RemoveTree(this->Scratch);
  }
  report.totalSeconds = Seconds() - start;
  this->Report("done", 1.0);
  return report;
}
} // namespace

std::string ScratchFolder(const std::string& output, const HierarchyOptions& options)
{
  return options.scratch.empty() ? output + ".scratch" : options.scratch;
}

HierarchyReport BuildHierarchy(
  LayerSource& source, const std::string& output, const HierarchyOptions& options, const BuildProgress& progress)
{
  Builder builder(source, output, options, progress);
  return builder.Run();
}

} // namespace resmr
