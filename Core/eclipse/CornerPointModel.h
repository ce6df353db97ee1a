// In-memory result of parsing an Eclipse grid deck (paper Sec. 3: the ni x nj x nk
// corner-point model with per-cell properties). Plain data, no VTK.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

/// A per-cell array (PORO, PERMX, SATNUM, ...) or a Cartesian geometry array (DX, TOPS ...).
/// Values are kept in double so ASCII input round-trips exactly; NaN marks "not given".
struct CellArray
{
  std::string name;
  bool isInteger = false; ///< region numbers (*NUM) and ACTNUM
  std::vector<double> values;
};

/// One FAULTS record: a box of cells (0-based, inclusive) and the face they fault on.
struct FaultFace
{
  enum Direction : int8_t
  {
    IMinus = 0,
    IPlus = 1,
    JMinus = 2,
    JPlus = 3,
    KMinus = 4,
    KPlus = 5
  };
  std::array<int32_t, 6> box{}; ///< i1 i2 j1 j2 k1 k2, 0-based inclusive
  Direction face = IPlus;
};

struct Fault
{
  std::string name;
  std::vector<FaultFace> faces;
};

/// MAPAXES: a point on the map y axis, the origin, a point on the map x axis.
struct MapAxes
{
  std::array<double, 2> yAxisPoint{};
  std::array<double, 2> origin{};
  std::array<double, 2> xAxisPoint{};
};

/// Where the grid lies on the map: MAPAXES, MAPUNITS and GRIDUNIT as the input gives them.
struct MapPlacement
{
  bool hasMapAxes = false;
  MapAxes mapAxes;
  std::string mapUnits;
  std::string gridUnit;
  bool gridUnitIsMap = false; ///< GRIDUNIT 'METRES' 'MAP': COORD already in map coordinates
};

struct CornerPointModel
{
  std::array<int64_t, 3> dims{ 0, 0, 0 }; ///< nx, ny, nz (0 until SPECGRID/DIMENS)

  std::vector<double> coord; ///< 6 (nx+1)(ny+1): pillar top xyz, bottom xyz
  std::vector<double> zcorn; ///< 8 nx ny nz depths, ECLIPSE order
  /// The same in single precision, used instead of zcorn when the source stores float32
  /// (EGRID): exact, and half the memory of the largest array of a model.
  std::vector<float> zcornSingle;
  std::vector<double> dxv, dyv, dzv; ///< Cartesian alternatives (one value per column/layer)

  bool hasMapAxes = false;
  MapAxes mapAxes;
  std::string mapUnits;
  std::string gridUnit;
  bool gridUnitIsMap = false;                         ///< GRIDUNIT 'METRES' 'MAP': COORD already in map coordinates
  std::vector<std::string> gdorient;                  ///< GDORIENT record, as written
  std::vector<std::array<int32_t, 2>> coordsysLayers; ///< COORDSYS k1 k2 (1-based)

  /// Cell arrays in first-definition order. ACTNUM, DX, DY, DZ and TOPS live here too so
  /// EQUALS / MULTIPLY / COPY / BOX edit them like any other array.
  std::vector<CellArray> arrays;

  std::vector<Fault> faults;
  std::vector<std::string> files;    ///< every file read, the deck first
  std::vector<std::string> warnings; ///< problems that did not stop the parse

  int64_t CellCount() const { return this->dims[0] * this->dims[1] * this->dims[2]; }
  MapPlacement Placement() const
  {
    return { this->hasMapAxes, this->mapAxes, this->mapUnits, this->gridUnit, this->gridUnitIsMap };
  }
  const CellArray* FindArray(const std::string& name) const;
  CellArray* FindArray(const std::string& name);
  bool HasCornerPointGeometry() const
  {
    return !this->coord.empty() && (!this->zcorn.empty() || !this->zcornSingle.empty());
  }
};

/// Keywords that carry grid geometry rather than cell properties.
bool IsGeometryArrayName(const std::string& name);

} // namespace resmr
