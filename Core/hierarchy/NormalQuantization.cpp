// Octahedral normal encoding in 16 bits, paper Sec. 5.3 (Cigolle et al. 2014, oct16P).
#include "NormalQuantization.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace resmr
{
namespace
{
constexpr int Levels = 127; // a component's code runs over -127..127

double SignNotZero(double value)
{
  return value >= 0 ? 1.0 : -1.0;
}

/// The (unnormalised) octahedron point of the component codes (su, sv): exact integers, the
/// fold of the lower half undone as the GLSL does.
std::array<int, 3> Unfold(int su, int sv)
{
  const int z = Levels - std::abs(su) - std::abs(sv);
  if (z < 0)
  {
    const int t = -z;
    return { su >= 0 ? su - t : su + t, sv >= 0 ? sv - t : sv + t, z };
  }
  return { su, sv, z };
}

uint16_t Pack(int su, int sv)
{
  return static_cast<uint16_t>(static_cast<uint8_t>(su) | static_cast<uint8_t>(sv) << 8); // mod 256
}

/// A byte as two's complement; -128 reads as -127, as an SNORM texture does.
int Unpack(int byte)
{
  return std::max(byte >= 128 ? byte - 256 : byte, -Levels);
}
} // namespace

uint16_t EncodeUnitNormal(double x, double y, double z)
{
  const double manhattan = std::abs(x) + std::abs(y) + std::abs(z);
  if (!(manhattan > 0) || !std::isfinite(manhattan))
  {
    return Pack(0, 0);
  }
  double u = x / manhattan, v = y / manhattan;
  if (z < 0)
  {
    const double foldedU = (1 - std::abs(v)) * SignNotZero(u);
    v = (1 - std::abs(u)) * SignNotZero(v);
    u = foldedU;
  }
  const double euclid = std::sqrt(x * x + y * y + z * z);
  const double nx = x / euclid, ny = y / euclid, nz = z / euclid;
  // Of the four codes around (u, v), the one nearest in angle; codes that would flip z's sign
  // lose to any that keep it (rounding both toward zero keeps z >= 0, away from zero z <= 0).
  const int lowU = static_cast<int>(std::floor(u * Levels)), lowV = static_cast<int>(std::floor(v * Levels));
  int bestU = 0, bestV = 0;
  bool bestKeepsSign = false;
  double bestCosine = -2;
  for (int du = 0; du < 2; ++du)
  {
    for (int dv = 0; dv < 2; ++dv)
    {
      const int su = std::clamp(lowU + du, -Levels, Levels), sv = std::clamp(lowV + dv, -Levels, Levels);
      const std::array<int, 3> p = Unfold(su, sv);
      const bool keepsSign = z > 0 ? p[2] >= 0 : z < 0 ? p[2] <= 0 : true;
      const double length = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
      const double cosine = (nx * p[0] + ny * p[1] + nz * p[2]) / length;
      if (keepsSign > bestKeepsSign || (keepsSign == bestKeepsSign && cosine > bestCosine))
      {
        bestU = su;
        bestV = sv;
        bestKeepsSign = keepsSign;
        bestCosine = cosine;
      }
    }
  }
  return Pack(bestU, bestV);
}

std::array<float, 3> DecodeUnitNormal(uint16_t code)
{
  const std::array<int, 3> p = Unfold(Unpack(code & 0xFF), Unpack(code >> 8));
  const double length = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
  return { static_cast<float>(p[0] / length), static_cast<float>(p[1] / length), static_cast<float>(p[2] / length) };
}

} // namespace resmr
