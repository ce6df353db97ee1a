/**
 * @class   vtkMultiresolutionReader
 * @brief   Opens a .resmr file as a small descriptor of the model, not its cells.
 *
 * The multiresolution view (paper Sec. 6) reads meshes from the file itself, as the camera
 * asks for them; the pipeline only carries what ParaView needs to list and colour the model:
 * the model's bounding box as 8 points and its 12 edges (z up, z = -depth), and one cell
 * array a property of the property file beside it (FILE.resmrp, or PropertyFileName), each
 * holding that property's minimum and maximum at the requested time step, so Color By lists
 * the properties and Rescale finds their ranges. The property file's report steps (in days)
 * are the time steps. A damaged file, or a property file of another geometry, is an error
 * naming the file. With ApplyMapAxes (the default) the box is placed by the file's MAPAXES,
 * as the grid readers place the grid; the representation draws the surface there too.
 */
#ifndef vtkMultiresolutionReader_h
#define vtkMultiresolutionReader_h

#include "ResMRRepresentationsModule.h"
#include "vtkPolyDataAlgorithm.h"

#include <string>
#include <vector>

namespace resmr
{
class MultiresolutionFile;
}

class RESMRREPRESENTATIONS_EXPORT vtkMultiresolutionReader : public vtkPolyDataAlgorithm
{
public:
  static vtkMultiresolutionReader* New();
  vtkTypeMacro(vtkMultiresolutionReader, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The .resmr file.
  vtkSetStdStringFromCharMacro(FileName);
  vtkGetCharFromStdStringMacro(FileName);

  /// The property file; empty (the default): FILE.resmrp beside the .resmr, if it exists.
  vtkSetStdStringFromCharMacro(PropertyFileName);
  vtkGetCharFromStdStringMacro(PropertyFileName);

  /// Place the model in map coordinates given by the input's MAPAXES (x, y rotated, scaled
  /// and shifted as the grid readers do; z unchanged). On by default.
  vtkSetMacro(ApplyMapAxes, bool);
  vtkGetMacro(ApplyMapAxes, bool);
  vtkBooleanMacro(ApplyMapAxes, bool);

  /// The property file actually used after the last update (empty if none).
  const std::string& GetResolvedPropertyFileName() const { return this->ResolvedPropertyFile; }
  /// Which version of that file it was (inode, size, modification time): the view opens the
  /// file again when a rewrite (resmr add-properties adding steps) changes it.
  const std::string& GetPropertyFileStamp() const { return this->PropertyFileStamp; }

  /// Reads the property file again on the next update (File > Reload Files, ReloadFiles() in
  /// pvpython): steps added since are offered.
  void Reload() { this->Modified(); }

  /// The property file's step shown at `time` (days): the last not after it (0 if none).
  int GetStepNumber(double time) const;

  /// Why the last update failed; empty if it did not.
  const char* GetLastError() const { return this->LastError.c_str(); }

  /// The grid's cells in I, J and K, after RequestInformation (0 before, or for a file that
  /// did not open).
  const int* GetDimensions() const { return this->Dimensions; }

protected:
  vtkMultiresolutionReader();
  ~vtkMultiresolutionReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkMultiresolutionReader(const vtkMultiresolutionReader&) = delete;
  void operator=(const vtkMultiresolutionReader&) = delete;

  std::string PropertyPathFor() const;
  std::size_t StepIndex(double time) const;
  int Fail(const std::string& message);
  /// A warning naming the regions no cut reaches (resmr::UnreachableRegions), if any.
  void WarnOfUnreachableRegions(const resmr::MultiresolutionFile& geometry);

  std::string FileName;
  std::string PropertyFileName;
  bool ApplyMapAxes = true;
  std::string ResolvedPropertyFile;
  std::string PropertyFileStamp;
  std::string LastError;
  std::string InformationFailed;    ///< why RequestInformation failed (the file did not open)
  std::vector<double> StepDays;     ///< per report step, from the property file
  std::vector<int32_t> StepNumbers; ///< the property file's step of each
  int Dimensions[3] = { 0, 0, 0 };
};

#endif
