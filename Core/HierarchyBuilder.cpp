// Out-of-core, multi-threaded build of the diamond hierarchy, paper Sec. 4.2 (with 4.3 and 6.2).
#include "HierarchyBuilder.h"

#include "ColumnCollapse.h"
#include "ColumnMesh.h"
#include "DiamondHierarchy.h"
#include "LeafPartition.h"
#include "MemoryBudget.h"
#include "MultiresolutionFile.h"
#include "RegionMesh.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
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
  std::vector<uint8_t> cutEdges; ///< per column, bit e
  std::vector<uint8_t> openSides; ///< per cell, bit e: side face e is external (see RegionMesh)
};

std::string RegionPath(const std::string& folder, int level, int64_t index)
{
  return folder + "/region-" + std::to_string(level) + "-" + std::to_string(index) + ".bin";
}

template <typename T>
void PutVector(std::FILE* file, const std::vector<T>& values, bool& ok)
{
  const uint64_t count = values.size();
  ok = ok && std::fwrite(&count, sizeof(count), 1, file) == 1;
  ok = ok && (count == 0 || std::fwrite(values.data(), sizeof(T), values.size(), file) == values.size());
}

template <typename T>
void GetVector(std::FILE* file, std::vector<T>& values, bool& ok)
{
  uint64_t count = 0;
  ok = ok && std::fread(&count, sizeof(count), 1, file) == 1 && count < (uint64_t(1) << 40);
  if (ok)
  {
    values.resize(count);
    ok = count == 0 || std::fread(values.data(), sizeof(T), values.size(), file) == values.size();
  }
}

void SaveRegion(const std::string& path, const ScratchRegion& region)
{
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file)
  {
    throw std::runtime_error(path + ": cannot create scratch file: " + std::strerror(errno));
  }
  bool ok = std::fwrite(&region.mesh.layers, sizeof(int32_t), 1, file) == 1;
  PutVector(file, region.mesh.positions, ok);
  PutVector(file, region.mesh.quadrics, ok);
  PutVector(file, region.mesh.topology, ok);
  PutVector(file, region.mesh.corners, ok);
  PutVector(file, region.mesh.activeCells, ok);
  PutVector(file, region.mesh.origin, ok);
  PutVector(file, region.cutEdges, ok);
  PutVector(file, region.openSides, ok);
  ok = (std::fclose(file) == 0) && ok;
  if (!ok)
  {
    unlink(path.c_str());
    throw std::runtime_error(path + ": scratch write failed (disk full?)");
  }
}

bool LoadRegion(const std::string& path, ScratchRegion& region)
{
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file)
  {
    return false; // an empty region saves nothing
  }
  bool ok = std::fread(&region.mesh.layers, sizeof(int32_t), 1, file) == 1;
  GetVector(file, region.mesh.positions, ok);
  GetVector(file, region.mesh.quadrics, ok);
  GetVector(file, region.mesh.topology, ok);
  GetVector(file, region.mesh.corners, ok);
  GetVector(file, region.mesh.activeCells, ok);
  GetVector(file, region.mesh.origin, ok);
  GetVector(file, region.cutEdges, ok);
  GetVector(file, region.openSides, ok);
  std::fclose(file);
  if (!ok)
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
std::vector<uint8_t> KeptCells(const std::vector<uint8_t>& perCell, const std::vector<uint8_t>& keep, std::size_t layers)
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

RegionMesh ToRegionMesh(const ScratchRegion& region)
{
  RegionMesh out;
  out.layers = region.mesh.layers;
  out.positions = region.mesh.positions;
  out.topology.resize(region.mesh.topology.size());
  for (std::size_t n = 0; n < out.topology.size(); ++n)
  {
    out.topology[n] = { static_cast<float>(region.mesh.topology[n][0]), static_cast<float>(region.mesh.topology[n][1]) };
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
  ExtractSurfaces(out);
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

/// Default Cmax: 4096 columns a region (a 64 x 64 patch: top and bottom surfaces of about 16k
/// triangles, the batch size at which GPUs reach full speed, while a diamond's merged mesh
/// stays a few hundred MB for 100 layers), but at most a 32nd of the model's columns (and at
/// least 256), so that small models get five or more levels, not a single one.
int64_t AutomaticCmax(int64_t columns)
{
  return std::max<int64_t>(256, std::min<int64_t>(4096, columns / 32));
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
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t)
  {
    pool.emplace_back(work);
  }
  work();
  for (auto& thread : pool)
  {
    thread.join();
  }
  if (failure)
  {
    std::rethrow_exception(failure);
  }
}

uint64_t Mix(uint64_t x)
{
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// Removes the scratch folder's leftovers on the way out, whatever happens.
struct ScratchFolder
{
  std::string path;
  bool created = false;
  explicit ScratchFolder(std::string folder)
    : path(std::move(folder))
  {
    if (mkdir(this->path.c_str(), 0755) != 0 && errno != EEXIST)
    {
      throw std::runtime_error(this->path + ": cannot create the scratch folder: " + std::strerror(errno));
    }
    this->created = true;
  }
  ~ScratchFolder()
  {
    if (this->created)
    {
      const std::string command = "rm -rf '" + this->path + "'";
      if (std::system(command.c_str()) != 0)
      {
        std::fprintf(stderr, "warning: could not remove the scratch folder %s\n", this->path.c_str());
      }
    }
  }
};

class Builder
{
public:
  Builder(LayerSource& source, const std::string& output, const HierarchyOptions& options, const BuildProgress& progress)
    : Source(source)
    , Output(output)
    , Options(options)
    , Progress(progress)
    , Scratch(options.scratch.empty() ? output + ".scratch" : options.scratch)
  {
    if (this->Options.cmax != 0 && this->Options.cmax < 16)
    {
      throw std::invalid_argument("--cmax must be at least 16 columns (or 0: chosen from the model)");
    }
  }

  HierarchyReport Run();

private:
  void Report(const char* phase, double fraction)
  {
    if (this->Progress)
    {
      std::lock_guard<std::mutex> guard(this->ProgressLock);
      this->Progress(phase, fraction);
    }
  }
  void BuildLeaf(int64_t leaf, const std::vector<int64_t>& columns);
  void BuildDiamond(const DiamondHierarchy::Diamond& diamond);
  void Emit(int level, int64_t index, const ScratchRegion& region, bool keepScratch);
  int ThreadsFor(int64_t bytesPerTask) const;

  LayerSource& Source;
  std::string Output;
  HierarchyOptions Options;
  BuildProgress Progress;
  ScratchFolder Scratch;
  std::mutex ProgressLock;
  std::unique_ptr<LeafPartition> Partition;
  DiamondHierarchy Tree;
  std::unique_ptr<MultiresolutionWriter> Writer;
  std::mutex RecordLock;
  std::map<std::pair<int, int64_t>, RegionRecord> Records;
  std::map<std::pair<int, int64_t>, std::array<double, 6>> OwnBoxes;
  std::atomic<int64_t> WorkDone{ 0 };
  int64_t WorkTotal = 1;
  double WorkStart = 0, WorkSpan = 1;
  const char* Phase = "";
};

int Builder::ThreadsFor(int64_t bytesPerTask) const
{
  int threads = this->Options.threads > 0 ? this->Options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(threads, 1);
  const int64_t budget = this->Options.memoryBytes > 0 ? this->Options.memoryBytes : AvailableMemoryBytes() / 2;
  const int64_t fit = std::max<int64_t>(1, budget / std::max<int64_t>(bytesPerTask, 1));
  return static_cast<int>(std::min<int64_t>(threads, fit));
}

void Builder::Emit(int level, int64_t index, const ScratchRegion& region, bool keepScratch)
{
  if (keepScratch)
  {
    SaveRegion(RegionPath(this->Scratch.path, level, index), region);
  }
  const RegionMesh mesh = ToRegionMesh(region);
  RegionRecord record;
  record.level = level;
  record.index = index;
  record.ownError = static_cast<float>(QuadricDistance(region.mesh));
  this->Writer->AddRegion(mesh, record);
  std::lock_guard<std::mutex> guard(this->RecordLock);
  this->Records[{ level, index }] = record;
  this->OwnBoxes[{ level, index }] = BoxOf(region.mesh.positions);
}

void Builder::BuildLeaf(int64_t leaf, const std::vector<int64_t>& columns)
{
  const auto& dims = this->Partition->Dims();
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
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
  i0 = std::max<int64_t>(i0 - 1, 0);
  j0 = std::max<int64_t>(j0 - 1, 0);
  i1 = std::min(i1 + 1, nx);
  j1 = std::min(j1 + 1, ny);
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
  for (int32_t c = 0; c < halo.ColumnSlots(); ++c)
  {
    if (!keep[c])
    {
      continue;
    }
    uint8_t cut = 0;
    for (int e = 0; e < 4; ++e)
    {
      const int32_t other = Across(halo, c, e);
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
  this->Emit(this->Tree.LeafLevel(), leaf, region, this->Tree.LeafLevel() > 0);
  this->WorkDone += static_cast<int64_t>(columns.size());
  this->Report(this->Phase, this->WorkStart + this->WorkSpan * static_cast<double>(this->WorkDone) / this->WorkTotal);
}

void Builder::BuildDiamond(const DiamondHierarchy::Diamond& diamond)
{
  const int childLevel = diamond.level + 1;
  std::vector<ScratchRegion> children;
  for (int64_t triangle : { diamond.first, diamond.second })
  {
    if (triangle < 0)
    {
      continue;
    }
    for (int64_t child : { 2 * triangle, 2 * triangle + 1 })
    {
      ScratchRegion region;
      const std::string path = RegionPath(this->Scratch.path, childLevel, child);
      if (LoadRegion(path, region))
      {
        unlink(path.c_str());
        children.push_back(std::move(region));
      }
    }
  }
  if (children.empty())
  {
    return;
  }
  // Merge: nodes the children share (never moved since they were split apart) are bitwise
  // equal, topological coordinate and whole vertex stack. Only nodes of different children
  // are joined: one child may hold two distinct nodes with equal data (where faults cross,
  // the diagonal columns at a pillar can agree while their edge neighbours do not).
  const int32_t layers = children.front().mesh.layers;
  const std::size_t interfaces = static_cast<std::size_t>(layers) + 1;
  ColumnMeshData merged;
  merged.layers = layers;
  std::vector<uint8_t> childCut, openSides;
  std::unordered_multimap<uint64_t, int32_t> nodeByKey;
  std::vector<int> nodeChild; // the last child a merged node was taken from
  int64_t inputColumns = 0;
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
          std::equal(stack, stack + interfaces * 3, &merged.positions[static_cast<std::size_t>(candidate) * interfaces * 3]))
        {
          found = candidate;
        }
      }
      if (found < 0)
      {
        found = static_cast<int32_t>(merged.topology.size());
        merged.topology.push_back(m.topology[n]);
        merged.positions.insert(merged.positions.end(), stack, stack + interfaces * 3);
        merged.quadrics.insert(merged.quadrics.end(), m.quadrics.begin() + n * interfaces,
          m.quadrics.begin() + (n + 1) * interfaces);
        nodeByKey.emplace(key, found);
        nodeChild.push_back(-1);
      }
      nodeChild[found] = static_cast<int>(which);
      map[n] = found;
    }
    for (std::size_t c = 0; c < m.corners.size(); ++c)
    {
      merged.corners.push_back({ map[m.corners[c][0]], map[m.corners[c][1]], map[m.corners[c][2]], map[m.corners[c][3]] });
    }
    merged.activeCells.insert(merged.activeCells.end(), m.activeCells.begin(), m.activeCells.end());
    merged.origin.insert(merged.origin.end(), m.origin.begin(), m.origin.end());
    childCut.insert(childCut.end(), child.cutEdges.begin(), child.cutEdges.end());
    openSides.insert(openSides.end(), child.openSides.begin(), child.openSides.end());
    inputColumns += m.ColumnCount();
  }
  children.clear();
  ColumnMesh mesh = ColumnMesh::FromData(std::move(merged));

  // Cut edges stay cut only where the merged mesh has no column across; their nodes border
  // another diamond and must not move, so every column touching one is locked.
  const int32_t slots = mesh.ColumnSlots();
  std::vector<uint8_t> external(static_cast<std::size_t>(mesh.NodeCount()), 0);
  for (int32_t c = 0; c < slots; ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      if ((childCut[c] & (1u << e)) && !mesh.IsBoundaryEdge(c, e))
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
  const int triangles = diamond.second >= 0 ? 2 : 1;
  const int64_t target = std::min<int64_t>(this->Options.cmax * triangles, (inputColumns + 1) / 2);
  if (mesh.AliveColumns() > target)
  {
    ColumnCollapse collapse(mesh, Mix(this->Options.seed ^ Mix(static_cast<uint64_t>(diamond.level) << 48 ^
                                                             static_cast<uint64_t>(diamond.first))));
    collapse.Simplify(target);
  }

  // Cut edges left are on the diamond's boundary, where columns are locked and unchanged.
  UpdateOpenSides(mesh, childCut, openSides);

  // Split along the diamond's hypotenuse by column centre.
  std::vector<uint8_t> side(static_cast<std::size_t>(slots), 0);
  for (int32_t c = 0; c < slots; ++c)
  {
    if (!mesh.IsColumnAlive(c))
    {
      continue;
    }
    double x = 0, y = 0;
    for (int32_t node : mesh.ColumnCorners(c))
    {
      for (int32_t k : { 0, layers })
      {
        const glm::dvec3 p = mesh.Position(node, k);
        x += p.x / 8;
        y += p.y / 8;
      }
    }
    side[c] = this->Tree.OnFirstSide(diamond, x, y) ? 1 : 2;
  }
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
        const int32_t other = Across(mesh, c, e);
        if (other >= 0 && side[other] != which)
        {
          cut |= static_cast<uint8_t>(1u << e);
        }
      }
      region.cutEdges.push_back(cut);
    }
    const int64_t index = which == 1 ? diamond.first : diamond.second;
    this->Emit(diamond.level, index, region, diamond.level > 0);
  }
  this->WorkDone += inputColumns;
  this->Report(this->Phase, this->WorkStart + this->WorkSpan * static_cast<double>(this->WorkDone) / this->WorkTotal);
}

double Seconds()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

HierarchyReport Builder::Run()
{
  HierarchyReport report;
  const double start = Seconds();
  const auto dims = this->Source.Dims();
  const int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  report.cells = nx * ny * nz;
  // Tiles of about 64 x 64 columns, fewer and bigger for very wide grids (at most ~1000 files).
  const int64_t tile = std::max<int64_t>(64, static_cast<int64_t>(std::ceil(std::sqrt(double(nx) * ny / 1000.0))));
  this->Partition.reset(new LeafPartition(this->Source, this->Scratch.path + "/tiles", tile,
    [this](double f) { this->Report("partition", 0.1 * f); }));
  report.partitionSeconds = Seconds() - start;
  report.activeCells = this->Partition->ActiveCells();

  // Hierarchy over the pillars' extent; leaves by column centre.
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
  if (this->Options.cmax == 0)
  {
    this->Options.cmax = AutomaticCmax(report.columns);
  }
  const int leafLevel = DiamondHierarchy::ChooseLeafLevel(codes, this->Options.cmax);
  this->Tree = DiamondHierarchy(extent[0], extent[1], extent[3], extent[4], leafLevel);
  report.leafLevel = leafLevel;
  std::sort(coded.begin(), coded.end());
  std::vector<std::pair<int64_t, std::vector<int64_t>>> leaves;
  for (const auto& entry : coded)
  {
    const int64_t leaf = static_cast<int64_t>(entry.first >> (DiamondHierarchy::MaxDepth - leafLevel));
    if (leaves.empty() || leaves.back().first != leaf)
    {
      leaves.push_back({ leaf, {} });
    }
    leaves.back().second.push_back(entry.second);
  }

  MultiresolutionHeader header;
  header.dims = dims;
  header.box = { extent[0], extent[1], extent[3], extent[4] };
  ChooseLattice(extent, header);
  header.leafLevel = leafLevel;
  header.cmax = static_cast<int32_t>(this->Options.cmax);
  this->Writer.reset(new MultiresolutionWriter(this->Output, header));

  // Work: leaf columns once, then the columns merged at each level (about halving).
  this->WorkTotal = std::max<int64_t>(1, report.columns);
  this->WorkStart = 0.1;
  this->WorkSpan = 0.1;
  this->Phase = "leaves";
  const double leafStart = Seconds();
  const int64_t vertexBytes = 24 + 80 + 40;
  const int64_t leafTask = (this->Options.cmax * 2) * (nz + 1) * vertexBytes * 2 + this->Options.cmax * 2 * nz * 40;
  const int leafThreads = this->ThreadsFor(leafTask);
  ParallelFor(static_cast<int64_t>(leaves.size()), leafThreads,
    [&](int64_t n) { this->BuildLeaf(leaves[static_cast<std::size_t>(n)].first, leaves[static_cast<std::size_t>(n)].second); });
  report.leafSeconds = Seconds() - leafStart;
  this->Partition.reset(); // tiles are no longer needed

  const double simplifyStart = Seconds();
  this->Phase = "simplify";
  this->WorkDone = 0;
  this->WorkTotal = std::max<int64_t>(1, 2 * report.columns);
  this->WorkStart = 0.2;
  this->WorkSpan = 0.8;
  const int64_t diamondTask = 4 * this->Options.cmax * (nz + 1) * vertexBytes * 3;
  const int diamondThreads = this->ThreadsFor(diamondTask);
  report.threadsUsed = std::max(leafThreads, diamondThreads);
  for (int level = leafLevel - 1; level >= 0; --level)
  {
    const auto diamonds = this->Tree.Diamonds(level);
    std::vector<DiamondHierarchy::Diamond> busy;
    for (const auto& d : diamonds)
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
    ParallelFor(static_cast<int64_t>(busy.size()), diamondThreads,
      [&](int64_t n) { this->BuildDiamond(busy[static_cast<std::size_t>(n)]); });
  }
  report.simplifySeconds = Seconds() - simplifyStart;

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
  std::vector<RegionRecord> records;
  for (const auto& entry : this->Records)
  {
    records.push_back(entry.second);
    report.nonEmptyRegions += entry.second.columns > 0 ? 1 : 0;
  }
  report.regions = static_cast<int64_t>(records.size());
  this->Writer->Commit(records);
  report.fileBytes = this->Writer->BytesWritten();
  report.totalSeconds = Seconds() - start;
  this->Report("done", 1.0);
  return report;
}
} // namespace

HierarchyReport BuildHierarchy(
  LayerSource& source, const std::string& output, const HierarchyOptions& options, const BuildProgress& progress)
{
  Builder builder(source, output, options, progress);
  return builder.Run();
}

} // namespace resmr
