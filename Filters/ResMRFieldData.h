// Field-data helper shared by the filters of ResMR::Filters (not wrapped: a private header).
#ifndef ResMRFieldData_h
#define ResMRFieldData_h

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkNew.h"

namespace resmr_filters
{
/// Adds a one-value double array `name` to `field` (a filter's report: counts, errors).
inline void AddValue(vtkFieldData* field, const char* name, double value)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->InsertNextValue(value);
  field->AddArray(array);
}
} // namespace resmr_filters

#endif
