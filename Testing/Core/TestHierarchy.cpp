// Tests of the multiresolution hierarchy and its file (paper Sec. 4.2, 4.3, 6.1, 6.2): the
// diamond tree, exact coverage of the original external faces at the finest level, crack-free
// conformal cuts, monotone errors and bounding volumes, thread-count independence,
// rejection of corrupt and truncated files, and MAPAXES carried in the header (older versions
// read as none, unknown ones refused).
#include "CoreTesting.h"
#include "FuzzResmrRepair.h"

#include "BuildSchedule.h"
#include "ColumnMesh.h"
#include "CornerPointGeometry.h"
#include "DiamondHierarchy.h"
#include "HierarchyBuilder.h"
#include "LayerSource.h"
#include "MultiresolutionFile.h"
#include "NormalQuantization.h"
#include "PerfectSpatialHash.h"
#include "RegionMesh.h"
#include "SyntheticReservoir.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <tuple>
#include <unistd.h>

using namespace resmr;

namespace
{
std::string TempPath(const std::string& name)
{
  return "/tmp/resmr-test-" + std::to_string(getpid()) + "-" + name;
}

SyntheticParameters SmallModel()
{
  SyntheticParameters p;
  p.nx = 60;
  p.ny = 48;
  p.nz = 6;
  p.seed = 3;
  return p;
}

/// `part` holds the cells and interfaces of `whole` from its first layer on, numbered from it,
/// and no stored surface unless it holds every layer.
bool SameAsWindow(const RegionMesh& whole, const RegionMesh& part)
{
  const int32_t first = part.firstLayer;
  bool same = part.topology == whole.topology && part.corners == whole.corners && part.cutEdges == whole.cutEdges &&
    first >= 0 && first + part.layers <= whole.layers &&
    part.positions.size() == std::size_t(whole.NodeCount()) * (part.layers + 1) * 3 &&
    part.active.size() == whole.corners.size() * std::size_t(part.layers) &&
    part.top.quads.empty() == (part.layers < whole.layers);
  for (std::size_t node = 0; same && node < std::size_t(whole.NodeCount()); ++node)
  {
    for (int32_t k = 0; k <= part.layers; ++k)
    {
      for (int a = 0; a < 3; ++a)
      {
        same = same &&
          part.positions[(node * (part.layers + 1) + k) * 3 + a] ==
            whole.positions[(node * (whole.layers + 1) + first + k) * 3 + a];
      }
    }
  }
  for (std::size_t c = 0; same && c < whole.corners.size(); ++c)
  {
    for (int32_t k = 0; k < part.layers; ++k)
    {
      same = same && part.active[c * part.layers + k] == whole.active[c * whole.layers + first + k] &&
        part.openSides[c * part.layers + k] == whole.openSides[c * whole.layers + first + k];
    }
  }
  return same;
}

void TestDiamondTree()
{
  const DiamondHierarchy tree(100, 200, 500, 400, 6);
  // Every triangle of a level is in exactly one diamond; mates share their hypotenuse.
  for (int level = 0; level <= 6; ++level)
  {
    const auto diamonds = tree.Diamonds(level);
    std::vector<int> seen(static_cast<std::size_t>(DiamondHierarchy::TriangleCount(level)), 0);
    for (const auto& d : diamonds)
    {
      ++seen[static_cast<std::size_t>(d.first)];
      if (d.second >= 0)
      {
        ++seen[static_cast<std::size_t>(d.second)];
        const auto a = tree.NormalisedTriangle(level, d.first), b = tree.NormalisedTriangle(level, d.second);
        CHECK(a.left == b.right && a.right == b.left);
      }
    }
    CHECK(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  }
  CHECK(tree.Diamonds(0).size() == 1 && tree.Diamonds(0)[0].second == 1);
  // Locate agrees with the triangles' areas: points sampled inside a triangle land in it, and
  // codes nest (the level-L triangle is the deep code shifted).
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int n = 0; n < 2000; ++n)
  {
    const int level = static_cast<int>(random() % 7);
    const int64_t index =
      static_cast<int64_t>(random() % static_cast<uint64_t>(DiamondHierarchy::TriangleCount(level)));
    const auto t = tree.ModelTriangle(level, index);
    double a = unit(random), b = unit(random);
    if (a + b > 1)
    {
      a = 1 - a;
      b = 1 - b;
    }
    a = 0.02 + 0.96 * a * 0.98;
    b = 0.02 + 0.96 * b * 0.98;
    const double x = t.apex[0] + a * (t.left[0] - t.apex[0]) + b * (t.right[0] - t.apex[0]);
    const double y = t.apex[1] + a * (t.left[1] - t.apex[1]) + b * (t.right[1] - t.apex[1]);
    CHECK(tree.Locate(x, y, level) == index);
    CHECK(static_cast<int64_t>(tree.Code(x, y) >> (DiamondHierarchy::MaxDepth - level)) == index);
  }
  // Leaf level: the shallowest with at most Cmax points a leaf.
  std::vector<uint64_t> codes;
  for (int n = 0; n < 1000; ++n)
  {
    codes.push_back(tree.Code(100 + 400 * unit(random), 200 + 200 * unit(random)));
  }
  const int level = DiamondHierarchy::ChooseLeafLevel(codes, 100);
  std::map<uint64_t, int> counts, coarser;
  for (uint64_t c : codes)
  {
    ++counts[c >> (DiamondHierarchy::MaxDepth - level)];
    ++coarser[c >> (DiamondHierarchy::MaxDepth - level + 1)];
  }
  int largest = 0, largestCoarser = 0;
  for (const auto& e : counts)
  {
    largest = std::max(largest, e.second);
  }
  for (const auto& e : coarser)
  {
    largestCoarser = std::max(largestCoarser, e.second);
  }
  CHECK(largest <= 100 && largestCoarser > 100);
}

/// A face named by its cell's topological corner coordinates and its outward direction in
/// (i, j, k) space: the same face of the same cell gives the same key at any level.
using FaceKey = std::tuple<std::array<std::array<double, 3>, 4>, std::array<int, 3>>;

FaceKey KeyOf(const RegionMesh& mesh, const std::array<uint32_t, 4>& quad)
{
  std::array<std::array<double, 3>, 4> corners;
  for (int v = 0; v < 4; ++v)
  {
    const uint32_t node = quad[v] / static_cast<uint32_t>(mesh.layers + 1);
    const uint32_t k = quad[v] % static_cast<uint32_t>(mesh.layers + 1);
    corners[v] = { mesh.topology[node][0], mesh.topology[node][1], static_cast<double>(k) };
  }
  std::array<double, 3> d1, d2;
  for (int a = 0; a < 3; ++a)
  {
    d1[a] = corners[2][a] - corners[0][a];
    d2[a] = corners[3][a] - corners[1][a];
  }
  const double n[3] = { d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0] };
  std::array<int, 3> direction{ (n[0] > 0) - (n[0] < 0), (n[1] > 0) - (n[1] < 0), (n[2] > 0) - (n[2] < 0) };
  std::sort(corners.begin(), corners.end());
  return { corners, direction };
}

std::multiset<FaceKey> FacesOf(const RegionMesh& mesh)
{
  std::multiset<FaceKey> faces;
  for (const RegionSurface* s : { &mesh.top, &mesh.bottom, &mesh.side })
  {
    for (const auto& q : s->quads)
    {
      faces.insert(KeyOf(mesh, q));
    }
  }
  return faces;
}

/// The original model's external faces, from one column mesh of the whole grid.
/// The original model as one region mesh, open sides and surfaces extracted.
RegionMesh OriginalMesh(const SyntheticParameters& p)
{
  SyntheticReservoir model(p);
  CornerPointModel deck;
  deck.dims = { p.nx, p.ny, p.nz };
  deck.coord = model.Coord();
  deck.zcornSingle.resize(static_cast<std::size_t>(8 * p.CellCount()));
  std::vector<bool> active(static_cast<std::size_t>(p.CellCount()));
  SyntheticLayerStream stream(model);
  SyntheticLayer layer;
  while (stream.Next(layer))
  {
    std::copy(layer.zcorn.begin(), layer.zcorn.end(), deck.zcornSingle.begin() + 8 * p.nx * p.ny * layer.k);
    for (int64_t c = 0; c < p.nx * p.ny; ++c)
    {
      active[static_cast<std::size_t>(layer.k * p.nx * p.ny + c)] = layer.state[c] == SyntheticCellState::Active;
    }
  }
  const CornerPointGeometry geometry = CornerPointGeometry::FromDeck(deck, false);
  const ColumnMesh whole = ColumnMesh::FromCornerPoints(geometry, active);
  const ColumnMeshData data = whole.Export();
  RegionMesh mesh;
  mesh.layers = data.layers;
  mesh.positions = data.positions;
  for (const auto& t : data.topology)
  {
    mesh.topology.push_back({ static_cast<float>(t[0]), static_cast<float>(t[1]) });
  }
  for (const auto& q : data.corners)
  {
    mesh.corners.push_back({ uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2]), uint32_t(q[3]) });
  }
  mesh.active = data.activeCells;
  mesh.cutEdges.assign(mesh.corners.size(), 0);
  ComputeOpenSides(mesh);
  ExtractSurfaces(mesh);
  return mesh;
}

std::multiset<FaceKey> OriginalFaces(const SyntheticParameters& p)
{
  return FacesOf(OriginalMesh(p));
}

/// A region's cut edges as (node data of a, node data of b) in the direction the region
/// walks them; a neighbour walks the same edge the other way. `fault`: the edge's side faces
/// are open (a fault between the two regions: the neighbour's nodes are on the same pillars
/// at other depths).
using NodeData = std::pair<std::array<float, 2>, std::vector<double>>;
struct CutEdge
{
  NodeData a, b;
  bool fault = false;
};

NodeData NodeOf(const RegionMesh& mesh, uint32_t node)
{
  const std::size_t interfaces = static_cast<std::size_t>(mesh.layers) + 1;
  return { mesh.topology[node],
    std::vector<double>(
      mesh.positions.begin() + node * interfaces * 3, mesh.positions.begin() + (node + 1) * interfaces * 3) };
}

std::vector<CutEdge> CutEdgesOf(const RegionMesh& mesh)
{
  std::vector<CutEdge> edges;
  const std::size_t layers = static_cast<std::size_t>(mesh.layers);
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      if (mesh.cutEdges[c] & (1u << e))
      {
        bool open = false;
        for (std::size_t k = 0; k < layers && c * layers + k < mesh.openSides.size(); ++k)
        {
          open = open || (mesh.openSides[c * layers + k] & (1u << e)) != 0;
        }
        edges.push_back({ NodeOf(mesh, mesh.corners[c][e]), NodeOf(mesh, mesh.corners[c][(e + 1) % 4]), open });
      }
    }
  }
  return edges;
}

/// A surface vertex by its data: topological coordinate and position, bit for bit.
using VertexData = std::array<double, 6>;

VertexData VertexOf(const RegionMesh& mesh, uint32_t vertex)
{
  const uint32_t node = vertex / static_cast<uint32_t>(mesh.layers + 1);
  const double* p = &mesh.positions[static_cast<std::size_t>(vertex) * 3];
  return { mesh.topology[node][0], mesh.topology[node][1], double(vertex % static_cast<uint32_t>(mesh.layers + 1)),
    p[0], p[1], p[2] };
}

/// A region of the file, read once into `cache`; null if the file has none of that index.
const RegionMesh* CachedRegion(const MultiresolutionFile& file, const std::pair<int, int64_t>& region,
  std::map<std::pair<int, int64_t>, RegionMesh>& cache)
{
  const RegionRecord* record = file.Find(region.first, region.second);
  if (!record)
  {
    return nullptr;
  }
  auto found = cache.find(region);
  if (found == cache.end())
  {
    found = cache.emplace(region, file.ReadRegion(static_cast<std::size_t>(record - file.Regions().data()))).first;
  }
  return &found->second;
}

/// Two checks that the cut has no crack. (1) Every cut edge of every region is walked the
/// other way by another region of the cut, with bitwise equal nodes, or, where a fault runs
/// between the two regions, on the same pillars with both sides' faces open. (2) Independently of
/// the cut flags: the external surfaces of all regions of the cut, joined by vertex data, are
/// closed (every directed edge is matched by one walked the other way), as the original
/// model's surface is. Returns the cut edges checked.
int64_t CheckCut(const MultiresolutionFile& file, const std::set<std::pair<int, int64_t>>& cut,
  std::map<std::pair<int, int64_t>, RegionMesh>& cache, const std::string& label)
{
  // Cut edges waiting for their match, by their nodes' topological coordinates.
  std::multimap<std::pair<std::array<float, 2>, std::array<float, 2>>, CutEdge> open;
  int64_t unmatched = 0;
  std::map<std::pair<VertexData, VertexData>, int> balance;
  int64_t checked = 0;
  for (const auto& region : cut)
  {
    const RegionMesh* found = CachedRegion(file, region, cache);
    if (!found)
    {
      continue;
    }
    for (const CutEdge& edge : CutEdgesOf(*found))
    {
      const auto match = open.find({ edge.b.first, edge.a.first });
      if (match == open.end())
      {
        open.insert({ { edge.a.first, edge.b.first }, edge });
      }
      else
      {
        const CutEdge& other = match->second;
        const bool same = other.a == edge.b && other.b == edge.a;
        unmatched += !same && !(edge.fault && other.fault);
        open.erase(match);
      }
      ++checked;
    }
    const RegionMesh& mesh = *found;
    // Top and bottom quads and the simplified side triangles, as the file holds them.
    std::vector<std::vector<uint32_t>> polygons;
    for (const RegionSurface* s : { &mesh.top, &mesh.bottom })
    {
      for (const auto& q : s->quads)
      {
        polygons.push_back({ q[0], q[1], q[2], q[3] });
      }
    }
    for (const auto& t : mesh.sideTriangles)
    {
      polygons.push_back({ t[0], t[1], t[2] });
    }
    {
      for (const auto& q : polygons)
      {
        for (std::size_t v = 0; v < q.size(); ++v)
        {
          // By position: a zero-area triangle between two vertices at one place (a pinched
          // cell's side) is left out of the side surface, which leaves no gap in space.
          VertexData a = VertexOf(mesh, q[v]), b = VertexOf(mesh, q[(v + 1) % q.size()]);
          a[0] = a[1] = a[2] = b[0] = b[1] = b[2] = 0;
          if (a == b)
          {
            continue; // an edge of no length (pinched cell) cannot open a crack
          }
          if (a < b)
          {
            ++balance[{ a, b }];
          }
          else
          {
            --balance[{ b, a }];
          }
        }
      }
    }
  }
  int64_t unbalanced = 0;
  for (const auto& entry : balance)
  {
    unbalanced += entry.second != 0;
    if (entry.second != 0 && getenv("DEBUG_OPEN"))
    {
      const auto& a = entry.first.first;
      const auto& b = entry.first.second;
      std::fprintf(stderr, "  open %d: (%g %g %g | %.3f %.3f %.3f) - (%g %g %g | %.3f %.3f %.3f)\n", entry.second, a[0],
        a[1], a[2], a[3], a[4], a[5], b[0], b[1], b[2], b[3], b[4], b[5]);
    }
  }
  if (unbalanced)
  {
    std::fprintf(stderr, "%s: %lld surface edges open\n", label.c_str(), static_cast<long long>(unbalanced));
  }
  CHECK(unbalanced == 0 && !balance.empty());
  if (!open.empty() || unmatched)
  {
    std::fprintf(stderr, "%s: %zu cut edges without their match, %lld matched by another edge\n", label.c_str(),
      open.size(), static_cast<long long>(unmatched));
  }
  CHECK(open.empty() && unmatched == 0);
  return checked;
}

/// The boundary nodes of a cut's regions (nodes on an edge only one column of their region
/// has), by topological coordinate: the distinct positions found there. Two or more at one
/// pillar are a fault's sides (nodes a region border shares are the same node twice).
using Pillar = std::array<float, 2>;
using PillarEdges = std::set<std::pair<Pillar, Pillar>>;

std::map<std::array<float, 2>, std::set<std::vector<double>>> BoundaryPillars(const MultiresolutionFile& file,
  const std::set<std::pair<int, int64_t>>& cut, std::map<std::pair<int, int64_t>, RegionMesh>& cache,
  PillarEdges* walked = nullptr)
{
  std::map<std::array<float, 2>, std::set<std::vector<double>>> pillars;
  for (const auto& region : cut)
  {
    const RegionMesh* found = CachedRegion(file, region, cache);
    if (!found)
    {
      continue;
    }
    const RegionMesh& mesh = *found;
    std::map<std::pair<uint32_t, uint32_t>, int> uses;
    for (const auto& q : mesh.corners)
    {
      for (int e = 0; e < 4; ++e)
      {
        const uint32_t a = q[e], b = q[(e + 1) % 4];
        ++uses[{ std::min(a, b), std::max(a, b) }];
      }
    }
    for (const auto& edge : uses)
    {
      for (uint32_t node : { edge.first.first, edge.first.second })
      {
        if (edge.second == 1)
        {
          pillars[mesh.topology[node]].insert(NodeOf(mesh, node).second);
        }
      }
    }
    for (const auto& q : mesh.corners)
    {
      for (int e = 0; walked && e < 4; ++e)
      {
        const uint32_t a = q[e], b = q[(e + 1) % 4];
        if (uses[{ std::min(a, b), std::max(a, b) }] == 1)
        {
          walked->insert({ mesh.topology[a], mesh.topology[b] });
        }
      }
    }
  }
  return pillars;
}

/// Every fault of the finest level (`faults`: pillars with two sides there) keeps both sides
/// wherever the cut has either: a side simplified on its own leaves the other alone at the
/// pillar, and the two part (a gap one sees through). With `outline` (the finest level's
/// outline pillars), a fault may also be welded: one node at the pillar, whose boundary edges
/// (where a weld meets a kept stretch of the fault) each have the other side's edge between
/// the same pillars; pillars on the outline are left out. Returns the pillars checked.
int64_t CheckFaultsWhole(const MultiresolutionFile& file, const std::set<std::pair<int, int64_t>>& cut,
  std::map<std::pair<int, int64_t>, RegionMesh>& cache, const std::set<std::array<float, 2>>& faults,
  const std::string& label, const std::set<Pillar>* outline = nullptr)
{
  int64_t checked = 0, alone = 0;
  PillarEdges walked;
  for (const auto& pillar : BoundaryPillars(file, cut, cache, &walked))
  {
    if (faults.count(pillar.first) && !(outline && outline->count(pillar.first)))
    {
      ++checked;
      bool partnered = outline != nullptr;
      for (const auto& edge : walked)
      {
        if (edge.first == pillar.first || edge.second == pillar.first)
        {
          partnered = partnered && walked.count({ edge.second, edge.first });
        }
      }
      alone += pillar.second.size() < 2 && !partnered;
      if (pillar.second.size() < 2 && !partnered && getenv("DEBUG_ALONE"))
      {
        std::fprintf(stderr, " alone (%g %g):", pillar.first[0], pillar.first[1]);
        for (const auto& edge : walked)
        {
          if (edge.first == pillar.first || edge.second == pillar.first)
          {
            std::fprintf(stderr, " (%g %g)->(%g %g)%s", edge.first[0], edge.first[1], edge.second[0], edge.second[1],
              walked.count({ edge.second, edge.first }) ? "=" : "!");
          }
        }
        std::fprintf(stderr, "\n");
      }
    }
  }
  if (alone)
  {
    std::fprintf(stderr, "%s: %lld of %lld fault pillars with one side only\n", label.c_str(),
      static_cast<long long>(alone), static_cast<long long>(checked));
  }
  CHECK(alone == 0);
  return checked;
}

/// A conformal cut: 40 random splits of diamonds whose triangles are all in the cut, from the
/// roots.
std::set<std::pair<int, int64_t>> RandomCut(const DiamondHierarchy& tree, int leafLevel, std::mt19937_64& random)
{
  std::set<std::pair<int, int64_t>> cut{ { 0, 0 }, { 0, 1 } };
  for (int step = 0; step < 40; ++step)
  {
    std::vector<DiamondHierarchy::Diamond> splittable;
    for (int level = 0; level < leafLevel; ++level)
    {
      for (const auto& d : tree.Diamonds(level))
      {
        if (cut.count({ level, d.first }) && (d.second < 0 || cut.count({ level, d.second })))
        {
          splittable.push_back(d);
        }
      }
    }
    if (splittable.empty())
    {
      break;
    }
    const auto& d = splittable[random() % splittable.size()];
    for (int64_t t : { d.first, d.second })
    {
      if (t >= 0)
      {
        cut.erase({ d.level, t });
        cut.insert({ d.level + 1, 2 * t });
        cut.insert({ d.level + 1, 2 * t + 1 });
      }
    }
  }
  return cut;
}

std::set<std::pair<int, int64_t>> LevelCut(int level)
{
  std::set<std::pair<int, int64_t>> cut;
  for (int64_t t = 0; t < DiamondHierarchy::TriangleCount(level); ++t)
  {
    cut.insert({ level, t });
  }
  return cut;
}

/// Options for the small model: Cmax 64, two threads.
HierarchyOptions SmallOptions()
{
  HierarchyOptions options;
  options.cmax = 64;
  options.threads = 2;
  return options;
}

/// Layer groups (format version 10): a window decodes the groups it reaches and no other, each
/// window across the groups' borders equal to the whole mesh sliced.
void TestLayerGroups()
{
  SyntheticParameters p;
  p.nx = 24;
  p.ny = 20;
  p.nz = 20; // 21 interfaces: groups of 8, 8 and 5
  p.seed = 5;
  const std::string path = TempPath("groups.resmr");
  HierarchyOptions options = SmallOptions();
  SyntheticLayerSource source(p, "synth:groups");
  BuildHierarchy(source, path, options);
  std::string bytes;
  {
    const MultiresolutionFile file(path);
    CHECK(file.Header().version == MultiresolutionHeader::LayerGroupsVersion);
    for (std::size_t i = 0; i < file.Regions().size(); ++i)
    {
      const RegionRecord& r = file.Regions()[i];
      // Written back to back just before the mesh chunk.
      CHECK(r.layerGroups > 0 && r.layerGroups < r.chunks[RegionRecord::Mesh].offset);
      const RegionMesh whole = file.ReadRegion(i);
      for (const std::array<int32_t, 2> window : { std::array<int32_t, 2>{ 0, 6 }, { 6, 7 }, { 7, 8 }, { 8, 8 },
             { 14, 16 }, { 16, 19 }, { 19, 19 }, { 3, 17 }, { 20, 25 } })
      {
        const RegionMesh part = file.ReadRegionLayers(i, window[0], window[1]);
        CHECK(part.firstLayer == std::min(window[0], 20) && SameAsWindow(whole, part));
      }
    }
    std::ifstream in(path, std::ios::binary);
    bytes.assign((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  // The last group (interfaces 16 to 20) damaged: windows above it still read, whole.
  const MultiresolutionFile clean(path);
  const RegionRecord& victim = clean.Regions().front();
  bytes[victim.chunks[RegionRecord::Mesh].offset - 3] ^= 0x5a;
  const std::string damaged = TempPath("groups-damaged.resmr");
  {
    std::ofstream out(damaged, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const MultiresolutionFile file(damaged);
  const RegionMesh whole = clean.ReadRegion(0);
  CHECK(SameAsWindow(whole, file.ReadRegionLayers(0, 0, 14)));
  CHECK(SameAsWindow(whole, file.ReadRegionLayers(0, 8, 9)));
  resmr_testing::ExpectError<FileFormatError>("damaged layer group", [&] { file.ReadRegion(0); },
    { damaged, "level " + std::to_string(victim.level), "mesh layer group 2", "checksum" });
  resmr_testing::ExpectError<FileFormatError>("window in a damaged layer group",
    [&] { file.ReadRegionLayers(0, 15, 16); }, { damaged, "mesh layer group 2", "checksum" });
}

void TestHierarchyFile()
{
  const SyntheticParameters p = SmallModel();
  const std::string path = TempPath("small.resmr");
  HierarchyOptions options = SmallOptions();
  SyntheticLayerSource source(p, "synth:small");
  const HierarchyReport report = BuildHierarchy(source, path, options);
  CHECK(report.leafLevel >= 4);
  const MultiresolutionFile file(path);
  CHECK(file.Header().dims == (std::array<int64_t, 3>{ p.nx, p.ny, p.nz }));
  CHECK(file.Header().leafLevel == report.leafLevel);

  // Finest level: exactly the original model's external faces, each once.
  std::multiset<FaceKey> leafFaces;
  int64_t leafColumns = 0;
  std::map<int, int64_t> columnsAtLevel, faultColumnsAtLevel;
  for (std::size_t i = 0; i < file.Regions().size(); ++i)
  {
    const RegionRecord& r = file.Regions()[i];
    columnsAtLevel[r.level] += r.columns;
    if (r.level != report.leafLevel)
    {
      // Coarse regions keep every fault's columns whole (and the columns beside them, which
      // cannot collapse into them: at most as many again); Cmax bounds the rest.
      const RegionMesh mesh = file.ReadRegion(i);
      std::map<std::array<float, 2>, int> sharing;
      for (const auto& t : mesh.topology)
      {
        ++sharing[{ t[0], t[1] }];
      }
      int64_t faultColumns = 0;
      for (const auto& q : mesh.corners)
      {
        faultColumns += std::any_of(q.begin(), q.end(), [&](uint32_t node) {
          return sharing[{ mesh.topology[node][0], mesh.topology[node][1] }] > 1;
        });
      }
      CHECK(r.columns <= options.cmax + 2 * faultColumns);
      faultColumnsAtLevel[r.level] += faultColumns;
    }
    if (r.level == report.leafLevel)
    {
      RegionMesh mesh = file.ReadRegion(i);
      ExtractSurfaces(mesh); // side quads are derived, not stored
      const auto faces = FacesOf(mesh);
      leafFaces.insert(faces.begin(), faces.end());
      leafColumns += mesh.ColumnCount();
    }
  }
  // A window of layers decodes the same cells and interfaces as the whole mesh, numbered from
  // the window's first layer; no stored surface.
  for (std::size_t i = 0; i < file.Regions().size(); i += 3)
  {
    const RegionMesh whole = file.ReadRegion(i);
    const int32_t nz = int32_t(p.nz);
    for (const std::array<int32_t, 2> window :
      { std::array<int32_t, 2>{ 0, 0 }, { 1, nz - 2 }, { nz - 1, nz - 1 }, { 2, 3 }, { -5, nz + 5 } })
    {
      const RegionMesh part = file.ReadRegionLayers(i, window[0], window[1]);
      const int32_t first = std::max(window[0], 0), last = std::min(window[1], nz - 1);
      CHECK(part.firstLayer == first && part.layers == last - first + 1);
      CHECK(SameAsWindow(whole, part));
    }
  }
  const auto original = OriginalFaces(p);
  CHECK(leafColumns == report.columns);
  CHECK(!original.empty());
  CHECK(leafFaces == original);
  if (leafFaces != original)
  {
    std::fprintf(stderr, "finest level: %zu faces, original %zu\n", leafFaces.size(), original.size());
  }
  // Property side (Sec. 5.3-5.4): active flags per layer, the perfect hash of the touched
  // cells, and their normals.
  {
    const auto& h = file.Header();
    int64_t activeCells = 0;
    std::vector<std::vector<uint8_t>> activeLayers;
    for (int64_t k = 0; k < p.nz; ++k)
    {
      activeLayers.push_back(file.ReadActiveLayer(k));
      for (uint8_t a : activeLayers.back())
      {
        activeCells += a;
      }
    }
    CHECK(activeCells == report.activeCells);
    const PerfectSpatialHash hash = file.ReadHash();
    const auto cellBytes = file.ReadModelArray(ModelChunk::HashCells);
    const auto normalBytes = file.ReadModelArray(ModelChunk::CellNormals);
    CHECK(cellBytes.size() == hash.TableSize() * 8 && normalBytes.size() == hash.TableSize() * 4);
    std::vector<uint64_t> slotCell(cellBytes.size() / 8);
    std::memcpy(slotCell.data(), cellBytes.data(), cellBytes.size());
    int64_t filled = 0, tops = 0, upward = 0;
    std::set<uint64_t> hashedCells;
    for (std::size_t slot = 0; slot < slotCell.size(); ++slot)
    {
      const uint64_t n = slotCell[slot];
      if (n == ~uint64_t(0))
      {
        continue;
      }
      ++filled;
      hashedCells.insert(n);
      const uint32_t i = uint32_t(n % uint64_t(p.nx)), j = uint32_t(n / uint64_t(p.nx) % uint64_t(p.ny)),
                     k = uint32_t(n / uint64_t(p.nx * p.ny));
      CHECK(hash.Slot(i, j, k) == slot); // the hash finds every cell where its data lies
      uint16_t codes[2];
      std::memcpy(codes, &normalBytes[slot * 4], 4);
      const auto top = DecodeUnitNormal(codes[0]), bottom = DecodeUnitNormal(codes[1]);
      if (!activeLayers[k][i + uint32_t(p.nx) * j])
      {
        continue; // never shown
      }
      ++tops;
      upward += top[2] > 0 && bottom[2] < 0;
    }
    CHECK(filled == static_cast<int64_t>(h.hashedCells) && filled > 0);
    if (upward != tops)
    {
      std::fprintf(stderr, "%lld of %lld cells have a top normal down or a bottom normal up\n",
        static_cast<long long>(tops - upward), static_cast<long long>(tops));
    }
    CHECK(upward == tops); // top normals look up, bottom normals down
    // Every cell under a top face and over a bottom face of the finest level is hashed.
    int64_t missing = 0;
    for (std::size_t i = 0; i < file.Regions().size(); ++i)
    {
      if (file.Regions()[i].level != report.leafLevel)
      {
        continue;
      }
      const RegionMesh mesh = file.ReadRegion(i);
      const uint32_t interfaces = uint32_t(mesh.layers + 1);
      for (int which = 0; which < 2; ++which)
      {
        for (const auto& q : (which ? mesh.bottom : mesh.top).quads)
        {
          double ti = 0, tj = 0;
          for (uint32_t v : q)
          {
            ti += mesh.topology[v / interfaces][0] / 4;
            tj += mesh.topology[v / interfaces][1] / 4;
          }
          const uint64_t k = q[0] % interfaces - (which ? 1 : 0);
          const uint64_t n =
            uint64_t(std::floor(ti)) + uint64_t(p.nx) * (uint64_t(std::floor(tj)) + uint64_t(p.ny) * k);
          missing += hashedCells.count(n) == 0;
        }
      }
    }
    CHECK(missing == 0);
    // Packed: the table holds few empty slots (Sec. 5.4; target 1.25 x the cells).
    std::fprintf(stderr, "hash: %lld cells in %llu slots (%ux%ux%u), offsets %llu\n", static_cast<long long>(filled),
      static_cast<unsigned long long>(hash.TableSize()), hash.tableSides[0], hash.tableSides[1], hash.tableSides[2],
      static_cast<unsigned long long>(hash.OffsetTableSize()));
    CHECK(double(hash.TableSize()) <= 1.25 * double(filled));
  }

  // Each level keeps about half the columns of the one below, beyond the fault columns every
  // level keeps (and those beside them): locked diamond boundaries keep more where regions
  // are small, as here (64 columns), so all levels above the leaves together hold at most
  // 1.2 times the leaves' columns beyond those (1 for exact halving).
  int64_t above = 0, kept = 0;
  for (int level = 0; level < report.leafLevel; ++level)
  {
    std::fprintf(stderr, "level %d: %lld columns, %lld along faults\n", level,
      static_cast<long long>(columnsAtLevel[level]), static_cast<long long>(faultColumnsAtLevel[level]));
    CHECK(columnsAtLevel[level] - 2 * faultColumnsAtLevel[level] <= 0.7 * columnsAtLevel[level + 1]);
    above += columnsAtLevel[level];
    kept += 2 * faultColumnsAtLevel[level];
  }
  CHECK(above - kept <= 1.2 * columnsAtLevel[report.leafLevel]);

  // Errors and bounding volumes: equal within a diamond, monotone up the tree.
  const DiamondHierarchy tree(
    file.Header().box[0], file.Header().box[1], file.Header().box[2], file.Header().box[3], file.Header().leafLevel);
  int64_t pairs = 0;
  for (const RegionRecord& r : file.Regions())
  {
    if (r.level > 0)
    {
      const RegionRecord* parent = file.Find(r.level - 1, r.index / 2);
      CHECK(parent != nullptr);
      if (parent)
      {
        CHECK(parent->error >= r.error);
        for (int a = 0; a < 3; ++a)
        {
          CHECK(parent->bounds[a] <= r.bounds[a] && parent->bounds[3 + a] >= r.bounds[3 + a]);
        }
        ++pairs;
      }
    }
  }
  CHECK(pairs > 10);
  for (int level = 0; level <= report.leafLevel; ++level)
  {
    for (const auto& d : tree.Diamonds(level))
    {
      const RegionRecord* a = file.Find(level, d.first);
      const RegionRecord* b = d.second >= 0 ? file.Find(level, d.second) : nullptr;
      if (a && b)
      {
        CHECK(a->error == b->error && a->bounds == b->bounds);
      }
    }
  }
  CHECK(file.Find(0, 0) && file.Find(0, 0)->error > 0);

  // Conformal cuts: every level whole, and random diamond splits from the roots; the faults
  // of the finest level keep both sides in each (the faults' columns are kept at every level
  // of a model this small).
  std::map<std::pair<int, int64_t>, RegionMesh> cache;
  const auto levelCut = LevelCut;
  std::set<std::array<float, 2>> faults;
  for (const auto& pillar : BoundaryPillars(file, levelCut(report.leafLevel), cache))
  {
    if (pillar.second.size() >= 2)
    {
      faults.insert(pillar.first);
    }
  }
  std::printf("%zu fault pillars at the finest level\n", faults.size());
  CHECK(faults.size() > 50);
  int64_t edges = 0, pillars = 0;
  for (int level = 0; level <= report.leafLevel; ++level)
  {
    const std::set<std::pair<int, int64_t>> cut = levelCut(level);
    edges += CheckCut(file, cut, cache, "level " + std::to_string(level));
    pillars += CheckFaultsWhole(file, cut, cache, faults, "level " + std::to_string(level));
  }
  std::mt19937_64 random(11);
  for (int trial = 0; trial < 12; ++trial)
  {
    const std::set<std::pair<int, int64_t>> cut = RandomCut(tree, report.leafLevel, random);
    edges += CheckCut(file, cut, cache, "random cut " + std::to_string(trial));
    pillars += CheckFaultsWhole(file, cut, cache, faults, "random cut " + std::to_string(trial));
  }
  CHECK(edges > 100 && pillars > 1000);

  // Thread count changes nothing but the chunks' order.
  const std::string single = TempPath("single.resmr");
  options.threads = 1;
  SyntheticLayerSource again(p, "synth:small");
  BuildHierarchy(again, single, options);
  const MultiresolutionFile other(single);
  CHECK(other.Regions().size() == file.Regions().size());
  for (std::size_t i = 0; i < file.Regions().size(); ++i)
  {
    const RegionRecord& r = file.Regions()[i];
    const RegionRecord* s = other.Find(r.level, r.index);
    CHECK(s && s->error == r.error && s->bounds == r.bounds && s->columns == r.columns);
    if (s && r.level >= report.leafLevel - 2)
    {
      const RegionMesh a = file.ReadRegion(i);
      const RegionMesh b = other.ReadRegion(static_cast<std::size_t>(s - other.Regions().data()));
      CHECK(a.positions == b.positions && a.corners == b.corners && a.active == b.active && a.cutEdges == b.cutEdges);
    }
  }
  std::remove(single.c_str());

  // Damaged files are refused with the file and the place named.
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string damaged = TempPath("damaged.resmr");
  const auto writeBytes = [&](const std::string& content) {
    std::ofstream out(damaged, std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
  };
  writeBytes(bytes.substr(0, bytes.size() - 100));
  resmr_testing::ExpectError<FileFormatError>(
    "truncated", [&] { MultiresolutionFile f(damaged); }, { damaged, "truncated" });
  writeBytes(bytes.substr(0, 100));
  resmr_testing::ExpectError<FileFormatError>(
    "stub", [&] { MultiresolutionFile f(damaged); }, { damaged, "too short" });
  std::string flipped = bytes;
  const RegionRecord& victim = file.Regions()[file.Regions().size() / 2];
  flipped[victim.chunks[RegionRecord::Mesh].offset + victim.chunks[RegionRecord::Mesh].stored / 2] ^= 0x5a;
  writeBytes(flipped);
  {
    const MultiresolutionFile f(damaged); // the index is intact: opening works, the chunk does not
    const std::size_t at = file.Regions().size() / 2;
    resmr_testing::ExpectError<FileFormatError>("flipped chunk", [&] { f.ReadRegion(at); },
      { damaged, "level " + std::to_string(victim.level), "mesh", "checksum" });
  }
  flipped = bytes;
  flipped[bytes.size() - 32 - 192 + 20] ^= 0x01; // inside the last index record
  writeBytes(flipped);
  resmr_testing::ExpectError<FileFormatError>(
    "flipped index", [&] { MultiresolutionFile f(damaged); }, { damaged, "index checksum" });
  flipped = bytes;
  flipped[40] ^= 0x10;
  writeBytes(flipped);
  resmr_testing::ExpectError<FileFormatError>(
    "flipped header", [&] { MultiresolutionFile f(damaged); }, { damaged, "header checksum" });
  writeBytes("GRDECL file, not ours " + std::string(400, ' '));
  resmr_testing::ExpectError<FileFormatError>(
    "not ours", [&] { MultiresolutionFile f(damaged); }, { damaged, "not a multiresolution" });
  std::remove(damaged.c_str());
  std::remove(path.c_str());
}

/// Faults too long to keep whole (here every fault: `faultColumns` 1) weld at the coarse
/// levels. Every level and random cut stays closed and crack-free, no fault side stands alone
/// (no gap), and a welded pillar's region counts half the throw there in its error.
/// The wall depth table holds every wall face of the original grid, each with its corners'
/// interface depths and nearest open cells; a damaged table is an error naming it.
void TestWallDepths()
{
  SyntheticParameters p = SmallModel();
  p.nz = 12;
  const std::string path = TempPath("walls.resmr");
  SyntheticLayerSource source(p, "synth:walls");
  const HierarchyReport report = BuildHierarchy(source, path, SmallOptions());
  const MultiresolutionFile file(path);
  const WallDepthTable table = file.ReadWallDepths();
  const RegionMesh original = OriginalMesh(p);
  std::vector<WallFace> expected;
  CollectWallFaces(original, p.nx, expected);
  CHECK(!expected.empty() && table.faces == expected.size() && report.wallFaces == expected.size());
  CHECK(table.layers == p.nz);
  int64_t outline = 0, faultFaces = 0, mismatched = 0;
  for (const WallFace& f : expected)
  {
    const uint32_t column = (f.key - 1) / 4, face = (f.key - 1) % 4;
    const uint32_t i = column % uint32_t(p.nx), j = column / uint32_t(p.nx);
    const bool onOutline = (face == 0 && i == 0) || (face == 1 && i + 1 == uint32_t(p.nx)) || (face == 2 && j == 0) ||
      (face == 3 && j + 1 == uint32_t(p.ny));
    (onOutline ? outline : faultFaces) += 1;
    const std::size_t slot = static_cast<std::size_t>(table.hash.Slot(i, j, face));
    const float* texel = &table.texels[table.slots[slot][1] * std::size_t(p.nz + 1) * 3];
    bool same = table.slots[slot][0] == f.key;
    const double step = file.Header().latticeStep[2]; // the file's positions are on its lattice
    for (int64_t k = 0; same && k <= p.nz; ++k)
    {
      same = std::fabs(texel[3 * k] - f.depthA[k]) <= step && std::fabs(texel[3 * k + 1] - f.depthB[k]) <= step &&
        texel[3 * k + 2] == float(f.open[std::min<int64_t>(k, p.nz - 1)]);
    }
    mismatched += same ? 0 : 1;
  }
  CHECK(mismatched == 0);
  CHECK(outline > 0 && faultFaces > 0); // the small model has faults
  // Depths grow down a face; a nearest open cell is open: active, with this side open.
  int64_t badOrder = 0;
  for (const WallFace& f : expected)
  {
    for (std::size_t k = 0; k + 1 < f.depthA.size(); ++k)
    {
      badOrder += f.depthA[k] > f.depthA[k + 1] || f.depthB[k] > f.depthB[k + 1] ? 1 : 0;
    }
  }
  CHECK(badOrder == 0);
  // Damaged: cut short, or a cell out of range.
  auto bytes = EncodeWallDepthTable(table);
  resmr_testing::ExpectError<FileFormatError>("short wall table",
    [&] { DecodeWallDepthTable(std::vector<uint8_t>(bytes.begin(), bytes.end() - 4), file.Header().dims, "walls"); },
    { "walls", "corrupt" });
  float big = 1e9f;
  std::memcpy(&bytes[bytes.size() - 4], &big, 4);
  resmr_testing::ExpectError<FileFormatError>("wall cell out of range",
    [&] { DecodeWallDepthTable(bytes, file.Header().dims, "walls"); }, { "walls", "out of range" });
  std::remove(path.c_str());
}

void TestWeldedFaults()
{
  const std::string path = TempPath("welded.resmr");
  HierarchyOptions options = SmallOptions();
  options.faultColumns = 1;
  SyntheticLayerSource source(SmallModel(), "synth:small");
  const HierarchyReport report = BuildHierarchy(source, path, options);
  const MultiresolutionFile file(path);
  std::map<std::pair<int, int64_t>, RegionMesh> cache;
  PillarEdges walked;
  std::set<Pillar> faults, outline;
  std::map<Pillar, double> halfThrow;
  for (const auto& pillar : BoundaryPillars(file, LevelCut(report.leafLevel), cache, &walked))
  {
    if (pillar.second.size() >= 2)
    {
      faults.insert(pillar.first);
    }
    if (pillar.second.size() == 2)
    {
      const std::vector<double>& a = *pillar.second.begin();
      const std::vector<double>& b = *pillar.second.rbegin();
      double& half = halfThrow[pillar.first];
      for (std::size_t v = 0; v < a.size(); v += 3)
      {
        half = std::max(half, std::hypot(a[v] - b[v], a[v + 1] - b[v + 1], a[v + 2] - b[v + 2]) / 2);
      }
    }
  }
  for (const auto& edge : walked)
  {
    if (!walked.count({ edge.second, edge.first }))
    {
      outline.insert(edge.first);
      outline.insert(edge.second);
    }
  }
  CHECK(faults.size() > 50);
  const auto& step = file.Header().latticeStep;
  const double rounding = std::hypot(step[0], step[1], step[2]);
  int64_t welded = 0, pillars = 0, underrated = 0;
  for (int level = 0; level < report.leafLevel; ++level)
  {
    const std::string label = "welded, level " + std::to_string(level);
    const auto cut = LevelCut(level);
    CheckCut(file, cut, cache, label);
    pillars += CheckFaultsWhole(file, cut, cache, faults, label, &outline);
    for (const auto& region : cut)
    {
      const RegionMesh* mesh = CachedRegion(file, region, cache);
      if (!mesh)
      {
        continue;
      }
      std::map<std::pair<uint32_t, uint32_t>, int> uses;
      for (const auto& q : mesh->corners)
      {
        for (int e = 0; e < 4; ++e)
        {
          ++uses[{ std::min(q[e], q[(e + 1) % 4]), std::max(q[e], q[(e + 1) % 4]) }];
        }
      }
      std::set<uint32_t> boundary;
      for (const auto& edge : uses)
      {
        if (edge.second == 1)
        {
          boundary.insert({ edge.first.first, edge.first.second });
        }
      }
      const float error = file.Find(region.first, region.second)->error;
      for (uint32_t node = 0; node < mesh->topology.size(); ++node)
      {
        const auto found = halfThrow.find(mesh->topology[node]);
        if (found != halfThrow.end() && !boundary.count(node))
        {
          ++welded;
          underrated += error < found->second - rounding;
        }
      }
    }
  }
  std::printf("welded: %lld fault nodes inside their regions, %lld pillars checked\n", static_cast<long long>(welded),
    static_cast<long long>(pillars));
  CHECK(welded > 20 && pillars > 20);
  CHECK(underrated == 0);
  const DiamondHierarchy tree(
    file.Header().box[0], file.Header().box[1], file.Header().box[2], file.Header().box[3], file.Header().leafLevel);
  std::mt19937_64 random(12);
  for (int trial = 0; trial < 12; ++trial)
  {
    const auto cut = RandomCut(tree, report.leafLevel, random);
    CheckCut(file, cut, cache, "welded, random cut " + std::to_string(trial));
    CheckFaultsWhole(file, cut, cache, faults, "welded, random cut " + std::to_string(trial), &outline);
  }
  std::remove(path.c_str());
}

/// A small Cartesian deck with `placement` (MAPUNITS, MAPAXES, GRIDUNIT records) written at `path`.
void WriteMapDeck(const std::string& path, const std::string& placement)
{
  std::ofstream out(path);
  out << "RUNSPEC\nDIMENS\n 12 10 3 /\nGRID\n"
      << placement << "DX\n 360*50 /\nDY\n 360*40 /\nDZ\n 360*5 /\nTOPS\n 120*1500 /\nACTNUM\n 300*1 60*0 /\n";
}

/// Bytes of `bytes` with the header's CRC made right again.
std::string WithHeaderCrc(std::string bytes)
{
  const uint32_t crc = Crc32(bytes.data(), 252);
  std::memcpy(&bytes[252], &crc, 4);
  return bytes;
}

void TestMapAxesInFile()
{
  // MAPAXES (a 30 degree turn), MAPUNITS and GRIDUNIT of a deck go to the header, exactly.
  const std::string deckPath = TempPath("map.GRDECL");
  WriteMapDeck(deckPath,
    "MAPUNITS\n 'METRES' /\nMAPAXES\n 455000.25 6781866.525404 455500.25 6781000.5 456366.275404 6781500.5 /\n"
    "GRIDUNIT\n 'METRES' ' ' /\n");
  const std::string path = TempPath("map.resmr");
  HierarchyOptions options;
  options.cmax = 64;
  options.threads = 1;
  {
    auto source = OpenLayerSource(deckPath, TempPath("map-spool"));
    BuildHierarchy(*source, path, options);
  }
  CornerPointModel deck;
  std::vector<bool> active;
  ReadCornerPointModel(deckPath, deck, active);
  const MultiresolutionFile file(path);
  const MapPlacement& map = file.Header().map;
  CHECK(file.Header().version == MultiresolutionHeader::Version);
  CHECK(map.hasMapAxes && !map.gridUnitIsMap && map.mapUnits == "METRES" && map.gridUnit == "METRES");
  CHECK(map.mapAxes.yAxisPoint == deck.mapAxes.yAxisPoint && map.mapAxes.origin == deck.mapAxes.origin &&
    map.mapAxes.xAxisPoint == deck.mapAxes.xAxisPoint);

  // The header's transform places every corner where the grid readers put it (FromDeck with
  // MAPAXES applied), bit for bit.
  std::array<double, 6> transform;
  CHECK(CornerPointGeometry::PlacementTransform(map, transform));
  CHECK(std::abs(transform[2] - std::sqrt(0.75)) < 1e-6 && std::abs(transform[3] - 0.5) < 1e-6);
  CornerPointModel mapDeck = deck;
  const CornerPointGeometry grid = CornerPointGeometry::FromDeck(deck, false);
  const CornerPointGeometry placed = CornerPointGeometry::FromDeck(mapDeck, true);
  int64_t same = 0, corners = 0;
  for (int64_t c = 0; c < grid.CellCount(); ++c)
  {
    const int64_t i = c % 12, j = c / 12 % 10, k = c / 120;
    double a[8][3], b[8][3];
    grid.CellCorners(i, j, k, a);
    placed.CellCorners(i, j, k, b);
    for (int v = 0; v < 8; ++v, ++corners)
    {
      CornerPointGeometry::ApplyMapTransform(transform, a[v][0], a[v][1]);
      same += a[v][0] == b[v][0] && a[v][1] == b[v][1] && a[v][2] == b[v][2] ? 1 : 0;
    }
  }
  CHECK(same == corners);
  std::printf("map axes: %lld of %lld corners placed by the header's MAPAXES as FromDeck places them\n",
    static_cast<long long>(same), static_cast<long long>(corners));

  // Geometry stays in grid coordinates: the hierarchy box is the grid's.
  CHECK(file.Header().box[0] >= -1 && file.Header().box[2] <= 12 * 50 + 1 && file.Header().box[3] <= 10 * 40 + 1);

  // GRIDUNIT ... 'MAP': COORD is already in map coordinates, nothing to apply.
  const std::string inMapPath = TempPath("inmap.GRDECL");
  WriteMapDeck(inMapPath, "MAPAXES\n 0 1 0 0 1 0 /\nGRIDUNIT\n 'METRES' 'MAP' /\n");
  const std::string inMap = TempPath("inmap.resmr");
  {
    auto source = OpenLayerSource(inMapPath, TempPath("map-spool"));
    BuildHierarchy(*source, inMap, options);
  }
  {
    const MultiresolutionFile f(inMap);
    CHECK(f.Header().map.hasMapAxes && f.Header().map.gridUnitIsMap);
    CHECK(!CornerPointGeometry::PlacementTransform(f.Header().map, transform));
  }

  // Version 3 (no map placement) still reads, as grid coordinates. Files before version 10
  // keep a mesh's positions in its mesh chunk: older versions are made from the committed
  // version 8 seed (the fuzz corpus's), newer ones from this file.
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string seedPath = std::string(RESMR_FUZZ_SEEDS) + "/valid_synth_9x8x2_cmax16_v8.resmr";
  std::ifstream seedIn(seedPath, std::ios::binary);
  const std::string seed((std::istreambuf_iterator<char>(seedIn)), std::istreambuf_iterator<char>());
  const MultiresolutionFile eight(seedPath);
  CHECK(eight.Header().version == 8);
  const std::string damaged = TempPath("map-damaged.resmr");
  const auto writeBytes = [&](const std::string& content) {
    std::ofstream out(damaged, std::ios::binary | std::ios::trunc);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
  };
  const auto withVersion = [&](uint32_t version) {
    const bool old = version < MultiresolutionHeader::LayerGroupsVersion;
    std::vector<uint8_t> b =
      old ? std::vector<uint8_t>(seed.begin(), seed.end()) : std::vector<uint8_t>(bytes.begin(), bytes.end());
    std::memcpy(&b[8], &version, 4);
    std::fill(b.begin() + 184, b.begin() + 252, 0);
    if (version < MultiresolutionHeader::TypicalErrorVersion)
    {
      // The typical error's bytes were reserved (zero) before; the index CRC follows them.
      const auto index = resmr_fuzz::Load<uint64_t>(b, b.size() - IndexTrailerBytes);
      for (std::size_t r = 0; r < eight.Regions().size(); ++r)
      {
        resmr_fuzz::Store<float>(b, static_cast<std::size_t>(index) + r * 192 + 4, 0.f);
      }
    }
    b = resmr_fuzz::Repair(b.data(), b.size(), resmr_fuzz::ResmrLayout(), false);
    return std::string(b.begin(), b.end());
  };
  writeBytes(withVersion(3));
  {
    const MultiresolutionFile old(damaged);
    CHECK(old.Header().version == 3 && !old.Header().map.hasMapAxes && old.Header().map.mapUnits.empty());
    CHECK(!CornerPointGeometry::PlacementTransform(old.Header().map, transform));
    CHECK(old.Regions().size() == eight.Regions().size() && old.Header().geometryId == eight.Header().geometryId);
    // Its regions' typical errors are unknown (the view estimates from their own errors).
    CHECK(std::all_of(
      old.Regions().begin(), old.Regions().end(), [](const RegionRecord& r) { return r.typicalError < 0; }));
    for (std::size_t r = 0; r < old.Regions().size(); ++r)
    {
      const RegionMesh mesh = old.ReadRegion(r);
      CHECK(mesh.VertexCount() == old.Regions()[r].vertices);
      CHECK(SameAsWindow(mesh, old.ReadRegionLayers(r, 1, 1)));
    }
  }
  // Versions this build does not know are refused by number.
  writeBytes(withVersion(2));
  resmr_testing::ExpectError<FileFormatError>("version 2", [&] { MultiresolutionFile f(damaged); },
    { damaged, "format version 2", "versions 3 to " + std::to_string(MultiresolutionHeader::Version), "resmr build" });
  const std::string newer = std::to_string(MultiresolutionHeader::Version + 1);
  writeBytes(withVersion(MultiresolutionHeader::Version + 1));
  resmr_testing::ExpectError<FileFormatError>(
    "version " + newer, [&] { MultiresolutionFile f(damaged); }, { damaged, "format version " + newer, "newer" });
  // Version 5 is the same bytes (its simplified sides drawn only past a few pixels of error).
  writeBytes(withVersion(5));
  {
    MultiresolutionFile five(damaged);
    CHECK(five.Header().version == 5 && five.Regions().size() == eight.Regions().size());
  }
  // A placement that cannot be right, under a good checksum, is named; a flipped byte there
  // fails the checksum.
  std::string broken = bytes;
  broken[184] = 7;
  writeBytes(WithHeaderCrc(broken));
  resmr_testing::ExpectError<FileFormatError>(
    "flags", [&] { MultiresolutionFile f(damaged); }, { damaged, "map placement", "unknown flags" });
  broken = bytes;
  std::memcpy(&broken[188 + 32], &broken[188 + 16], 16); // x axis point onto the origin
  writeBytes(WithHeaderCrc(broken));
  resmr_testing::ExpectError<FileFormatError>(
    "axes", [&] { MultiresolutionFile f(damaged); }, { damaged, "MAPAXES", "coincide" });
  broken = bytes;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&broken[188], &nan, 8);
  writeBytes(WithHeaderCrc(broken));
  resmr_testing::ExpectError<FileFormatError>(
    "nan", [&] { MultiresolutionFile f(damaged); }, { damaged, "MAPAXES", "not finite" });
  broken = bytes;
  broken[240] = '\x01';
  writeBytes(WithHeaderCrc(broken));
  resmr_testing::ExpectError<FileFormatError>(
    "units", [&] { MultiresolutionFile f(damaged); }, { damaged, "MAPUNITS", "not text" });
  broken = bytes;
  broken[200] ^= 0x04;
  writeBytes(broken);
  resmr_testing::ExpectError<FileFormatError>(
    "flipped placement", [&] { MultiresolutionFile f(damaged); }, { damaged, "header checksum" });
  for (const std::string& p : { deckPath, path, inMapPath, inMap, damaged })
  {
    std::remove(p.c_str());
  }
  rmdir(TempPath("map-spool").c_str());
}

void TestBuildSchedule()
{
  // A tree whose leaf level has 2048 triangles, about 70% of them holding columns.
  const DiamondHierarchy tree(0, 0, 300, 200, 10);
  std::mt19937_64 random(5);
  std::vector<int64_t> leaves;
  for (int64_t t = 0; t < DiamondHierarchy::TriangleCount(10); ++t)
  {
    if (random() % 10 < 7)
    {
      leaves.push_back(t);
    }
  }
  std::shuffle(leaves.begin(), leaves.end(), random);
  const BuildSchedule schedule(tree, leaves);
  const auto& tasks = schedule.Tasks();
  // Every leaf once; every task after those it depends on; every triangle above a built one
  // in exactly one diamond task.
  std::set<int64_t> leafSeen;
  std::map<std::pair<int, int64_t>, int> triangles;
  for (std::size_t t = 0; t < tasks.size(); ++t)
  {
    const auto& task = tasks[t];
    CHECK(task.leaf == (task.level == 10));
    if (task.leaf)
    {
      CHECK(leaves[static_cast<std::size_t>(task.leafIndex)] == task.first);
      CHECK(leafSeen.insert(task.first).second);
    }
    for (int64_t triangle : { task.first, task.second })
    {
      if (triangle >= 0)
      {
        ++triangles[{ task.level, triangle }];
      }
    }
    for (int32_t d : task.dependsOn)
    {
      CHECK(d >= 0 && static_cast<std::size_t>(d) < t);
    }
  }
  CHECK(leafSeen.size() == leaves.size());
  for (int level = 0; level < 10; ++level)
  {
    for (int64_t t = 0; t < DiamondHierarchy::TriangleCount(level); ++t)
    {
      const int shift = 10 - level;
      const bool built = std::any_of(leaves.begin(), leaves.end(), [&](int64_t leaf) { return (leaf >> shift) == t; });
      const int count = triangles[{ level, t }];
      CHECK(!built || count == 1);
    }
  }
  // Depth first: run in order, regions made but not yet merged stay few (level by level, a
  // whole level of them waits).
  std::vector<int32_t> consumersLeft(tasks.size(), 0);
  for (const auto& task : tasks)
  {
    for (int32_t d : task.dependsOn)
    {
      ++consumersLeft[static_cast<std::size_t>(d)];
    }
  }
  int64_t waiting = 0, most = 0;
  for (const auto& task : tasks)
  {
    for (int32_t d : task.dependsOn)
    {
      waiting -= --consumersLeft[static_cast<std::size_t>(d)] == 0 ? 1 : 0;
    }
    ++waiting;
    most = std::max(most, waiting);
  }
  std::printf("schedule: %zu tasks, %zu leaves, at most %lld made and not yet merged\n", tasks.size(), leaves.size(),
    static_cast<long long>(most));
  CHECK(most <= static_cast<int64_t>(leaves.size()) / 8);

  // Run on 3 threads: each task once, after its dependencies; tasks marked done are skipped.
  std::vector<uint8_t> done(tasks.size(), 0);
  for (std::size_t t = 0; t < tasks.size() / 3; ++t)
  {
    done[t] = 1;
  }
  std::vector<std::atomic<int>> runs(tasks.size());
  std::atomic<int> misordered{ 0 };
  schedule.Run(3, done, [&](int32_t t) {
    for (int32_t d : tasks[static_cast<std::size_t>(t)].dependsOn)
    {
      misordered += done[static_cast<std::size_t>(d)] || runs[static_cast<std::size_t>(d)] == 1 ? 0 : 1;
    }
    ++runs[static_cast<std::size_t>(t)];
  });
  CHECK(misordered == 0);
  for (std::size_t t = 0; t < tasks.size(); ++t)
  {
    CHECK(runs[t] == (done[t] ? 0 : 1));
  }
  // A failing task stops the run and its error comes out.
  std::atomic<int> after{ 0 };
  resmr_testing::ExpectError<std::runtime_error>("failing task",
    [&] {
      schedule.Run(2, std::vector<uint8_t>(tasks.size(), 0), [&](int32_t t) {
        if (t == 40)
        {
          throw std::runtime_error("task 40 failed");
        }
        after += t > 40 ? 1 : 0;
      });
    },
    { "task 40 failed" });
  CHECK(after < static_cast<int>(tasks.size()) - 41);
}

/// Every region's parent is in the file: the view reaches a region only through its parent.
/// On these models a split of a simplified diamond by column centre alone sent all of a
/// triangle's columns to its partner, 4 regions (14 active cells) in the first one went
/// without a parent, and no cut drew them.
void TestEveryRegionReachable()
{
  std::size_t regions = 0;
  for (uint64_t seed : { 1, 2, 3 })
  {
    SyntheticParameters p;
    p.nx = 120;
    p.ny = 90;
    p.nz = 4;
    p.seed = seed;
    const std::string path = TempPath("reachable.resmr");
    HierarchyOptions options;
    options.cmax = 16;
    options.threads = 2;
    SyntheticLayerSource source(p, "synth:reachable");
    BuildHierarchy(source, path, options);
    const MultiresolutionFile file(path);
    const std::vector<std::size_t> unreachable = UnreachableRegions(file);
    for (std::size_t r : unreachable)
    {
      std::fprintf(stderr, "seed %llu: region (%d, %lld) has no parent\n", static_cast<unsigned long long>(seed),
        file.Regions()[r].level, static_cast<long long>(file.Regions()[r].index));
    }
    CHECK(unreachable.empty());
    regions += file.Regions().size();
    std::remove(path.c_str());
  }
  CHECK(regions > 3000);
}

void TestFailedBuildLeavesNothing()
{
  // An existing file of the output's name survives a failed build untouched.
  const std::string path = TempPath("kept.resmr");
  {
    std::ofstream out(path);
    out << "older";
  }
  SyntheticParameters p = SmallModel();
  HierarchyOptions options;
  options.cmax = 1; // refused
  SyntheticLayerSource source(p, "synth:kept");
  resmr_testing::ExpectError<std::invalid_argument>(
    "cmax", [&] { BuildHierarchy(source, path, options); }, { "--cmax" });
  std::ifstream in(path);
  std::string content;
  in >> content;
  CHECK(content == "older");
  std::remove(path.c_str());
}
} // namespace

int main()
{
  TestDiamondTree();
  TestBuildSchedule();
  TestHierarchyFile();
  TestLayerGroups();
  TestWallDepths();
  TestWeldedFaults();
  TestMapAxesInFile();
  TestFailedBuildLeavesNothing();
  TestEveryRegionReachable();
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d check(s) failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("all hierarchy checks passed\n");
  return 0;
}
