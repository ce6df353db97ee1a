// Wall depths (ours; the paper paints every fragment by its interpolated topological
// coordinate, Sec. 5.1-5.2): the true depth of every layer interface along each wall of the
// original grid, so that a coarse side fragment finds its layer from its own depth.
//
// Why: on the walls (the model's outside and the faults) every layer shows, each a fraction
// of a pixel thick in an overview of a many-layer model. A coarse level paints a wall cell
// within its error of its place (SideSurfaceSimplification.h), which is many layers there:
// most of what an overview at a coarse tolerance gets wrong is on the walls, the right
// column and the wrong layer. A wall's layer interfaces are known exactly: this table holds
// them, and the viewer picks the layer whose interval holds the fragment's depth.
//
// Contract:
// - A wall face is an original column's side (i, j, face) with a run of at least
//   MinWallRun open side cells one above the other (RegionMesh::openSides), or of all its
//   layers on models of fewer; face 0: I- (topological i = i), 1: I+ (i + 1), 2: J- (j = j),
//   3: J+ (j + 1). Its key is (j nx + i) 4 + face + 1 (0: an empty slot). Shorter runs (the
//   sides of pinched-out cells, most of a model's open side cells, mostly hidden inside it)
//   show a few layers at most, which the coordinates paint within a few layers anyway.
// - Each face holds, for every interface k = 0..nk, the depth at its two corners, A (the
//   lower topological coordinate along the face) and B, as the leaf meshes give them (faults
//   split corners: each side of a fault has its own), and for every cell k below an
//   interface the nearest open cell of the face (k itself when open; the upper one on a tie):
//   a fragment that lands on a cell the exact wall does not show names one it does.
// - Faces are found by a perfect spatial hash of (i, j, face) (PerfectSpatialHash.h): each
//   slot holds its face's key (membership) and row. Row r holds texels [r (nk + 1),
//   (r + 1)(nk + 1)) of three floats (depth A, depth B, nearest open cell; the last
//   interface's third value repeats the one above). Faces are lines, which spatial hashes
//   pack loosely (a third of the slots filled): rows keep the texels to the faces alone.
// - Memory: 8 bytes a slot and (nk + 1) x 12 bytes a face, faces about the model's outline
//   and its faults times two (a surface of the model, never its volume).
#pragma once

#include "PerfectSpatialHash.h"
#include "RegionMesh.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

/// One wall face as read from a leaf mesh.
struct WallFace
{
  uint32_t key = 0;           ///< (j nx + i) 4 + face + 1
  std::vector<float> depthA;  ///< nk + 1 interfaces
  std::vector<float> depthB;  ///< nk + 1 interfaces
  std::vector<uint32_t> open; ///< nk cells: nearest open cell
};

struct WallDepthTable
{
  int32_t layers = 0; ///< nk
  uint64_t faces = 0;
  PerfectSpatialHash hash;
  std::vector<std::array<uint32_t, 2>> slots; ///< a slot each: key (0: empty), row
  std::vector<float> texels;                  ///< (nk + 1) x 3 a face (row)
  bool Empty() const { return this->faces == 0; }
};

/// Open side cells one above the other that make a face a wall.
constexpr int32_t MinWallRun = 4;

/// The key of (i, j, face), 0-based.
inline uint32_t WallFaceKey(uint32_t i, uint32_t j, uint32_t face, uint32_t nx)
{
  return (j * nx + i) * 4u + face + 1u;
}

/// Appends the wall faces of a leaf region (whole original columns, integer topological
/// coordinates; positions present). `nx`: the model's first dimension.
void CollectWallFaces(const RegionMesh& leaf, int64_t nx, std::vector<WallFace>& out);

/// Packs the faces (distinct keys; throws std::invalid_argument naming a face listed twice).
WallDepthTable BuildWallDepthTable(const std::vector<WallFace>& faces, int32_t layers, int64_t nx);

/// The table as stored (ModelChunk::WallDepths): a little-endian header (nk, faces, m, r),
/// the offsets, the slots (key, row) and the rows' texels.
std::vector<uint8_t> EncodeWallDepthTable(const WallDepthTable& table);
/// Decodes and checks a stored table against the model's dims; throws FileFormatError
/// naming `place`.
WallDepthTable DecodeWallDepthTable(
  const std::vector<uint8_t>& bytes, const std::array<int64_t, 3>& dims, const std::string& place);

} // namespace resmr
