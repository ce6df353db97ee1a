// Hexahedron quality and boundary Hausdorff distance (checks of paper Sec. 4.1's goals).
#include "MeshQuality.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace resmr
{
namespace
{
glm::dvec3 PointAt(const HexMesh& mesh, int64_t id)
{
  const double* p = &mesh.points[static_cast<std::size_t>(id) * 3];
  return { p[0], p[1], p[2] };
}

struct FaceKey
{
  std::array<int64_t, 4> ids;
  bool operator==(const FaceKey& other) const { return this->ids == other.ids; }
};
struct FaceHash
{
  std::size_t operator()(const FaceKey& key) const
  {
    uint64_t h = 1469598103934665603ull;
    for (int64_t id : key.ids)
    {
      h = (h ^ static_cast<uint64_t>(id)) * 1099511628211ull;
    }
    return static_cast<std::size_t>(h);
  }
};

/// The six faces of cell `cell`, as corner lists: top, bottom, then the four sides.
std::array<std::array<int64_t, 4>, 6> Faces(const std::array<int64_t, 8>& c)
{
  return { { { c[0], c[1], c[2], c[3] }, { c[4], c[7], c[6], c[5] }, { c[0], c[4], c[5], c[1] },
    { c[1], c[5], c[6], c[2] }, { c[2], c[6], c[7], c[3] }, { c[3], c[7], c[4], c[0] } } };
}

struct Triangle
{
  glm::dvec3 a, b, c;
};

/// Calls `visit(face, key)` for each face of each active cell, `key` its sorted node ids.
template<typename Visit>
void ForEachActiveFace(const HexMesh& mesh, Visit visit)
{
  for (std::size_t c = 0; c < mesh.cells.size(); ++c)
  {
    if (!mesh.active[c])
    {
      continue;
    }
    for (const auto& face : Faces(mesh.cells[c]))
    {
      FaceKey key{ face };
      std::sort(key.ids.begin(), key.ids.end());
      visit(face, key);
    }
  }
}

/// External faces of active cells (those only one active cell has), split into triangles.
std::vector<Triangle> BoundaryTriangles(const HexMesh& mesh, std::vector<std::array<glm::dvec3, 4>>& quads)
{
  std::unordered_map<FaceKey, int, FaceHash> count;
  count.reserve(mesh.cells.size() * 3);
  ForEachActiveFace(mesh, [&](const auto&, const FaceKey& key) { ++count[key]; });
  std::vector<Triangle> triangles;
  quads.clear();
  ForEachActiveFace(mesh, [&](const auto& face, const FaceKey& key) {
    if (count[key] != 1)
    {
      return;
    }
    const std::array<glm::dvec3, 4> p = { PointAt(mesh, face[0]), PointAt(mesh, face[1]), PointAt(mesh, face[2]),
      PointAt(mesh, face[3]) };
    quads.push_back(p);
    triangles.push_back({ p[0], p[1], p[2] });
    triangles.push_back({ p[0], p[2], p[3] });
  });
  return triangles;
}

/// Closest point on a triangle (Ericson, Real-Time Collision Detection 5.1.5).
double SquaredDistance(const glm::dvec3& p, const Triangle& t)
{
  const glm::dvec3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  auto squared = [&](const glm::dvec3& q) { return glm::dot(p - q, p - q); };
  if (d1 <= 0 && d2 <= 0)
  {
    return squared(t.a);
  }
  const glm::dvec3 bp = p - t.b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3)
  {
    return squared(t.b);
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
  {
    return squared(t.a + ab * (d1 / (d1 - d3)));
  }
  const glm::dvec3 cp = p - t.c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6)
  {
    return squared(t.c);
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
  {
    return squared(t.a + ac * (d2 / (d2 - d6)));
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
  {
    return squared(t.b + (t.c - t.b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  }
  const double denominator = va + vb + vc;
  if (!(std::fabs(denominator) > 0))
  {
    return std::min({ squared(t.a), squared(t.b), squared(t.c) });
  }
  const double v = vb / denominator, w = vc / denominator;
  return squared(t.a + ab * v + ac * w);
}

/// Triangles bucketed in a uniform grid for nearest-distance queries.
class TriangleGrid
{
public:
  explicit TriangleGrid(std::vector<Triangle> triangles)
    : Triangles(std::move(triangles))
  {
    this->Low = glm::dvec3(std::numeric_limits<double>::max());
    glm::dvec3 high(-std::numeric_limits<double>::max());
    for (const Triangle& t : this->Triangles)
    {
      for (const glm::dvec3& p : { t.a, t.b, t.c })
      {
        this->Low = glm::min(this->Low, p);
        high = glm::max(high, p);
      }
    }
    const glm::dvec3 extent = glm::max(high - this->Low, glm::dvec3(1e-9));
    // About two triangles a bucket, over the extents actually spanned.
    const double target = std::max<double>(1.0, static_cast<double>(this->Triangles.size()) / 2.0);
    double size = std::cbrt(extent.x * extent.y * extent.z / target);
    for (int pass = 0; pass < 3; ++pass)
    {
      double buckets = 1;
      for (int d = 0; d < 3; ++d)
      {
        buckets *= std::max(1.0, std::floor(extent[d] / size));
      }
      size *= std::cbrt(std::max(1.0, buckets / target));
    }
    this->Size = std::max(size, 1e-9);
    for (int d = 0; d < 3; ++d)
    {
      this->Count[d] = static_cast<int64_t>(std::min(1024.0, std::max(1.0, std::ceil(extent[d] / this->Size))));
    }
    this->Start.assign(static_cast<std::size_t>(this->Count[0] * this->Count[1] * this->Count[2] + 1), 0);
    std::vector<std::pair<int64_t, int64_t>> entries; // bucket, triangle
    for (std::size_t t = 0; t < this->Triangles.size(); ++t)
    {
      const Triangle& tri = this->Triangles[t];
      const glm::dvec3 lo = glm::min(tri.a, glm::min(tri.b, tri.c)), hi = glm::max(tri.a, glm::max(tri.b, tri.c));
      const auto a = this->Bucket(lo), b = this->Bucket(hi);
      for (int64_t z = a[2]; z <= b[2]; ++z)
        for (int64_t y = a[1]; y <= b[1]; ++y)
          for (int64_t x = a[0]; x <= b[0]; ++x)
            entries.push_back({ (z * this->Count[1] + y) * this->Count[0] + x, static_cast<int64_t>(t) });
    }
    std::sort(entries.begin(), entries.end());
    this->Items.reserve(entries.size());
    for (const auto& entry : entries)
    {
      ++this->Start[entry.first + 1];
      this->Items.push_back(entry.second);
    }
    for (std::size_t i = 1; i < this->Start.size(); ++i)
    {
      this->Start[i] += this->Start[i - 1];
    }
  }

  const std::vector<Triangle>& All() const { return this->Triangles; }

  /// Distance from p to the nearest triangle.
  double Distance(const glm::dvec3& p) const
  {
    if (this->Triangles.empty())
    {
      return std::numeric_limits<double>::infinity();
    }
    const auto centre = this->Bucket(p);
    double best = std::numeric_limits<double>::infinity();
    const int64_t maxRing = std::max({ this->Count[0], this->Count[1], this->Count[2] });
    for (int64_t ring = 0; ring <= maxRing; ++ring)
    {
      for (int64_t z = centre[2] - ring; z <= centre[2] + ring; ++z)
        for (int64_t y = centre[1] - ring; y <= centre[1] + ring; ++y)
          for (int64_t x = centre[0] - ring; x <= centre[0] + ring; ++x)
          {
            if (std::max({ std::llabs(x - centre[0]), std::llabs(y - centre[1]), std::llabs(z - centre[2]) }) != ring ||
              x < 0 || y < 0 || z < 0 || x >= this->Count[0] || y >= this->Count[1] || z >= this->Count[2])
            {
              continue;
            }
            const int64_t bucket = (z * this->Count[1] + y) * this->Count[0] + x;
            for (int64_t i = this->Start[bucket]; i < this->Start[bucket + 1]; ++i)
            {
              best = std::min(best, std::sqrt(SquaredDistance(p, this->Triangles[this->Items[i]])));
            }
          }
      // A triangle not met yet lies wholly in buckets of the next rings, at least `ring`
      // buckets from p (also when p is outside the grid and its bucket was clamped).
      if (best <= static_cast<double>(ring) * this->Size)
      {
        break;
      }
    }
    return best;
  }

private:
  std::array<int64_t, 3> Bucket(const glm::dvec3& p) const
  {
    std::array<int64_t, 3> b;
    for (int d = 0; d < 3; ++d)
    {
      const double cell = std::floor((p[d] - this->Low[d]) / this->Size);
      b[d] = static_cast<int64_t>(std::min(static_cast<double>(this->Count[d] - 1), std::max(0.0, cell)));
    }
    return b;
  }

  std::vector<Triangle> Triangles;
  glm::dvec3 Low;
  double Size = 1;
  int64_t Count[3] = { 1, 1, 1 };
  std::vector<int64_t> Start;
  std::vector<int64_t> Items;
};

double LargestDistance(const std::vector<Triangle>& triangles, const TriangleGrid& target, int perTriangle,
  int64_t& samples, std::array<double, 3>& worst)
{
  // Samples on the triangles themselves (so a surface is at distance 0 from itself): the
  // centroid, then points towards each corner.
  static const double weights[6][3] = { { 4.0 / 6, 1.0 / 6, 1.0 / 6 }, { 1.0 / 6, 4.0 / 6, 1.0 / 6 },
    { 1.0 / 6, 1.0 / 6, 4.0 / 6 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  double largest = 0;
  for (const Triangle& t : triangles)
  {
    for (int s = -1; s < perTriangle; ++s)
    {
      const glm::dvec3 p =
        s < 0 ? (t.a + t.b + t.c) / 3.0 : weights[s % 6][0] * t.a + weights[s % 6][1] * t.b + weights[s % 6][2] * t.c;
      const double distance = target.Distance(p);
      if (distance > largest)
      {
        largest = distance;
        worst = { p.x, p.y, p.z };
      }
      ++samples;
    }
  }
  return largest;
}
} // namespace

namespace
{
// Corner neighbours of a VTK-ordered hexahedron, in right-handed order.
constexpr int CornerNeighbours[8][3] = { { 1, 3, 4 }, { 2, 0, 5 }, { 3, 1, 6 }, { 0, 2, 7 }, { 7, 5, 0 }, { 4, 6, 1 },
  { 5, 7, 2 }, { 6, 4, 3 } };

/// A HexMesh cell's corners in VTK order in a z-up frame: the bottom face (the deeper
/// interface) first, counter-clockwise seen from above.
void ZUpVTKCorners(const glm::dvec3 corners[8], int orientation, glm::dvec3 p[8])
{
  static const int forward[8] = { 4, 5, 6, 7, 0, 1, 2, 3 };
  static const int backward[8] = { 4, 7, 6, 5, 0, 3, 2, 1 };
  const int* order = orientation > 0 ? forward : backward;
  for (int i = 0; i < 8; ++i)
  {
    p[i] = corners[order[i]];
    p[i].z = -p[i].z;
  }
}
} // namespace

double HexScaledJacobian(const glm::dvec3 corners[8], int orientation, bool& degenerate)
{
  const auto& next = CornerNeighbours;
  glm::dvec3 p[8];
  ZUpVTKCorners(corners, orientation, p);
  double longest = 0, shortest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 8; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      const double length = glm::length(p[next[i][j]] - p[i]);
      longest = std::max(longest, length);
      shortest = std::min(shortest, length);
    }
  }
  degenerate = !(shortest > 1e-9 * longest);
  if (degenerate)
  {
    return 0;
  }
  double worst = 1;
  for (int i = 0; i < 8; ++i)
  {
    const glm::dvec3 e1 = p[next[i][0]] - p[i], e2 = p[next[i][1]] - p[i], e3 = p[next[i][2]] - p[i];
    worst = std::min(worst, glm::dot(e1, glm::cross(e2, e3)) / (glm::length(e1) * glm::length(e2) * glm::length(e3)));
  }
  return worst;
}

bool HexInverted(const glm::dvec3 corners[8], int orientation)
{
  const auto& next = CornerNeighbours;
  glm::dvec3 p[8];
  ZUpVTKCorners(corners, orientation, p);
  for (int i = 0; i < 8; ++i)
  {
    const glm::dvec3 e1 = p[next[i][0]] - p[i], e2 = p[next[i][1]] - p[i], e3 = p[next[i][2]] - p[i];
    const double det = glm::dot(e1, glm::cross(e2, e3));
    if (det >= 0)
    {
      continue;
    }
    // Rare path: as HexScaledJacobian decides it.
    bool degenerate = false;
    return HexScaledJacobian(corners, orientation, degenerate) < -1e-9 && !degenerate;
  }
  return false;
}

HexQuality MeasureHexahedra(const HexMesh& mesh, int orientation)
{
  HexQuality quality;
  double sum = 0;
  int64_t measured = 0;
  for (const auto& c : mesh.cells)
  {
    ++quality.cells;
    glm::dvec3 corners[8];
    for (int i = 0; i < 8; ++i)
    {
      corners[i] = PointAt(mesh, c[i]);
    }
    bool degenerate = false;
    const double worst = HexScaledJacobian(corners, orientation, degenerate);
    if (degenerate)
    {
      ++quality.degenerate;
      continue;
    }
    quality.inverted += worst < -1e-9 ? 1 : 0; // straight corners (0) are not inverted
    quality.minScaledJacobian = std::min(quality.minScaledJacobian, worst);
    sum += worst;
    ++measured;
  }
  quality.meanScaledJacobian = measured > 0 ? sum / static_cast<double>(measured) : 0;
  if (measured == 0)
  {
    quality.minScaledJacobian = 0;
  }
  return quality;
}

BoundaryDistance MeasureBoundaryDistance(const HexMesh& a, const HexMesh& b, int perFace)
{
  BoundaryDistance result;
  std::vector<std::array<glm::dvec3, 4>> quadsA, quadsB;
  const TriangleGrid gridA(BoundaryTriangles(a, quadsA));
  const TriangleGrid gridB(BoundaryTriangles(b, quadsB));
  result.forward = LargestDistance(gridA.All(), gridB, perFace, result.samples, result.worstForward);
  result.backward = LargestDistance(gridB.All(), gridA, perFace, result.samples, result.worstBackward);
  result.hausdorff = std::max(result.forward, result.backward);
  glm::dvec3 low(std::numeric_limits<double>::max()), high(-std::numeric_limits<double>::max());
  for (const auto& q : quadsA)
  {
    for (const glm::dvec3& p : q)
    {
      low = glm::min(low, p);
      high = glm::max(high, p);
    }
  }
  result.diagonal = quadsA.empty() ? 0 : glm::length(high - low);
  result.relative = result.diagonal > 0 ? result.hausdorff / result.diagonal : 0;
  return result;
}

} // namespace resmr
