#include "vtkMultiresolutionExtractSubset.h"

#include "vtkMultiresolutionReader.h"

#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"

#include <algorithm>

vtkStandardNewMacro(vtkMultiresolutionExtractSubset);

namespace
{
/// The multiresolution reader upstream of `algorithm`, if any.
vtkMultiresolutionReader* ReaderUpstream(vtkAlgorithm* algorithm)
{
  for (int depth = 0; algorithm && depth < 16; ++depth)
  {
    if (auto* reader = vtkMultiresolutionReader::SafeDownCast(algorithm))
    {
      return reader;
    }
    algorithm = algorithm->GetNumberOfInputPorts() > 0 && algorithm->GetNumberOfInputConnections(0) > 0
      ? algorithm->GetInputAlgorithm(0, 0)
      : nullptr;
  }
  return nullptr;
}
} // namespace

vtkMultiresolutionExtractSubset::vtkMultiresolutionExtractSubset() = default;
vtkMultiresolutionExtractSubset::~vtkMultiresolutionExtractSubset() = default;

int vtkMultiresolutionExtractSubset::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*)
{
  const vtkMultiresolutionReader* reader = ReaderUpstream(this);
  const int* dims = reader ? reader->GetDimensions() : nullptr;
  for (int a = 0; a < 3; ++a)
  {
    const int n = dims ? dims[a] : 0;
    const int bounds[4] = { n > 0 ? 1 : 0, n, n > 0 ? 1 : 0, n };
    std::copy(bounds, bounds + 4, this->VOIRange + 4 * a);
  }
  return 1;
}

int vtkMultiresolutionExtractSubset::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!input || !output)
  {
    return 0;
  }
  int box[6];
  std::copy(this->VOI, this->VOI + 6, box);
  if (this->Exclude)
  {
    // Chained excluded boxes add up; the include boxes upstream pass unchanged.
    vtkNew<vtkIntArray> excluded;
    excluded->SetName(ExcludedArrayName());
    vtkIntArray* before = vtkIntArray::SafeDownCast(input->GetFieldData()->GetAbstractArray(ExcludedArrayName()));
    const vtkIdType whole = before ? before->GetNumberOfValues() / 6 * 6 : 0;
    for (vtkIdType n = 0; n < whole; ++n)
    {
      excluded->InsertNextValue(before->GetValue(n));
    }
    for (int n = 0; n < 6; ++n)
    {
      excluded->InsertNextValue(box[n]);
    }
    PassWithFieldArray(input, output, excluded);
    return 1;
  }
  // Chained filters: the intersection of their boxes.
  vtkIntArray* upstream = vtkIntArray::SafeDownCast(input->GetFieldData()->GetAbstractArray(RangeArrayName()));
  if (upstream && upstream->GetNumberOfValues() == 6)
  {
    for (int a = 0; a < 3; ++a)
    {
      box[2 * a] = std::max(box[2 * a], upstream->GetValue(2 * a));
      box[2 * a + 1] = std::min(box[2 * a + 1], upstream->GetValue(2 * a + 1));
    }
  }
  vtkNew<vtkIntArray> range;
  range->SetName(RangeArrayName());
  range->SetNumberOfValues(6);
  for (int n = 0; n < 6; ++n)
  {
    range->SetValue(n, box[n]);
  }
  PassWithFieldArray(input, output, range);
  return 1;
}

void vtkMultiresolutionExtractSubset::PassWithFieldArray(
  vtkPolyData* input, vtkPolyData* output, vtkAbstractArray* array)
{
  output->ShallowCopy(input);
  vtkNew<vtkFieldData> fields;
  fields->ShallowCopy(input->GetFieldData()); // the input's own field data stays unchanged
  fields->RemoveArray(array->GetName());
  fields->AddArray(array);
  output->SetFieldData(fields);
}

void vtkMultiresolutionExtractSubset::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "VOI: " << this->VOI[0] << " " << this->VOI[1] << " " << this->VOI[2] << " " << this->VOI[3] << " "
     << this->VOI[4] << " " << this->VOI[5] << "\n";
  os << indent << "Exclude: " << this->Exclude << "\n";
}
