/**
 * @class   vtkMultiresolutionExtractSubset
 * @brief   Shows only the cells of a .resmr model whose I, J, K lie in a box.
 *
 * The I/J/K range filter of the multiresolution view (ours; see Core/view/CellRange.h): the
 * output is the input's descriptor (vtkMultiresolutionReader) with the box added to the field
 * array RangeArrayName(), and the Multiresolution Surface representation draws that box's
 * cells alone, with the faces where the box cuts the model: exact at a pixel tolerance of 0,
 * within the tolerance otherwise. VOI is ECLIPSE's, from 1 and inclusive, like stock Extract
 * Subset's (which counts from 0 and would only see the descriptor's eight corner points);
 * values past the grid are clamped. Chained filters intersect their boxes. With Exclude on,
 * the box's cells are hidden instead (ResInsight's exclude range): the box is added to the
 * field array ExcludedArrayName() and the cells around it stay, the faces it exposes drawn;
 * chained, every excluded box is left out of what the include boxes keep. The model is never
 * loaded: the boxes travel with the descriptor to wherever the view draws (pvserver included).
 */
#ifndef vtkMultiresolutionExtractSubset_h
#define vtkMultiresolutionExtractSubset_h

#include "ResMRRepresentationsModule.h"
#include "vtkPolyDataAlgorithm.h"

class vtkAbstractArray;
class vtkPolyData;

class RESMRREPRESENTATIONS_EXPORT vtkMultiresolutionExtractSubset : public vtkPolyDataAlgorithm
{
public:
  static vtkMultiresolutionExtractSubset* New();
  vtkTypeMacro(vtkMultiresolutionExtractSubset, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The field array holding the range: 6 ints, I0 I1 J0 J1 K0 K1 from 1, inclusive.
  static const char* RangeArrayName() { return "ResMR Cell Range"; }
  /// The field array holding the excluded boxes: 6 ints a box, as RangeArrayName's.
  static const char* ExcludedArrayName() { return "ResMR Excluded Cells"; }

  /// What the descriptor's filters output: `input` with `array` in place of its field array of
  /// the same name (the input's own field data stays unchanged).
  static void PassWithFieldArray(vtkPolyData* input, vtkPolyData* output, vtkAbstractArray* array);

  /// The box: I from VOI[0] to VOI[1], J from VOI[2] to VOI[3], K from VOI[4] to VOI[5],
  /// from 1 and inclusive. By default every cell.
  vtkSetVector6Macro(VOI, int);
  vtkGetVector6Macro(VOI, int);

  /// Hide VOI's cells instead of keeping only them (default off).
  vtkSetMacro(Exclude, bool);
  vtkGetMacro(Exclude, bool);
  vtkBooleanMacro(Exclude, bool);

  /// After RequestInformation: 1, NI, 1, NI, 1, NJ, 1, NJ, 1, NK, 1, NK of the model upstream,
  /// the VOI sliders' bounds (0 when no .resmr is upstream).
  vtkGetVectorMacro(VOIRange, int, 12);

protected:
  vtkMultiresolutionExtractSubset();
  ~vtkMultiresolutionExtractSubset() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkMultiresolutionExtractSubset(const vtkMultiresolutionExtractSubset&) = delete;
  void operator=(const vtkMultiresolutionExtractSubset&) = delete;

  int VOI[6] = { 1, 1 << 30, 1, 1 << 30, 1, 1 << 30 };
  bool Exclude = false;
  int VOIRange[12] = { 0 };
};

#endif
