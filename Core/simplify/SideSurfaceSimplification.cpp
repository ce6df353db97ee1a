// Simplification of a region's side surface, paper Sec. 4.3: the side quads as triangles, then
// half-edge collapses in order of quadric error, each bounded by the exact distance of every
// vertex removed so far to the triangles left.
#include "SideSurfaceSimplification.h"

#include "Quadric.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>

namespace resmr
{
namespace
{
using Vec = glm::dvec3;
using Triangle = std::array<uint32_t, 3>;

constexpr uint32_t None = std::numeric_limits<uint32_t>::max();
constexpr double DegenerateInput = 1e-12;  ///< twice the area over the longest edge squared
constexpr double Thinnest = 1e-6;          ///< the same, least allowed for a changed triangle
constexpr double SmallestTurnCosine = 0.5; ///< 60 degrees from the triangle's current normal
constexpr double FoldCosine = -0.9;        ///< two triangles of an edge facing opposite ways
// Fractions of the bounding box diagonal: rounding allowed on the distance bound and on the
// quadric error, and the quadric costs that count as equal.
constexpr double BoundRounding = 1e-9, QuadricRounding = 1e-6, CostStep = 1e-7;
/// Barycentric weights this far below 0 (or above 1) still count as inside a triangle.
constexpr double PaintedSlack = 1e-9;

/// Position in a z-up frame, so that the quads' turn gives outward normals.
Vec At(const RegionMesh& mesh, uint32_t vertex)
{
  const double* p = &mesh.positions[static_cast<std::size_t>(vertex) * 3];
  return { p[0], p[1], -p[2] };
}

double Dot2(const Vec& v)
{
  return glm::dot(v, v);
}

/// Twice the area over the longest edge squared: 0 for a needle or a cap, 0.87 at most.
double Thickness(const Vec& a, const Vec& b, const Vec& c)
{
  const double longest = std::max({ Dot2(b - a), Dot2(c - b), Dot2(a - c) });
  const double area = glm::length(glm::cross(b - a, c - a));
  return longest > 0 && std::isfinite(area) ? area / longest : 0;
}

/// Squared distance of p to the triangle (Ericson, Real-Time Collision Detection, 5.1.5).
double SquaredDistance(const Vec& p, const Vec& a, const Vec& b, const Vec& c)
{
  const Vec ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0)
  {
    return Dot2(ap);
  }
  const Vec bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3)
  {
    return Dot2(bp);
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
  {
    return Dot2(ap - ab * (d1 / (d1 - d3)));
  }
  const Vec cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6)
  {
    return Dot2(cp);
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
  {
    return Dot2(ap - ac * (d2 / (d2 - d6)));
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
  {
    return Dot2(bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
  }
  const double denominator = 1 / (va + vb + vc);
  return Dot2(ap - ab * (vb * denominator) - ac * (vc * denominator));
}

/// Where a triangle with topological coordinates (ta, tb, tc) paints the coordinate t, as the
/// weights (u, v) of b and c: the least-squares solution, since t may leave the triangle's
/// plane of coordinates (a wall turning a corner). False where the coordinates span no plane.
bool PaintedAt(const Vec& ta, const Vec& tb, const Vec& tc, const Vec& t, double& u, double& v)
{
  const Vec e1 = tb - ta, e2 = tc - ta, d = t - ta;
  const double a11 = Dot2(e1), a12 = glm::dot(e1, e2), a22 = Dot2(e2);
  const double determinant = a11 * a22 - a12 * a12;
  if (!(determinant > 1e-12 * a11 * a22))
  {
    return false;
  }
  const double b1 = glm::dot(e1, d), b2 = glm::dot(e2, d);
  u = (a22 * b1 - a12 * b2) / determinant;
  v = (a11 * b2 - a12 * b1) / determinant;
  return true;
}

class Simplifier
{
public:
  Simplifier(const RegionMesh& mesh, const std::vector<Triangle>& input, double maxError);
  std::vector<Triangle> Run(SideSimplificationStats& stats);

private:
  struct Candidate
  {
    double step;   ///< quadric cost in CostStep units
    double length; ///< squared length of the edge
    uint32_t fan;  ///< triangles around the removed vertex
    uint32_t from, to, stamp;
  };
  /// std::priority_queue keeps the largest on top: invert for the cheapest, then the shortest
  /// edge (coplanar collapses along short edges first keep fans from spanning a wall's rows,
  /// which would block the vertices on its creases), then the smaller fan (no chain of
  /// collapses down one pillar piling every triangle onto one vertex), then by vertex.
  struct Later
  {
    bool operator()(const Candidate& a, const Candidate& b) const
    {
      if (a.step != b.step)
      {
        return a.step > b.step;
      }
      if (a.length != b.length)
      {
        return a.length > b.length;
      }
      if (a.fan != b.fan)
      {
        return a.fan > b.fan;
      }
      return a.from != b.from ? a.from > b.from : a.to > b.to;
    }
  };

  double QuadricCost(uint32_t from, uint32_t to) const;
  double Step(double cost) const { return std::floor(cost / this->Quantum); }
  void Plan(uint32_t vertex, bool changed);
  bool Fan(uint32_t vertex);
  bool Check(uint32_t from, uint32_t to);
  bool FacesInput(uint32_t vertex, const Vec& normal) const;
  void Collapse(uint32_t from, uint32_t to);

  std::vector<Vec> Position; ///< centred on the bounding box, z up
  std::vector<Vec> Topology; ///< (ti, tj, tk), what the viewer interpolates to paint a cell
  std::vector<uint32_t> Global;
  std::vector<Triangle> Triangles;
  std::vector<uint8_t> Alive;
  std::vector<Vec> InputNormal;                  ///< unit normal of the input triangle a slot started as
  std::vector<uint32_t> InputStart, InputAround; ///< input triangles of each vertex (CSR)
  std::vector<std::vector<uint32_t>> Star;       ///< live triangles of each vertex
  std::vector<std::vector<uint32_t>> Riders;     ///< removed vertices nearest each triangle
  std::vector<Quadric> Quadrics;
  std::vector<uint8_t> Locked, Removed;
  std::vector<uint32_t> Stamp, Mark;
  std::vector<std::vector<uint32_t>> Refused; ///< targets Check() refused since the fan changed
  uint32_t MarkValue = 0;
  std::priority_queue<Candidate, std::vector<Candidate>, Later> Queue;
  double Tolerance = 0, BoundLimit = 0, QuadricLimit = 0, Quantum = 1, Largest = 0;

  // Scratch of Fan() and Check(), kept for Collapse().
  std::vector<std::pair<uint32_t, uint32_t>> Links; ///< (a, b) of each fan triangle (v, a, b)
  std::vector<uint32_t> ByStart;                    ///< indices into Links sorted by a
  std::vector<uint32_t> Ring;                       ///< the link in turn order
  std::vector<uint32_t> RingTriangle;               ///< (v, ring i, ring i + 1)
  std::vector<uint32_t> Kept, Dropped;
  std::vector<std::pair<uint32_t, uint32_t>> Carried; ///< (removed vertex, kept triangle)
  double PlannedError = 0;
};

Simplifier::Simplifier(const RegionMesh& mesh, const std::vector<Triangle>& input, double maxError)
{
  // Local numbering of the surface's vertices, in mesh order (determinism); 0 marks use.
  std::vector<uint32_t> local(static_cast<std::size_t>(mesh.VertexCount()), None);
  for (const Triangle& t : input)
  {
    for (uint32_t v : t)
    {
      local[v] = 0;
    }
  }
  for (std::size_t v = 0; v < local.size(); ++v)
  {
    if (local[v] == 0)
    {
      local[v] = static_cast<uint32_t>(this->Global.size());
      this->Global.push_back(static_cast<uint32_t>(v));
    }
  }
  const std::size_t n = this->Global.size();
  // Centred positions keep the quadrics' and distances' rounding small.
  Vec low(std::numeric_limits<double>::infinity()), high(-std::numeric_limits<double>::infinity());
  for (uint32_t v : this->Global)
  {
    low = glm::min(low, At(mesh, v));
    high = glm::max(high, At(mesh, v));
  }
  const Vec centre = 0.5 * (low + high);
  const double diagonal = n ? glm::length(high - low) : 0;
  this->Tolerance = BoundRounding * diagonal;
  const double error = maxError > 0 ? maxError : 0; // NaN too
  this->BoundLimit = error + this->Tolerance;
  this->QuadricLimit = error + QuadricRounding * diagonal;
  this->Quantum = diagonal > 0 ? CostStep * diagonal : 1;
  this->Position.resize(n);
  this->Topology.resize(n);
  const uint32_t interfaces = static_cast<uint32_t>(mesh.layers + 1);
  for (std::size_t v = 0; v < n; ++v)
  {
    this->Position[v] = At(mesh, this->Global[v]) - centre;
    const auto& node = mesh.topology[this->Global[v] / interfaces];
    this->Topology[v] = Vec(node[0], node[1], this->Global[v] % interfaces);
  }

  this->Star.resize(n);
  this->Quadrics.resize(n);
  for (const Triangle& g : input)
  {
    const Triangle t{ local[g[0]], local[g[1]], local[g[2]] };
    const Vec& a = this->Position[t[0]];
    const Vec cross = glm::cross(this->Position[t[1]] - a, this->Position[t[2]] - a);
    const double length = glm::length(cross);
    const Vec normal = cross / length;
    // Area-weighted plane quadric, a third to each corner.
    const Quadric plane = Quadric::FromPlane(normal, -glm::dot(normal, a), length / 6);
    for (uint32_t v : t)
    {
      this->Star[v].push_back(static_cast<uint32_t>(this->Triangles.size()));
      this->Quadrics[v] += plane;
    }
    this->Triangles.push_back(t);
    this->InputNormal.push_back(normal);
  }
  // The stars are the input's yet: keep them to compare turned triangles with.
  this->InputStart.assign(n + 1, 0);
  for (std::size_t v = 0; v < n; ++v)
  {
    this->InputStart[v + 1] = this->InputStart[v] + static_cast<uint32_t>(this->Star[v].size());
    this->InputAround.insert(this->InputAround.end(), this->Star[v].begin(), this->Star[v].end());
  }
  this->Alive.assign(this->Triangles.size(), 1);
  this->Riders.resize(this->Triangles.size());
  this->Removed.assign(n, 0);
  this->Stamp.assign(n, 0);
  this->Refused.resize(n);
  this->Mark.assign(n, 0);

  // Rule 1: the top and bottom surfaces' vertices; rule 2: the nodes of cut edges.
  this->Locked.assign(n, 0);
  for (const RegionSurface* surface : { &mesh.top, &mesh.bottom })
  {
    for (const auto& q : surface->quads)
    {
      for (uint32_t v : q)
      {
        if (local[v] != None)
        {
          this->Locked[local[v]] = 1;
        }
      }
    }
  }
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      if (c < mesh.cutEdges.size() && (mesh.cutEdges[c] & (1u << e)))
      {
        for (uint32_t node : { mesh.corners[c][e], mesh.corners[c][(e + 1) % 4] })
        {
          for (int32_t k = 0; k <= mesh.layers; ++k)
          {
            const uint32_t v = local[mesh.Vertex(node, k)];
            if (v != None)
            {
              this->Locked[v] = 1;
            }
          }
        }
      }
    }
  }
  // Rule 3: no closed disc around the vertex, or a fold through it.
  for (uint32_t v = 0; v < n; ++v)
  {
    if (this->Locked[v])
    {
      continue;
    }
    if (!this->Fan(v))
    {
      this->Locked[v] = 1;
      continue;
    }
    for (std::size_t i = 0; i < this->Ring.size(); ++i)
    {
      const uint32_t before = this->RingTriangle[(i + this->Ring.size() - 1) % this->Ring.size()];
      if (glm::dot(this->InputNormal[before], this->InputNormal[this->RingTriangle[i]]) < FoldCosine)
      {
        this->Locked[v] = 1;
      }
    }
  }
}

bool Simplifier::FacesInput(uint32_t vertex, const Vec& normal) const
{
  for (uint32_t i = this->InputStart[vertex]; i < this->InputStart[vertex + 1]; ++i)
  {
    if (glm::dot(normal, this->InputNormal[this->InputAround[i]]) > 0)
    {
      return true;
    }
  }
  return false;
}

double Simplifier::QuadricCost(uint32_t from, uint32_t to) const
{
  Quadric q = this->Quadrics[from];
  q += this->Quadrics[to];
  // The trace sums the planes' weights (unit normals): the ratio is a mean squared distance.
  const double weight = q.q[0] + q.q[4] + q.q[7];
  return weight > 0 ? std::sqrt(q.Error(this->Position[to]) / weight) : 0;
}

void Simplifier::Plan(uint32_t vertex, bool changed)
{
  // One candidate a vertex in the queue, its cheapest target not yet refused: far fewer
  // entries than one an edge where collapses pile many triangles onto one vertex.
  if (changed)
  {
    ++this->Stamp[vertex];
    this->Refused[vertex].clear();
  }
  if (this->Locked[vertex] || this->Removed[vertex])
  {
    return;
  }
  const auto& refused = this->Refused[vertex];
  const uint32_t fan = static_cast<uint32_t>(this->Star[vertex].size());
  Candidate best{ 0, 0, fan, vertex, None, this->Stamp[vertex] };
  ++this->MarkValue;
  for (uint32_t t : this->Star[vertex])
  {
    for (uint32_t to : this->Triangles[t])
    {
      if (to == vertex || this->Mark[to] == this->MarkValue ||
        std::find(refused.begin(), refused.end(), to) != refused.end())
      {
        continue;
      }
      this->Mark[to] = this->MarkValue;
      const double cost = this->QuadricCost(vertex, to);
      if (cost <= this->QuadricLimit)
      {
        const double length = Dot2(this->Position[to] - this->Position[vertex]);
        const Candidate c{ this->Step(cost), length, fan, vertex, to, best.stamp };
        if (best.to == None || Later()(best, c))
        {
          best = c;
        }
      }
    }
  }
  if (best.to != None)
  {
    this->Queue.push(best);
  }
}

bool Simplifier::Fan(uint32_t vertex)
{
  // One closed disc turning one way: each link vertex starts exactly one fan triangle and
  // ends exactly one, and the link is a single cycle.
  this->Links.clear();
  this->Ring.clear();
  this->RingTriangle.clear();
  const auto& star = this->Star[vertex];
  if (star.size() < 3)
  {
    return false;
  }
  for (std::size_t i = 0; i < star.size(); ++i)
  {
    const Triangle& t = this->Triangles[star[i]];
    const int at = t[0] == vertex ? 0 : t[1] == vertex ? 1 : 2;
    this->Links.push_back({ t[(at + 1) % 3], t[(at + 2) % 3] });
  }
  std::vector<uint32_t>& byStart = this->ByStart;
  byStart.resize(star.size());
  for (std::size_t i = 0; i < star.size(); ++i)
  {
    byStart[i] = static_cast<uint32_t>(i);
  }
  std::sort(byStart.begin(), byStart.end(),
    [&](uint32_t a, uint32_t b) { return this->Links[a].first < this->Links[b].first; });
  for (std::size_t i = 1; i < byStart.size(); ++i)
  {
    if (this->Links[byStart[i]].first == this->Links[byStart[i - 1]].first)
    {
      return false;
    }
  }
  uint32_t at = 0;
  for (std::size_t step = 0; step < star.size(); ++step)
  {
    this->Ring.push_back(this->Links[at].first);
    this->RingTriangle.push_back(star[at]);
    const uint32_t next = this->Links[at].second;
    const auto found = std::lower_bound(
      byStart.begin(), byStart.end(), next, [&](uint32_t i, uint32_t value) { return this->Links[i].first < value; });
    if (found == byStart.end() || this->Links[*found].first != next)
    {
      return false; // the link ends: a border
    }
    at = *found;
    if (at == 0 && step + 1 < star.size())
    {
      return false; // closed early: several cycles
    }
  }
  return at == 0;
}

bool Simplifier::Check(uint32_t from, uint32_t to)
{
  if (!this->Fan(from))
  {
    return false;
  }
  const std::size_t k = this->Ring.size();
  const auto target = std::find(this->Ring.begin(), this->Ring.end(), to);
  const std::size_t i = static_cast<std::size_t>(target - this->Ring.begin());
  if (i == k)
  {
    return false;
  }
  const uint32_t after = this->Ring[(i + 1) % k], before = this->Ring[(i + k - 1) % k];
  // Link condition: the two ends share no neighbour but the two triangles' far corners.
  ++this->MarkValue;
  for (uint32_t w : this->Ring)
  {
    this->Mark[w] = this->MarkValue;
  }
  for (uint32_t t : this->Star[to])
  {
    for (uint32_t w : this->Triangles[t])
    {
      if (w != to && w != from && this->Mark[w] == this->MarkValue && w != after && w != before)
      {
        return false;
      }
      // A triangle of a three-fan survives as (to, after, before): it must not exist yet.
      const Triangle& other = this->Triangles[t];
      if (k == 3 && w == after && std::find(other.begin(), other.end(), before) != other.end())
      {
        return false;
      }
    }
  }

  this->Kept.clear();
  this->Dropped.clear();
  for (std::size_t j = 0; j < k; ++j)
  {
    const uint32_t t = this->RingTriangle[j];
    if (j == i || j == (i + k - 1) % k)
    {
      this->Dropped.push_back(t);
      continue;
    }
    const Vec& a = this->Position[this->Ring[j]];
    const Vec& b = this->Position[this->Ring[(j + 1) % k]];
    const Vec& p = this->Position[to];
    const Vec old = glm::cross(a - this->Position[from], b - this->Position[from]);
    const Vec now = glm::cross(a - p, b - p);
    const bool turned = glm::dot(now, old) < SmallestTurnCosine * glm::length(now) * glm::length(old) ||
      !(glm::dot(now, this->InputNormal[t]) > 0);
    if (turned || Thickness(p, a, b) < Thinnest || !this->FacesInput(to, now) ||
      !this->FacesInput(this->Ring[j], now) || !this->FacesInput(this->Ring[(j + 1) % k], now))
    {
      return false;
    }
    this->Kept.push_back(t);
  }

  // Every vertex removed so far that rides on the fan, and `from` itself, must stay within
  // the bound of the new fan, both from its triangles and from where they paint its
  // topological coordinate; each rides on the triangle that paints it.
  this->Carried.clear();
  double largest = 0;
  auto place = [&](uint32_t vertex) {
    const Vec& q = this->Position[vertex];
    double nearest = std::numeric_limits<double>::infinity(), painting = nearest, outside = nearest;
    uint32_t painter = this->Kept[0];
    for (uint32_t t : this->Kept)
    {
      Triangle c = this->Triangles[t];
      std::replace(c.begin(), c.end(), from, to);
      const Vec &a = this->Position[c[0]], &b = this->Position[c[1]], &d = this->Position[c[2]];
      nearest = std::min(nearest, SquaredDistance(q, a, b, d));
      double u = 0, v = 0;
      if (PaintedAt(this->Topology[c[0]], this->Topology[c[1]], this->Topology[c[2]], this->Topology[vertex], u, v))
      {
        // The triangle whose coordinates hold the vertex's paints it; outside every one
        // (rounding, a corner), the nearest extrapolates.
        const double out = std::max({ 0.0, -u - PaintedSlack, -v - PaintedSlack, u + v - 1 - PaintedSlack });
        const double error = Dot2(a + u * (b - a) + v * (d - a) - q);
        if (out < outside || (out == outside && error < painting))
        {
          outside = out;
          painting = error;
          painter = t;
        }
      }
    }
    this->Carried.push_back({ vertex, painter });
    largest = std::max({ largest, nearest, painting });
  };
  place(from);
  for (std::size_t j = 0; j < k && largest <= this->BoundLimit * this->BoundLimit; ++j)
  {
    for (uint32_t rider : this->Riders[this->RingTriangle[j]])
    {
      place(rider);
    }
  }
  this->PlannedError = std::sqrt(largest);
  return this->PlannedError <= this->BoundLimit;
}

void Simplifier::Collapse(uint32_t from, uint32_t to)
{
  for (uint32_t t : this->Dropped)
  {
    this->Alive[t] = 0;
    for (uint32_t w : this->Triangles[t])
    {
      if (w != from)
      {
        auto& star = this->Star[w];
        star.erase(std::find(star.begin(), star.end(), t));
      }
    }
    this->Riders[t].clear();
  }
  for (uint32_t t : this->Kept)
  {
    std::replace(this->Triangles[t].begin(), this->Triangles[t].end(), from, to);
    this->Star[to].push_back(t);
    this->Riders[t].clear();
  }
  for (const auto& carried : this->Carried)
  {
    this->Riders[carried.second].push_back(carried.first);
  }
  this->Quadrics[to] += this->Quadrics[from];
  this->Removed[from] = 1;
  this->Star[from].clear();
  this->Largest = std::max(this->Largest, this->PlannedError);
  // Only these fans changed; other neighbours of `to` keep their candidates, re-costed when
  // they come up.
  const std::vector<uint32_t> ring = this->Ring;
  ++this->Stamp[from];
  this->Plan(to, true);
  for (uint32_t w : ring)
  {
    this->Plan(w, true);
  }
}

std::vector<Triangle> Simplifier::Run(SideSimplificationStats& stats)
{
  stats.inputTriangles = static_cast<int64_t>(this->Triangles.size());
  stats.lockedVertices = std::count(this->Locked.begin(), this->Locked.end(), 1);
  for (uint32_t v = 0; v < this->Position.size(); ++v)
  {
    this->Plan(v, true);
  }
  while (!this->Queue.empty())
  {
    const Candidate c = this->Queue.top();
    this->Queue.pop();
    if (c.stamp != this->Stamp[c.from])
    {
      continue;
    }
    // The target's quadric may have grown since: put the candidate back at its true cost.
    const double cost = this->QuadricCost(c.from, c.to);
    if (this->Step(cost) > c.step)
    {
      if (cost <= this->QuadricLimit)
      {
        this->Queue.push({ this->Step(cost), c.length, c.fan, c.from, c.to, c.stamp });
      }
      continue;
    }
    if (this->Check(c.from, c.to))
    {
      this->Collapse(c.from, c.to);
    }
    else
    {
      this->Refused[c.from].push_back(c.to);
      this->Plan(c.from, false);
    }
  }
  std::vector<Triangle> output;
  for (std::size_t t = 0; t < this->Triangles.size(); ++t)
  {
    if (this->Alive[t])
    {
      const Triangle& l = this->Triangles[t];
      output.push_back({ this->Global[l[0]], this->Global[l[1]], this->Global[l[2]] });
    }
  }
  stats.outputTriangles = static_cast<int64_t>(output.size());
  stats.largestError = this->Largest;
  return output;
}
} // namespace

std::vector<Triangle> TriangulateSideSurface(const RegionMesh& mesh)
{
  std::vector<Triangle> triangles;
  triangles.reserve(mesh.side.quads.size() * 2);
  for (const auto& q : mesh.side.quads)
  {
    const Vec p[4] = { At(mesh, q[0]), At(mesh, q[1]), At(mesh, q[2]), At(mesh, q[3]) };
    using Split = std::array<std::array<int, 3>, 2>;
    const Split split = Dot2(p[2] - p[0]) <= Dot2(p[3] - p[1]) ? Split{ { { 0, 1, 2 }, { 0, 2, 3 } } }
                                                               : Split{ { { 0, 1, 3 }, { 1, 2, 3 } } };
    for (const auto& s : split)
    {
      if (Thickness(p[s[0]], p[s[1]], p[s[2]]) > DegenerateInput)
      {
        triangles.push_back({ q[s[0]], q[s[1]], q[s[2]] });
      }
    }
  }
  return triangles;
}

std::vector<Triangle> SimplifySideSurface(const RegionMesh& mesh, double maxError, SideSimplificationStats* stats)
{
  SideSimplificationStats ignored;
  Simplifier simplifier(mesh, TriangulateSideSurface(mesh), maxError);
  return simplifier.Run(stats ? *stats : ignored);
}

} // namespace resmr
