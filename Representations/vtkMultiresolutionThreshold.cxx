#include "vtkMultiresolutionThreshold.h"

#include "vtkMultiresolutionExtractSubset.h"

#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <cstdio>
#include <string>

vtkStandardNewMacro(vtkMultiresolutionThreshold);

vtkMultiresolutionThreshold::vtkMultiresolutionThreshold()
{
  this->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_CELLS, vtkDataSetAttributes::SCALARS);
}

vtkMultiresolutionThreshold::~vtkMultiresolutionThreshold() = default;

int vtkMultiresolutionThreshold::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!input || !output)
  {
    return 0;
  }
  // The descriptor's cell arrays are the property file's (two cells: the step's range).
  // An array named but not the descriptor's (a script's typo, a property file without it)
  // still filters, by name: the surface then draws nothing and says which array it lacks, as
  // stock Threshold outputs nothing, rather than showing the model unfiltered.
  vtkDataArray* array = this->GetInputArrayToProcess(0, inputVector);
  vtkInformation* selected = this->GetInputArrayInformation(0);
  const char* name = array                                   ? array->GetName()
    : selected && selected->Has(vtkDataObject::FIELD_NAME()) ? selected->Get(vtkDataObject::FIELD_NAME())
                                                             : nullptr;
  if (!array && name && *name)
  {
    vtkWarningMacro(<< "the model has no array '" << name << "': nothing passes");
  }
  vtkStringArray* upstream = vtkStringArray::SafeDownCast(input->GetFieldData()->GetAbstractArray(FilterArrayName()));
  std::string lines = upstream && upstream->GetNumberOfValues() == 1 ? upstream->GetValue(0) : std::string();
  if (name && *name)
  {
    char bounds[64];
    // %.9g: a float's value survives the text exactly.
    std::snprintf(bounds, sizeof(bounds), "%.9g %.9g ", this->LowerThreshold, this->UpperThreshold);
    lines += bounds + std::string(name) + "\n";
  }
  else
  {
    vtkWarningMacro(<< "no array to filter by: the model shows unfiltered");
  }
  vtkNew<vtkStringArray> filters;
  filters->SetName(FilterArrayName());
  filters->InsertNextValue(lines);
  vtkMultiresolutionExtractSubset::PassWithFieldArray(input, output, filters);
  return 1;
}

void vtkMultiresolutionThreshold::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LowerThreshold: " << this->LowerThreshold << "\n";
  os << indent << "UpperThreshold: " << this->UpperThreshold << "\n";
}
