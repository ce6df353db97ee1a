// 2D diamond hierarchy of triangular regions, paper Sec. 4.2 (Fig. 8).
#include "DiamondHierarchy.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>

namespace resmr
{
namespace
{
using Point = DiamondHierarchy::Point;

Point Midpoint(const Point& a, const Point& b)
{
  return { 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]) };
}

double Cross(const Point& origin, const Point& a, const Point& b)
{
  return (a[0] - origin[0]) * (b[1] - origin[1]) - (a[1] - origin[1]) * (b[0] - origin[0]);
}

/// Roots: the unit square split along its diagonal from (0, 0) to (1, 1).
DiamondHierarchy::Triangle Root(int64_t index)
{
  if (index == 0)
  {
    return { { 1.0, 0.0 }, { 0.0, 0.0 }, { 1.0, 1.0 } };
  }
  return { { 0.0, 1.0 }, { 1.0, 1.0 }, { 0.0, 0.0 } };
}

/// Child 0 keeps the parent's left end, child 1 its right end; each child's hypotenuse is one
/// of the parent's legs.
DiamondHierarchy::Triangle Child(const DiamondHierarchy::Triangle& t, int which)
{
  const Point m = Midpoint(t.left, t.right);
  return which == 0 ? DiamondHierarchy::Triangle{ m, t.left, t.apex }
                    : DiamondHierarchy::Triangle{ m, t.apex, t.right };
}
} // namespace

DiamondHierarchy::DiamondHierarchy(double xmin, double ymin, double xmax, double ymax, int leafLevel)
  : X0(xmin)
  , Y0(ymin)
  , Width(xmax > xmin ? xmax - xmin : 1.0)
  , Height(ymax > ymin ? ymax - ymin : 1.0)
  , Leaves(leafLevel)
{
  if (leafLevel < 0 || leafLevel > MaxDepth)
  {
    throw std::invalid_argument(
      "diamond hierarchy: leaf level " + std::to_string(leafLevel) + " outside 0.." + std::to_string(MaxDepth));
  }
}

int DiamondHierarchy::ChooseLeafLevel(std::vector<uint64_t> codes, int64_t cmax)
{
  std::sort(codes.begin(), codes.end());
  for (int level = 0; level < MaxDepth; ++level)
  {
    const int shift = MaxDepth - level;
    int64_t largest = 0;
    for (std::size_t begin = 0; begin < codes.size();)
    {
      std::size_t end = begin + 1;
      while (end < codes.size() && (codes[end] >> shift) == (codes[begin] >> shift))
      {
        ++end;
      }
      largest = std::max<int64_t>(largest, static_cast<int64_t>(end - begin));
      begin = end;
    }
    if (largest <= cmax)
    {
      return level;
    }
  }
  return MaxDepth;
}

DiamondHierarchy::Point DiamondHierarchy::Normalise(double x, double y) const
{
  return { std::clamp((x - this->X0) / this->Width, 0.0, 1.0), std::clamp((y - this->Y0) / this->Height, 0.0, 1.0) };
}

int64_t DiamondHierarchy::Locate(double x, double y, int level) const
{
  const Point p = this->Normalise(x, y);
  int64_t index = p[0] >= p[1] ? 0 : 1;
  Triangle t = Root(index);
  for (int l = 0; l < level; ++l)
  {
    const Point m = Midpoint(t.left, t.right);
    // Child 0 holds the left end: same side of the bisector (m, apex) as it, or on it.
    const double side = Cross(m, t.apex, p);
    const double leftSide = Cross(m, t.apex, t.left);
    const int which = (side == 0.0 || (side > 0.0) == (leftSide > 0.0)) ? 0 : 1;
    t = Child(t, which);
    index = 2 * index + which;
  }
  return index;
}

DiamondHierarchy::Triangle DiamondHierarchy::NormalisedTriangle(int level, int64_t index) const
{
  if (level < 0 || level > MaxDepth || index < 0 || index >= TriangleCount(level))
  {
    throw std::out_of_range(
      "diamond hierarchy: no triangle " + std::to_string(index) + " at level " + std::to_string(level));
  }
  Triangle t = Root(index >> level);
  for (int l = level - 1; l >= 0; --l)
  {
    t = Child(t, static_cast<int>((index >> l) & 1));
  }
  return t;
}

DiamondHierarchy::Triangle DiamondHierarchy::ModelTriangle(int level, int64_t index) const
{
  Triangle t = this->NormalisedTriangle(level, index);
  for (Point* p : { &t.apex, &t.left, &t.right })
  {
    (*p)[0] = this->X0 + (*p)[0] * this->Width;
    (*p)[1] = this->Y0 + (*p)[1] * this->Height;
  }
  return t;
}

bool DiamondHierarchy::OnFirstSide(const Diamond& diamond, double x, double y) const
{
  if (diamond.second < 0)
  {
    return true;
  }
  const Triangle t = this->NormalisedTriangle(diamond.level, diamond.first);
  const Point p = this->Normalise(x, y);
  const double side = Cross(t.left, t.right, p);
  const double apexSide = Cross(t.left, t.right, t.apex);
  return side == 0.0 || (side > 0.0) == (apexSide > 0.0);
}

std::vector<DiamondHierarchy::Diamond> DiamondHierarchy::Diamonds(int level) const
{
  // Triangles of a level meet at their hypotenuse midpoints, which are exact dyadic numbers.
  std::map<std::pair<double, double>, int64_t> open;
  std::vector<Diamond> diamonds;
  const int64_t count = TriangleCount(level);
  for (int64_t index = 0; index < count; ++index)
  {
    const Triangle t = this->NormalisedTriangle(level, index);
    const Point m = Midpoint(t.left, t.right);
    const auto key = std::make_pair(m[0], m[1]);
    const auto found = open.find(key);
    if (found == open.end())
    {
      open.emplace(key, index);
    }
    else
    {
      diamonds.push_back({ level, found->second, index });
      open.erase(found);
    }
  }
  for (const auto& single : open)
  {
    diamonds.push_back({ level, single.second, -1 });
  }
  std::sort(diamonds.begin(), diamonds.end(), [](const Diamond& a, const Diamond& b) { return a.first < b.first; });
  return diamonds;
}

} // namespace resmr
