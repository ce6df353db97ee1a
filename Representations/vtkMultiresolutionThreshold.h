/**
 * @class   vtkMultiresolutionThreshold
 * @brief   Shows only the cells of a .resmr model whose value of an array lies in a range.
 *
 * The property filter of the multiresolution view (ours; see Core/view/PropertyFilter.h): the
 * output is the input's descriptor (vtkMultiresolutionReader) with the filter added to the
 * field array FilterArrayName(), and the Multiresolution Surface representation draws the
 * cells whose value of the array at the time step shown lies in [LowerThreshold,
 * UpperThreshold] (cells with no value never do), with the faces the filter exposes painted
 * with their cells' own values: exact at a pixel tolerance of 0. Like stock Threshold of the
 * full grid, but the model is never loaded; chained filters (and an Extract Subset upstream
 * or downstream) must all hold. The array is chosen as stock Threshold's Scalars, among the
 * property file's arrays; the time toolbar moves the filtered set with the step.
 */
#ifndef vtkMultiresolutionThreshold_h
#define vtkMultiresolutionThreshold_h

#include "ResMRRepresentationsModule.h"
#include "vtkPolyDataAlgorithm.h"

class RESMRREPRESENTATIONS_EXPORT vtkMultiresolutionThreshold : public vtkPolyDataAlgorithm
{
public:
  static vtkMultiresolutionThreshold* New();
  vtkTypeMacro(vtkMultiresolutionThreshold, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The field array holding the filters: a string, one "low high name" line a filter.
  static const char* FilterArrayName() { return "ResMR Value Filter"; }

  /// The range of values kept, inclusive.
  vtkSetMacro(LowerThreshold, double);
  vtkGetMacro(LowerThreshold, double);
  vtkSetMacro(UpperThreshold, double);
  vtkGetMacro(UpperThreshold, double);

protected:
  vtkMultiresolutionThreshold();
  ~vtkMultiresolutionThreshold() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkMultiresolutionThreshold(const vtkMultiresolutionThreshold&) = delete;
  void operator=(const vtkMultiresolutionThreshold&) = delete;

  double LowerThreshold = 0;
  double UpperThreshold = 1;
};

#endif
