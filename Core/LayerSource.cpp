// Layer-by-layer corner-point input for the partitioning pass (paper Sec. 4.2).
#include "LayerSource.h"

#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "GrdeclParser.h"
#include "SyntheticReservoir.h"

#include <cstdio>
#include <stdexcept>

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

void ReadCornerPointModel(const std::string& path, GrdeclDeck& deck, std::vector<bool>& active)
{
  if (LooksLikeEclipseGridFile(path))
  {
    EclipseGrid grid = ReadEclipseGrid(path);
    active.resize(static_cast<std::size_t>(grid.deck.CellCount()));
    for (int64_t c = 0; c < grid.deck.CellCount(); ++c)
    {
      active[static_cast<std::size_t>(c)] = grid.IsActive(c);
    }
    deck = std::move(grid.deck);
    return;
  }
  deck = ParseGrdeclFile(path);
  const CellArray* actnum = deck.FindArray("ACTNUM");
  active.resize(static_cast<std::size_t>(deck.CellCount()));
  for (int64_t c = 0; c < deck.CellCount(); ++c)
  {
    active[static_cast<std::size_t>(c)] = !actnum || actnum->values[static_cast<std::size_t>(c)] != 0;
  }
}

namespace
{
/// A grid file's layers, owning the model they come from.
class GridFileLayerSource : public LayerSource
{
public:
  explicit GridFileLayerSource(const std::string& path)
  {
    ReadCornerPointModel(path, this->Deck, this->Active);
    this->Geometry.reset(new CornerPointGeometry(CornerPointGeometry::FromDeck(this->Deck, false)));
    this->Layers.reset(new CornerPointLayerSource(*this->Geometry, this->Active, path));
  }
  std::array<int64_t, 3> Dims() const override { return this->Layers->Dims(); }
  const std::vector<double>& Coord() const override { return this->Layers->Coord(); }
  bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) override { return this->Layers->Next(zcorn, active); }
  std::string Name() const override { return this->Layers->Name(); }

private:
  GrdeclDeck Deck;
  std::vector<bool> Active;
  std::unique_ptr<CornerPointGeometry> Geometry;
  std::unique_ptr<CornerPointLayerSource> Layers;
};
} // namespace

std::unique_ptr<LayerSource> OpenLayerSource(const std::string& input)
{
  if (input.rfind("synth:", 0) == 0)
  {
    SyntheticParameters p;
    long long nx = 0, ny = 0, nz = 0;
    unsigned long long seed = 1;
    if (std::sscanf(input.c_str() + 6, "%lldx%lldx%lld:%llu", &nx, &ny, &nz, &seed) < 3)
    {
      throw std::invalid_argument(input + ": expected synth:NIxNJxNK[:SEED]");
    }
    p.nx = nx;
    p.ny = ny;
    p.nz = nz;
    p.seed = seed;
    p.Validate();
    return std::unique_ptr<LayerSource>(new SyntheticLayerSource(p, input));
  }
  return std::unique_ptr<LayerSource>(new GridFileLayerSource(input));
}

} // namespace resmr
