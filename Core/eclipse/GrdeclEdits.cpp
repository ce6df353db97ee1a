// What the deck parser does with each array and each edit keyword (paper Sec. 3; ours).
#include "GrdeclEdits.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

namespace resmr
{
namespace
{
bool EndsWith(const std::string& text, const char* suffix)
{
  const std::string tail(suffix);
  return text.size() > tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

bool StartsWith(const std::string& text, const char* prefix)
{
  return text.rfind(prefix, 0) == 0;
}
} // namespace

std::string SimulatorArrayKind(const std::string& name)
{
  if (EndsWith(name, "NUM"))
  {
    return ""; // MULTNUM, FLUXNUM, ...: region numbers are shown
  }
  if (StartsWith(name, "TRAN") || StartsWith(name, "HMTRAN"))
  {
    return "transmissibility, computed by the simulator";
  }
  if (name == "PORV" || name == "MINPVV")
  {
    return "pore volume, computed by the simulator";
  }
  if (name == "DEPTH")
  {
    return "cell depth, taken from the grid's corners";
  }
  if (StartsWith(name, "MULT") || StartsWith(name, "HMMULT"))
  {
    return "flow multiplier";
  }
  if (StartsWith(name, "DIFFM") || name == "DIFFX" || name == "DIFFY" || name == "DIFFZ")
  {
    return "diffusivity multiplier";
  }
  if (name == "SIGMAV" || name == "DZMTRXV" || name == "DZMATRIX" || name == "LX" || name == "LY" || name == "LZ")
  {
    return "dual-porosity coupling factor";
  }
  return "";
}

bool IsViewerArray(const std::string& name)
{
  static const std::unordered_set<std::string> names = { "ACTNUM", "DX", "DY", "DZ", "TOPS", "PORO", "PERMX", "PERMY",
    "PERMZ", "PERMXY", "PERMYZ", "PERMZX", "PERMR", "PERMTHT", "NTG", "SWATINIT", "SWL", "SWLPC", "SWCR", "SWU", "SGL",
    "SGLPC", "SGCR", "SGU", "SOWCR", "SOGCR", "KRW", "KRWR", "KRO", "KRORW", "KRORG", "KRG", "KRGR", "PCW", "PCG",
    "PRESSURE", "SWAT", "SGAS", "SOIL", "RS", "RV", "PBUB", "PDEW", "TEMPI", "SALT", "FACIES", "THCONR", "THCONSF",
    "SPOLY", "SFOAM", "SSOL" };
  return names.count(name) > 0 || EndsWith(name, "NUM");
}

std::function<double(double, double)> ArrayOperation(const std::string& operation, double alpha, double beta)
{
  using Op = std::function<double(double, double)>;
  // ECLIPSE's OPERATE table: R is the target's value, X the source's.
  if (operation == "MULTA")
    return Op([=](double, double x) { return alpha * x + beta; });
  if (operation == "POLY")
    return Op([=](double r, double x) { return r + alpha * std::pow(x, beta); });
  if (operation == "SLOG")
    return Op([=](double, double x) { return std::pow(10.0, alpha + beta * x); });
  if (operation == "LOG10")
    return Op([](double, double x) { return std::log10(x); });
  if (operation == "LOGE")
    return Op([](double, double x) { return std::log(x); });
  if (operation == "INV")
    return Op([](double, double x) { return 1.0 / x; });
  if (operation == "MULTX")
    return Op([=](double, double x) { return alpha * x; });
  if (operation == "ADDX")
    return Op([=](double, double x) { return alpha + x; });
  if (operation == "COPY")
    return Op([](double, double x) { return x; });
  if (operation == "MAXLIM")
    return Op([=](double, double x) { return std::min(alpha, x); });
  if (operation == "MINLIM")
    return Op([=](double, double x) { return std::max(alpha, x); });
  if (operation == "MULTP")
    return Op([=](double, double x) { return alpha * std::pow(x, beta); });
  if (operation == "ABS")
    return Op([](double, double x) { return std::fabs(x); });
  if (operation == "MULTIPLY")
    return Op([](double r, double x) { return r * x; });
  return Op();
}

bool OperationReadsTarget(const std::string& operation)
{
  return operation == "POLY" || operation == "MULTIPLY";
}

std::string RegionArrayName(const std::string& given)
{
  if (given == "M")
  {
    return "MULTNUM";
  }
  if (given == "F")
  {
    return "FLUXNUM";
  }
  if (given == "O")
  {
    return "OPERNUM";
  }
  return EndsWith(given, "NUM") ? given : std::string();
}

SkippedShape SkippedKeyword(const std::string& keyword, std::string& why)
{
  struct Entry
  {
    SkippedShape shape;
    const char* why;
  };
  static const std::unordered_map<std::string, Entry> entries = {
    { "MULTFLT", { SkippedShape::Records, "fault transmissibility multipliers" } },
    { "MULTREGT", { SkippedShape::Records, "transmissibility multipliers between regions" } },
    { "MULTREGP", { SkippedShape::Records, "pore volume multipliers of regions" } },
    { "MULTREGH", { SkippedShape::Records, "transmissibility multipliers of regions" } },
    { "EDITNNC", { SkippedShape::Records, "non-neighbour connection multipliers" } },
    { "EDITNNCR", { SkippedShape::Records, "non-neighbour connection transmissibilities" } },
    { "NNC", { SkippedShape::Records, "non-neighbour connections" } },
    { "AQUNUM",
      { SkippedShape::Records,
        "numerical aquifers (the simulator gives their cells the aquifer's porosity "
        "and permeability; the viewer shows the grid's)" } },
    { "AQUCON", { SkippedShape::Records, "aquifer connections" } },
    { "AQUCT", { SkippedShape::Records, "Carter-Tracy aquifers" } },
    { "AQUFETP", { SkippedShape::Records, "Fetkovich aquifers" } },
    { "AQUANCON", { SkippedShape::Records, "analytic aquifer connections" } },
    { "THPRES", { SkippedShape::Records, "threshold pressures between regions" } },
    { "AMALGAM", { SkippedShape::Records, "amalgamated local grids" } },
    { "MINPV",
      { SkippedShape::OneRecord,
        "the minimum pore volume under which the simulator makes cells inactive "
        "(it shows the cells ACTNUM makes active)" } },
    { "MINPORV",
      { SkippedShape::OneRecord,
        "the minimum pore volume under which the simulator makes cells inactive "
        "(it shows the cells ACTNUM makes active)" } },
    { "MINPVFIL", { SkippedShape::OneRecord, "the minimum pore volume for filling pinch-outs" } },
    { "PINCH", { SkippedShape::OneRecord, "connections the simulator makes across pinched-out layers" } },
    { "CARFIN", { SkippedShape::LocalGrid, "a local grid refinement" } },
    { "RADFIN", { SkippedShape::LocalGrid, "a radial local grid refinement" } },
    { "RADFIN4", { SkippedShape::LocalGrid, "a radial local grid refinement" } },
    { "REFINE", { SkippedShape::LocalGrid, "edits of a local grid" } },
  };
  const auto found = entries.find(keyword);
  if (found == entries.end())
  {
    return SkippedShape::None;
  }
  why = found->second.why;
  return found->second.shape;
}

} // namespace resmr
