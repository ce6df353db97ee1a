// The camera as the view-dependent selection sees it, paper Sec. 6.2: the selection measures
// projected errors in model coordinates (the file's frame), so the renderer's camera is
// carried into that frame once a frame. Ours: the 4x4 matrix helpers, the actor and MAPAXES
// placement folded into the projection in double precision (map coordinates are large), and
// the matrices the shaders receive (model to clip and view, normals, face winding).
//
// Matrices are row-major: m[4 * i + j] is row i, column j, and a point p maps to M * p.
#pragma once

#include "ViewSelection.h"

#include <array>

namespace resmr
{

using Matrix4 = std::array<double, 16>;

Matrix4 IdentityMatrix();
/// a * b.
Matrix4 Multiply(const Matrix4& a, const Matrix4& b);
Matrix4 Transpose(const Matrix4& m);
/// The inverse of `m` in `inverse`; false (inverse untouched) when `m` is singular.
bool Invert(const Matrix4& m, Matrix4& inverse);
/// M * p for a homogeneous p (no division by w).
std::array<double, 4> Transform(const Matrix4& m, const std::array<double, 4>& p);
/// Translation by t.
Matrix4 TranslationMatrix(const std::array<double, 3>& t);
/// The placement of grid (x, y) in map coordinates (CornerPointGeometry::PlacementTransform's
/// six numbers: x' = m0 + x m2 + y m4, y' = m1 + x m3 + y m5) as a matrix; z is kept.
Matrix4 PlacementMatrix(const std::array<double, 6>& placement);
/// `m` in single precision, column-major (OpenGL's uniform layout).
std::array<float, 16> ColumnMajor(const Matrix4& m);
/// The normal matrix of `modelToView`: the inverse transpose of its upper-left 3x3, in single
/// precision, column-major. The identity when that part is singular.
std::array<float, 9> NormalMatrix(const Matrix4& modelToView);
/// Determinant of the upper-left 3x3: negative when the transform mirrors, which turns the
/// winding of front faces.
double LinearDeterminant(const Matrix4& m);

/// What the selection needs of the renderer's camera, in world coordinates.
struct CameraState
{
  Matrix4 worldToClip = IdentityMatrix(); ///< row-major, OpenGL clip space
  std::array<double, 3> position{};
  std::array<double, 3> directionOfProjection{ 0, 0, -1 };
  double nearClip = 0; ///< distance of the near clipping plane from the eye
  bool parallel = false;
  double parallelScale = 1;     ///< half the viewport height in world units (parallel)
  double viewAngleDegrees = 30; ///< vertical field of view (perspective)
  double viewportHeight = 1;    ///< pixels
};

/// The view in model coordinates: `modelToWorld` places the model in the world (actor matrix
/// times MAPAXES placement). Clip matrix = worldToClip * modelToWorld; eye and direction
/// carried back by the inverse of modelToWorld; the near distance in model units; pixels per
/// unit at distance 1 (perspective) or anywhere (parallel). tolerancePixels is left at its
/// default for the caller to set.
ViewParameters ViewFromCamera(const CameraState& camera, const Matrix4& modelToWorld);

} // namespace resmr
