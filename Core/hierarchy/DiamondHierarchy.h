// The 2D diamond hierarchy of paper Sec. 4.2 (Adaptive TetraPuzzles in the plane): the model's
// x-y bounding box split along its diagonal into two right triangles, each bisected at the
// midpoint of its longest edge, level after level. A diamond is the pair of triangles sharing
// a longest edge (one triangle where that edge is on the box); both are always split or shown
// together, which keeps any cut of the tree conformal.
//
// Contract:
// - Triangles are named (level, index): level 0 holds the two roots (index 0 and 1); the
//   children of (L, n) are (L + 1, 2n) and (L + 1, 2n + 1); parent (L - 1, n / 2).
// - The tree is complete down to its leaf level: every diamond splits at once, so diamonds are
//   the same at every level whatever the column density. Leaves may hold fewer than Cmax
//   columns, never more (unless more than Cmax columns share a centre).
// - Work is done in the box normalised to the unit square, where every triangle is an
//   isosceles right triangle and all vertices are dyadic (exact in doubles). Locate() puts
//   every point in exactly one triangle of a level (ties go to the first child).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

class DiamondHierarchy
{
public:
  using Point = std::array<double, 2>;
  /// Apex, then the two ends of the longest edge (hypotenuse), in normalised coordinates.
  struct Triangle
  {
    Point apex, left, right;
  };
  /// A diamond of one level: two triangles sharing their hypotenuse, or one (second = -1)
  /// whose hypotenuse lies on the box.
  struct Diamond
  {
    int level = 0;
    int64_t first = -1, second = -1;
  };

  /// Deepest level Locate codes are computed for.
  static constexpr int MaxDepth = 40;

  DiamondHierarchy() = default;
  /// The box [xmin, xmax] x [ymin, ymax] (a zero extent is widened to 1) and the leaf level.
  DiamondHierarchy(double xmin, double ymin, double xmax, double ymax, int leafLevel);

  /// The shallowest leaf level at which no leaf holds more than `cmax` of the points whose
  /// MaxDepth codes are given (MaxDepth if none is enough).
  static int ChooseLeafLevel(std::vector<uint64_t> codes, int64_t cmax);

  int LeafLevel() const { return this->Leaves; }
  static int64_t TriangleCount(int level) { return int64_t(2) << level; }

  /// The triangle of `level` holding (x, y) (model coordinates; outside points are clamped).
  int64_t Locate(double x, double y, int level) const;
  /// Locate at MaxDepth; the triangle of a shallower level L is code >> (MaxDepth - L).
  uint64_t Code(double x, double y) const { return static_cast<uint64_t>(this->Locate(x, y, MaxDepth)); }

  Triangle NormalisedTriangle(int level, int64_t index) const;
  /// The same in model coordinates.
  Triangle ModelTriangle(int level, int64_t index) const;
  /// Whether (x, y) lies on the side of the diamond's hypotenuse where `first` is (ties: yes).
  bool OnFirstSide(const Diamond& diamond, double x, double y) const;

  /// The diamonds of a level, each triangle in exactly one.
  std::vector<Diamond> Diamonds(int level) const;

  double MinX() const { return this->X0; }
  double MinY() const { return this->Y0; }
  double SizeX() const { return this->Width; }
  double SizeY() const { return this->Height; }

private:
  Point Normalise(double x, double y) const;
  double X0 = 0, Y0 = 0, Width = 1, Height = 1;
  int Leaves = 0;
};

} // namespace resmr
