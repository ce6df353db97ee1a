// Layer-by-layer corner-point input for the partitioning pass (paper Sec. 4.2).
#include "LayerSource.h"

#include "CornerPointGeometry.h"
#include "SyntheticReservoir.h"

namespace resmr
{

SyntheticLayerSource::SyntheticLayerSource(const SyntheticParameters& parameters, std::string name)
  : Model(new SyntheticReservoir(parameters))
  , Label(std::move(name))
{
  this->Stream.reset(new SyntheticLayerStream(*this->Model));
  this->CoordValues = this->Model->Coord();
}

SyntheticLayerSource::~SyntheticLayerSource() = default;

std::array<int64_t, 3> SyntheticLayerSource::Dims() const
{
  const auto& p = this->Model->Parameters();
  return { p.nx, p.ny, p.nz };
}

bool SyntheticLayerSource::Next(std::vector<float>& zcorn, std::vector<uint8_t>& active)
{
  SyntheticLayer layer;
  if (!this->Stream->Next(layer))
  {
    return false;
  }
  zcorn = std::move(layer.zcorn);
  active.resize(layer.state.size());
  for (std::size_t c = 0; c < layer.state.size(); ++c)
  {
    active[c] = layer.state[c] == SyntheticCellState::Active ? 1 : 0;
  }
  return true;
}

CornerPointLayerSource::CornerPointLayerSource(
  const CornerPointGeometry& geometry, const std::vector<bool>& active, std::string name)
  : Geometry(geometry)
  , Active(active)
  , Label(std::move(name))
{
}

std::array<int64_t, 3> CornerPointLayerSource::Dims() const
{
  return this->Geometry.Dims();
}

const std::vector<double>& CornerPointLayerSource::Coord() const
{
  return this->Geometry.Coord();
}

bool CornerPointLayerSource::Next(std::vector<float>& zcorn, std::vector<uint8_t>& active)
{
  const auto dims = this->Geometry.Dims();
  const int64_t nx = dims[0], ny = dims[1];
  if (this->K >= dims[2])
  {
    return false;
  }
  const int64_t k = this->K++;
  zcorn.assign(static_cast<std::size_t>(8 * nx * ny), 0.f);
  active.assign(static_cast<std::size_t>(nx * ny), 0);
  double corners[8][3];
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      this->Geometry.CellCorners(i, j, k, corners);
      for (int c = 0; c < 8; ++c)
      {
        const int64_t di = c & 1, dj = (c >> 1) & 1, dk = c >> 2;
        zcorn[static_cast<std::size_t>(dk * 4 * nx * ny + (2 * j + dj) * 2 * nx + 2 * i + di)] =
          static_cast<float>(corners[c][2]);
      }
      active[static_cast<std::size_t>(j * nx + i)] = this->Active[static_cast<std::size_t>((k * ny + j) * nx + i)] ? 1 : 0;
    }
  }
  return true;
}

} // namespace resmr
