// Cell-face normals in two bytes, paper Sec. 5.3: the top and bottom face normal of every cell
// in the octahedral encoding (Meyer et al. 2010; Cigolle et al., "A Survey of Efficient
// Representations for Independent Unit Vectors", JCGT 2014), 8 bits a component, rounded to
// the nearest of the four neighbouring codes by angle (the survey's precise "oct16P").
//
// Contract:
// - The unit sphere is projected onto the octahedron |x| + |y| + |z| = 1, the lower half
//   folded over the upper, giving (u, v) in [-1, 1]^2; each is stored as a signed byte
//   round(127 u) in -127..127 (two's complement, -128 never written): low byte u, high byte
//   v. So a GL RG8_SNORM texture returns (u, v) directly, and code 0 is +z.
// - Round trip: at most 0.64 degrees from the input direction (0.636 measured over 10^7
//   random vectors, a third near the equator; wider rounding searches do no better, it is
//   the lattice's covering radius); +-x, +-y, +-z come back exactly.
// - The sign of z survives: z > 0 decodes to z >= 0 and z < 0 to z <= 0 (the fold's seam,
//   z = 0, is the equator).
// - Any non-zero finite vector is normalised first; zero or non-finite input encodes +z.
//
// GLSL decode of a code read as uint (e.g. from an R16UI texture):
//   vec2 e = max(vec2(bitfieldExtract(int(code), 0, 8), bitfieldExtract(int(code), 8, 8)) / 127.0,
//                vec2(-1.0));
//   vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
//   float t = max(-n.z, 0.0);
//   n.xy -= t * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
//   n = normalize(n);
#pragma once

#include <array>
#include <cstdint>

namespace resmr
{

/// The octahedral code of the direction of (x, y, z).
uint16_t EncodeUnitNormal(double x, double y, double z);

/// The unit vector a code stands for (the GLSL decode above, in exact integer steps).
std::array<float, 3> DecodeUnitNormal(uint16_t code);

} // namespace resmr
