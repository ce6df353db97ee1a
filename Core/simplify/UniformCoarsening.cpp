// Uniform b x b column coarsening, the yardstick of the Sec. 4.1 benchmark.
#include "UniformCoarsening.h"

#include "CornerPointGeometry.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>

namespace resmr
{

HexMesh CoarsenUniformly(const CornerPointGeometry& geometry, const std::vector<bool>& active, int64_t block)
{
  const int64_t nx = geometry.Dims()[0], ny = geometry.Dims()[1], nz = geometry.Dims()[2];
  if (block < 1 || static_cast<int64_t>(active.size()) != nx * ny * nz)
  {
    throw std::invalid_argument("uniform coarsening: bad block size or active flags");
  }
  HexMesh out;
  out.layers = nz;
  // Points shared by exact position and interface.
  std::map<std::array<double, 4>, int64_t> pointIds;
  auto pointOf = [&](const double xyz[3], int64_t k, double ti, double tj) {
    const std::array<double, 4> key = { xyz[0], xyz[1], xyz[2], static_cast<double>(k) };
    const auto found = pointIds.find(key);
    if (found != pointIds.end())
    {
      return found->second;
    }
    const int64_t id = out.PointCount();
    pointIds.emplace(key, id);
    out.points.insert(out.points.end(), { xyz[0], xyz[1], xyz[2] });
    out.topology.insert(out.topology.end(), { ti, tj, static_cast<double>(k) });
    return id;
  };
  // Corner q of a column ((i,j), (i+1,j), (i+1,j+1), (i,j+1)) as an ECLIPSE corner index.
  static const int eclipseCorner[4] = { 0, 1, 3, 2 };
  double corners[8][3];
  for (int64_t bj = 0; bj * block < ny; ++bj)
  {
    for (int64_t bi = 0; bi * block < nx; ++bi)
    {
      const int64_t i0 = bi * block, i1 = std::min(nx, i0 + block);
      const int64_t j0 = bj * block, j1 = std::min(ny, j0 + block);
      std::vector<uint8_t> layerActive(static_cast<std::size_t>(nz), 0);
      bool any = false;
      for (int64_t k = 0; k < nz; ++k)
      {
        for (int64_t j = j0; j < j1; ++j)
        {
          for (int64_t i = i0; i < i1; ++i)
          {
            layerActive[k] |= active[static_cast<std::size_t>((k * ny + j) * nx + i)] ? 1 : 0;
          }
        }
        any = any || layerActive[k];
      }
      if (!any)
      {
        continue;
      }
      // The fine column at each corner of the block, and the corner it gives.
      const int64_t ci[4] = { i0, i1 - 1, i1 - 1, i0 };
      const int64_t cj[4] = { j0, j0, j1 - 1, j1 - 1 };
      std::vector<std::array<int64_t, 4>> interfaces(static_cast<std::size_t>(nz + 1));
      for (int q = 0; q < 4; ++q)
      {
        for (int64_t k = 0; k < nz; ++k)
        {
          geometry.CellCorners(ci[q], cj[q], k, corners);
          const double ti = static_cast<double>(q == 1 || q == 2 ? i1 : i0);
          const double tj = static_cast<double>(q >= 2 ? j1 : j0);
          interfaces[k][q] = pointOf(corners[eclipseCorner[q]], k, ti, tj);
          if (k == nz - 1)
          {
            interfaces[nz][q] = pointOf(corners[eclipseCorner[q] + 4], nz, ti, tj);
          }
        }
      }
      for (int64_t k = 0; k < nz; ++k)
      {
        out.cells.push_back({ interfaces[k][0], interfaces[k][1], interfaces[k][2], interfaces[k][3],
          interfaces[k + 1][0], interfaces[k + 1][1], interfaces[k + 1][2], interfaces[k + 1][3] });
        out.active.push_back(layerActive[k]);
      }
    }
  }
  return out;
}

} // namespace resmr
