// Synthetic corner-point reservoir models of any size, streamed layer by layer: the stand-in
// for the massive models of paper Sec. 7 (up to 1.2 billion cells), which no public data set
// provides. The geology exercises every case of Sec. 4.1 and Fig. 3: layers of varying
// thickness over a dipping anticline, normal faults (some oblique to i and j) that break faces,
// sloping pillars, pinch-outs made inactive, an oil-water contact and a ragged field outline
// leaving partly active columns, and layer-correlated PORO / NTG / PERMX with optional report
// steps of PRESSURE and SWAT as water moves from injectors to producers.
//
// Contract:
// - Deterministic: the same parameters give the same bits on every machine. Only IEEE-exact
//   operations (+ - * / sqrt, floor) and integer hashing are used, no libm transcendental
//   functions, and the file is compiled without floating-point contraction.
// - Memory O(nx * ny), independent of nz: SyntheticReservoir holds per-column state (about
//   60 bytes a column); each SyntheticLayerStream holds one layer (about 60 bytes a column).
// - Layers come out in k order (k = 0 is the top), each with its ZCORN values in ECLIPSE order,
//   cell states and properties; several streams over one model may run at once (the model is
//   read-only once built).
// - Invalid parameters throw std::invalid_argument with a message naming the parameter.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

struct SyntheticParameters
{
  int64_t nx = 100, ny = 100, nz = 20;
  uint64_t seed = 1;
  int faults = 6;                ///< normal faults; every third runs along i or j, the rest oblique
  double maxThrow = 0.3;         ///< largest throw as a fraction of the gross thickness
  double dipDegrees = 2.0;       ///< regional dip
  double pinchedFraction = 0.05; ///< cells pinched out (zero thickness), inside the outline
  double waterFraction = 0.2;    ///< cells below the oil-water contact, inside the outline
  double outsideFraction = 0.25; ///< columns outside the irregular field outline
  int steps = 0;                 ///< report steps of PRESSURE and SWAT (0: none)
  double cellSize = 0;           ///< lateral cell size in metres (0: from the model size)
  double grossThickness = 0;     ///< metres (0: from nz)

  /// Throws std::invalid_argument naming the first bad parameter.
  void Validate() const;
  int64_t CellCount() const { return this->nx * this->ny * this->nz; }
};

/// Whether `text` names a generated model: "synth:NIxNJxNK[:SEED[:STEPS]]", the input of
/// resmr build, simplify and add-properties that needs no file.
bool IsSyntheticSpec(const std::string& text);

/// The parameters a synth: spec names, validated: NI NJ NK cells, SEED (default 1) and STEPS
/// report steps (default 0; only properties depend on them, never the grid), the rest at their
/// defaults (those of resmr synth). Throws std::invalid_argument naming the spec if malformed.
SyntheticParameters ParseSyntheticSpec(const std::string& spec);

/// Why a cell is inactive (or not).
enum class SyntheticCellState : uint8_t
{
  Active = 0,
  Outside = 1, ///< outside the field outline (whole column)
  Pinched = 2, ///< thinner than the pinch-out threshold (PINCH / MINPV-like)
  Water = 3    ///< centre below the oil-water contact
};

/// One layer of cells, i fastest then j.
struct SyntheticLayer
{
  int64_t k = -1;
  std::vector<float> zcorn;              ///< 8 nx ny: top face block then bottom face block
  std::vector<SyntheticCellState> state; ///< nx ny
  std::vector<float> depth;              ///< cell centre depth, metres
  std::vector<float> thickness;          ///< mean corner thickness (DZ), metres
  std::vector<float> poro, ntg, permx;   ///< fraction, fraction, mD
  std::vector<float> poreVolume;         ///< rm3, 0 for inactive cells
  int64_t activeCells = 0;
};

struct SyntheticStatistics
{
  int64_t cells = 0, active = 0, outside = 0, pinched = 0, water = 0;
  int64_t lateralFaces = 0; ///< internal i and j faces
  int64_t faultFaces = 0;   ///< of those, faces whose two cells do not share corners
  void Add(const SyntheticStatistics& other);
};

struct SyntheticDate
{
  int year = 0, month = 0, day = 0;
};

class SyntheticReservoir
{
public:
  /// Builds the per-column model (structure, faults, outline, wells) and calibrates the
  /// pinch-out threshold and the oil-water contact on a sample of columns.
  explicit SyntheticReservoir(const SyntheticParameters& parameters);

  const SyntheticParameters& Parameters() const { return this->Params; }

  /// COORD: 6 (nx+1)(ny+1) values, pillar top x y z then bottom x y z (z = depth).
  std::vector<double> Coord() const;

  /// Lateral faces and fault faces of one layer (the same in every layer: faults are vertical
  /// in (i, j)).
  int64_t LateralFacesPerLayer() const;
  int64_t FaultFacesPerLayer() const { return this->FaultFacesInLayer; }

  /// Report step s in 1..steps: elapsed days and calendar date (start 2025-01-01).
  static SyntheticDate StartDate() { return { 2025, 1, 1 }; }
  int StepDays(int step) const;
  SyntheticDate StepDate(int step) const;

  /// PRESSURE (bar) and SWAT of every cell of `layer` at report step `step` (1..steps).
  void FillStep(int step, const SyntheticLayer& layer, float* pressure, float* swat) const;

  double OilWaterContact() const { return this->Contact; }
  double CellSizeX() const { return this->Dx; }
  double CellSizeY() const { return this->Dy; }

private:
  friend class SyntheticLayerStream;
  struct FaultPlane
  {
    double px, py, normalX, normalY, length, throwMetres;
  };

  double Noise(uint64_t channel, double i, double j, double k) const;
  double ThicknessFactor(double noise) const;
  void BuildStructure();
  void BuildFaults();
  void BuildOutline();
  void Calibrate();
  void PlaceWells();

  SyntheticParameters Params;
  double Dx = 0, Dy = 0, Gross = 0;
  std::vector<double> LayerThickness;  ///< nominal, per layer (nz values)
  std::vector<double> LayerQuality;    ///< 0 (shale) .. 1 (clean sand), per layer
  std::vector<double> TopDepth;        ///< per pillar
  std::vector<float> Throw;            ///< 4 per column: downthrow of each corner (faults)
  std::vector<uint8_t> Inside;         ///< per column: inside the field outline
  std::vector<float> InjectorDistance; ///< per column, metres to the nearest injector
  std::vector<float> WellPressure;     ///< per column, injector support minus producer drawdown
  std::vector<FaultPlane> Faults;
  double PinchLevel = 0; ///< noise level under which a layer has zero thickness
  double ThicknessScale = 1;
  double Contact = 0;    ///< oil-water contact depth
  double FrontReach = 0; ///< metres the water front travels by the last step
  int64_t FaultFacesInLayer = 0;
};

/// Walks the layers of a model top to bottom, keeping one layer interface in memory.
class SyntheticLayerStream
{
public:
  explicit SyntheticLayerStream(const SyntheticReservoir& model);
  /// Fills `layer` with the next layer; false after the last.
  bool Next(SyntheticLayer& layer);
  /// Counts of the layers produced so far.
  const SyntheticStatistics& Statistics() const { return this->Counts; }

private:
  const SyntheticReservoir& Model;
  int64_t K = 0;
  std::vector<double> Interface;  ///< depth of the current layer's top, per pillar (no throw)
  std::vector<double> Below;      ///< the same for its bottom
  std::vector<double> LayerNoise; ///< per pillar
  std::vector<double> LatticePlane;
  SyntheticStatistics Counts;
};

} // namespace resmr
