// Camera to view parameters (paper Sec. 6.2); see ViewTransforms.h.
#include "ViewTransforms.h"

#include <algorithm>
#include <cmath>

namespace resmr
{

Matrix4 IdentityMatrix()
{
  return { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
}

Matrix4 Multiply(const Matrix4& a, const Matrix4& b)
{
  Matrix4 c{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      for (int k = 0; k < 4; ++k)
      {
        c[4 * i + j] += a[4 * i + k] * b[4 * k + j];
      }
    }
  }
  return c;
}

Matrix4 Transpose(const Matrix4& m)
{
  Matrix4 t{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      t[4 * i + j] = m[4 * j + i];
    }
  }
  return t;
}

namespace
{
/// The 3x3 determinant of `m` without row `row` and column `column`.
double Minor(const Matrix4& m, int row, int column)
{
  double e[9];
  int n = 0;
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      if (i != row && j != column)
      {
        e[n++] = m[4 * i + j];
      }
    }
  }
  return e[0] * (e[4] * e[8] - e[5] * e[7]) - e[1] * (e[3] * e[8] - e[5] * e[6]) + e[2] * (e[3] * e[7] - e[4] * e[6]);
}
} // namespace

bool Invert(const Matrix4& m, Matrix4& inverse)
{
  // The adjugate over the determinant: exact for the affine matrices placing a model, and
  // cheap enough once a frame.
  Matrix4 cofactors{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      cofactors[4 * i + j] = ((i + j) % 2 == 0 ? 1 : -1) * Minor(m, i, j);
    }
  }
  double determinant = 0;
  for (int j = 0; j < 4; ++j)
  {
    determinant += m[j] * cofactors[j];
  }
  if (determinant == 0)
  {
    return false;
  }
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      inverse[4 * i + j] = cofactors[4 * j + i] / determinant;
    }
  }
  return true;
}

std::array<double, 4> Transform(const Matrix4& m, const std::array<double, 4>& p)
{
  std::array<double, 4> r{};
  for (int i = 0; i < 4; ++i)
  {
    r[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3] * p[3];
  }
  return r;
}

Matrix4 TranslationMatrix(const std::array<double, 3>& t)
{
  return { 1, 0, 0, t[0], 0, 1, 0, t[1], 0, 0, 1, t[2], 0, 0, 0, 1 };
}

Matrix4 PlacementMatrix(const std::array<double, 6>& p)
{
  return { p[2], p[4], 0, p[0], p[3], p[5], 0, p[1], 0, 0, 1, 0, 0, 0, 0, 1 };
}

std::array<float, 16> ColumnMajor(const Matrix4& m)
{
  std::array<float, 16> out{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      out[4 * j + i] = static_cast<float>(m[4 * i + j]);
    }
  }
  return out;
}

std::array<float, 9> NormalMatrix(const Matrix4& modelToView)
{
  Matrix4 linear{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      linear[4 * i + j] = i < 3 && j < 3 ? modelToView[4 * i + j] : (i == j ? 1 : 0);
    }
  }
  Matrix4 inverse = linear; // a singular part is passed on as it is (nothing shows then)
  Invert(linear, inverse);
  // Transposed, then column-major: element (i, j) of the transpose is inverse(j, i), stored
  // at 3 j + i.
  std::array<float, 9> out{};
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      out[3 * j + i] = static_cast<float>(inverse[4 * j + i]);
    }
  }
  return out;
}

double LinearDeterminant(const Matrix4& m)
{
  return m[0] * m[5] * m[10] + m[1] * m[6] * m[8] + m[2] * m[4] * m[9] - m[0] * m[6] * m[9] - m[1] * m[4] * m[10] -
    m[2] * m[5] * m[8];
}

ViewParameters ViewFromCamera(const CameraState& camera, const Matrix4& modelToWorld)
{
  ViewParameters view;
  view.worldToClip = Multiply(camera.worldToClip, modelToWorld);
  Matrix4 worldToModel = modelToWorld; // a singular placement is used as it is
  Invert(modelToWorld, worldToModel);
  const std::array<double, 4> eye =
    Transform(worldToModel, { camera.position[0], camera.position[1], camera.position[2], 1 });
  view.eye = { eye[0], eye[1], eye[2] };
  const std::array<double, 4> direction = Transform(worldToModel,
    { camera.directionOfProjection[0], camera.directionOfProjection[1], camera.directionOfProjection[2], 0 });
  // The camera's direction is a unit vector in the world: its length in the model converts
  // the near distance to model units.
  const double length =
    std::sqrt(direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
  view.nearDistance = camera.nearClip * length;
  view.direction = { direction[0], direction[1], direction[2] };
  if (length != 0)
  {
    for (double& component : view.direction)
    {
      component /= length;
    }
  }
  view.parallel = camera.parallel;
  const double degreesToRadians = 0.017453292519943295; // pi / 180
  view.pixelsPerUnit = view.parallel
    ? camera.viewportHeight / (2.0 * std::max(camera.parallelScale, 1e-30))
    : camera.viewportHeight / (2.0 * std::tan(camera.viewAngleDegrees * degreesToRadians / 2));
  return view;
}

} // namespace resmr
