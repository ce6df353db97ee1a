#include "DerivedArrays.h"

#include "EclipseResults.h"

#include <algorithm>
#include <limits>

namespace resmr
{

bool NeedsDerivedOil(const std::vector<std::string>& names)
{
  const auto holds = [&](const char* name) { return std::find(names.begin(), names.end(), name) != names.end(); };
  return holds("SWAT") && !holds(DerivedOilName);
}

bool ReadDerivedOil(const EclipseResults& results, std::size_t step, float* cellValues, int64_t cellCount)
{
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (!results.ReadDynamic(step, "SWAT", cellValues, nan))
  {
    return false;
  }
  std::vector<float> gas(static_cast<std::size_t>(cellCount), 0.0f);
  results.ReadDynamic(step, "SGAS", gas.data(), nan); // two-phase runs have no SGAS
  for (std::size_t cell = 0; cell < gas.size(); ++cell)
  {
    cellValues[cell] = 1.0f - cellValues[cell] - gas[cell];
  }
  return true;
}

} // namespace resmr
