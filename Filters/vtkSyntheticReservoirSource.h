/**
 * @class   vtkSyntheticReservoirSource
 * @brief   A synthetic faulted reservoir model, generated in memory.
 *
 * The same generator as `resmr synth` (resmr::SyntheticReservoir, Core): a dipping anticline
 * of layers with varying thickness, normal faults (some oblique to I and J) with sloping
 * pillars, pinch-outs, an oil-water contact and a ragged field outline; PORO, PERMX, PERMY,
 * PERMZ and NTG per cell, and with Steps > 0 one time step per report step (time in days)
 * carrying PRESSURE and SWAT as water moves from injectors to producers.
 *
 * The output follows the readers' contract (vtkEGRIDReader): a vtkExplicitStructuredGrid with
 * z up, I/J/K from 1, ACTNUM, inactive cells hidden, float arrays with NaN in inactive
 * cells; the generated model is identical to what `resmr synth` writes for the same
 * parameters. Meant for small models: a grid that would not fit in memory at full resolution
 * (MemoryLimitMB, default the available memory) is refused with a message pointing to
 * `resmr synth` and the multiresolution path.
 */
#ifndef vtkSyntheticReservoirSource_h
#define vtkSyntheticReservoirSource_h

#include "ResMRFiltersModule.h" // for export macro
#include "vtkExplicitStructuredGridAlgorithm.h"

#include <memory>
#include <string>

class RESMRFILTERS_EXPORT vtkSyntheticReservoirSource : public vtkExplicitStructuredGridAlgorithm
{
public:
  static vtkSyntheticReservoirSource* New();
  vtkTypeMacro(vtkSyntheticReservoirSource, vtkExplicitStructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Cells along I, J and K (default 60 x 50 x 20).
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  ///@}

  ///@{
  /// Geology knobs, as `resmr synth` options of the same names (see its --help).
  vtkSetClampMacro(Seed, int, 0, VTK_INT_MAX);
  vtkGetMacro(Seed, int);
  vtkSetClampMacro(Faults, int, 0, 32);
  vtkGetMacro(Faults, int);
  vtkSetClampMacro(Throw, double, 0.0, 2.0);
  vtkGetMacro(Throw, double);
  vtkSetClampMacro(Dip, double, 0.0, 30.0);
  vtkGetMacro(Dip, double);
  vtkSetClampMacro(PinchedFraction, double, 0.0, 0.5);
  vtkGetMacro(PinchedFraction, double);
  vtkSetClampMacro(WaterFraction, double, 0.0, 0.9);
  vtkGetMacro(WaterFraction, double);
  vtkSetClampMacro(OutsideFraction, double, 0.0, 0.9);
  vtkGetMacro(OutsideFraction, double);
  vtkSetClampMacro(Steps, int, 0, 10000);
  vtkGetMacro(Steps, int);
  ///@}

  ///@{
  /// Memory in MiB the grid may take (about 300 bytes a cell); 0: the available memory.
  vtkSetClampMacro(MemoryLimitMB, int, 0, VTK_INT_MAX);
  vtkGetMacro(MemoryLimitMB, int);
  ///@}

  /// Why the last update failed, empty if it did not.
  const char* GetLastError() { return this->LastError.c_str(); }

protected:
  vtkSyntheticReservoirSource();
  ~vtkSyntheticReservoirSource() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkSyntheticReservoirSource(const vtkSyntheticReservoirSource&) = delete;
  void operator=(const vtkSyntheticReservoirSource&) = delete;

  bool BuildModelIfNeeded();
  void ReportError(const std::string& message);

  int Dimensions[3] = { 60, 50, 20 };
  int Seed = 1;
  int Faults = 6;
  double Throw = 0.3;
  double Dip = 2.0;
  double PinchedFraction = 0.05;
  double WaterFraction = 0.2;
  double OutsideFraction = 0.25;
  int Steps = 5;
  int MemoryLimitMB = 0;
  std::string LastError;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
