// Corner-point geometry of an Eclipse grid (paper Sec. 3): pillars (COORD) and corner depths
// (ZCORN), or the same built from Cartesian DX/DY/DZ/TOPS; cell corners, handedness and
// which cell faces are shared with their topological neighbours (faults break sharing).
//
// Contract:
// - Corners are in double precision; MAPAXES is applied on request (not when GRIDUNIT says
//   the grid is already in map coordinates). Depth stays positive down here; callers that
//   show z up negate it.
// - Corner order is ECLIPSE's: c = di + 2 dj + 4 dk (dk = 0 top, 1 bottom).
#pragma once

#include "CornerPointModel.h"

#include <array>
#include <cstdint>
#include <vector>

namespace resmr
{

/// The point at `depth` on a pillar given as COORD's 6 values (top x y depth, bottom x y
/// depth); a pillar with no depth extent is vertical.
inline void PointOnPillar(const double* pillar, double depth, double xyz[3])
{
  const double dz = pillar[5] - pillar[2];
  double x = pillar[0], y = pillar[1];
  if (dz != 0.0)
  {
    const double t = (depth - pillar[2]) / dz;
    x += t * (pillar[3] - pillar[0]);
    y += t * (pillar[4] - pillar[1]);
  }
  xyz[0] = x;
  xyz[1] = y;
  xyz[2] = depth;
}

class CornerPointGeometry
{
public:
  /// Takes COORD/ZCORN from the deck (moved, not copied) or builds them from DX/DY/DZ/TOPS
  /// (or DXV/DYV/DZV). Throws InputError if the geometry is inconsistent.
  static CornerPointGeometry FromDeck(CornerPointModel& deck, bool applyMapAxes);

  /// Switches the MAPAXES transform on or off (no effect without MAPAXES, or when GRIDUNIT
  /// says the grid is already in map coordinates); handedness follows.
  void SetMapAxesApplied(bool apply);

  const std::array<int64_t, 3>& Dims() const { return this->Dimensions; }
  int64_t CellCount() const { return this->Dimensions[0] * this->Dimensions[1] * this->Dimensions[2]; }

  /// The 8 corners (x, y, depth) of cell (i, j, k), 0-based, ECLIPSE corner order.
  void CellCorners(int64_t i, int64_t j, int64_t k, double corners[8][3]) const;

  /// True if, with depth down and k increasing downwards, the (i, j) axes turn clockwise
  /// seen from above (ECLIPSE "left-handed"): hexahedra need their k order mirrored to have
  /// positive volume in a z-up frame.
  bool IsLeftHanded() const { return this->LeftHanded; }

  /// Corners merged into shared points: corners of neighbouring cells on the same pillar at
  /// the same depth become one point, so faces are shared exactly where ECLIPSE connects
  /// cells (faults, layer gaps and pinched-out cells keep their own points).
  struct SharedCorners
  {
    std::vector<double> points;      ///< x, y, depth per point
    std::vector<int64_t> cellPoints; ///< 8 point ids per cell, ECLIPSE corner order
  };
  SharedCorners BuildSharedCorners() const;

  const std::vector<double>& Coord() const { return this->CoordValues; }
  /// Origin and unit axes from MAPAXES; false if an axis point coincides with the origin.
  static bool MapTransformOf(const MapAxes& axes, std::array<double, 6>& transform);
  /// The transform FromDeck applies: MAPAXES given and usable, grid not already in map units.
  static bool PlacementTransform(const MapPlacement& placement, std::array<double, 6>& transform);
  /// Grid (x, y) to map coordinates with a MapTransformOf transform.
  static void ApplyMapTransform(const std::array<double, 6>& m, double& x, double& y)
  {
    const double mx = m[0] + x * m[2] + y * m[4];
    y = m[1] + x * m[3] + y * m[5];
    x = mx;
  }
  /// Throws the InputError FromDeck throws for MAPAXES the deck cannot use (axis points on
  /// the origin), whether or not the transform is applied.
  static void CheckMapAxes(const CornerPointModel& deck);
  /// True when corner depths are held in single precision (as EGRID stores them).
  bool HasSinglePrecisionDepths() const { return !this->ZcornSingle.empty(); }

private:
  double Z(int64_t i, int64_t j, int64_t k, int corner) const
  {
    const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
    const int64_t di = corner & 1, dj = (corner >> 1) & 1, dk = corner >> 2;
    const auto index = static_cast<std::size_t>(((2 * k + dk) * 2 * ny + 2 * j + dj) * 2 * nx + 2 * i + di);
    return this->ZcornSingle.empty() ? this->ZcornValues[index] : this->ZcornSingle[index];
  }
  void DetectHandedness();
  void PillarPoint(int64_t pillar, double depth, double xyz[3]) const;

  std::array<int64_t, 3> Dimensions{};
  std::vector<double> CoordValues;
  std::vector<double> ZcornValues;
  std::vector<float> ZcornSingle; ///< used instead of ZcornValues when not empty

  bool MapAxesAvailable = false; ///< MAPAXES given and valid, grid not already in map units
  bool MapAxesApplied = false;
  std::array<double, 6> MapTransform{}; ///< origin x y, unit x axis, unit y axis
  bool LeftHanded = false;
};

} // namespace resmr
