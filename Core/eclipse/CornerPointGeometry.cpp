// Corner-point geometry (paper Sec. 3: the irregular hexahedral reservoir grid).
#include "CornerPointGeometry.h"

#include "Errors.h"

#include <algorithm>
#include <cmath>

namespace resmr
{
namespace
{
/// Builds pillars and corner depths for a Cartesian grid given by DX/DY/DZ/TOPS. Columns are
/// placed by the cell sizes of the first row and layer, as ECLIPSE does for block-centred
/// grids; each cell keeps its own TOPS and DZ, so depths are exact.
void BuildCartesian(CornerPointModel& deck, std::vector<double>& coord, std::vector<double>& zcorn)
{
  const int64_t nx = deck.dims[0], ny = deck.dims[1], nz = deck.dims[2];
  const std::string& file = deck.files.front();
  const auto cellArray = [&](const char* name) -> const std::vector<double>* {
    const CellArray* array = deck.FindArray(name);
    return array ? &array->values : nullptr;
  };
  const auto size = [&](const char* name, const std::vector<double>& vectorForm, int64_t i, int64_t j, int64_t k,
                      int axis) {
    const int64_t along = axis == 0 ? i : (axis == 1 ? j : k);
    double value = std::nan("");
    if (!vectorForm.empty())
    {
      value = vectorForm[static_cast<std::size_t>(along)];
    }
    else if (const std::vector<double>* full = cellArray(name))
    {
      value = (*full)[static_cast<std::size_t>((k * ny + j) * nx + i)];
    }
    if (!std::isfinite(value) || value < 0)
    {
      throw InputError(file, 0, name,
        "cell (" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "," + std::to_string(k + 1) +
          ") has no valid size");
    }
    return value;
  };
  std::vector<double> xEdges(static_cast<std::size_t>(nx + 1), 0.0);
  std::vector<double> yEdges(static_cast<std::size_t>(ny + 1), 0.0);
  for (int64_t i = 0; i < nx; ++i)
  {
    xEdges[i + 1] = xEdges[i] + size("DX", deck.dxv, i, 0, 0, 0);
  }
  for (int64_t j = 0; j < ny; ++j)
  {
    yEdges[j + 1] = yEdges[j] + size("DY", deck.dyv, 0, j, 0, 1);
  }
  coord.resize(static_cast<std::size_t>(6 * (nx + 1) * (ny + 1)));
  for (int64_t j = 0; j <= ny; ++j)
  {
    for (int64_t i = 0; i <= nx; ++i)
    {
      double* pillar = &coord[static_cast<std::size_t>(6 * (j * (nx + 1) + i))];
      pillar[0] = pillar[3] = xEdges[i];
      pillar[1] = pillar[4] = yEdges[j];
      pillar[2] = 0.0;
      pillar[5] = 1.0;
    }
  }
  const std::vector<double>* tops = cellArray("TOPS");
  zcorn.assign(static_cast<std::size_t>(8 * nx * ny * nz), 0.0);
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      double top = 0.0;
      for (int64_t k = 0; k < nz; ++k)
      {
        const double given = (*tops)[static_cast<std::size_t>((k * ny + j) * nx + i)];
        if (std::isfinite(given))
        {
          top = given;
        }
        else if (k == 0)
        {
          throw InputError(file, 0, "TOPS",
            "column (" + std::to_string(i + 1) + "," + std::to_string(j + 1) + ") has no top depth in layer 1");
        }
        const double bottom = top + size("DZ", deck.dzv, i, j, k, 2);
        for (int corner = 0; corner < 8; ++corner)
        {
          const int64_t di = corner & 1, dj = (corner >> 1) & 1, dk = corner >> 2;
          zcorn[static_cast<std::size_t>(((2 * k + dk) * 2 * ny + 2 * j + dj) * 2 * nx + 2 * i + di)] =
            dk ? bottom : top;
        }
        top = bottom;
      }
    }
  }
}
} // namespace

CornerPointGeometry CornerPointGeometry::FromDeck(CornerPointModel& deck, bool applyMapAxes)
{
  CornerPointGeometry geometry;
  geometry.Dimensions = deck.dims;
  if (!deck.HasCornerPointGeometry())
  {
    const bool hasDx = deck.FindArray("DX") || !deck.dxv.empty();
    const bool hasDy = deck.FindArray("DY") || !deck.dyv.empty();
    const bool hasDz = deck.FindArray("DZ") || !deck.dzv.empty();
    if (!hasDx || !hasDy || !hasDz || !deck.FindArray("TOPS"))
    {
      throw InputError(deck.files.empty() ? std::string("deck") : deck.files.front(), 0, "COORD",
        "no grid geometry: need COORD and ZCORN, or DX/DXV, DY/DYV, DZ/DZV and TOPS");
    }
  }
  if (deck.HasCornerPointGeometry())
  {
    const int64_t nx = deck.dims[0], ny = deck.dims[1];
    const std::size_t depths = deck.zcornSingle.empty() ? deck.zcorn.size() : deck.zcornSingle.size();
    if (static_cast<int64_t>(deck.coord.size()) != 6 * (nx + 1) * (ny + 1) ||
      static_cast<int64_t>(depths) != 8 * deck.CellCount())
    {
      throw InputError(deck.files.empty() ? std::string("deck") : deck.files.front(), 0, "ZCORN",
        "COORD/ZCORN sizes do not match the grid dimensions");
    }
    geometry.CoordValues = std::move(deck.coord);
    geometry.ZcornValues = std::move(deck.zcorn);
    geometry.ZcornSingle = std::move(deck.zcornSingle);
    deck.coord.clear();
    deck.zcorn.clear();
    deck.zcornSingle.clear();
  }
  else
  {
    BuildCartesian(deck, geometry.CoordValues, geometry.ZcornValues);
  }
  CheckMapAxes(deck);
  geometry.MapAxesAvailable = PlacementTransform(deck.Placement(), geometry.MapTransform);
  geometry.SetMapAxesApplied(applyMapAxes);
  return geometry;
}

void CornerPointGeometry::CheckMapAxes(const CornerPointModel& deck)
{
  std::array<double, 6> transform;
  if (deck.hasMapAxes && !deck.gridUnitIsMap && !MapTransformOf(deck.mapAxes, transform))
  {
    throw InputError(deck.files.empty() ? std::string("deck") : deck.files.front(), 0, "MAPAXES",
      "axis points coincide with the origin");
  }
}

bool CornerPointGeometry::MapTransformOf(const MapAxes& axes, std::array<double, 6>& transform)
{
  const double ex[2] = { axes.xAxisPoint[0] - axes.origin[0], axes.xAxisPoint[1] - axes.origin[1] };
  const double ey[2] = { axes.yAxisPoint[0] - axes.origin[0], axes.yAxisPoint[1] - axes.origin[1] };
  const double lx = std::hypot(ex[0], ex[1]);
  const double ly = std::hypot(ey[0], ey[1]);
  if (!(lx > 0) || !(ly > 0) || !std::isfinite(lx) || !std::isfinite(ly))
  {
    return false;
  }
  transform = { axes.origin[0], axes.origin[1], ex[0] / lx, ex[1] / lx, ey[0] / ly, ey[1] / ly };
  return true;
}

bool CornerPointGeometry::PlacementTransform(const MapPlacement& placement, std::array<double, 6>& transform)
{
  return placement.hasMapAxes && !placement.gridUnitIsMap && MapTransformOf(placement.mapAxes, transform);
}

void CornerPointGeometry::SetMapAxesApplied(bool apply)
{
  this->MapAxesApplied = apply && this->MapAxesAvailable;
  this->DetectHandedness();
}

void CornerPointGeometry::PillarPoint(int64_t pillar, double depth, double xyz[3]) const
{
  PointOnPillar(&this->CoordValues[static_cast<std::size_t>(6 * pillar)], depth, xyz);
  if (this->MapAxesApplied)
  {
    ApplyMapTransform(this->MapTransform, xyz[0], xyz[1]);
  }
}

void CornerPointGeometry::CellCorners(int64_t i, int64_t j, int64_t k, double corners[8][3]) const
{
  const int64_t nx = this->Dimensions[0];
  for (int corner = 0; corner < 8; ++corner)
  {
    const int64_t di = corner & 1, dj = (corner >> 1) & 1;
    this->PillarPoint((j + dj) * (nx + 1) + i + di, this->Z(i, j, k, corner), corners[corner]);
  }
}

void CornerPointGeometry::DetectHandedness()
{
  // Sum of the (i, j) cross products of the top pillar ends: its sign is the grid's turn.
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  const auto point = [&](int64_t i, int64_t j, double out[2]) {
    const double* p = &this->CoordValues[static_cast<std::size_t>(6 * (j * (nx + 1) + i))];
    out[0] = p[0];
    out[1] = p[1];
    if (this->MapAxesApplied)
    {
      ApplyMapTransform(this->MapTransform, out[0], out[1]);
    }
  };
  double turn = 0.0;
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      double p00[2], p10[2], p01[2];
      point(i, j, p00);
      point(i + 1, j, p10);
      point(i, j + 1, p01);
      const double ax = p10[0] - p00[0], ay = p10[1] - p00[1];
      const double bx = p01[0] - p00[0], by = p01[1] - p00[1];
      turn += ax * by - ay * bx;
    }
  }
  // i x j pointing up (counter-clockwise from above) with k going down: left-handed.
  this->LeftHanded = turn > 0.0;
}

CornerPointGeometry::SharedCorners CornerPointGeometry::BuildSharedCorners() const
{
  const int64_t nx = this->Dimensions[0], ny = this->Dimensions[1], nz = this->Dimensions[2];
  SharedCorners shared;
  shared.cellPoints.assign(static_cast<std::size_t>(8 * nx * ny * nz), -1);
  shared.points.reserve(static_cast<std::size_t>(3 * (nx + 1) * (ny + 1) * (nz + 1)));
  struct Entry
  {
    double depth;
    int64_t slot; ///< index into cellPoints
  };
  std::vector<Entry> entries;
  entries.reserve(static_cast<std::size_t>(8 * nz));
  for (int64_t pj = 0; pj <= ny; ++pj)
  {
    for (int64_t pi = 0; pi <= nx; ++pi)
    {
      entries.clear();
      // Up to four columns meet at a pillar; each brings a top and a bottom corner per layer.
      for (int64_t cj = pj - 1; cj <= pj; ++cj)
      {
        for (int64_t ci = pi - 1; ci <= pi; ++ci)
        {
          if (ci < 0 || cj < 0 || ci >= nx || cj >= ny)
          {
            continue;
          }
          const int corner = int(pi - ci) + 2 * int(pj - cj);
          for (int64_t k = 0; k < nz; ++k)
          {
            const int64_t cell = (k * ny + cj) * nx + ci;
            entries.push_back({ this->Z(ci, cj, k, corner), 8 * cell + corner });
            entries.push_back({ this->Z(ci, cj, k, corner + 4), 8 * cell + corner + 4 });
          }
        }
      }
      std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.depth < b.depth; });
      const int64_t pillar = pj * (nx + 1) + pi;
      for (std::size_t e = 0; e < entries.size(); ++e)
      {
        if (e == 0 || entries[e].depth != entries[e - 1].depth)
        {
          double xyz[3];
          this->PillarPoint(pillar, entries[e].depth, xyz);
          shared.points.insert(shared.points.end(), xyz, xyz + 3);
        }
        shared.cellPoints[static_cast<std::size_t>(entries[e].slot)] =
          static_cast<int64_t>(shared.points.size() / 3 - 1);
      }
    }
  }
  return shared;
}

} // namespace resmr
