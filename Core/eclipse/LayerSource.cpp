// Layer-by-layer corner-point input for the partitioning pass (paper Sec. 4.2).
#include "LayerSource.h"

#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "Errors.h"
#include "GrdeclParser.h"
#include "SyntheticReservoir.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{

SyntheticLayerSource::SyntheticLayerSource(const SyntheticParameters& parameters, std::string name)
  : Model(new SyntheticReservoir(parameters))
  , Label(std::move(name))
{
  this->Stream.reset(new SyntheticLayerStream(*this->Model));
  this->CoordValues = this->Model->Coord();
  this->Dimensions = { parameters.nx, parameters.ny, parameters.nz };
}

SyntheticLayerSource::~SyntheticLayerSource() = default;

std::array<int64_t, 3> SyntheticLayerSource::Dims() const
{
  return this->Dimensions;
}

void SyntheticLayerSource::Finished()
{
  this->Stream.reset();
  this->Model.reset();
  std::vector<double>().swap(this->CoordValues);
}

bool SyntheticLayerSource::Next(std::vector<float>& zcorn, std::vector<uint8_t>& active)
{
  SyntheticLayer layer;
  if (!this->Stream || !this->Stream->Next(layer))
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
  const CornerPointGeometry& geometry, const std::vector<bool>& active, std::string name, MapPlacement placement)
  : Geometry(geometry)
  , Active(active)
  , Label(std::move(name))
  , Map(std::move(placement))
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
      active[static_cast<std::size_t>(j * nx + i)] =
        this->Active[static_cast<std::size_t>((k * ny + j) * nx + i)] ? 1 : 0;
    }
  }
  return true;
}

void ReadCornerPointModel(const std::string& path, CornerPointModel& deck, std::vector<bool>& active)
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
/// An EGRID/FEGRID read layer by layer: COORD whole, each layer's ZCORN and ACTNUM through
/// forward cursors (layers come in increasing order).
class EclipseGridLayerSource : public LayerSource
{
public:
  explicit EclipseGridLayerSource(const std::string& path)
    : File(path)
    , Layout(LocateEclipseGrid(this->File, std::numeric_limits<int64_t>::max()))
  {
    const EclipseRecord& coord = *this->Layout.coord;
    this->CoordValues.resize(static_cast<std::size_t>(coord.count));
    this->File.Read(coord, this->CoordValues.data());
    for (std::size_t v = 0; v < this->CoordValues.size(); ++v)
    {
      if (!std::isfinite(this->CoordValues[v]))
      {
        this->File.Fail(&coord, coord.headerOffset, "value " + std::to_string(v + 1) + " is not finite");
      }
    }
    CornerPointGeometry::CheckMapAxes(this->Layout.deck);
    // ACTNUM 2 or 3 anywhere makes the grid dual porosity (ReadEclipseGrid): a first pass
    // through ACTNUM, a piece at a time, when FILEHEAD does not say so.
    this->DualPorosity = this->Layout.dualPorosityHeader;
    if (this->Layout.actnum && !this->DualPorosity)
    {
      EclipseRecordCursor scan(this->File, *this->Layout.actnum);
      const int64_t count = this->Layout.actnum->count;
      std::vector<int32_t> values(static_cast<std::size_t>(std::min<int64_t>(count, 1 << 16)));
      for (int64_t first = 0; first < count && !this->DualPorosity; first += 1 << 16)
      {
        const int64_t n = std::min<int64_t>(1 << 16, count - first);
        scan.Read(n, values.data());
        for (int64_t v = 0; v < n; ++v)
        {
          this->DualPorosity |= values[static_cast<std::size_t>(v)] > 1;
        }
      }
    }
    if (this->Layout.actnum)
    {
      this->Actnum.reset(new EclipseRecordCursor(this->File, *this->Layout.actnum));
    }
    this->Zcorn.reset(new EclipseRecordCursor(this->File, *this->Layout.zcorn));
  }

  std::array<int64_t, 3> Dims() const override { return this->Layout.deck.dims; }
  const std::vector<double>& Coord() const override { return this->CoordValues; }
  std::string Name() const override { return this->File.Path(); }
  MapPlacement Placement() const override { return this->Layout.deck.Placement(); }

  bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) override
  {
    const auto& dims = this->Layout.deck.dims;
    if (this->K >= dims[2])
    {
      return false;
    }
    const int64_t layer = dims[0] * dims[1];
    const EclipseRecord& record = *this->Layout.zcorn;
    const int64_t first = 8 * layer * this->K;
    zcorn.resize(static_cast<std::size_t>(8 * layer));
    const auto finite = [&](const auto* values) {
      for (int64_t v = 0; v < 8 * layer; ++v)
      {
        if (!std::isfinite(values[v]))
        {
          this->File.Fail(&record, record.headerOffset, "value " + std::to_string(first + v + 1) + " is not finite");
        }
      }
    };
    if (record.type == EclipseDataType::Real)
    {
      this->Zcorn->Read(8 * layer, zcorn.data()); // float32 as written
      finite(zcorn.data());
    }
    else
    {
      // Other types as ReadEclipseGrid holds them (double), then rounded as CellCorners' are.
      this->Depths.resize(static_cast<std::size_t>(8 * layer));
      this->Zcorn->Read(8 * layer, this->Depths.data());
      finite(this->Depths.data());
      for (int64_t v = 0; v < 8 * layer; ++v)
      {
        zcorn[static_cast<std::size_t>(v)] = static_cast<float>(this->Depths[static_cast<std::size_t>(v)]);
      }
    }
    active.assign(static_cast<std::size_t>(layer), 1);
    if (this->Actnum)
    {
      this->Values.resize(static_cast<std::size_t>(layer));
      this->Actnum->Read(layer, this->Values.data());
      for (int64_t c = 0; c < layer; ++c)
      {
        active[static_cast<std::size_t>(c)] =
          ActiveCellValue(this->Values[static_cast<std::size_t>(c)], this->DualPorosity) ? 1 : 0;
      }
    }
    ++this->K;
    return true;
  }

private:
  EclipseKeywordFile File;
  EclipseGridLayout Layout; ///< points into File's index
  std::vector<double> CoordValues;
  bool DualPorosity = false;
  std::unique_ptr<EclipseRecordCursor> Zcorn, Actnum;
  std::vector<double> Depths;
  std::vector<int32_t> Values;
  int64_t K = 0;
};

/// A GRDECL/DATA deck parsed with bounded memory (ParseGrdeclGrid), its grid arrays read back
/// from the spool layer by layer. Cartesian decks (DX/DY/DZ/TOPS) are turned into corner
/// points a layer at a time, as CornerPointGeometry's BuildCartesian does for the whole grid.
class GrdeclLayerSource : public LayerSource
{
public:
  GrdeclLayerSource(const std::string& path, const std::string& spoolFolder)
    : Label(path)
  {
    this->Deck = ParseGrdeclGrid(path, spoolFolder, this->Spool);
    const CornerPointModel& deck = this->Deck;
    const std::string& file = deck.files.front();
    const int64_t nx = deck.dims[0], ny = deck.dims[1];
    // The checks and their order are CornerPointGeometry::FromDeck's.
    const bool cornerPoint = !deck.coord.empty() && this->Spool.zcorn;
    if (!cornerPoint)
    {
      const bool hasDx = this->Spool.dx || !deck.dxv.empty();
      const bool hasDy = this->Spool.dy || !deck.dyv.empty();
      const bool hasDz = this->Spool.dz || !deck.dzv.empty();
      if (!hasDx || !hasDy || !hasDz || !this->Spool.tops)
      {
        throw InputError(
          file, 0, "COORD", "no grid geometry: need COORD and ZCORN, or DX/DXV, DY/DYV, DZ/DZV and TOPS");
      }
    }
    if (cornerPoint)
    {
      if (static_cast<int64_t>(deck.coord.size()) != 6 * (nx + 1) * (ny + 1))
      {
        throw InputError(file, 0, "ZCORN", "COORD/ZCORN sizes do not match the grid dimensions");
      }
      this->CoordValues = std::move(this->Deck.coord);
      this->Deck.coord.clear();
    }
    else
    {
      this->BuildCartesianCoord();
    }
    CornerPointGeometry::CheckMapAxes(this->Deck);
  }

  std::array<int64_t, 3> Dims() const override { return this->Deck.dims; }
  const std::vector<double>& Coord() const override { return this->CoordValues; }
  std::string Name() const override { return this->Label; }
  MapPlacement Placement() const override { return this->Deck.Placement(); }

  bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) override
  {
    const int64_t nx = this->Deck.dims[0], ny = this->Deck.dims[1];
    if (this->K >= this->Deck.dims[2])
    {
      return false;
    }
    const int64_t layer = nx * ny;
    zcorn.resize(static_cast<std::size_t>(8 * layer));
    if (this->Spool.zcorn)
    {
      this->Spool.zcorn->Read(8 * layer * this->K, zcorn.data(), 8 * layer);
    }
    else
    {
      this->CartesianLayer(zcorn);
    }
    active.assign(static_cast<std::size_t>(layer), 1);
    if (this->Spool.actnum)
    {
      this->Values.resize(static_cast<std::size_t>(layer));
      this->Spool.actnum->Read(layer * this->K, this->Values.data(), layer);
      for (int64_t c = 0; c < layer; ++c)
      {
        active[static_cast<std::size_t>(c)] = this->Values[static_cast<std::size_t>(c)] != 0 ? 1 : 0;
      }
    }
    ++this->K;
    return true;
  }

  std::vector<std::string> Warnings() const override { return this->Deck.warnings; }

private:
  /// A cell size as BuildCartesian takes it: the vector form (DXV ...) if given, else the
  /// cell's value (`layerValues` holds layer k of the array when given, else read here).
  double CellSize(const char* name, const std::vector<double>& vectorForm, SpoolFile* full, const double* layerValues,
    int64_t i, int64_t j, int64_t k, int axis)
  {
    const int64_t nx = this->Deck.dims[0], ny = this->Deck.dims[1];
    const int64_t along = axis == 0 ? i : (axis == 1 ? j : k);
    double value = std::nan("");
    if (!vectorForm.empty())
    {
      value = vectorForm[static_cast<std::size_t>(along)];
    }
    else if (layerValues)
    {
      value = layerValues[j * nx + i];
    }
    else if (full)
    {
      full->Read((k * ny + j) * nx + i, &value, 1);
    }
    if (!std::isfinite(value) || value < 0)
    {
      throw InputError(this->Deck.files.front(), 0, name,
        "cell (" + std::to_string(i + 1) + "," + std::to_string(j + 1) + "," + std::to_string(k + 1) +
          ") has no valid size");
    }
    return value;
  }

  void BuildCartesianCoord()
  {
    const int64_t nx = this->Deck.dims[0], ny = this->Deck.dims[1];
    std::vector<double> xEdges(static_cast<std::size_t>(nx + 1), 0.0);
    std::vector<double> yEdges(static_cast<std::size_t>(ny + 1), 0.0);
    for (int64_t i = 0; i < nx; ++i)
    {
      xEdges[i + 1] = xEdges[i] + this->CellSize("DX", this->Deck.dxv, this->Spool.dx.get(), nullptr, i, 0, 0, 0);
    }
    for (int64_t j = 0; j < ny; ++j)
    {
      yEdges[j + 1] = yEdges[j] + this->CellSize("DY", this->Deck.dyv, this->Spool.dy.get(), nullptr, 0, j, 0, 1);
    }
    this->CoordValues.resize(static_cast<std::size_t>(6 * (nx + 1) * (ny + 1)));
    for (int64_t j = 0; j <= ny; ++j)
    {
      for (int64_t i = 0; i <= nx; ++i)
      {
        double* pillar = &this->CoordValues[static_cast<std::size_t>(6 * (j * (nx + 1) + i))];
        pillar[0] = pillar[3] = xEdges[i];
        pillar[1] = pillar[4] = yEdges[j];
        pillar[2] = 0.0;
        pillar[5] = 1.0;
      }
    }
    this->Tops.assign(static_cast<std::size_t>(nx * ny), 0.0);
  }

  /// Layer K of a Cartesian deck: each column's top from TOPS where given, else the bottom
  /// of the cell above; bottom = top + DZ.
  void CartesianLayer(std::vector<float>& zcorn)
  {
    const int64_t nx = this->Deck.dims[0], ny = this->Deck.dims[1], k = this->K;
    const int64_t layer = nx * ny;
    std::vector<double> given(static_cast<std::size_t>(layer));
    this->Spool.tops->Read(layer * k, given.data(), layer);
    std::vector<double> thickness;
    if (this->Deck.dzv.empty())
    {
      thickness.resize(static_cast<std::size_t>(layer));
      this->Spool.dz->Read(layer * k, thickness.data(), layer);
    }
    for (int64_t j = 0; j < ny; ++j)
    {
      for (int64_t i = 0; i < nx; ++i)
      {
        const std::size_t column = static_cast<std::size_t>(j * nx + i);
        double top = this->Tops[column];
        if (std::isfinite(given[column]))
        {
          top = given[column];
        }
        else if (k == 0)
        {
          throw InputError(this->Deck.files.front(), 0, "TOPS",
            "column (" + std::to_string(i + 1) + "," + std::to_string(j + 1) + ") has no top depth in layer 1");
        }
        const double bottom = top +
          this->CellSize(
            "DZ", this->Deck.dzv, this->Spool.dz.get(), thickness.empty() ? nullptr : thickness.data(), i, j, k, 2);
        for (int corner = 0; corner < 8; ++corner)
        {
          const int64_t di = corner & 1, dj = (corner >> 1) & 1, dk = corner >> 2;
          zcorn[static_cast<std::size_t>(dk * 4 * layer + (2 * j + dj) * 2 * nx + 2 * i + di)] =
            static_cast<float>(dk ? bottom : top);
        }
        this->Tops[column] = bottom;
      }
    }
  }

  std::string Label;
  CornerPointModel Deck;
  GrdeclGridSpool Spool;
  std::vector<double> CoordValues;
  std::vector<double> Tops; ///< Cartesian: each column's depth reached so far
  std::vector<double> Values;
  int64_t K = 0;
};
} // namespace

std::unique_ptr<LayerSource> OpenLayerSource(const std::string& input, const std::string& spoolFolder)
{
  if (IsSyntheticSpec(input))
  {
    return std::unique_ptr<LayerSource>(new SyntheticLayerSource(ParseSyntheticSpec(input), input));
  }
  if (LooksLikeEclipseGridFile(input))
  {
    return std::unique_ptr<LayerSource>(new EclipseGridLayerSource(input));
  }
  std::string folder = spoolFolder;
  if (folder.empty())
  {
    const char* temporary = std::getenv("TMPDIR");
    folder = temporary && *temporary ? temporary : "/tmp";
  }
  // The folder may be the builder's scratch folder, not made yet: made here, and removed
  // again if the deck fails (the spool files themselves are never seen in it).
  const bool made = mkdir(folder.c_str(), 0755) == 0;
  if (!made && errno != EEXIST)
  {
    throw InputError(
      folder, 0, "", std::string("cannot create the folder for temporary files: ") + std::strerror(errno));
  }
  try
  {
    return std::unique_ptr<LayerSource>(new GrdeclLayerSource(input, folder));
  }
  catch (...)
  {
    if (made)
    {
      rmdir(folder.c_str());
    }
    throw;
  }
}

} // namespace resmr
