// Tests of the side surface simplification (paper Sec. 4.3): hand-built walls (planar walls
// reduced to their borders, curved walls kept exact at error 0, time on a large surface), then
// every region of synthetic hierarchies: locked vertices kept, border edges unchanged, no
// degenerate or turned triangle, every removed vertex within the error of the output and of
// where the output paints its topological coordinate, the
// reduction above the leaves, determinism.
#include "CoreTesting.h"

#include "HierarchyBuilder.h"
#include "LayerSource.h"
#include "MultiresolutionFile.h"
#include "RegionMesh.h"
#include "SideSurfaceSimplification.h"
#include "SyntheticReservoir.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <unistd.h>

using namespace resmr;

namespace
{
using Triangles = std::vector<std::array<uint32_t, 3>>;
using Edge = std::pair<uint32_t, uint32_t>;

std::string TempPath(const std::string& name)
{
  return "/tmp/resmr-test-" + std::to_string(getpid()) + "-" + name;
}

glm::dvec3 At(const RegionMesh& mesh, uint32_t vertex)
{
  const double* p = &mesh.positions[static_cast<std::size_t>(vertex) * 3];
  return { p[0], p[1], -p[2] };
}

glm::dvec3 NormalOf(const RegionMesh& mesh, const std::array<uint32_t, 3>& t)
{
  return glm::cross(At(mesh, t[1]) - At(mesh, t[0]), At(mesh, t[2]) - At(mesh, t[0]));
}

/// Distance of p to the triangle, from barycentric clamping on the three edges when the
/// projection falls outside (independent of the library's closest-point code).
double Distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
  const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  const glm::dvec3 q = p - glm::dot(p - a, n) * n;
  const bool inside = glm::dot(glm::cross(b - a, q - a), n) >= 0 && glm::dot(glm::cross(c - b, q - b), n) >= 0 &&
    glm::dot(glm::cross(a - c, q - c), n) >= 0;
  if (inside)
  {
    return std::fabs(glm::dot(p - a, n));
  }
  double best = std::numeric_limits<double>::infinity();
  for (const auto& e : { std::make_pair(a, b), std::make_pair(b, c), std::make_pair(c, a) })
  {
    const glm::dvec3 d = e.second - e.first;
    const double s = std::clamp(glm::dot(p - e.first, d) / glm::dot(d, d), 0.0, 1.0);
    best = std::min(best, glm::length(p - (e.first + s * d)));
  }
  return best;
}

/// The triangle turned to start at its smallest vertex (the same triangle, the same turn).
std::array<uint32_t, 3> Rotated(const std::array<uint32_t, 3>& t)
{
  const int first = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
  return { t[first], t[(first + 1) % 3], t[(first + 2) % 3] };
}

/// Directed edges used by one triangle, with the edge walked either way counted together.
std::set<Edge> BorderEdges(const Triangles& triangles)
{
  std::map<Edge, int> uses;
  for (const auto& t : triangles)
  {
    for (int i = 0; i < 3; ++i)
    {
      const uint32_t a = t[i], b = t[(i + 1) % 3];
      ++uses[{ std::min(a, b), std::max(a, b) }];
    }
  }
  std::set<Edge> border;
  for (const auto& t : triangles)
  {
    for (int i = 0; i < 3; ++i)
    {
      const uint32_t a = t[i], b = t[(i + 1) % 3];
      if (uses[{ std::min(a, b), std::max(a, b) }] == 1)
      {
        border.insert({ a, b });
      }
    }
  }
  return border;
}

using Box = std::pair<glm::dvec3, glm::dvec3>;

std::vector<Box> BoxesOf(const RegionMesh& mesh, const Triangles& triangles)
{
  std::vector<Box> boxes;
  for (const auto& t : triangles)
  {
    const glm::dvec3 a = At(mesh, t[0]), b = At(mesh, t[1]), c = At(mesh, t[2]);
    boxes.push_back({ glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)) });
  }
  return boxes;
}

/// Distance of p to the box: a lower bound of its distance to what the box holds.
double BoxDistance(const glm::dvec3& p, const Box& box)
{
  return glm::length(glm::max(glm::dvec3(0.0), glm::max(box.first - p, p - box.second)));
}

struct Measured
{
  int64_t input = 0, output = 0, removed = 0;
  double farthest = 0;  ///< of a removed vertex from the output
  double misplaced = 0; ///< of a removed vertex from where the output paints its coordinate
};

/// Topological coordinate (ti, tj, tk) of a vertex: what the viewer interpolates to paint.
glm::dvec3 TopologyOf(const RegionMesh& mesh, uint32_t vertex)
{
  const uint32_t interfaces = static_cast<uint32_t>(mesh.layers + 1);
  const auto& node = mesh.topology[vertex / interfaces];
  return { node[0], node[1], static_cast<double>(vertex % interfaces) };
}

/// Distance from vertex v to the point where `output` paints v's topological coordinate: on
/// the triangle whose interpolated coordinates hold it (least squares off the triangle's
/// plane of coordinates), the least outside one where none holds it.
double PaintedDistance(const RegionMesh& mesh, const Triangles& output, uint32_t v)
{
  const glm::dvec3 t = TopologyOf(mesh, v);
  double outside = std::numeric_limits<double>::infinity(), distance = outside;
  for (const auto& o : output)
  {
    const glm::dvec3 ta = TopologyOf(mesh, o[0]), tb = TopologyOf(mesh, o[1]), tc = TopologyOf(mesh, o[2]);
    const glm::dvec3 low = glm::min(ta, glm::min(tb, tc)), high = glm::max(ta, glm::max(tb, tc));
    if (outside == 0 && (glm::any(glm::lessThan(t, low - 1e-6)) || glm::any(glm::greaterThan(t, high + 1e-6))))
    {
      continue; // a triangle holding it is found; this one cannot
    }
    const glm::dvec3 e1 = tb - ta, e2 = tc - ta, d = t - ta;
    const double a11 = glm::dot(e1, e1), a12 = glm::dot(e1, e2), a22 = glm::dot(e2, e2);
    const double det = a11 * a22 - a12 * a12;
    if (!(det > 1e-12 * a11 * a22))
    {
      continue;
    }
    const double u = (a22 * glm::dot(e1, d) - a12 * glm::dot(e2, d)) / det;
    const double w = (a11 * glm::dot(e2, d) - a12 * glm::dot(e1, d)) / det;
    const double out = std::max({ 0.0, -u - 1e-9, -w - 1e-9, u + w - 1 - 1e-9 });
    const glm::dvec3 a = At(mesh, o[0]);
    const double error = glm::length(a + u * (At(mesh, o[1]) - a) + w * (At(mesh, o[2]) - a) - At(mesh, v));
    if (out < outside || (out == outside && error < distance))
    {
      outside = out;
      distance = error;
    }
  }
  return distance;
}

/// Simplifies the region's side surface and checks the contract; returns the counts.
Measured CheckRegion(const RegionMesh& mesh, double maxError, const std::string& label)
{
  Measured m;
  const Triangles input = TriangulateSideSurface(mesh);
  SideSimplificationStats stats;
  const Triangles output = SimplifySideSurface(mesh, maxError, &stats);
  m.input = static_cast<int64_t>(input.size());
  m.output = static_cast<int64_t>(output.size());
  CHECK(stats.inputTriangles == m.input && stats.outputTriangles == m.output);
  CHECK(m.output <= m.input);
  CHECK(SimplifySideSurface(mesh, maxError) == output); // deterministic

  // The input: each quad as two triangles, fewer where pinched.
  CHECK(input.size() <= 2 * mesh.side.quads.size());

  std::set<uint32_t> used, kept;
  glm::dvec3 low(std::numeric_limits<double>::infinity()), high(-std::numeric_limits<double>::infinity());
  for (const auto& t : input)
  {
    for (uint32_t v : t)
    {
      used.insert(v);
      low = glm::min(low, At(mesh, v));
      high = glm::max(high, At(mesh, v));
    }
  }
  for (const auto& t : output)
  {
    kept.insert(t.begin(), t.end());
  }
  CHECK(std::includes(used.begin(), used.end(), kept.begin(), kept.end()));
  const double tolerance = 1e-9 * (used.empty() ? 0 : glm::length(high - low));

  // Rules 1 and 2: top and bottom vertices and the nodes of cut edges stay.
  std::set<uint32_t> locked;
  for (const RegionSurface* s : { &mesh.top, &mesh.bottom })
  {
    for (const auto& q : s->quads)
    {
      locked.insert(q.begin(), q.end());
    }
  }
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      if (mesh.cutEdges[c] & (1u << e))
      {
        for (uint32_t node : { mesh.corners[c][e], mesh.corners[c][(e + 1) % 4] })
        {
          for (int32_t k = 0; k <= mesh.layers; ++k)
          {
            locked.insert(mesh.Vertex(node, k));
          }
        }
      }
    }
  }
  int64_t lost = 0;
  for (uint32_t v : used)
  {
    lost += locked.count(v) && !kept.count(v);
  }
  CHECK(lost == 0);

  // The border is untouched: border vertices are locked, so the edges are the same.
  CHECK(BorderEdges(output) == BorderEdges(input));

  std::map<uint32_t, std::vector<uint32_t>> incident;
  for (std::size_t s = 0; s < input.size(); ++s)
  {
    for (uint32_t v : input[s])
    {
      incident[v].push_back(static_cast<uint32_t>(s));
    }
  }
  // No degenerate triangle (a changed one no thinner than 1e-6), none repeated; each faces as
  // the input surface under it.
  std::set<std::array<uint32_t, 3>> distinct, original;
  for (const auto& t : input)
  {
    original.insert(Rotated(t));
  }
  int64_t thin = 0, turned = 0;
  for (const auto& t : output)
  {
    std::array<uint32_t, 3> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    distinct.insert(sorted);
    const glm::dvec3 n = NormalOf(mesh, t);
    const glm::dvec3 a = At(mesh, t[0]), b = At(mesh, t[1]), c = At(mesh, t[2]);
    const double longest = std::max({ glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c) });
    if (!(glm::length(n) > (original.count(Rotated(t)) ? 1e-12 : 0.999e-6) * longest))
    {
      ++thin;
      continue;
    }
    // Facing as the input around it: at each corner, some input triangle of that vertex faces
    // the same way. (Nearest input triangles would not do: the two faces of a fault lie back
    // to back closer than the error.)
    for (uint32_t v : t)
    {
      const auto& around = incident[v];
      const bool agrees = std::any_of(
        around.begin(), around.end(), [&](uint32_t s) { return glm::dot(n, NormalOf(mesh, input[s])) > 0; });
      turned += !agrees;
    }
  }
  CHECK(thin == 0);
  CHECK(turned == 0);
  CHECK(distinct.size() == output.size());

  // One-sided distance: every removed vertex within the error of the output (bounding boxes
  // first, then the exact distance).
  const auto boxes = BoxesOf(mesh, output);
  const double reach = maxError + tolerance;
  for (uint32_t v : used)
  {
    if (kept.count(v))
    {
      continue;
    }
    ++m.removed;
    const glm::dvec3 p = At(mesh, v);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < output.size(); ++t)
    {
      if (BoxDistance(p, boxes[t]) <= std::min(best, reach))
      {
        const auto& o = output[t];
        best = std::min(best, Distance(p, At(mesh, o[0]), At(mesh, o[1]), At(mesh, o[2])));
      }
    }
    m.farthest = std::max(m.farthest, best);
    m.misplaced = std::max(m.misplaced, PaintedDistance(mesh, output, v));
  }
  CHECK(m.farthest <= reach * (1 + 1e-9));
  // Its cell corner is painted within the error of its place too.
  CHECK(m.misplaced <= reach * (1 + 1e-9));
  // The reported error is the largest distance (measured to the nearest triangle it rides on).
  CHECK(stats.largestError <= reach);
  CHECK(m.removed == 0 || stats.largestError >= m.farthest * (1 - 1e-6) - tolerance);
  if (m.farthest > reach * (1 + 1e-9) || m.misplaced > reach * (1 + 1e-9) || lost || turned || thin)
  {
    std::fprintf(stderr, "%s: farthest %g, painted %g away (error %g), %lld locked lost, %lld turned, %lld thin\n",
      label.c_str(), m.farthest, m.misplaced, maxError, static_cast<long long>(lost), static_cast<long long>(turned),
      static_cast<long long>(thin));
  }
  return m;
}

/// An nx x ny block of columns on vertical or bent pillars, every cell active. `bend` moves
/// interface k of every pillar outward in x and y by bend * k^2 (curved walls);
/// `slope` tilts the layers, so quads are planar only where `bend` is 0; `uneven` makes the
/// layers' thickness 3 +- uneven, odd layers thicker.
RegionMesh Block(int nx, int ny, int layers, double bend, double slope, double uneven = 0)
{
  RegionMesh mesh;
  mesh.layers = layers;
  for (int j = 0; j <= ny; ++j)
  {
    for (int i = 0; i <= nx; ++i)
    {
      mesh.topology.push_back({ static_cast<float>(i), static_cast<float>(j) });
      for (int k = 0; k <= layers; ++k)
      {
        // Rows of a wall stay straight: the walls are cylinders bent in depth.
        const double outX = (2 * i > nx) - (2 * i < nx), outY = (2 * j > ny) - (2 * j < ny);
        mesh.positions.push_back(100.0 * i + bend * k * k * outX);
        mesh.positions.push_back(100.0 * j + bend * k * k * outY);
        mesh.positions.push_back(2000.0 + 3.0 * k + uneven * (k % 2) + slope * i);
      }
    }
  }
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i)
    {
      const uint32_t n = static_cast<uint32_t>(j * (nx + 1) + i), row = static_cast<uint32_t>(nx + 1);
      mesh.corners.push_back({ n, n + 1, n + row + 1, n + row });
    }
  }
  mesh.active.assign(mesh.corners.size() * static_cast<std::size_t>(layers), 1);
  mesh.cutEdges.assign(mesh.corners.size(), 0);
  ComputeOpenSides(mesh);
  ExtractSurfaces(mesh);
  return mesh;
}

void TestHandBuilt()
{
  // Planar walls on vertical pillars: everything but the top and bottom rows goes, each wall
  // becomes a fan of its border (2n triangles for n + 1 top and n + 1 bottom vertices), the
  // same count as a single-layer block.
  for (const double slope : { 0.0, 0.7 })
  {
    const RegionMesh planar = Block(7, 3, 12, 0, slope);
    const Measured m = CheckRegion(planar, 0, "planar block");
    CHECK(m.input == 2 * 2 * (7 + 3) * 12);
    CHECK(m.output == 2 * 2 * (7 + 3));
    CHECK(m.farthest <= 1e-9);
  }
  // Planar walls of uneven layers: a wall cannot become one fan of its border, whose
  // interpolated layers would stray from the true ones; at error 0 every interface stays,
  // only the vertices inside a row go (each row a straight line of evenly spaced columns).
  // An error of a layer's thickness lets interfaces go.
  const RegionMesh uneven = Block(7, 3, 12, 0, 0.7, 1.0);
  const Measured inPlace = CheckRegion(uneven, 0, "uneven layers, error 0");
  CHECK(inPlace.misplaced <= 1e-9);
  CHECK(inPlace.output < inPlace.input && inPlace.output > 2 * 2 * (7 + 3)); // more than the border's fan
  const Measured layered = CheckRegion(uneven, 3.0, "uneven layers, error 3");
  CHECK(layered.output < inPlace.output && layered.misplaced > 0.1);

  // Curved walls at error 0: only vertices lying on the surface left may go (collinear along a
  // wall's rows); a larger error removes more.
  const RegionMesh curved = Block(6, 5, 10, 0.4, 0.3);
  const Measured exact = CheckRegion(curved, 0, "curved block, error 0");
  CHECK(exact.output < exact.input && exact.farthest <= 1e-9);
  const Measured loose = CheckRegion(curved, 2.0, "curved block, error 2");
  CHECK(loose.output < exact.output && loose.farthest > 0.1);
  CHECK(SimplifySideSurface(curved, std::nan("")) == SimplifySideSurface(curved, 0));
  CHECK(SimplifySideSurface(curved, -1) == SimplifySideSurface(curved, 0));

  // A cut edge locks its two nodes' vertices, and only active cells count: a column with an
  // inactive middle cell brings top and bottom faces inside (rule 1).
  RegionMesh cut = Block(4, 4, 8, 0.2, 0);
  cut.cutEdges[0] = 1; // edge 0 of column 0 borders another region
  cut.active[static_cast<std::size_t>(5 * 8 + 3)] = 0;
  ComputeOpenSides(cut);
  ExtractSurfaces(cut);
  CheckRegion(cut, 0.5, "cut block");

  // Time on a large side surface: 125 x 125 columns of 100 layers, 100,000 triangles.
  const RegionMesh large = Block(125, 125, 100, 0.002, 0.5);
  const auto start = std::chrono::steady_clock::now();
  SideSimplificationStats stats;
  const Triangles simplified = SimplifySideSurface(large, 0.5, &stats);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("large block: %lld -> %lld side triangles in %.3f s (largest error %.3g)\n",
    static_cast<long long>(stats.inputTriangles), static_cast<long long>(stats.outputTriangles), seconds,
    stats.largestError);
  CHECK(stats.inputTriangles == 100000 && !simplified.empty());
  CHECK(stats.outputTriangles < stats.inputTriangles / 4);
}

/// Every region of a synthetic hierarchy; returns input and output triangles by level.
std::map<int, Measured> CheckHierarchy(const SyntheticParameters& p, int64_t cmax, bool exact, const std::string& name)
{
  const std::string path = TempPath(name + ".resmr");
  HierarchyOptions options;
  options.cmax = cmax;
  options.threads = 2;
  SyntheticLayerSource source(p, "synth:" + name);
  const HierarchyReport report = BuildHierarchy(source, path, options);
  const MultiresolutionFile file(path);
  // Positions read back lie on the lattice: walls planar before are planar to within a step.
  const auto& step = file.Header().latticeStep;
  const double lattice = std::sqrt(step[0] * step[0] + step[1] * step[1] + step[2] * step[2]);
  std::map<int, Measured> levels;
  double slowest = 0;
  for (std::size_t i = 0; i < file.Regions().size(); ++i)
  {
    const RegionRecord& r = file.Regions()[i];
    RegionMesh mesh = file.ReadRegion(i);
    if (mesh.side.quads.empty())
    {
      ExtractSurfaces(mesh);
    }
    const std::string label = name + " level " + std::to_string(r.level) + " region " + std::to_string(r.index);
    const auto start = std::chrono::steady_clock::now();
    SimplifySideSurface(mesh, r.error + lattice);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    slowest = std::max(slowest, took.count());
    const Measured m = CheckRegion(mesh, r.error + lattice, label);
    Measured& level = levels[r.level];
    level.input += m.input;
    level.output += m.output;
    level.removed += m.removed;
    level.farthest = std::max(level.farthest, m.farthest);
    if (exact && r.level < report.leafLevel)
    {
      // Error 0 on walls bent by the column collapse: nothing may leave the surface.
      CheckRegion(mesh, 0, label + ", error 0");
    }
  }
  for (const auto& e : levels)
  {
    const Measured& l = e.second;
    std::printf("%s level %d%s: side triangles %lld -> %lld (%.1f%% fewer), farthest removed vertex %.3g\n",
      name.c_str(), e.first, e.first == report.leafLevel ? " (leaves)" : "", static_cast<long long>(l.input),
      static_cast<long long>(l.output), 100.0 * (1.0 - double(l.output) / double(l.input)), l.farthest);
  }
  std::printf("%s: slowest region %.3f s\n", name.c_str(), slowest);
  std::remove(path.c_str());
  CHECK(report.leafLevel >= 2);
  return levels;
}

void TestHierarchies()
{
  SyntheticParameters small;
  small.nx = 60;
  small.ny = 48;
  small.nz = 6;
  small.seed = 3;
  CheckHierarchy(small, 64, true, "small");

  // Many layers: most of the side surface goes where layers are many.
  SyntheticParameters layered;
  layered.nx = 40;
  layered.ny = 40;
  layered.nz = 30;
  layered.seed = 5;
  const auto levels = CheckHierarchy(layered, 64, false, "layered");
  const int leaf = levels.rbegin()->first;
  const Measured& above = levels.at(leaf - 1);
  CHECK(above.output <= 0.6 * above.input);
}

/// Every edge of the quads used once each way (by position), so the surface is closed.
bool Closed(const RegionMesh& mesh)
{
  std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, int> balance;
  const auto at = [&](uint32_t v) {
    const double* p = &mesh.positions[static_cast<std::size_t>(v) * 3];
    return std::array<double, 3>{ p[0], p[1], p[2] };
  };
  for (const RegionSurface* surface : { &mesh.top, &mesh.bottom, &mesh.side })
  {
    for (const auto& q : surface->quads)
    {
      for (int v = 0; v < 4; ++v)
      {
        const auto a = at(q[v]), b = at(q[(v + 1) % 4]);
        if (a != b)
        {
          a < b ? ++balance[{ a, b }] : --balance[{ b, a }];
        }
      }
    }
  }
  return std::all_of(balance.begin(), balance.end(), [](const auto& e) { return e.second == 0; });
}

void TestSealedPinchOuts()
{
  // Two columns of three layers; the middle layer is inactive and 5 mm thick (layer 1's
  // interfaces moved together), the outer ones active.
  RegionMesh mesh = Block(2, 1, 3, 0, 0);
  for (std::size_t v = 0; v < mesh.positions.size() / 3; ++v)
  {
    const int k = static_cast<int>(v % 4);
    if (k >= 2)
    {
      mesh.positions[v * 3 + 2] -= 3.0 - 0.005;
    }
  }
  for (std::size_t c = 0; c < 2; ++c)
  {
    mesh.active[c * 3 + 1] = 0;
  }
  ComputeOpenSides(mesh);
  const auto extract = [&](double thickness, uint8_t cutOfSecond) {
    mesh.sealedPinchThickness = thickness;
    mesh.cutEdges = { 0, cutOfSecond };
    ExtractSurfaces(mesh);
    return std::array<std::size_t, 3>{ mesh.top.quads.size(), mesh.bottom.quads.size(), mesh.side.quads.size() };
  };
  // Unsealed: both active cells of a column show their top and bottom, and 3 open sides each.
  CHECK((extract(0, 0) == std::array<std::size_t, 3>{ 4, 4, 12 }));
  CHECK(Closed(mesh));
  CHECK((extract(0.004, 0) == std::array<std::size_t, 3>{ 4, 4, 12 })); // thicker than allowed
  // Sealed: one top and one bottom a column; the thin run's own outer sides close the gap.
  CHECK((extract(0.01, 0) == std::array<std::size_t, 3>{ 2, 2, 18 }));
  CHECK(Closed(mesh));
  // A column with a cut edge is never sealed (the region across decides for its cells): the
  // first column's sealed cell then shows a side to the second's open run.
  CHECK((extract(0.01, 1) == std::array<std::size_t, 3>{ 3, 3, 16 }));
  CHECK(Closed(mesh));
  // A thin run at the top of a column is the model's surface, never sealed: the first
  // column's top is its third layer's.
  mesh.active[0] = 0;
  ComputeOpenSides(mesh);
  CHECK((extract(0.01, 0) == std::array<std::size_t, 3>{ 2, 2, 3 + 4 + 4 + 3 }));
  CHECK(Closed(mesh));
}
} // namespace

int main()
{
  TestHandBuilt();
  TestSealedPinchOuts();
  TestHierarchies();
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d check(s) failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("all side surface checks passed\n");
  return 0;
}
