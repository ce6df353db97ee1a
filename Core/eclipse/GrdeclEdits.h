// What the deck parser does with each array and each edit keyword (paper Sec. 3: the model's
// cell properties). Ours: the paper reads clean grids; decks from geomodelling tools and
// simulators also carry edits of arrays a viewer never builds (transmissibilities, pore
// volumes, multipliers, local grids, aquifers), and those must not stop the model opening.
//
// Contract:
// - An array is a viewer array (built, shown, edited exactly), a simulator array (computed
//   by the simulator from the grid: TRAN*, PORV, DEPTH, MULT*, DIFFM*, HM*), or unknown.
// - Edits of simulator arrays and unknown arrays the deck did not give whole are skipped
//   with a warning; edits the viewer cannot honour on a viewer array stay errors.
// - Keywords with no bearing on the grid or its cell arrays (MULTFLT, NNC, AQUNUM, PINCH,
//   CARFIN ... ENDFIN, ...) are read to their end and skipped, each with a warning saying
//   what the simulator does that the picture does not show.
#pragma once

#include <functional>
#include <string>

namespace resmr
{

/// Arrays the viewer builds and shows: geometry, porosity, permeability, NTG, region numbers
/// (*NUM), saturation end points, initial solution and the like.
bool IsViewerArray(const std::string& name);

/// Arrays the simulator computes or uses only for flow; "" if `name` is not one, otherwise
/// what it is ("transmissibility", "pore volume", ...), for warnings.
std::string SimulatorArrayKind(const std::string& name);

/// The OPERATE / OPERATER operations (ECLIPSE's names): result = f(target, source), where
/// alpha and beta are the record's parameters. Empty function for an unknown name.
std::function<double(double target, double source)> ArrayOperation(
  const std::string& operation, double alpha, double beta);

/// True for operations whose result depends on the target's old value (POLY, MULTIPLY).
bool OperationReadsTarget(const std::string& operation);

/// The region array an EQUALREG/MULTIREG/ADDREG/COPYREG/OPERATER record names: M, F, O (or
/// the full name of a *NUM array); "" if it is not one.
std::string RegionArrayName(const std::string& given);

/// How a keyword that does not touch the viewer's arrays is laid out, to read it to its end.
enum class SkippedShape
{
  None,      ///< not a skipped keyword
  OneRecord, ///< one record ended by '/'
  Records,   ///< records ended by an empty record
  LocalGrid  ///< a local grid block: CARFIN/RADFIN/REFINE ... ENDFIN
};

/// The layout of a skipped keyword and, in `why`, what the simulator does with it that the
/// viewer does not show.
SkippedShape SkippedKeyword(const std::string& keyword, std::string& why);

} // namespace resmr
