// Out-of-core loading of region meshes, paper Sec. 6.2-6.3: draw buffers with cell
// coordinates, and the loader threads with their least-recently-used memory budget.
#include "RegionCache.h"

#include "MergedSides.h"

#ifdef __linux__
#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace resmr
{
namespace
{
using Vector = std::array<double, 3>;

Vector Minus(const Vector& a, const Vector& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}

Vector Cross(const Vector& a, const Vector& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}

double Dot(const Vector& a, const Vector& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Position of a vertex, z up.
Vector ZUp(const RegionMesh& mesh, uint32_t vertex)
{
  const double* p = &mesh.positions[static_cast<std::size_t>(vertex) * 3];
  return { p[0], p[1], -p[2] };
}

/// Topological coordinate (ti, tj, tk) of a vertex: its node's (ti, tj) and its interface.
Vector Topological(const RegionMesh& mesh, uint32_t vertex)
{
  const uint32_t perNode = static_cast<uint32_t>(mesh.layers + 1);
  const auto& t = mesh.topology[vertex / perNode];
  return { t[0], t[1], static_cast<double>(mesh.firstLayer + int32_t(vertex % perNode)) };
}

/// sign(det d(x, y, z)/d(i, j, k)) of one cell, 0 if degenerate: the images of the column's
/// diagonals and of the layer's thickness against the diagonals in topological space.
int CellHandedness(const RegionMesh& mesh, std::size_t column, int32_t layer)
{
  const auto& q = mesh.corners[column];
  const auto middle = [&](uint32_t node) {
    const Vector a = ZUp(mesh, mesh.Vertex(node, layer)), b = ZUp(mesh, mesh.Vertex(node, layer + 1));
    return Vector{ (a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2 };
  };
  const Vector u = Minus(middle(q[2]), middle(q[0])), v = Minus(middle(q[3]), middle(q[1]));
  Vector w{ 0, 0, 0 };
  for (int n = 0; n < 4; ++n)
  {
    const Vector d = Minus(ZUp(mesh, mesh.Vertex(q[n], layer + 1)), ZUp(mesh, mesh.Vertex(q[n], layer)));
    w = { w[0] + d[0], w[1] + d[1], w[2] + d[2] };
  }
  const double physical = Dot(u, Cross(v, w));
  const auto& t0 = mesh.topology[q[0]];
  const auto& t1 = mesh.topology[q[1]];
  const auto& t2 = mesh.topology[q[2]];
  const auto& t3 = mesh.topology[q[3]];
  const double topological =
    double(t2[0] - t0[0]) * double(t3[1] - t1[1]) - double(t2[1] - t0[1]) * double(t3[0] - t1[0]);
  const double scale = std::sqrt(Dot(u, u) * Dot(v, v) * Dot(w, w));
  if (!(std::fabs(physical) > 1e-9 * scale) || topological == 0 || !std::isfinite(physical))
  {
    return 0;
  }
  return (physical > 0) == (topological > 0) ? 1 : -1;
}

/// Whether `offset` moves the triangle's centre into an active cell of the region whose open
/// side lies on the triangle's plane along `axis`.
bool OwnsSide(const RegionMesh& mesh, const Vector& centre, double plane, int axis, const std::array<double, 3>& offset,
  const std::map<std::pair<int64_t, int64_t>, std::size_t>& columns)
{
  const int64_t i = static_cast<int64_t>(std::floor(centre[0] + offset[0]));
  const int64_t j = static_cast<int64_t>(std::floor(centre[1] + offset[1]));
  const int64_t k = static_cast<int64_t>(std::floor(centre[2] + offset[2])) - mesh.firstLayer;
  const auto found = columns.find({ i, j });
  if (found == columns.end() || k < 0 || k >= mesh.layers)
  {
    return false;
  }
  const std::size_t cell = found->second * static_cast<std::size_t>(mesh.layers) + static_cast<std::size_t>(k);
  const auto& q = mesh.corners[found->second];
  for (int e = 0; mesh.active[cell] && e < 4; ++e)
  {
    if (mesh.topology[q[e]][axis] == plane && mesh.topology[q[(e + 1) % 4]][axis] == plane &&
      ((mesh.openSides[cell] >> e) & 1))
    {
      return true;
    }
  }
  return false;
}

/// Checks the offset the normal gave a side triangle against the region's cells and corrects
/// it where it is wrong: a triangle with no area in topological space (a sliver along a face's
/// edge) has no normal, and a long simplified triangle over curved cells can turn the other
/// way in topological space than in space. Tries the cells around the triangle, half a cell
/// off on each axis its vertices share, and takes the first active cell of the region whose
/// open side lies on the triangle's plane. Only for regions of whole cells (integer
/// topological coordinates, the leaves); a triangle spanning two faces keeps its offset.
void CheckSideCell(const RegionMesh& mesh, const std::array<Vector, 3>& t,
  const std::map<std::pair<int64_t, int64_t>, std::size_t>& columns, std::array<double, 3>& offset)
{
  bool shared[3];
  for (int a = 0; a < 3; ++a)
  {
    shared[a] = t[0][a] == t[1][a] && t[1][a] == t[2][a];
  }
  // A point inside the triangle (or its segment) that falls on no cell boundary.
  const double w0 = 1.0 / 3 + 1.4142135623730951e-3, w1 = 1.0 / 3 + 1.7320508075688772e-3, w2 = 1 - w0 - w1;
  Vector centre;
  for (int a = 0; a < 3; ++a)
  {
    centre[a] = shared[a] ? t[0][a] : w0 * t[0][a] + w1 * t[1][a] + w2 * t[2][a];
  }
  for (int axis = 0; axis < 2; ++axis)
  {
    if (shared[axis] && OwnsSide(mesh, centre, t[0][axis], axis, offset, columns))
    {
      return;
    }
  }
  for (int axis = 0; axis < 2; ++axis)
  {
    if (!shared[axis])
    {
      continue;
    }
    // Every combination of half-cell steps on the shared axes.
    for (int signs = 0; signs < 8; ++signs)
    {
      std::array<double, 3> step{ 0, 0, 0 };
      bool valid = true;
      for (int a = 0; a < 3; ++a)
      {
        if (shared[a])
        {
          step[a] = (signs >> a) & 1 ? 0.5 : -0.5;
        }
        else if ((signs >> a) & 1)
        {
          valid = false; // one try for an axis the vertices do not share
        }
      }
      if (valid && OwnsSide(mesh, centre, t[0][axis], axis, step, columns))
      {
        offset = step;
        return;
      }
    }
  }
}

/// The region's columns by cell (i, j), or none if its topological coordinates are not all
/// integers (a simplified region).
std::map<std::pair<int64_t, int64_t>, std::size_t> ColumnsByCell(const RegionMesh& mesh)
{
  std::map<std::pair<int64_t, int64_t>, std::size_t> columns;
  if (mesh.active.empty() || mesh.openSides.empty())
  {
    return columns;
  }
  for (const auto& t : mesh.topology)
  {
    if (t[0] != std::floor(t[0]) || t[1] != std::floor(t[1]))
    {
      return columns;
    }
  }
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    const auto cell = mesh.ColumnCell(c);
    columns[{ static_cast<int64_t>(cell[0]), static_cast<int64_t>(cell[1]) }] = c;
  }
  return columns;
}

constexpr uint32_t Unused = std::numeric_limits<uint32_t>::max();

void PushVertex(RegionDrawBuffers& out, const Vector& position, const std::array<double, 3>& origin, const Vector& cell)
{
  out.vertices.push_back(static_cast<float>(position[0] - origin[0]));
  out.vertices.push_back(static_cast<float>(position[1] - origin[1]));
  out.vertices.push_back(static_cast<float>(position[2] - origin[2]));
  out.vertices.push_back(static_cast<float>(cell[0]));
  out.vertices.push_back(static_cast<float>(cell[1]));
  out.vertices.push_back(static_cast<float>(cell[2]));
}

/// Top or bottom quads as triangles; vertices shared within the surface, the cell coordinate
/// half a layer into the cell (down for a top face: k grows downward).
void AddQuads(const RegionMesh& mesh, const RegionSurface& surface, double kOffset, const std::array<double, 3>& origin,
  std::vector<uint32_t>& map, RegionDrawBuffers& out)
{
  std::fill(map.begin(), map.end(), Unused);
  const auto index = [&](uint32_t vertex) {
    uint32_t& slot = map[vertex];
    if (slot == Unused)
    {
      slot = static_cast<uint32_t>(out.vertices.size() / 6);
      Vector cell = Topological(mesh, vertex);
      cell[2] += kOffset;
      PushVertex(out, ZUp(mesh, vertex), origin, cell);
    }
    return slot;
  };
  for (const auto& q : surface.quads)
  {
    const uint32_t a = index(q[0]), b = index(q[1]), c = index(q[2]), d = index(q[3]);
    out.indices.insert(out.indices.end(), { a, b, c, a, c, d });
  }
}
} // namespace

int TopologyHandedness(const MultiresolutionFile& file)
{
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
  {
    if (file.Regions()[r].columns <= 0)
    {
      continue;
    }
    RegionMesh mesh;
    try
    {
      mesh = file.ReadRegion(r);
    }
    catch (const std::exception&)
    {
      continue; // a damaged region: the next one tells as well
    }
    for (std::size_t c = 0; c < mesh.corners.size(); ++c)
    {
      for (int32_t k = 0; k < mesh.layers; ++k)
      {
        const int sign = CellHandedness(mesh, c, k);
        if (sign != 0)
        {
          return sign;
        }
      }
    }
  }
  return 1;
}

void UseOriginalSideFaces(RegionMesh& mesh)
{
  ExtractSurfaces(mesh);
  mesh.sideTriangles.clear();
  mesh.sideTriangles.reserve(mesh.side.quads.size() * 2);
  const auto at = [&](uint32_t vertex) { return &mesh.positions[static_cast<std::size_t>(vertex) * 3]; };
  const auto same = [&](uint32_t a, uint32_t b) { return std::equal(at(a), at(a) + 3, at(b)); };
  for (const auto& quad : mesh.side.quads)
  {
    if (same(quad[0], quad[1]) && same(quad[2], quad[3]))
    {
      continue; // a cell of no thickness at either end: the face covers nothing
    }
    mesh.sideTriangles.push_back({ quad[0], quad[1], quad[2] });
    mesh.sideTriangles.push_back({ quad[0], quad[2], quad[3] });
  }
}

RegionDrawBuffers LoadRegionDrawBuffers(const MultiresolutionFile& file, std::size_t region,
  const std::array<double, 3>& origin, int handedness, int32_t layer, bool exactSides, const CellFilter* filter)
{
  // Not ReadRegionSurfaces: the buffers need positions. One layer, or the layers a filter may
  // keep, need only theirs (their cells and faces; the stored surfaces are extracted again).
  const auto& dims = file.Header().dims;
  const auto filterLayers = [&](const std::vector<std::array<float, 2>>& topology) {
    return FilterLayers(*filter, topology, dims);
  };
  RegionMesh mesh = layer >= 0 ? file.ReadRegionLayers(region, layer, layer)
    : filter                   ? file.ReadRegionLayers(region, filterLayers)
                               : file.ReadRegion(region);
  const std::array<float, 4> footprint = RegionFootprint(mesh);
  if (layer >= 0)
  {
    RegionDrawBuffers out = PrepareLayerDrawBuffers(mesh, layer, origin, handedness);
    out.footprint = footprint;
    return out;
  }
  if (!(mesh.sealedPinchThickness > 0))
  {
    // Leaves (and older files) seal only runs of no thickness at all: their faces lie on one
    // another inside the solid and hide nothing, but on models that pinch out they are most
    // of the leaves' top and bottom triangles.
    mesh.sealedPinchThickness = std::numeric_limits<double>::min();
  }
  if (filter)
  {
    // A property filter: a leaf it crosses is masked by its cells' values, a coarse region it
    // crosses by layer blocks (within the region's filter error), a region it leaves whole by
    // range.
    const RangeClass valueClass = filter->HasValues() ? filter->values->Classify(footprint, 1) : RangeClass::Inside;
    const bool leaf = file.Regions()[region].level >= file.Header().leafLevel;
    // Faces inside the model that the filter or an excluded box exposes carry their cells'
    // values (a leaf's) or their layer blocks' means (a coarse region's).
    const bool exposing =
      valueClass != RangeClass::Inside || ExclusionExposes(footprint, filter->range, file.Header().dims);
    CellBox box;
    if (exposing && leaf)
    {
      box = ReadCellBox(mesh, *filter, file.Header().dims);
    }
    const bool boxed = !box.tables.empty();
    if (valueClass == RangeClass::Inside)
    {
      MaskToRange(mesh, filter->range);
    }
    else
    {
      MaskToFilter(mesh, *filter, boxed ? &box : nullptr);
    }
    UseOriginalSideFaces(mesh);
    RegionDrawBuffers out = PrepareRegionDrawBuffers(mesh, origin, handedness);
    const double ownError = file.Regions()[region].ownError;
    if (!leaf && ownError > 0)
    {
      // The file's simplified side spans every layer: a masked coarse region draws its exact
      // side merged in K within its error where that side would be drawn.
      AddCoarseSide(mesh, MergedSideTriangles(mesh, ownError), origin, handedness, out);
    }
    if (boxed && filter->paintTable >= 0)
    {
      out.faceValues = FaceValues(out.vertices, out.indices, box);
    }
    else if (exposing && !leaf && filter->paintTable >= 0 && filter->paintBlocks)
    {
      out.faceValues = FaceMeans(out.vertices, out.indices, *filter->paintBlocks, file.Header().dims);
    }
    out.ranged = true;
    out.footprint = footprint;
    out.topCone = mesh.top.cone; // the range's faces, not the region's stored surfaces
    out.bottomCone = mesh.bottom.cone;
    return out;
  }
  const std::vector<std::array<uint32_t, 3>> simplifiedSide = mesh.sideTriangles;
  UseOriginalSideFaces(mesh);
  // Without a simplified side in the file, the exact one is the only side there is.
  const bool exact = exactSides || simplifiedSide.empty();
  if (!exact)
  {
    mesh.sideTriangles.clear();
  }
  RegionDrawBuffers out = PrepareRegionDrawBuffers(mesh, origin, handedness);
  out.exactSides = exact;
  out.footprint = footprint;
  AddCoarseSide(mesh, simplifiedSide, origin, handedness, out);
  return out;
}

namespace
{
/// Appends side triangles, each with its own vertices (the cell offset belongs to the
/// triangle); `checkCells` moves each one's offset to the cell that owns an exact side face.
void AddSideTriangles(const RegionMesh& mesh, const std::vector<std::array<uint32_t, 3>>& sideTriangles,
  const std::array<double, 3>& origin, int handedness, bool checkCells, RegionDrawBuffers& out)
{
  // Side triangles: the face's constant axis is the largest component of its normal in
  // topological space n_T; the physical outward normal is det(A) A^-T n_T (A = d(x, y, z) /
  // d(i, j, k)), so the outward direction along that axis has the sign of
  // handedness * n_T[axis] and the cell lies on the other side. Each triangle has its own
  // vertices, since the offset belongs to the triangle.
  const auto columns = checkCells ? ColumnsByCell(mesh) : std::map<std::pair<int64_t, int64_t>, std::size_t>{};
  for (const auto& t : sideTriangles)
  {
    const Vector t0 = Topological(mesh, t[0]), t1 = Topological(mesh, t[1]), t2 = Topological(mesh, t[2]);
    const Vector n = Cross(Minus(t1, t0), Minus(t2, t0));
    int axis = 0;
    for (int a = 1; a < 3; ++a)
    {
      if (std::fabs(n[a]) > std::fabs(n[axis]))
      {
        axis = a;
      }
    }
    std::array<double, 3> offset{ 0, 0, 0 };
    offset[axis] = 0.5 * (n[axis] > 0 ? -handedness : n[axis] < 0 ? handedness : 0);
    if (!columns.empty())
    {
      CheckSideCell(mesh, { t0, t1, t2 }, columns, offset);
    }
    // The vertex of largest k goes last, the turn kept (RegionDrawBuffers::indices).
    std::array<Vector, 3> cells{ t0, t1, t2 };
    int last = 0;
    for (int v = 0; v < 3; ++v)
    {
      for (int a = 0; a < 3; ++a)
      {
        cells[v][a] += offset[a];
      }
      last = cells[v][2] > cells[last][2] ? v : last;
    }
    const uint32_t first = static_cast<uint32_t>(out.vertices.size() / 6);
    for (int n = 1; n <= 3; ++n)
    {
      const int v = (last + n) % 3;
      PushVertex(out, ZUp(mesh, t[v]), origin, cells[v]);
    }
    out.indices.insert(out.indices.end(), { first, first + 1, first + 2 });
  }
}

RegionDrawBuffers PrepareDrawBuffers(const RegionMesh& mesh, const RegionSurface& top, const RegionSurface& bottom,
  const std::vector<std::array<uint32_t, 3>>& sideTriangles, const std::array<double, 3>& origin, int handedness)
{
  RegionDrawBuffers out;
  out.topCone = top.cone;
  out.bottomCone = bottom.cone;
  std::vector<uint32_t> map(static_cast<std::size_t>(mesh.VertexCount()), Unused);
  // A top face lies on its cell's upper interface k: the cell is at k + 0.5; a bottom face on
  // the lower interface k + 1: the cell is at (k + 1) - 0.5.
  AddQuads(mesh, top, 0.5, origin, map, out);
  out.topIndices = static_cast<uint32_t>(out.indices.size());
  AddQuads(mesh, bottom, -0.5, origin, map, out);
  out.bottomIndices = static_cast<uint32_t>(out.indices.size()) - out.topIndices;
  AddSideTriangles(mesh, sideTriangles, origin, handedness, true, out);
  out.sideIndices = static_cast<uint32_t>(out.indices.size()) - out.topIndices - out.bottomIndices;
  return out;
}
} // namespace

void AddCoarseSide(const RegionMesh& mesh, const std::vector<std::array<uint32_t, 3>>& simplifiedSide,
  const std::array<double, 3>& origin, int handedness, RegionDrawBuffers& out)
{
  const std::size_t before = out.indices.size();
  AddSideTriangles(mesh, simplifiedSide, origin, handedness, false, out);
  out.coarseSideIndices = static_cast<uint32_t>(out.indices.size() - before);
}

DrawPiece NextDrawPiece(const RegionDrawBuffers& buffers, std::size_t first, std::size_t maxBytes)
{
  const std::vector<uint32_t>& indices = buffers.indices;
  DrawPiece piece{ first, first, UINT32_MAX, 0, 0 };
  for (std::size_t n = first; n + 3 <= indices.size(); n += 3)
  {
    const uint32_t low = std::min({ piece.lowVertex, indices[n], indices[n + 1], indices[n + 2] });
    const uint32_t high = std::max({ piece.highVertex, indices[n], indices[n + 1], indices[n + 2] });
    const std::size_t bytes = (std::size_t(high - low) + 1) * 24 + (n + 3 - first) * 4;
    if (n > first && bytes > maxBytes)
    {
      break;
    }
    piece = { first, n + 3, low, high, bytes };
  }
  return piece;
}

RegionDrawBuffers PrepareRegionDrawBuffers(const RegionMesh& mesh, const std::array<double, 3>& origin, int handedness)
{
  return PrepareDrawBuffers(mesh, mesh.top, mesh.bottom, mesh.sideTriangles, origin, handedness);
}

RegionDrawBuffers PrepareLayerDrawBuffers(
  const RegionMesh& mesh, int32_t layer, const std::array<double, 3>& origin, int handedness)
{
  const int32_t own = layer - mesh.firstLayer; // the mesh's
  if (own < 0 || own >= mesh.layers)
  {
    throw std::out_of_range("layer " + std::to_string(layer) + " of a region mesh of layers " +
      std::to_string(mesh.firstLayer) + " to " + std::to_string(mesh.firstLayer + mesh.layers - 1));
  }
  RegionSurface top, bottom, side;
  ExtractLayerSurfaces(mesh, own, top, bottom, side);
  // Side quads as two triangles each, turning as the quads: the whole model's side is
  // triangles too, so both views share the offset rules (the layer's k is exact either way).
  std::vector<std::array<uint32_t, 3>> triangles;
  triangles.reserve(side.quads.size() * 2);
  for (const auto& quad : side.quads)
  {
    triangles.push_back({ quad[0], quad[1], quad[2] });
    triangles.push_back({ quad[0], quad[2], quad[3] });
  }
  RegionDrawBuffers out = PrepareDrawBuffers(mesh, top, bottom, triangles, origin, handedness);
  out.layer = layer;
  return out;
}

RegionCache::RegionCache(std::shared_ptr<const MultiresolutionFile> file,
  std::shared_ptr<const PropertyFile> properties, std::size_t budgetBytes, bool simplifiedSides)
  : File(std::move(file))
  , Properties(std::move(properties))
  , SimplifiedSides(simplifiedSides)
  , BudgetBytes(budgetBytes)
{
  const auto& origin = this->File->Header().latticeOrigin;
  this->ModelOrigin = { origin[0], origin[1], -origin[2] };
  this->LayerSlots = static_cast<uint64_t>(std::max<int64_t>(this->File->Header().dims[2], 0)) + 3;
  const std::size_t count = this->File->Regions().size();
  this->IsRoot.assign(count, 0);
  this->IsLeaf.assign(count, 0);
  for (std::size_t r = 0; r < count; ++r)
  {
    this->IsLeaf[r] = this->File->Regions()[r].level == this->File->Header().leafLevel;
    if (this->File->Regions()[r].level == 0)
    {
      this->Roots.push_back(r);
      this->IsRoot[r] = 1;
      this->Pinned.push_back(this->RequestKeyLocked(r, this->CurrentLayer, true));
    }
  }
  const unsigned loaders = std::clamp(std::thread::hardware_concurrency(), 1u, IdleLoaders);
  for (unsigned l = 0; l < loaders; ++l)
  {
    this->Loaders.emplace_back([this] { this->Run(Role::Idle); });
  }
#ifdef __linux__
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    for (std::thread& loader : this->Loaders)
    {
      clockid_t clock{};
      if (pthread_getcpuclockid(loader.native_handle(), &clock) == 0)
      {
        this->LoaderClocks.push_back(clock);
      }
    }
    this->WindowStart = std::chrono::steady_clock::now();
  }
#endif
  this->Standby = std::thread([this] { this->Run(Role::Standby); });
  this->Essential = std::thread([this] { this->Run(Role::Essential); });
}

RegionCache::~RegionCache()
{
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    this->Stopping = true;
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
  this->Idle.notify_all();
  for (std::thread& loader : this->Loaders)
  {
    loader.join();
  }
  this->Standby.join();
  this->Essential.join();
}

bool RegionCache::SetLayer(int32_t layer)
{
  if (layer < -1 || layer >= this->SimplifiedLayer())
  {
    return false;
  }
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    this->ChosenLayer = layer;
    if (this->CurrentLayer != this->RangeLayer())
    {
      this->SwitchLayerLocked(layer);
    }
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
  return true;
}

void RegionCache::SetRange(const CellRange* range)
{
  CellFilter filter;
  if (range)
  {
    filter.range = *range;
  }
  this->SetFilter(range ? &filter : nullptr);
}

void RegionCache::SetFilter(const CellFilter* filter)
{
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    const bool ranged = this->CurrentLayer == this->RangeLayer();
    if (filter && (!ranged || *filter != this->CurrentFilter))
    {
      this->CurrentFilter = *filter;
      ++this->RangeGeneration;
      this->CurrentLayer = -2; // switched below, whatever it was
    }
    this->SwitchLayerLocked(filter ? this->RangeLayer() : this->ChosenLayer);
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
}

bool RegionCache::Ranged() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->CurrentLayer == this->RangeLayer();
}

void RegionCache::VisitFootprints(const std::function<void(std::size_t, const std::array<float, 4>&)>& visit) const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  for (const auto& entry : this->Entries)
  {
    const std::size_t region = this->RegionOf(entry.first);
    if (entry.second.buffers && entry.first == this->KeyOf(region, this->CurrentLayer))
    {
      visit(region, entry.second.buffers->footprint);
    }
  }
}

void RegionCache::SwitchLayerLocked(int32_t layer)
{
  if (layer == this->CurrentLayer)
  {
    return;
  }
  this->CurrentLayer = layer;
  this->Pinned.clear();
  for (std::size_t r : this->Roots)
  {
    this->Pinned.push_back(this->RequestKeyLocked(r, layer, true));
  }
  // The old layer's request is void: its regions become evictable, and none loads now.
  this->Wanted.clear();
  this->Predicted.clear();
  this->InWanted.clear();
  this->InPredicted.clear();
  this->WantedBlocked = this->PredictedBlocked = false;
  ++this->Changes; // what Get returns has changed
}

int32_t RegionCache::Layer() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->CurrentLayer;
}

std::shared_ptr<const RegionDrawBuffers> RegionCache::Get(std::size_t region) const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  const auto found = this->Entries.find(this->KeyOf(region, this->CurrentLayer));
  if (found != this->Entries.end() && found->second.buffers)
  {
    return found->second.buffers;
  }
  if (this->CurrentLayer >= 0 || !this->SimplifiedSides)
  {
    return nullptr;
  }
  const auto simplified = this->Entries.find(this->KeyOf(region, this->SimplifiedLayer()));
  return simplified == this->Entries.end() ? nullptr : simplified->second.buffers;
}

std::shared_ptr<const RegionDrawBuffers> RegionCache::Get(std::size_t region, int32_t layer) const
{
  if (layer < -1 || layer >= this->SimplifiedLayer())
  {
    return nullptr;
  }
  std::lock_guard<std::mutex> lock(this->Lock);
  const auto found = this->Entries.find(this->KeyOf(region, layer));
  return found == this->Entries.end() ? nullptr : found->second.buffers;
}

bool RegionCache::IsResident(std::size_t region) const
{
  return this->Get(region) != nullptr;
}

void RegionCache::Request(const std::vector<std::size_t>& wanted, const std::vector<std::size_t>& predicted,
  const std::vector<std::size_t>& simplified, bool urgent)
{
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    this->WantedUrgent = urgent;
    this->Wanted.clear();
    this->Predicted.clear();
    this->InWanted.clear();
    this->InPredicted.clear();
    // Wanted regions get the newest time, predicted ones just under it: among regions of one
    // request, predicted ones are evicted first.
    this->Clock += 2;
    const std::size_t count = this->IsRoot.size();
    const int32_t layer = this->CurrentLayer;
    std::vector<uint8_t> lean;
    if (this->SimplifiedSides && layer < 0)
    {
      lean.assign(count, 0);
      for (std::size_t r : simplified)
      {
        if (r < count)
        {
          lean[r] = 1;
        }
      }
    }
    const auto keyOf = [&](std::size_t r, int32_t l) {
      return this->RequestKeyLocked(r, l, l < 0 && !lean.empty() && lean[r]);
    };
    for (std::size_t r : wanted)
    {
      const Key key = r < count ? keyOf(r, layer) : 0;
      if (r < count && this->InWanted.insert(key).second)
      {
        this->Wanted.push_back(key);
        this->Entries[key].lastRequested = this->Clock;
      }
    }
    const auto predict = [&](std::size_t r, int32_t l) {
      const Key key = r < count ? keyOf(r, l) : 0;
      if (r < count && !this->InWanted.count(key) && this->InPredicted.insert(key).second)
      {
        this->Predicted.push_back(key);
        this->Entries[key].lastRequested = this->Clock - 1;
      }
    };
    for (std::size_t r : predicted)
    {
      predict(r, layer);
    }
    // The next layer switch is probably to a neighbour: its roots, so that it need not wait.
    for (const int32_t next : { layer + 1, layer - 1 })
    {
      if (layer >= 0 && next >= 0 && next < this->SimplifiedLayer())
      {
        for (std::size_t r : this->Roots)
        {
          predict(r, next);
        }
      }
    }
    this->WantedBlocked = this->PredictedBlocked = false;
    this->RescueIfStarvedLocked();
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
}

void RegionCache::RequestProperty(const std::string& name, int32_t step, int32_t layer)
{
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    this->PropertyName = name;
    this->PropertyStep = step;
    this->PropertyLayer = layer;
    this->PropertyWanted = !(this->CurrentProperty && this->CurrentProperty->name == name &&
      this->CurrentProperty->step == step && this->CurrentProperty->layer == layer);
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
}

std::shared_ptr<const PropertyTableData> RegionCache::Property() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->CurrentProperty;
}

void RegionCache::RequestCutPlanes(
  const std::string& name, int32_t step, const std::vector<std::array<int64_t, 2>>& planes)
{
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    const std::vector<std::array<int64_t, 2>> wanted(
      planes.begin(), planes.begin() + static_cast<std::ptrdiff_t>(std::min(planes.size(), MaxCutPlanes)));
    if (name == this->CutName && step == this->CutStep && wanted == this->CutWanted)
    {
      return; // asked every frame: nothing new
    }
    this->CutName = name;
    this->CutStep = step;
    this->CutWanted = wanted;
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
}

std::shared_ptr<const CutPlaneData> RegionCache::CutPlane(
  const std::string& name, int32_t step, int axis, int64_t index) const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  for (const auto& plane : this->CutPlanes)
  {
    if (plane->name == name && plane->step == step && plane->axis == axis && plane->index == index)
    {
      return plane;
    }
  }
  return nullptr;
}

int64_t RegionCache::NextCutPlaneLocked() const
{
  for (std::size_t n = 0; n < this->CutWanted.size(); ++n)
  {
    const int axis = static_cast<int>(this->CutWanted[n][0]);
    const int64_t index = this->CutWanted[n][1];
    const bool held = std::any_of(this->CutPlanes.begin(), this->CutPlanes.end(), [&](const auto& plane) {
      return plane->name == this->CutName && plane->step == this->CutStep && plane->axis == axis &&
        plane->index == index;
    });
    const std::string key = CutKey(this->CutName, this->CutStep, axis, index);
    if (!held && std::find(this->CutFailed.begin(), this->CutFailed.end(), key) == this->CutFailed.end())
    {
      return static_cast<int64_t>(n);
    }
  }
  return -1;
}

void RegionCache::LoadCutPlaneLocked(std::unique_lock<std::mutex>& lock, std::size_t wanted)
{
  auto plane = std::make_shared<CutPlaneData>();
  plane->name = this->CutName;
  plane->step = this->CutStep;
  plane->axis = static_cast<int>(this->CutWanted[wanted][0]);
  plane->index = this->CutWanted[wanted][1];
  this->CutLoading = true;
  lock.unlock();
  std::string error;
  try
  {
    const int table = this->Properties ? this->Properties->Find(plane->name, plane->step) : -1;
    if (table < 0)
    {
      throw std::runtime_error((this->Properties ? this->Properties->Path() : std::string("no property file")) +
        ": property " + plane->name + " step " + std::to_string(plane->step) + " not found");
    }
    plane->values = this->Properties->ReadPlane(static_cast<std::size_t>(table), plane->axis, plane->index);
  }
  catch (const std::exception& e)
  {
    error = e.what();
  }
  lock.lock();
  this->CutLoading = false;
  if (!error.empty())
  {
    this->CutFailed.push_back(CutKey(plane->name, plane->step, plane->axis, plane->index));
    this->Error = error;
    return;
  }
  this->CutPlanes.push_back(std::move(plane));
  if (this->CutPlanes.size() > MaxCutPlanes)
  {
    this->CutPlanes.erase(this->CutPlanes.begin());
  }
  ++this->Changes;
}

std::shared_ptr<const ModelTables> RegionCache::Tables() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->LoadedTables;
}

bool RegionCache::MissingLocked(Key key) const
{
  const auto found = this->Entries.find(key);
  return found == this->Entries.end() || (!found->second.buffers && !found->second.failed);
}

bool RegionCache::PendingLocked() const
{
  if (this->PropertyWanted || !this->TablesTried || this->NextCutPlaneLocked() >= 0 || this->CutLoading)
  {
    return true;
  }
  const auto missing = [&](Key key) { return this->MissingLocked(key); };
  if (std::any_of(this->Pinned.begin(), this->Pinned.end(), missing))
  {
    return true;
  }
  if (!this->WantedBlocked && std::any_of(this->Wanted.begin(), this->Wanted.end(), missing))
  {
    return true;
  }
  return !this->WantedBlocked && !this->PredictedBlocked &&
    std::any_of(this->Predicted.begin(), this->Predicted.end(), missing);
}

bool RegionCache::Pending() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  this->RescueIfStarvedLocked();
  return this->PendingLocked();
}

bool RegionCache::WaitIdle(std::chrono::milliseconds timeout) const
{
  return this->WaitWhile(timeout, &RegionCache::PendingLocked);
}

bool RegionCache::WaitWhile(std::chrono::milliseconds timeout, bool (RegionCache::*busy)() const) const
{
  std::unique_lock<std::mutex> lock(this->Lock);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  // Each load ends with Idle notified, so every mesh that arrives wakes this wait.
  while ((this->*busy)())
  {
    if (!this->WaitSliceLocked(lock, deadline))
    {
      return false;
    }
  }
  return true;
}

bool RegionCache::WaitSliceLocked(
  std::unique_lock<std::mutex>& lock, std::chrono::steady_clock::time_point deadline) const
{
  this->RescueIfStarvedLocked();
  const auto now = std::chrono::steady_clock::now();
  if (now >= deadline)
  {
    return false;
  }
  const std::chrono::steady_clock::duration slice = this->StarvationWindow / 2;
  this->Idle.wait_for(lock, std::min<std::chrono::steady_clock::duration>(deadline - now, slice));
  return true;
}

bool RegionCache::RootsMissingLocked() const
{
  return this->Error.empty() &&
    std::any_of(this->Pinned.begin(), this->Pinned.end(), [&](Key key) { return this->MissingLocked(key); });
}

bool RegionCache::RootsMissing() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->RootsMissingLocked();
}

bool RegionCache::WaitForRoots(std::chrono::milliseconds timeout)
{
  std::unique_lock<std::mutex> lock(this->Lock);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (this->RootsMissingLocked())
  {
    const auto waiting = std::find_if(this->Pinned.begin(), this->Pinned.end(),
      [&](Key key) { return this->MissingLocked(key) && !this->Loading.count(key); });
    if (this->HandednessKnown && waiting != this->Pinned.end())
    {
      this->LoadRegionLocked(lock, *waiting, Role::Essential); // at this thread's priority
      this->Idle.notify_all();
      this->Wake.notify_all();
      continue;
    }
    if (!this->WaitSliceLocked(lock, deadline))
    {
      return false;
    }
  }
  return true;
}

void RegionCache::SetStarvationWindow(std::chrono::milliseconds window)
{
  std::lock_guard<std::mutex> lock(this->Lock);
  this->StarvationWindow = std::max(window, std::chrono::milliseconds(1));
}

uint64_t RegionCache::StandbyRescues() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->Rescues;
}

void RegionCache::SetBudget(std::size_t bytes)
{
  {
    std::lock_guard<std::mutex> lock(this->Lock);
    this->BudgetBytes = bytes;
    // Evict at once what may go (neither a root nor wanted by the newest frame).
    for (Key key : this->EvictableLocked(std::numeric_limits<Key>::max()))
    {
      if (this->Bytes <= this->BudgetBytes)
      {
        break;
      }
      this->EvictLocked(key);
    }
    this->WantedBlocked = this->PredictedBlocked = false;
  }
  this->Wake.notify_all();
  this->StandbyWake.notify_all();
  this->Idle.notify_all();
}

std::size_t RegionCache::Budget() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->BudgetBytes;
}

std::size_t RegionCache::ResidentBytes() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->Bytes;
}

std::size_t RegionCache::ResidentCount() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->Resident;
}

uint64_t RegionCache::Generation() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->Changes;
}

std::string RegionCache::LastError() const
{
  std::lock_guard<std::mutex> lock(this->Lock);
  return this->Error;
}

bool RegionCache::EarlierWantedLoadingLocked(Key key, bool passIdle) const
{
  if (!this->InWanted.count(key))
  {
    return false;
  }
  const std::size_t at = this->WantedIndexLocked(key);
  return std::any_of(this->Loading.begin(), this->Loading.end(), [&](Key other) {
    return other != key && !(passIdle && this->IdleLoading.count(other)) && this->InWanted.count(other) &&
      this->WantedIndexLocked(other) < at;
  });
}

std::size_t RegionCache::WantedIndexLocked(Key key) const
{
  return static_cast<std::size_t>(std::find(this->Wanted.begin(), this->Wanted.end(), key) - this->Wanted.begin());
}

bool RegionCache::IsPinnedLocked(Key key) const
{
  return std::find(this->Pinned.begin(), this->Pinned.end(), key) != this->Pinned.end();
}

RegionCache::Key RegionCache::RequestKeyLocked(std::size_t region, int32_t layer, bool simplified) const
{
  const Key whole = this->KeyOf(region, layer);
  if (layer >= 0 || !this->SimplifiedSides || this->IsLeaf[region] || !(simplified || this->IsRoot[region]))
  {
    return whole;
  }
  // Resident with its exact side already: that copy serves, and nothing is read again.
  const auto found = this->Entries.find(whole);
  const bool haveWhole = found != this->Entries.end() && found->second.buffers;
  return haveWhole && !this->IsRoot[region] ? whole : this->KeyOf(region, this->SimplifiedLayer());
}

std::vector<RegionCache::Key> RegionCache::EvictableLocked(Key key) const
{
  // Loading a wanted region may evict predicted ones; loading anything else may not evict
  // what the newest frame wants or predicts. Roots never go.
  const bool wanted = this->InWanted.count(key) != 0;
  std::vector<std::pair<uint64_t, Key>> order;
  for (const auto& entry : this->Entries)
  {
    const Key k = entry.first;
    if (entry.second.buffers && k != key && !this->IsPinnedLocked(k) && !this->InWanted.count(k) &&
      (wanted || !this->InPredicted.count(k)))
    {
      order.emplace_back(entry.second.lastRequested, k);
    }
  }
  std::sort(order.begin(), order.end());
  std::vector<Key> keys;
  keys.reserve(order.size());
  for (const auto& o : order)
  {
    keys.push_back(o.second);
  }
  if (wanted)
  {
    // Then what the frame wants after it, the last first: the request is in order of need,
    // and loaders working side by side may have finished a later region first.
    const std::vector<Key> later = this->ResidentWantedFromLocked(this->WantedIndexLocked(key) + 1);
    keys.insert(keys.end(), later.begin(), later.end());
  }
  return keys;
}

std::vector<RegionCache::Key> RegionCache::ResidentWantedFromLocked(std::size_t first) const
{
  std::vector<Key> keys;
  for (std::size_t n = this->Wanted.size(); n-- > first;)
  {
    const auto found = this->Entries.find(this->Wanted[n]);
    if (found != this->Entries.end() && found->second.buffers && !this->IsPinnedLocked(this->Wanted[n]))
    {
      keys.push_back(this->Wanted[n]);
    }
  }
  return keys;
}

void RegionCache::EvictLocked(Key key)
{
  Entry& entry = this->Entries[key];
  if (entry.buffers)
  {
    this->Bytes -= entry.buffers->Bytes();
    entry.buffers.reset();
    --this->Resident;
    ++this->Changes;
  }
}

int64_t RegionCache::NextRegionLocked(bool roots)
{
  const auto missing = [&](Key key) { return this->MissingLocked(key); };
  for (Key key : this->Pinned)
  {
    if (missing(key) && !this->Loading.count(key))
    {
      if (!roots)
      {
        return -1; // the essential loader's, and nothing drawn before them
      }
      return static_cast<int64_t>(key);
    }
  }
  for (int list = 0; list < 2; ++list)
  {
    const bool wanted = list == 0;
    if (this->WantedBlocked || (!wanted && this->PredictedBlocked))
    {
      return -1;
    }
    for (Key key : wanted ? this->Wanted : this->Predicted)
    {
      if (!missing(key) || this->Loading.count(key))
      {
        continue; // loaded, or being read by another loader
      }
      // An entry refused earlier for the budget is not decoded again while it cannot fit.
      const std::size_t known = this->Entries[key].bytes;
      if (known > 0)
      {
        std::size_t freeable = 0;
        for (Key e : this->EvictableLocked(key))
        {
          freeable += this->Entries[e].buffers->Bytes();
        }
        if (this->Bytes - freeable + known > this->BudgetBytes)
        {
          (wanted ? this->WantedBlocked : this->PredictedBlocked) = true;
          this->WantedBlockedAt = wanted ? this->WantedIndexLocked(key) : this->WantedBlockedAt;
          break;
        }
      }
      return static_cast<int64_t>(key);
    }
  }
  return -1;
}

void RegionCache::InsertLocked(Key key, std::shared_ptr<const RegionDrawBuffers> buffers)
{
  Entry& entry = this->Entries[key];
  const std::size_t need = buffers->Bytes();
  entry.bytes = need;
  if (this->WantedBlocked && this->InWanted.count(key) && this->WantedIndexLocked(key) > this->WantedBlockedAt)
  {
    return; // read beside one that could not fit, which stopped the loading before it
  }
  if (this->IsPinnedLocked(key))
  {
    // A root goes in whatever the budget; what another loader put in meanwhile makes room,
    // the least needed first, so the roots and the budget hold together.
    std::vector<Key> order = this->EvictableLocked(std::numeric_limits<Key>::max());
    const std::vector<Key> wanted = this->ResidentWantedFromLocked(0);
    order.insert(order.end(), wanted.begin(), wanted.end());
    for (Key e : order)
    {
      if (this->Bytes + need <= this->BudgetBytes)
      {
        break;
      }
      this->EvictLocked(e);
    }
  }
  if (!this->IsPinnedLocked(key) && this->Bytes + need > this->BudgetBytes)
  {
    const bool inWanted = this->InWanted.count(key) != 0, inPredicted = this->InPredicted.count(key) != 0;
    const std::vector<Key> evictable = inWanted || inPredicted ? this->EvictableLocked(key) : std::vector<Key>();
    std::size_t freeable = 0;
    for (Key e : evictable)
    {
      freeable += this->Entries[e].buffers->Bytes();
    }
    if (this->Bytes - freeable + need > this->BudgetBytes)
    {
      // Loading stops here: the selection draws ancestors instead.
      if (inWanted)
      {
        this->WantedBlocked = true;
        this->WantedBlockedAt = this->WantedIndexLocked(key);
      }
      else if (inPredicted)
      {
        this->PredictedBlocked = true;
      }
      return;
    }
    for (Key e : evictable)
    {
      if (this->Bytes + need <= this->BudgetBytes)
      {
        break;
      }
      this->EvictLocked(e);
    }
  }
  this->Entries[key].buffers = std::move(buffers);
  this->Bytes += need;
  ++this->Resident;
  ++this->Changes;
}

void RegionCache::Run(Role role)
{
  const bool standby = role == Role::Standby;
#ifdef __linux__
  if (role == Role::Idle)
  {
    // Below the render thread: decompression must not take the cores a frame (or a software
    // rasterizer's threads) needs; it uses what the frames leave. Nice 19, not SCHED_IDLE: this
    // thread takes the cache's mutex for its bookkeeping, and a SCHED_IDLE thread preempted
    // while holding it on cores the machine's other work keeps busy waits for an idle core,
    // the render thread waiting on the mutex with it; at nice 19 the scheduler's fairness
    // bounds that wait. Nearer nice 0 it would take cores a frame's rasterizer threads need.
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  }
  else if (standby)
  {
    // The standby only loads while the idle loaders are starved (see RescueIfStarvedLocked): an
    // ordinary thread, below the render thread. (An unprivileged thread cannot lower its nice
    // value, so the idle loader cannot be raised instead.)
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 10);
  }
  // So profilers and the view bench can tell them apart.
  pthread_setname_np(
    pthread_self(), role == Role::Idle ? "resmr-loader" : (standby ? "resmr-standby" : "resmr-essential"));
#endif
  std::unique_lock<std::mutex> lock(this->Lock);
  while (!this->Stopping)
  {
    if (standby && !this->Rescuing)
    {
      this->StandbyWake.wait(lock);
      continue;
    }
    if (!this->LoadNextLocked(lock, role))
    {
      if (role != Role::Essential)
      {
        // Any loader may see the end of the work (another's last read in flight ends
        // it when nothing else is left).
        this->Rescuing = this->Rescuing && this->PendingLocked();
        this->Idle.notify_all();
      }
      (standby ? this->StandbyWake : this->Wake).wait(lock);
    }
  }
}

bool RegionCache::StandsInLocked() const
{
  return this->CurrentProperty && this->CurrentProperty->name == this->PropertyName &&
    this->CurrentProperty->layer == this->PropertyLayer;
}

bool RegionCache::EssentialPendingLocked() const
{
  if (!this->HandednessKnown)
  {
    return true;
  }
  const bool rootWaiting = std::any_of(this->Pinned.begin(), this->Pinned.end(),
    [&](Key key) { return this->MissingLocked(key) && !this->Loading.count(key); });
  const bool rootMissing =
    std::any_of(this->Pinned.begin(), this->Pinned.end(), [&](Key key) { return this->MissingLocked(key); });
  if (rootWaiting || (!rootMissing && !this->TablesTried && !this->TablesLoading))
  {
    return true;
  }
  if (this->PropertyWanted && this->TablesTried && !this->PropertyLoading && !this->StandsInLocked())
  {
    return true;
  }
  return !rootMissing && this->NextUrgentLocked() >= 0;
}

int64_t RegionCache::NextUrgentLocked() const
{
  if (!this->WantedUrgent || this->WantedBlocked)
  {
    return -1;
  }
  int64_t held = -1;
  for (Key key : this->Wanted)
  {
    if (!this->MissingLocked(key))
    {
      continue;
    }
    if (!this->Loading.count(key))
    {
      return static_cast<int64_t>(key);
    }
    if (held < 0 && this->IdleLoading.count(key) && !this->ReadAgain.count(key))
    {
      held = static_cast<int64_t>(key);
    }
  }
  return held;
}

void RegionCache::RescueIfStarvedLocked() const
{
#ifdef __linux__
  // Starved: work waited through a whole window while the idle loaders together ran for under
  // a tenth of it (the machine's other processes keep every core busy). A long read that runs
  // does not count, so the standby does not take a core from the frames for it.
  const auto window = this->StarvationWindow;
  const auto now = std::chrono::steady_clock::now();
  double cpuSeconds = 0;
  for (const clockid_t clock : this->LoaderClocks)
  {
    timespec cpu{};
    if (clock_gettime(clock, &cpu) != 0)
    {
      return;
    }
    cpuSeconds += cpu.tv_sec + 1e-9 * cpu.tv_nsec;
  }
  if (this->LoaderClocks.empty())
  {
    return;
  }
  if (!this->PendingLocked())
  {
    this->Rescuing = false; // the work is done: the next wait is the idle loaders' again
  }
  if (this->Rescuing || !this->PendingLocked())
  {
    this->WindowStart = now;
    this->WindowCpuSeconds = cpuSeconds;
    return;
  }
  const double elapsed = std::chrono::duration<double>(now - this->WindowStart).count();
  if (now - this->WindowStart < window)
  {
    return;
  }
  if (cpuSeconds - this->WindowCpuSeconds < 0.1 * elapsed)
  {
    this->Rescuing = true;
    ++this->Rescues;
    this->StandbyWake.notify_all();
  }
  this->WindowStart = now;
  this->WindowCpuSeconds = cpuSeconds;
#endif
}

bool RegionCache::LoadNextLocked(std::unique_lock<std::mutex>& lock, Role role)
{
  const bool essentialOnly = role == Role::Essential;
  if (essentialOnly && !this->EssentialPendingLocked())
  {
    return false;
  }
  // The handedness, the roots first (the first image), then the model's tables and the
  // property (colour), then the regions the view wants. What the picture cannot do without
  // is read by the essential loader alone: a loader below the process's priority that took
  // it held it, and the picture with it, for as long as the machine's other work starved
  // that loader (on a busy machine the tables, so the colours, never came in a 100 s flight).
  // A property an earlier step of it stands in for is the other loaders' work. A property
  // waits for missing roots: a frame blocks on the roots (WaitForRoots), and a filter
  // change's masked roots waited 0.5 s behind a 96 MB table on the 100M model.
  const bool rootMissing =
    std::any_of(this->Pinned.begin(), this->Pinned.end(), [&](Key key) { return this->MissingLocked(key); });
  if (!this->HandednessKnown)
  {
    if (!essentialOnly)
    {
      return false; // regions need it
    }
    this->LoadHandednessLocked(lock);
  }
  else if (essentialOnly && !this->TablesTried && !this->TablesLoading && !rootMissing)
  {
    this->LoadTablesLocked(lock);
  }
  else if (this->PropertyWanted && this->TablesTried && !this->PropertyLoading && !rootMissing &&
    essentialOnly != this->StandsInLocked())
  {
    this->LoadPropertyLocked(lock);
  }
  else if (!essentialOnly && !this->CutLoading && !rootMissing && this->NextCutPlaneLocked() >= 0)
  {
    this->LoadCutPlaneLocked(lock, static_cast<std::size_t>(this->NextCutPlaneLocked()));
  }
  else
  {
    int64_t next = this->NextRegionLocked(essentialOnly);
    if (essentialOnly && (next < 0 || !this->IsPinnedLocked(static_cast<Key>(next))))
    {
      next = rootMissing ? -1 : this->NextUrgentLocked();
    }
    if (next < 0)
    {
      return false;
    }
    this->LoadRegionLocked(lock, static_cast<Key>(next), role);
  }
  this->Idle.notify_all();
  this->Wake.notify_all(); // work that waited on this (the tables on the roots) may go
  return true;
}

void RegionCache::LoadHandednessLocked(std::unique_lock<std::mutex>& lock)
{
  // Both loaders may compute it at once: it is the same either way.
  lock.unlock();
  int handedness = 1;
  std::string failure;
  try
  {
    handedness = TopologyHandedness(*this->File);
  }
  catch (const std::exception& error)
  {
    failure = error.what();
  }
  lock.lock();
  this->Handedness = handedness;
  this->HandednessKnown = true;
  if (!failure.empty())
  {
    this->Error = failure;
  }
}

void RegionCache::LoadTablesLocked(std::unique_lock<std::mutex>& lock)
{
  this->TablesLoading = true;
  std::shared_ptr<ModelTables> tables = std::make_shared<ModelTables>();
  tables->handedness = this->Handedness; // known before the tables are read
  lock.unlock();
  std::string error;
  try
  {
    tables->hash = this->File->ReadHash();
    tables->normals = this->File->ReadModelArray(ModelChunk::CellNormals);
    try
    {
      tables->walls = this->File->ReadWallDepths();
      const float below = static_cast<float>(-this->ModelOrigin[2]); // the origin's depth
      for (std::size_t t = 0; t < tables->walls.texels.size(); t += 3)
      {
        tables->walls.texels[t] -= below;
        tables->walls.texels[t + 1] -= below;
      }
    }
    catch (const FileFormatError& e)
    {
      // Only the walls' layers are lost: they are painted as before, from the coordinates.
      tables->walls = WallDepthTable{};
      tables->wallsError = e.what();
    }
  }
  catch (const std::exception& e)
  {
    tables.reset();
    error = e.what();
  }
  lock.lock();
  this->TablesLoading = false;
  this->TablesTried = true;
  this->LoadedTables = tables;
  if (!error.empty())
  {
    this->Error = error;
  }
}

void RegionCache::LoadPropertyLocked(std::unique_lock<std::mutex>& lock)
{
  const std::string name = this->PropertyName;
  const int32_t step = this->PropertyStep;
  const int32_t layer = this->PropertyLayer;
  this->PropertyLoading = true;
  lock.unlock();
  std::shared_ptr<PropertyTableData> table;
  std::string error;
  try
  {
    const int index = this->Properties ? this->Properties->Find(name, step) : -1;
    if (index < 0)
    {
      error = (this->Properties ? this->Properties->Path() : std::string("no property file")) + ": property " + name +
        " step " + std::to_string(step) + " not found";
    }
    else
    {
      table = std::make_shared<PropertyTableData>();
      table->name = name;
      table->step = step;
      table->layer = layer;
      table->values = layer < 0 ? this->Properties->ReadPacked(static_cast<std::size_t>(index))
                                : this->Properties->ReadLayer(static_cast<std::size_t>(index), layer);
    }
  }
  catch (const std::exception& e)
  {
    table.reset();
    error = "property " + name + " step " + std::to_string(step) +
      (layer >= 0 ? " layer " + std::to_string(layer + 1) : std::string()) + ": " + e.what();
  }
  lock.lock();
  this->PropertyLoading = false;
  if (name == this->PropertyName && step == this->PropertyStep && layer == this->PropertyLayer)
  {
    this->PropertyWanted = false;
    this->CurrentProperty = table; // null when the table could not be read
    if (!error.empty())
    {
      this->Error = error;
    }
  }
}

void RegionCache::LoadRegionLocked(std::unique_lock<std::mutex>& lock, Key key, Role role)
{
  const std::size_t region = this->RegionOf(key);
  const int32_t layer = this->LayerOf(key);
  const int handedness = this->Handedness;
  const bool ranged = layer == this->RangeLayer();
  const CellFilter filter = this->CurrentFilter;
  if (ranged && key != this->KeyOf(region, layer))
  {
    this->Entries[key].failed = true; // an earlier range's: nothing asks for it any more
    return;
  }
  // The essential loader may read again what a starved idle loader holds (NextUrgentLocked):
  // whichever read ends first goes in.
  const bool again = this->Loading.count(key) != 0;
  (again ? this->ReadAgain : this->Loading).insert(key);
  if (role == Role::Idle)
  {
    this->IdleLoading.insert(key);
  }
  lock.unlock();
  std::shared_ptr<RegionDrawBuffers> buffers;
  std::string error;
  try
  {
    // ReadRegion, not ReadRegionSurfaces: the buffers need the positions.
    const bool simplified = layer == this->SimplifiedLayer();
    buffers = std::make_shared<RegionDrawBuffers>(LoadRegionDrawBuffers(*this->File, region, this->ModelOrigin,
      handedness, simplified || ranged ? -1 : layer, !simplified, ranged ? &filter : nullptr));
  }
  catch (const std::exception& e)
  {
    error = e.what();
  }
  lock.lock();
  // Regions go in in the request's order: one read beside an earlier one waits for it, so
  // that loading stops at the first region that cannot fit, as with one loader. Not for the
  // idle loaders' reads, though: on a busy machine they may not run for seconds, and the
  // standby and essential loaders waiting on them brought in almost nothing (a 100 s flight of
  // the 100M model with two cores busy held under 60 MB of 512); the earlier region, when it
  // comes, evicts later ones to fit (InsertLocked).
  while (!again && !this->Stopping && this->EarlierWantedLoadingLocked(key, role != Role::Idle))
  {
    this->Idle.wait(lock);
  }
  if (again)
  {
    this->ReadAgain.erase(key);
  }
  else
  {
    this->Loading.erase(key);
    this->IdleLoading.erase(key);
  }
  this->Idle.notify_all();
  if (this->Stopping || !this->MissingLocked(key))
  {
    return; // the other read of it went in first
  }
  if (!error.empty())
  {
    this->Entries[key].failed = true;
    this->Error = error;
  }
  else
  {
    this->InsertLocked(key, std::move(buffers));
  }
}

} // namespace resmr
