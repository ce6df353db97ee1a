// Quadric error metric of Garland and Heckbert, as paper Sec. 4.1 uses it: the sum of
// squared distances of a point to a set of (weighted) planes, stored as the 10 distinct
// entries of a symmetric 4x4 matrix; sums of quadrics measure merged vertices.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <cmath>

namespace resmr
{

struct Quadric
{
  // q11 q12 q13 q14 q22 q23 q24 q33 q34 q44
  std::array<double, 10> q{};

  /// The plane n . p + d = 0 (n of unit length) with a weight.
  static Quadric FromPlane(const glm::dvec3& n, double d, double weight)
  {
    Quadric result;
    const double a = n.x, b = n.y, c = n.z;
    result.q = { a * a, a * b, a * c, a * d, b * b, b * c, b * d, c * c, c * d, d * d };
    for (double& value : result.q)
    {
      value *= weight;
    }
    return result;
  }

  /// The plane through a quadrilateral face (best fit: normal from the diagonals, through
  /// the centroid); false for a face without area (a pinched-out cell).
  static bool PlaneOfQuad(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3,
    glm::dvec3& normal, double& d)
  {
    const glm::dvec3 cross = glm::cross(p2 - p0, p3 - p1);
    const double length = glm::length(cross);
    const double scale = glm::length(p2 - p0) + glm::length(p3 - p1);
    if (!(length > 1e-12 * scale * scale) || !std::isfinite(length))
    {
      return false;
    }
    normal = cross / length;
    d = -glm::dot(normal, 0.25 * (p0 + p1 + p2 + p3));
    return true;
  }

  Quadric& operator+=(const Quadric& other)
  {
    for (int i = 0; i < 10; ++i)
    {
      this->q[i] += other.q[i];
    }
    return *this;
  }

  /// Sum of weighted squared distances of p to the planes.
  double Error(const glm::dvec3& p) const
  {
    const double x = p.x, y = p.y, z = p.z;
    const auto& m = this->q;
    const double error = m[0] * x * x + 2 * m[1] * x * y + 2 * m[2] * x * z + 2 * m[3] * x + m[4] * y * y +
      2 * m[5] * y * z + 2 * m[6] * y + m[7] * z * z + 2 * m[8] * z + m[9];
    return error > 0 ? error : 0; // rounding can give tiny negatives
  }

  /// The z that minimises the error at fixed x and y (paper Sec. 4.1:
  /// z = -(q13 x + q23 y + q34) / q33); `fallback` when q33 is 0 (no plane constrains z).
  double OptimalZ(double x, double y, double fallback) const
  {
    const auto& m = this->q;
    if (!(std::fabs(m[7]) > 1e-12 * (std::fabs(m[0]) + std::fabs(m[4]) + std::fabs(m[7]))))
    {
      return fallback;
    }
    const double z = -(m[2] * x + m[5] * y + m[8]) / m[7];
    return std::isfinite(z) ? z : fallback;
  }
};

} // namespace resmr
