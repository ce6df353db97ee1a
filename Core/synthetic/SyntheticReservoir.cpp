// Synthetic reservoir geology, streamed by layers (stand-in for the paper's Sec. 7 models).
// Compiled with -ffp-contract=off: the same bits on every machine (see the header).
#include "SyntheticReservoir.h"

#include "HashMix.h"

#include "CivilCalendar.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace resmr
{
namespace
{
// Independent noise fields, one hash channel each.
enum Channel : uint64_t
{
  ThicknessChannel = 1,
  OutlineChannel,
  LeanXChannel,
  LeanYChannel,
  RoughnessChannel,
  QualityChannel,
  LayerThicknessChannel
};

constexpr int Octaves = 3;
constexpr double OctaveAmplitude[Octaves] = { 0.5, 0.3, 0.2 };
constexpr double Pi = 3.14159265358979323846;

uint64_t Mix(uint64_t x)
{
  return HashMix(x);
}

/// Uniform in [0, 1) from a lattice point of a channel.
double LatticeValue(uint64_t seed, uint64_t channel, int64_t a, int64_t b, int64_t c)
{
  uint64_t h = Mix(seed ^ Mix(channel * GoldenGamma));
  h = Mix(h ^ static_cast<uint64_t>(a));
  h = Mix(h ^ (static_cast<uint64_t>(b) * 0xd1b54a32d192ed03ull));
  h = Mix(h ^ (static_cast<uint64_t>(c) * 0x8cb92ba72f3d8dd7ull));
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

double Lerp(double a, double b, double t)
{
  return a + (b - a) * t;
}

double Smooth(double t)
{
  return t * t * (3.0 - 2.0 * t);
}

double Clamp(double value, double low, double high)
{
  return value < low ? low : (value > high ? high : value);
}

/// exp(x) from exact operations only: 2^n by ldexp, e^r by a Taylor series (|r| <= ln2/2).
double DeterministicExp(double x)
{
  const double n = std::floor(x * 1.4426950408889634 + 0.5);
  const double r = x - n * 0.6931471805599453;
  double sum = 1.0;
  double term = 1.0;
  for (int i = 1; i <= 14; ++i)
  {
    term = term * r / i;
    sum = sum + term;
  }
  return std::ldexp(sum, static_cast<int>(n));
}

/// Wavelengths of octave o, in pillars (lateral) and layers (vertical).
double LateralWavelength(double base, int octave)
{
  return base / static_cast<double>(1 << octave);
}
double VerticalWavelength(int octave)
{
  return 4.0 / static_cast<double>(1 << octave);
}

/// One lattice coordinate and its smoothed weight; shared by the sample and layer paths so
/// both give identical bits.
struct LatticeCoordinate
{
  int64_t cell;
  double weight;
};
LatticeCoordinate Locate(double t, double wavelength)
{
  const double g = t / wavelength;
  const double cell = std::floor(g);
  return { static_cast<int64_t>(cell), Smooth(g - cell) };
}

double LatticeInLayer(uint64_t seed, uint64_t channel, int octave, int64_t a, int64_t b, LatticeCoordinate kc)
{
  const uint64_t octaveChannel = channel * 16 + static_cast<uint64_t>(octave);
  return Lerp(
    LatticeValue(seed, octaveChannel, a, b, kc.cell), LatticeValue(seed, octaveChannel, a, b, kc.cell + 1), kc.weight);
}

double Quantile(std::vector<double> values, double fraction)
{
  if (values.empty())
  {
    return 0;
  }
  const auto index = static_cast<std::size_t>(Clamp(fraction, 0.0, 1.0) * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
  return values[index];
}

/// Small deterministic generator for the model's random choices.
class SplitMix
{
public:
  explicit SplitMix(uint64_t seed)
    : State(Mix(seed + 0x632be59bd9b4e019ull))
  {
  }
  double Uniform()
  {
    this->State += GoldenGamma;
    return static_cast<double>(Mix(this->State) >> 11) * (1.0 / 9007199254740992.0);
  }
  /// A random unit vector.
  void Direction(double& x, double& y)
  {
    for (;;)
    {
      x = 2 * this->Uniform() - 1;
      y = 2 * this->Uniform() - 1;
      const double length2 = x * x + y * y;
      if (length2 > 0.01 && length2 <= 1)
      {
        const double length = std::sqrt(length2);
        x /= length;
        y /= length;
        return;
      }
    }
  }

private:
  uint64_t State;
};

} // namespace

void SyntheticParameters::Validate() const
{
  auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
  if (this->nx < 1 || this->ny < 1 || this->nz < 1)
  {
    fail("dimensions must be at least 1 cell each (got " + std::to_string(this->nx) + " x " + std::to_string(this->ny) +
      " x " + std::to_string(this->nz) + ")");
  }
  if (this->nx > 1000000 || this->ny > 1000000 || this->nz > 1000000)
  {
    fail("each dimension is at most 1000000 cells (got " + std::to_string(this->nx) + " x " + std::to_string(this->ny) +
      " x " + std::to_string(this->nz) + ")");
  }
  if (this->nx * this->ny > 100000000)
  {
    fail("nx * ny is at most 100 million columns: the generator keeps about 120 bytes per "
         "column in memory (got " +
      std::to_string(this->nx * this->ny) + ")");
  }
  if (this->faults < 0 || this->faults > 32)
  {
    fail("faults must be 0 to 32 (got " + std::to_string(this->faults) + ")");
  }
  auto inRange = [&](double value, double low, double high, const char* name) {
    if (!(value >= low && value <= high))
    {
      char text[160];
      std::snprintf(text, sizeof(text), "%s must be within [%g, %g] (got %g)", name, low, high, value);
      fail(text);
    }
  };
  inRange(this->maxThrow, 0, 2, "throw");
  inRange(this->dipDegrees, 0, 30, "dip");
  inRange(this->pinchedFraction, 0, 0.5, "pinched fraction");
  inRange(this->waterFraction, 0, 0.9, "water fraction");
  inRange(this->outsideFraction, 0, 0.9, "outside fraction");
  inRange(this->cellSize, 0, 100000, "cell size");
  inRange(this->grossThickness, 0, 100000, "gross thickness");
  if (this->steps < 0 || this->steps > 10000)
  {
    fail("steps must be 0 to 10000 (got " + std::to_string(this->steps) + ")");
  }
}

bool IsSyntheticSpec(const std::string& text)
{
  return text.rfind("synth:", 0) == 0;
}

SyntheticParameters ParseSyntheticSpec(const std::string& spec)
{
  const auto malformed = [&]() { return std::invalid_argument(spec + ": expected synth:NIxNJxNK[:SEED[:STEPS]]"); };
  if (!IsSyntheticSpec(spec))
  {
    throw malformed();
  }
  const char* at = spec.c_str() + 6;
  const char* const end = spec.c_str() + spec.size();
  const auto number = [&](auto& value) {
    const auto result = std::from_chars(at, end, value);
    if (result.ec != std::errc() || result.ptr == at)
    {
      throw malformed();
    }
    at = result.ptr;
  };
  const auto expect = [&](char separator) {
    if (at == end || *at != separator)
    {
      throw malformed();
    }
    ++at;
  };
  SyntheticParameters p;
  number(p.nx);
  expect('x');
  number(p.ny);
  expect('x');
  number(p.nz);
  if (at != end)
  {
    expect(':');
    number(p.seed);
  }
  if (at != end)
  {
    expect(':');
    number(p.steps);
  }
  if (at != end)
  {
    throw malformed();
  }
  try
  {
    p.Validate();
  }
  catch (const std::invalid_argument& error)
  {
    throw std::invalid_argument(spec + ": " + error.what());
  }
  return p;
}

void SyntheticStatistics::Add(const SyntheticStatistics& other)
{
  this->cells += other.cells;
  this->active += other.active;
  this->outside += other.outside;
  this->pinched += other.pinched;
  this->water += other.water;
  this->lateralFaces += other.lateralFaces;
  this->faultFaces += other.faultFaces;
}

SyntheticReservoir::SyntheticReservoir(const SyntheticParameters& parameters)
  : Params(parameters)
{
  this->Params.Validate();
  const int64_t maxDim = std::max(this->Params.nx, this->Params.ny);
  this->Dx =
    this->Params.cellSize > 0 ? this->Params.cellSize : Clamp(8000.0 / static_cast<double>(maxDim), 10.0, 100.0);
  this->Dy = this->Dx;
  this->Gross = this->Params.grossThickness > 0 ? this->Params.grossThickness
                                                : Clamp(3.0 * static_cast<double>(this->Params.nz), 40.0, 400.0);

  // Layers: nominal thicknesses and sand quality, both correlated over a few layers.
  const int64_t nz = this->Params.nz;
  this->LayerThickness.resize(static_cast<std::size_t>(nz));
  this->LayerQuality.resize(static_cast<std::size_t>(nz));
  double sum = 0;
  for (int64_t k = 0; k < nz; ++k)
  {
    const double kk = static_cast<double>(k);
    this->LayerThickness[k] = 0.4 + 1.2 * this->Noise(LayerThicknessChannel, 0, 0, kk);
    this->LayerQuality[k] = Clamp((this->Noise(QualityChannel, 0, 0, kk) - 0.3) / 0.4, 0.0, 1.0);
    sum += this->LayerThickness[k];
  }
  for (double& thickness : this->LayerThickness)
  {
    thickness = thickness * this->Gross / sum;
  }
  this->BuildStructure();
  this->BuildFaults();
  this->BuildOutline();
  this->Calibrate();
  if (this->Params.steps > 0)
  {
    this->PlaceWells();
  }
}

double SyntheticReservoir::Noise(uint64_t channel, double i, double j, double k) const
{
  const double base = std::max(6.0, static_cast<double>(std::max(this->Params.nx, this->Params.ny)) / 3.0);
  double total = 0;
  for (int o = 0; o < Octaves; ++o)
  {
    const double wavelength = LateralWavelength(base, o);
    const LatticeCoordinate x = Locate(i, wavelength);
    const LatticeCoordinate y = Locate(j, wavelength);
    const LatticeCoordinate z = Locate(k, VerticalWavelength(o));
    const uint64_t seed = this->Params.seed;
    const double l00 = LatticeInLayer(seed, channel, o, x.cell, y.cell, z);
    const double l10 = LatticeInLayer(seed, channel, o, x.cell + 1, y.cell, z);
    const double l01 = LatticeInLayer(seed, channel, o, x.cell, y.cell + 1, z);
    const double l11 = LatticeInLayer(seed, channel, o, x.cell + 1, y.cell + 1, z);
    total = total + OctaveAmplitude[o] * Lerp(Lerp(l00, l10, x.weight), Lerp(l01, l11, x.weight), y.weight);
  }
  return total;
}

double SyntheticReservoir::ThicknessFactor(double noise) const
{
  return std::max(0.0, noise - this->PinchLevel) * this->ThicknessScale;
}

void SyntheticReservoir::BuildStructure()
{
  const int64_t nx = this->Params.nx, ny = this->Params.ny;
  const double lx = static_cast<double>(nx) * this->Dx, ly = static_cast<double>(ny) * this->Dy;
  const double extent = std::max(lx, ly);
  SplitMix random(this->Params.seed ^ 0x5354525543ull);
  // tan of the dip by its series (no libm): exact to 1e-9 up to the 30 degree limit.
  const double angle = this->Params.dipDegrees * Pi / 180.0;
  const double a2 = angle * angle;
  const double tanDip = angle * (1 + a2 * (1.0 / 3 + a2 * (2.0 / 15 + a2 * (17.0 / 315 + a2 * (62.0 / 2835)))));
  double dipX, dipY, axisX, axisY;
  random.Direction(dipX, dipY);
  random.Direction(axisX, axisY);
  const double crestX = lx * (0.35 + 0.3 * random.Uniform());
  const double crestY = ly * (0.35 + 0.3 * random.Uniform());
  const double longRadius = 0.5 * extent, shortRadius = 0.3 * extent;
  const double relief = 1.5 * this->Gross + 0.5 * tanDip * extent;
  this->TopDepth.resize(static_cast<std::size_t>((nx + 1) * (ny + 1)));
  for (int64_t j = 0; j <= ny; ++j)
  {
    for (int64_t i = 0; i <= nx; ++i)
    {
      const double x = static_cast<double>(i) * this->Dx, y = static_cast<double>(j) * this->Dy;
      const double u = (x - crestX) * axisX + (y - crestY) * axisY;
      const double v = (y - crestY) * axisX - (x - crestX) * axisY;
      const double r2 = (u / longRadius) * (u / longRadius) + (v / shortRadius) * (v / shortRadius);
      const double bump = 1.0 / ((1.0 + r2) * (1.0 + r2));
      const double rough =
        0.16 * this->Gross * (this->Noise(RoughnessChannel, static_cast<double>(i), static_cast<double>(j), 0) - 0.5);
      this->TopDepth[j * (nx + 1) + i] =
        2000.0 + tanDip * (dipX * (x - 0.5 * lx) + dipY * (y - 0.5 * ly)) - relief * bump + rough;
    }
  }
}

void SyntheticReservoir::BuildFaults()
{
  const int64_t nx = this->Params.nx, ny = this->Params.ny;
  const double lx = static_cast<double>(nx) * this->Dx, ly = static_cast<double>(ny) * this->Dy;
  const double extent = std::max(lx, ly);
  SplitMix random(this->Params.seed ^ 0x4641554c54ull);
  this->Throw.assign(static_cast<std::size_t>(4 * nx * ny), 0.0f);
  std::vector<double> pillarThrow(static_cast<std::size_t>((nx + 1) * (ny + 1)));
  for (int f = 0; f < this->Params.faults; ++f)
  {
    FaultPlane fault{};
    if (f % 3 == 0)
    {
      // Along j (constant i) or along i (constant j), alternately.
      const bool alongJ = (f / 3) % 2 == 0;
      fault.normalX = alongJ ? 1 : 0;
      fault.normalY = alongJ ? 0 : 1;
    }
    else
    {
      do
      {
        random.Direction(fault.normalX, fault.normalY);
      } while (std::fabs(fault.normalX) < 0.3 || std::fabs(fault.normalY) < 0.3);
    }
    fault.px = lx * (0.15 + 0.7 * random.Uniform());
    fault.py = ly * (0.15 + 0.7 * random.Uniform());
    fault.length = extent * (0.6 + 0.8 * random.Uniform());
    fault.throwMetres = this->Params.maxThrow * this->Gross * (0.35 + 0.65 * random.Uniform());
    if (random.Uniform() < 0.5)
    {
      fault.normalX = -fault.normalX;
      fault.normalY = -fault.normalY;
    }
    this->Faults.push_back(fault);

    // Downthrow at each pillar: largest at the fault's middle, tapering to zero at its tips
    // and decaying away from it into the hanging wall (rollover).
    const double strikeX = -fault.normalY, strikeY = fault.normalX;
    for (int64_t j = 0; j <= ny; ++j)
    {
      for (int64_t i = 0; i <= nx; ++i)
      {
        const double x = static_cast<double>(i) * this->Dx - fault.px;
        const double y = static_cast<double>(j) * this->Dy - fault.py;
        const double along = 2.0 * (x * strikeX + y * strikeY) / fault.length;
        const double across = std::fabs(x * fault.normalX + y * fault.normalY);
        const double taper = std::fabs(along) < 1 ? (1 - along * along) * (1 - along * along) : 0.0;
        pillarThrow[j * (nx + 1) + i] = fault.throwMetres * taper / (1.0 + across / (0.5 * fault.length));
      }
    }
    // Cells whose centre lies in the hanging wall move down by the throw at their corners;
    // neighbours on the same side keep sharing faces.
    for (int64_t j = 0; j < ny; ++j)
    {
      for (int64_t i = 0; i < nx; ++i)
      {
        const double x = (static_cast<double>(i) + 0.5) * this->Dx - fault.px;
        const double y = (static_cast<double>(j) + 0.5) * this->Dy - fault.py;
        if (x * fault.normalX + y * fault.normalY <= 0)
        {
          continue;
        }
        const int64_t p = j * (nx + 1) + i;
        float* corners = &this->Throw[4 * (j * nx + i)];
        corners[0] = static_cast<float>(corners[0] + pillarThrow[p]);
        corners[1] = static_cast<float>(corners[1] + pillarThrow[p + 1]);
        corners[2] = static_cast<float>(corners[2] + pillarThrow[p + nx + 1]);
        corners[3] = static_cast<float>(corners[3] + pillarThrow[p + nx + 2]);
      }
    }
  }
  // Faces whose two cells do not share their corners (the same in every layer).
  int64_t faults = 0;
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      const float* a = &this->Throw[4 * (j * nx + i)];
      if (i + 1 < nx)
      {
        const float* b = a + 4;
        faults += (a[1] != b[0] || a[3] != b[2]) ? 1 : 0;
      }
      if (j + 1 < ny)
      {
        const float* b = a + 4 * nx;
        faults += (a[2] != b[0] || a[3] != b[1]) ? 1 : 0;
      }
    }
  }
  this->FaultFacesInLayer = faults;
}

int64_t SyntheticReservoir::LateralFacesPerLayer() const
{
  const int64_t nx = this->Params.nx, ny = this->Params.ny;
  return (nx - 1) * ny + nx * (ny - 1);
}

void SyntheticReservoir::BuildOutline()
{
  // An ellipse made ragged by noise; its size is set so the requested fraction of columns
  // falls outside.
  const int64_t nx = this->Params.nx, ny = this->Params.ny;
  std::vector<double> distance(static_cast<std::size_t>(nx * ny));
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      const double u = (static_cast<double>(i) + 0.5) / static_cast<double>(nx) - 0.5;
      const double v = (static_cast<double>(j) + 0.5) / static_cast<double>(ny) - 0.5;
      const double noise = this->Noise(OutlineChannel, static_cast<double>(i) + 0.5, static_cast<double>(j) + 0.5, 0);
      distance[j * nx + i] = std::sqrt(u * u + v * v) + 0.5 * (noise - 0.5);
    }
  }
  double limit = std::numeric_limits<double>::infinity();
  if (this->Params.outsideFraction > 0)
  {
    std::vector<double> sample;
    const int64_t stride = std::max<int64_t>(1, (nx * ny) / 1000000);
    for (int64_t c = 0; c < nx * ny; c += stride)
    {
      sample.push_back(distance[c]);
    }
    limit = Quantile(std::move(sample), 1.0 - this->Params.outsideFraction);
  }
  this->Inside.resize(distance.size());
  for (std::size_t c = 0; c < distance.size(); ++c)
  {
    this->Inside[c] = distance[c] < limit ? 1 : 0;
  }
}

void SyntheticReservoir::Calibrate()
{
  // A grid of sample columns, through every layer: the pinch-out level is the quantile of
  // layer noise matching the requested pinched fraction, the thickness scale makes layers
  // average their nominal thickness, and the oil-water contact is the depth quantile
  // matching the requested water fraction.
  const int64_t nx = this->Params.nx, ny = this->Params.ny, nz = this->Params.nz;
  const int64_t wanted = std::clamp<int64_t>((1 << 20) / nz, 64, 1024);
  const int64_t side = std::max<int64_t>(1, static_cast<int64_t>(std::sqrt(static_cast<double>(wanted))));
  const int64_t strideI = std::max<int64_t>(1, nx / side), strideJ = std::max<int64_t>(1, ny / side);
  std::vector<std::array<int64_t, 2>> columns;
  for (int64_t j = strideJ / 2; j < ny; j += strideJ)
  {
    for (int64_t i = strideI / 2; i < nx; i += strideI)
    {
      columns.push_back({ i, j });
    }
  }
  // Noise at the four corner pillars of a sample column, recomputed when needed: only every
  // kStride-th layer is kept for the quantiles (at most 2^18 values, 2 MB), so memory does
  // not grow with nz.
  const int64_t kStride = std::max<int64_t>(1, (static_cast<int64_t>(columns.size()) * nz + (1 << 18) - 1) >> 18);
  auto cornerNoise = [&](std::size_t c, int64_t k, int corner) {
    return this->Noise(ThicknessChannel, static_cast<double>(columns[c][0] + (corner & 1)),
      static_cast<double>(columns[c][1] + (corner >> 1)), static_cast<double>(k));
  };
  std::vector<double> cornerNoiseMax;
  cornerNoiseMax.reserve(columns.size() * static_cast<std::size_t>((nz + kStride - 1) / kStride));
  for (std::size_t c = 0; c < columns.size(); ++c)
  {
    for (int64_t k = 0; k < nz; k += kStride)
    {
      // A cell has zero thickness where all four corners are under the pinch-out level.
      double highest = 0;
      for (int corner = 0; corner < 4; ++corner)
      {
        highest = std::max(highest, cornerNoise(c, k, corner));
      }
      cornerNoiseMax.push_back(highest);
    }
  }
  this->PinchLevel =
    this->Params.pinchedFraction > 0 ? Clamp(Quantile(cornerNoiseMax, this->Params.pinchedFraction), 0.0, 0.95) : 0.0;
  // Layers average their nominal thickness: the mean of max(0, noise - level) over the
  // sampled corners.
  double mean = 0;
  int64_t samples = 0;
  for (std::size_t c = 0; c < columns.size(); ++c)
  {
    for (int64_t k = 0; k < nz; k += kStride)
    {
      for (int corner = 0; corner < 4; ++corner)
      {
        mean += std::max(0.0, cornerNoise(c, k, corner) - this->PinchLevel);
        ++samples;
      }
    }
  }
  mean /= static_cast<double>(samples);
  this->ThicknessScale = mean > 0 ? 1.0 / mean : 1.0;

  this->Contact = std::numeric_limits<double>::infinity();
  if (this->Params.waterFraction > 0)
  {
    std::vector<double> depths;
    for (int pass = 0; pass < 2 && depths.empty(); ++pass)
    {
      for (std::size_t c = 0; c < columns.size(); ++c)
      {
        const int64_t column = columns[c][1] * nx + columns[c][0];
        if (pass == 0 && !this->Inside[column])
        {
          continue; // the contact is set among the cells inside the outline
        }
        const int64_t p = columns[c][1] * (nx + 1) + columns[c][0];
        const int64_t pillars[4] = { p, p + 1, p + nx + 1, p + nx + 2 };
        double top[4];
        for (int corner = 0; corner < 4; ++corner)
        {
          top[corner] = this->TopDepth[pillars[corner]] + this->Throw[4 * column + corner];
        }
        for (int64_t k = 0; k < nz; ++k)
        {
          double centre = 0, thickness = 0;
          for (int corner = 0; corner < 4; ++corner)
          {
            const double t = this->LayerThickness[k] * this->ThicknessFactor(cornerNoise(c, k, corner));
            centre += top[corner] + 0.5 * t;
            thickness += t;
            top[corner] += t;
          }
          if (k % kStride == 0 && 0.25 * thickness >= 0.01 * this->LayerThickness[k])
          {
            depths.push_back(0.25 * centre);
          }
        }
      }
    }
    if (!depths.empty())
    {
      this->Contact = Quantile(std::move(depths), 1.0 - this->Params.waterFraction);
    }
  }
}

void SyntheticReservoir::PlaceWells()
{
  // Injectors on the flanks just above the contact, producers near the crest.
  const int64_t nx = this->Params.nx, ny = this->Params.ny;
  const double extent = std::max(static_cast<double>(nx) * this->Dx, static_cast<double>(ny) * this->Dy);
  SplitMix random(this->Params.seed ^ 0x57454c4cull);
  struct Candidate
  {
    double depth, x, y;
  };
  std::vector<Candidate> candidates;
  for (int attempt = 0; attempt < 4000 && candidates.size() < 400; ++attempt)
  {
    const auto i = std::min<int64_t>(nx - 1, static_cast<int64_t>(random.Uniform() * static_cast<double>(nx)));
    const auto j = std::min<int64_t>(ny - 1, static_cast<int64_t>(random.Uniform() * static_cast<double>(ny)));
    const double depth = this->TopDepth[j * (nx + 1) + i] + this->Throw[4 * (j * nx + i)];
    if (this->Inside[j * nx + i] && depth < this->Contact)
    {
      candidates.push_back(
        { depth, (static_cast<double>(i) + 0.5) * this->Dx, (static_cast<double>(j) + 0.5) * this->Dy });
    }
  }
  if (candidates.empty())
  {
    candidates.push_back({ 0, 0.5 * static_cast<double>(nx) * this->Dx, 0.5 * static_cast<double>(ny) * this->Dy });
  }
  std::stable_sort(
    candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.depth < b.depth; });
  auto pick = [&](bool deepest, std::size_t count) {
    std::vector<Candidate> chosen;
    for (std::size_t n = 0; n < candidates.size() && chosen.size() < count; ++n)
    {
      const Candidate& c = candidates[deepest ? candidates.size() - 1 - n : n];
      bool farEnough = true;
      for (const Candidate& other : chosen)
      {
        const double dx = c.x - other.x, dy = c.y - other.y;
        farEnough = farEnough && dx * dx + dy * dy > 0.04 * extent * extent;
      }
      if (farEnough)
      {
        chosen.push_back(c);
      }
    }
    return chosen;
  };
  const std::vector<Candidate> injectors = pick(true, 3);
  const std::vector<Candidate> producers = pick(false, 2);
  const double wellRadius = 0.06 * extent;
  this->InjectorDistance.resize(static_cast<std::size_t>(nx * ny));
  this->WellPressure.resize(static_cast<std::size_t>(nx * ny));
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      const double x = (static_cast<double>(i) + 0.5) * this->Dx, y = (static_cast<double>(j) + 0.5) * this->Dy;
      double nearest = std::numeric_limits<double>::infinity(), pressure = 0;
      for (const Candidate& w : injectors)
      {
        const double d2 = (x - w.x) * (x - w.x) + (y - w.y) * (y - w.y);
        nearest = std::min(nearest, d2);
        pressure += 1.0 / (1.0 + d2 / (wellRadius * wellRadius));
      }
      for (const Candidate& w : producers)
      {
        const double d2 = (x - w.x) * (x - w.x) + (y - w.y) * (y - w.y);
        pressure -= 1.0 / (1.0 + d2 / (wellRadius * wellRadius));
      }
      this->InjectorDistance[j * nx + i] = static_cast<float>(std::sqrt(nearest));
      this->WellPressure[j * nx + i] = static_cast<float>(pressure);
    }
  }
  double reach = 0;
  for (const Candidate& w : producers)
  {
    reach += this->InjectorDistance[static_cast<int64_t>(w.y / this->Dy) * nx + static_cast<int64_t>(w.x / this->Dx)];
  }
  this->FrontReach = std::max(0.8 * reach / static_cast<double>(producers.size()), 0.2 * extent);
}

std::vector<double> SyntheticReservoir::Coord() const
{
  // Pillars lean smoothly (sloping pillars); each passes through its nominal (x, y) at the
  // middle of its column and spans every depth its corners take.
  const int64_t nx = this->Params.nx, ny = this->Params.ny;
  float maxThrow = 0;
  for (float value : this->Throw)
  {
    maxThrow = std::max(maxThrow, value);
  }
  const double thickest = this->Gross * this->ThicknessScale * (1.0 - this->PinchLevel);
  const double lean = 0.3 * this->Dx / this->Gross;
  std::vector<double> coord(static_cast<std::size_t>(6 * (nx + 1) * (ny + 1)));
  for (int64_t j = 0; j <= ny; ++j)
  {
    for (int64_t i = 0; i <= nx; ++i)
    {
      const int64_t p = j * (nx + 1) + i;
      const double x = static_cast<double>(i) * this->Dx, y = static_cast<double>(j) * this->Dy;
      const double leanX =
        lean * (2 * this->Noise(LeanXChannel, static_cast<double>(i), static_cast<double>(j), 0) - 1);
      const double leanY =
        lean * (2 * this->Noise(LeanYChannel, static_cast<double>(i), static_cast<double>(j), 0) - 1);
      const double middle = this->TopDepth[p] + 0.5 * this->Gross;
      const double top = this->TopDepth[p] - 1.0;
      const double bottom = this->TopDepth[p] + thickest + maxThrow + 1.0;
      double* out = &coord[6 * p];
      out[0] = x + leanX * (top - middle);
      out[1] = y + leanY * (top - middle);
      out[2] = top;
      out[3] = x + leanX * (bottom - middle);
      out[4] = y + leanY * (bottom - middle);
      out[5] = bottom;
    }
  }
  return coord;
}

int SyntheticReservoir::StepDays(int step) const
{
  return static_cast<int>((3650LL * step) / std::max(1, this->Params.steps));
}

SyntheticDate SyntheticReservoir::StepDate(int step) const
{
  const SyntheticDate start = StartDate();
  const std::array<int, 3> date =
    CivilFromDays(DaysFromCivil(start.year, start.month, start.day) + this->StepDays(step));
  return { date[0], date[1], date[2] };
}

void SyntheticReservoir::FillStep(int step, const SyntheticLayer& layer, float* pressure, float* swat) const
{
  const int64_t columns = this->Params.nx * this->Params.ny;
  const double progress = static_cast<double>(step) / static_cast<double>(std::max(1, this->Params.steps));
  const double front = this->FrontReach * progress;
  const double extent =
    std::max(static_cast<double>(this->Params.nx) * this->Dx, static_cast<double>(this->Params.ny) * this->Dy);
  const double frontWidth = 0.03 * extent;
  const double quality = this->LayerQuality[layer.k];
  const double connate = 0.12 + 0.13 * (1.0 - quality), residualOil = 0.2;
  const double contactTop = std::isfinite(this->Contact) ? this->Contact - this->Gross : 0.0;
  for (int64_t c = 0; c < columns; ++c)
  {
    const double depth = layer.depth[c];
    pressure[c] =
      static_cast<float>(180.0 + 0.085 * (depth - 2000.0) + 35.0 * (1.0 - 0.5 * progress) * this->WellPressure[c]);
    // Water runs ahead in permeable layers and slumps to the bottom.
    const double speed = Clamp(std::sqrt(layer.permx[c] / 100.0), 0.35, 1.8);
    const double sinking = std::isfinite(this->Contact) ? Clamp((depth - contactTop) / this->Gross, 0.0, 1.0) : 0.0;
    const double travel = this->InjectorDistance[c] / speed * (1.0 - 0.25 * sinking);
    double water = connate;
    if (front > 0)
    {
      const double behind = Smooth(Clamp((front - travel) / frontWidth + 0.5, 0.0, 1.0));
      const double x = std::min(1.0, travel / front);
      water = connate + behind * (1.0 - residualOil - connate) * (1.0 - 0.6 * x * x);
    }
    swat[c] = static_cast<float>(water);
  }
}

SyntheticLayerStream::SyntheticLayerStream(const SyntheticReservoir& model)
  : Model(model)
  , Interface(model.TopDepth)
{
  this->Below.resize(this->Interface.size());
  this->LayerNoise.resize(this->Interface.size());
}

bool SyntheticLayerStream::Next(SyntheticLayer& layer)
{
  const SyntheticReservoir& m = this->Model;
  const int64_t nx = m.Params.nx, ny = m.Params.ny, nz = m.Params.nz;
  if (this->K >= nz)
  {
    return false;
  }
  const int64_t k = this->K++;
  const int64_t columns = nx * ny;

  // Layer noise at every pillar: lattice planes of this layer, then smoothstep weights per
  // pillar row and column (the same arithmetic as SyntheticReservoir::Noise, bit for bit).
  const double base = std::max(6.0, static_cast<double>(std::max(nx, ny)) / 3.0);
  std::fill(this->LayerNoise.begin(), this->LayerNoise.end(), 0.0);
  for (int o = 0; o < Octaves; ++o)
  {
    const double wavelength = LateralWavelength(base, o);
    const LatticeCoordinate z = Locate(static_cast<double>(k), VerticalWavelength(o));
    const int64_t cellsX = Locate(static_cast<double>(nx), wavelength).cell + 2;
    const int64_t cellsY = Locate(static_cast<double>(ny), wavelength).cell + 2;
    this->LatticePlane.resize(static_cast<std::size_t>(cellsX * cellsY));
    for (int64_t b = 0; b < cellsY; ++b)
    {
      for (int64_t a = 0; a < cellsX; ++a)
      {
        this->LatticePlane[b * cellsX + a] = LatticeInLayer(m.Params.seed, ThicknessChannel, o, a, b, z);
      }
    }
    std::vector<LatticeCoordinate> xs(static_cast<std::size_t>(nx + 1));
    for (int64_t i = 0; i <= nx; ++i)
    {
      xs[i] = Locate(static_cast<double>(i), wavelength);
    }
    for (int64_t j = 0; j <= ny; ++j)
    {
      const LatticeCoordinate y = Locate(static_cast<double>(j), wavelength);
      const double* row0 = &this->LatticePlane[y.cell * cellsX];
      const double* row1 = row0 + cellsX;
      double* out = &this->LayerNoise[j * (nx + 1)];
      for (int64_t i = 0; i <= nx; ++i)
      {
        const LatticeCoordinate x = xs[i];
        out[i] = out[i] +
          OctaveAmplitude[o] *
            Lerp(
              Lerp(row0[x.cell], row0[x.cell + 1], x.weight), Lerp(row1[x.cell], row1[x.cell + 1], x.weight), y.weight);
      }
    }
  }
  const double nominal = m.LayerThickness[k];
  for (std::size_t p = 0; p < this->Below.size(); ++p)
  {
    this->Below[p] = this->Interface[p] + nominal * m.ThicknessFactor(this->LayerNoise[p]);
  }

  layer.k = k;
  layer.zcorn.resize(static_cast<std::size_t>(8 * columns));
  layer.state.resize(static_cast<std::size_t>(columns));
  layer.depth.resize(static_cast<std::size_t>(columns));
  layer.thickness.resize(static_cast<std::size_t>(columns));
  layer.poro.resize(static_cast<std::size_t>(columns));
  layer.ntg.resize(static_cast<std::size_t>(columns));
  layer.permx.resize(static_cast<std::size_t>(columns));
  layer.poreVolume.resize(static_cast<std::size_t>(columns));
  const double quality = m.LayerQuality[k];
  const double pinchThickness = 0.01 * nominal;
  const double area = m.Dx * m.Dy;
  SyntheticStatistics counts;
  float* top = layer.zcorn.data();
  float* bottom = top + 4 * columns;
  for (int64_t j = 0; j < ny; ++j)
  {
    for (int64_t i = 0; i < nx; ++i)
    {
      const int64_t c = j * nx + i;
      const int64_t p = j * (nx + 1) + i;
      const int64_t pillars[4] = { p, p + 1, p + nx + 1, p + nx + 2 };
      const float* drop = &m.Throw[4 * c];
      double centre = 0, thickness = 0, noise = 0;
      for (int corner = 0; corner < 4; ++corner)
      {
        const double upper = this->Interface[pillars[corner]] + drop[corner];
        const double lower = this->Below[pillars[corner]] + drop[corner];
        const int64_t z = (2 * j + (corner >> 1)) * 2 * nx + 2 * i + (corner & 1);
        top[z] = static_cast<float>(upper);
        bottom[z] = static_cast<float>(lower);
        centre += upper + lower;
        thickness += lower - upper;
        noise += this->LayerNoise[pillars[corner]];
      }
      centre *= 0.125;
      thickness *= 0.25;
      noise *= 0.25;
      SyntheticCellState state = !m.Inside[c] ? SyntheticCellState::Outside
        : thickness < pinchThickness          ? SyntheticCellState::Pinched
        : centre > m.Contact                  ? SyntheticCellState::Water
                                              : SyntheticCellState::Active;
      // Clean sands are porous, thick and permeable; shales are none of these. Within a
      // layer, thicker parts are better sands (the layer noise, contrast stretched).
      const double lateral = Clamp((noise - 0.5) * 2.5 + 0.5, 0.0, 1.0);
      const double poro = 0.03 + 0.27 * (0.55 * quality + 0.45 * lateral);
      const double ntg = Clamp(0.1 + 0.9 * (0.65 * quality + 0.35 * lateral), 0.0, 1.0);
      const double permx = 0.5 * DeterministicExp(27.0 * (poro - 0.03));
      layer.state[c] = state;
      layer.depth[c] = static_cast<float>(centre);
      layer.thickness[c] = static_cast<float>(thickness);
      layer.poro[c] = static_cast<float>(poro);
      layer.ntg[c] = static_cast<float>(ntg);
      layer.permx[c] = static_cast<float>(permx);
      layer.poreVolume[c] =
        state == SyntheticCellState::Active ? static_cast<float>(area * thickness * poro * ntg) : 0.0f;
      counts.active += state == SyntheticCellState::Active;
      counts.outside += state == SyntheticCellState::Outside;
      counts.pinched += state == SyntheticCellState::Pinched;
      counts.water += state == SyntheticCellState::Water;
    }
  }
  counts.cells = columns;
  counts.lateralFaces = m.LateralFacesPerLayer();
  counts.faultFaces = m.FaultFacesPerLayer();
  layer.activeCells = counts.active;
  this->Counts.Add(counts);
  this->Interface.swap(this->Below);
  return true;
}

} // namespace resmr
