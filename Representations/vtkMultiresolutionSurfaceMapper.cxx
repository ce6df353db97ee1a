#include "vtkMultiresolutionSurfaceMapper.h"

#include "vtkMultiresolutionCellPicker.h"
#include "vtkMultiresolutionGpuRegions.h"
#include "vtkMultiresolutionReducedResolution.h"
#include "vtkMultiresolutionShaderVariants.h"
#include "vtkMultiresolutionTableTextures.h"

#include "CellInspection.h"
#include "CellRange.h"
#include "CornerPointGeometry.h"
#include "FramePlanning.h"
#include "FrameRateController.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "PropertyFilter.h"
#include "RegionCache.h"
#include "Residency.h"
#include "UploadPacer.h"
#include "ViewSelection.h"
#include "ViewTransforms.h"

#include "vtkActor.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLRenderer.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkScalarsToColors.h"
#include "vtkShaderProgram.h"
#include "vtkStringArray.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include <sstream>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMultiresolutionSurfaceMapper);

namespace
{
double ElapsedMs(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

/// GPU time of a frame, from a timer query read back a frame or more later (never waits).
class GpuTimer
{
public:
  /// Takes the last query's result if the driver has it, and times this frame unless that
  /// query is still outstanding.
  void Begin()
  {
    if (this->Query != 0 && this->Outstanding)
    {
      GLint available = 0;
      glGetQueryObjectiv(this->Query, GL_QUERY_RESULT_AVAILABLE, &available);
      if (available)
      {
        GLuint64 nanoseconds = 0;
        glGetQueryObjectui64v(this->Query, GL_QUERY_RESULT, &nanoseconds);
        this->LastMs = nanoseconds * 1e-6;
        this->Outstanding = false;
      }
    }
    if (this->Query == 0)
    {
      glGenQueries(1, &this->Query);
    }
    this->Timing = !this->Outstanding;
    if (this->Timing)
    {
      glBeginQuery(GL_TIME_ELAPSED, this->Query);
    }
  }

  void End()
  {
    if (this->Timing)
    {
      glEndQuery(GL_TIME_ELAPSED);
      this->Outstanding = true;
    }
  }

  /// The GPU time of the last frame whose query came back (0 before any).
  double Ms() const { return this->LastMs; }

  void Release()
  {
    if (this->Query != 0)
    {
      glDeleteQueries(1, &this->Query);
      this->Query = 0;
      this->Outstanding = false;
    }
  }

private:
  unsigned int Query = 0;
  bool Outstanding = false;
  bool Timing = false;
  double LastMs = 0;
};

/// A VTK matrix as a row-major array.
resmr::Matrix4 RowMajor(vtkMatrix4x4* m)
{
  resmr::Matrix4 r{};
  for (int i = 0; i < 16; ++i)
  {
    r[i] = m->GetElement(i / 4, i % 4);
  }
  return r;
}
} // namespace

struct vtkMultiresolutionSurfaceMapper::Internals
{
  // Files (reopened when the descriptor names others).
  std::string FilePath, PropertyPath, PropertyStamp;
  std::shared_ptr<const resmr::MultiresolutionFile> File;
  std::shared_ptr<const resmr::PropertyFile> Properties;
  std::unique_ptr<resmr::ViewSelector> Selector;
  std::unique_ptr<resmr::RegionCache> Cache;
  std::string Error;
  std::string LayerError; ///< why Layer cannot be drawn, empty if it can
  std::string RangeShown; ///< the I/J/K range drawn last (CellRange::Describe), for the log
  /// The file's region footprints (MultiresolutionFile::ReadFootprints), empty without them.
  std::vector<std::array<float, 4>> Footprints;
  /// The property filters drawn last, resolved against the property file (their block ranges
  /// read once a filter and step); null: none.
  std::shared_ptr<const resmr::ValueFilterSet> ValueFilters;
  /// The painted table's layer blocks (faces of coarse filtered regions), and which table.
  std::shared_ptr<const std::vector<resmr::BlockSummary>> PaintBlocks;
  int PaintBlocksTable = -1;
  std::string Reported;     ///< the last error sent to vtkErrorMacro (each failure once)
  bool WallsWarned = false; ///< a damaged wall depth table was reported

  // GPU side.
  vtkOpenGLRenderWindow* Window = nullptr;
  vtkMultiresolutionGpuRegions Regions;
  vtkMultiresolutionTableTextures Tables;
  vtkMultiresolutionShaderVariants Shaders;
  vtkMultiresolutionReducedResolution Reduced;
  vtkMultiresolutionCellPicker Picker;
  GpuTimer Timer;

  // View state and readout.
  resmr::FrameRateController Controller;
  bool ControllerRunning = false; ///< holding a frame rate since the file opened
  bool UploadsDeferred = false;   ///< loaded meshes wait for the next frame's upload
  resmr::UploadPacer Pacer;       ///< predicts what mesh copies cost (fresh GPU memory is slow)
  bool HavePreviousView = false;
  resmr::ViewParameters PreviousView;
  double Tolerance = 1;
  double RenderScale = 1;    ///< the last frame's
  double EstimatedError = 0; ///< the last frame's (ViewSelection::estimatedErrorPixels)
  bool Controlled = false;   ///< the last frame used the controller's tolerance
  bool HaveLastClip = false;
  resmr::Matrix4 LastClip{}; ///< the last frame's model to clip transform
  vtkIdType Triangles = 0;
  int Drawn = 0, Substituted = 0;
  double FrameMs = 0;
  bool Pending = false;
  bool LoadersBusy = false; ///< the cache still reads what the last frame wanted
  std::chrono::steady_clock::time_point FrameStart;
  bool HaveFrameStart = false;

  // Picking: what PickAt asked for, and what the last pick found.
  bool PickPending = false;
  std::array<double, 2> PickPixel{};
  bool InspectPending = false;
  std::array<int64_t, 3> Inspect{}; ///< I, J, K from 1
  int PicksDone = 0;                ///< picks and inspections answered, for scripts
  /// The last frame drawn, which a pick between frames draws again (PickFromLastFrame).
  std::unique_ptr<Frame> Last;
  vtkWeakPointer<vtkRenderer> LastRenderer;
  vtkWeakPointer<vtkActor> LastActor;
  struct Picked
  {
    std::array<int, 3> cell{ 0, 0, 0 }; ///< I, J, K from 1; 0: nothing
    int active = -1;
    std::array<double, 3> point{};
    std::array<double, 24> corners{};
    std::string values;
  } Pick;

  void Close()
  {
    this->ControllerRunning = false;
    this->Cache.reset();
    this->Selector.reset();
    this->Footprints.clear();
    this->Properties.reset();
    this->File.reset();
    this->FilePath.clear();
    this->PropertyPath.clear();
    this->PropertyStamp.clear();
    this->Tables.Forget(this->Window);
  }

  void ReleaseGpu()
  {
    this->Picker.ReleaseGraphicsResources(this->Window);
    this->Reduced.ReleaseGraphicsResources(this->Window);
    this->Regions.ReleaseGraphicsResources();
    this->Tables.ForgetAll(this->Window);
  }
};

struct vtkMultiresolutionSurfaceMapper::Frame
{
  Frame(vtkRenderer* frameRenderer, vtkActor* frameActor)
    : renderer(frameRenderer)
    , actor(frameActor)
  {
  }

  vtkRenderer* renderer;
  vtkActor* actor;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double rendererMs = 0;        ///< the renderer's time for the last frame
  double intervalMs = 0;        ///< since the last frame began (0: the first)
  bool afterAllocation = false; ///< the last frame allocated a table texture
  bool bounded = true;          ///< interactive: a bounded upload a frame (no WaitForDetailMs)
  bool moving = false;          ///< the camera (or the actor) moved since the last frame
  bool controlled = false;      ///< drawn at the frame-rate controller's tolerance (moving)
  double scale = 1;             ///< the fraction of the view's width and height drawn
  // What the descriptor names.
  std::string filePath, propertyPath, propertyStamp;
  int32_t step = 0;
  bool applyMapAxes = false;
  int32_t layer = -1;     ///< 0-based; -1: the whole model
  std::string rangeText;  ///< the descriptor's I/J/K range, from 1 (empty: none)
  std::string filterText; ///< the descriptor's property filters, "low high name" a line
  bool ranged = false;    ///< drawing the cells of `range` (and `filters`) only
  resmr::CellRange range;
  std::vector<resmr::ValueFilter> filters;
  resmr::PropertyRequest property;
  /// The property table drawn: the requested one or one standing in; null: solid colour.
  std::shared_ptr<const resmr::PropertyTableData> drawnProperty;
  // The view.
  vtkOpenGLRenderWindow* window = nullptr;
  resmr::Matrix4 modelToWorld{}, modelToClip{}, modelToView{};
  resmr::ViewParameters view;
  resmr::ViewSelection selection;
  // Uploads and drawing.
  std::chrono::steady_clock::time_point tablesStart;
  std::size_t tableBytes = 0; ///< copied for the model's tables this frame
  double uploadMs = 0;        ///< the frame's copying allowance (resmr::UploadBudgetMs)
  vtkShaderProgram* program = nullptr;
  int colorMode = SolidColor;
  bool lit = false;            ///< the last program readied lights the surface
  bool clockwiseFront = false; ///< glFrontFace is GL_CW (a mirroring transform, back faces culled)
  bool cullBackFaces = false;  ///< back faces may be culled this frame (ViewSelection::backFacesHidden, no layer)
  /// The pick pass's pixel centre and viewport (x, y, width, height); x < 0: no pick. Faces
  /// are then drawn only in the triangle chunks that may cover the pixel.
  std::array<double, 4> pickPixel{ -1, -1, 0, 0 };
};

vtkMultiresolutionSurfaceMapper::vtkMultiresolutionSurfaceMapper()
  : Internal(new Internals)
{
  this->Internal->Controller.Reset(this->PixelTolerance);
}

vtkMultiresolutionSurfaceMapper::~vtkMultiresolutionSurfaceMapper() = default;

int vtkMultiresolutionSurfaceMapper::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  return 1;
}

double vtkMultiresolutionSurfaceMapper::GetCurrentTolerance() const
{
  return this->Internal->Tolerance;
}
double vtkMultiresolutionSurfaceMapper::GetCurrentEstimatedError() const
{
  return this->Internal->EstimatedError;
}
double vtkMultiresolutionSurfaceMapper::GetCurrentRenderScale() const
{
  return this->Internal->RenderScale;
}

bool vtkMultiresolutionSurfaceMapper::GetCurrentFrameControlled() const
{
  return this->Internal->Controlled;
}
double vtkMultiresolutionSurfaceMapper::GetResidentMB() const
{
  const std::size_t bytes = this->Internal->Cache ? this->Internal->Cache->ResidentBytes() : 0;
  return double(bytes + this->Internal->Regions.Bytes()) / (1 << 20);
}
vtkIdType vtkMultiresolutionSurfaceMapper::GetTrianglesDrawn() const
{
  return this->Internal->Triangles;
}
int vtkMultiresolutionSurfaceMapper::GetRegionsDrawn() const
{
  return this->Internal->Drawn;
}
int vtkMultiresolutionSurfaceMapper::GetRegionsSubstituted() const
{
  return this->Internal->Substituted;
}
double vtkMultiresolutionSurfaceMapper::GetLastFrameMs() const
{
  return this->Internal->FrameMs;
}
bool vtkMultiresolutionSurfaceMapper::GetLoadsPending() const
{
  return this->Internal->Pending;
}
double vtkMultiresolutionSurfaceMapper::GetRefreshWaitMs() const
{
  return resmr::RefreshWaitMs(this->Internal->FrameMs, this->Internal->LoadersBusy);
}
void vtkMultiresolutionSurfaceMapper::PickAt(double x, double y)
{
  this->Internal->PickPending = x >= 0 && y >= 0;
  this->Internal->PickPixel = { x, y };
  this->PickFromLastFrame();
}
void vtkMultiresolutionSurfaceMapper::InspectCell(int i, int j, int k)
{
  this->Internal->InspectPending = i > 0 && j > 0 && k > 0;
  this->Internal->Inspect = { i, j, k };
  this->PickFromLastFrame();
}
int vtkMultiresolutionSurfaceMapper::GetPicksDone() const
{
  return this->Internal->PicksDone;
}

void vtkMultiresolutionSurfaceMapper::PickFromLastFrame()
{
  // A pick needs no new frame: the last one's cut, camera and window, drawn once more into one
  // pixel (a hover over a large model would otherwise wait for a whole frame). Without a last
  // frame (or its renderer gone) the next render picks.
  Internals& in = *this->Internal;
  if (!(in.PickPending || in.InspectPending) || !in.Last || !in.LastRenderer || !in.LastActor || !in.Window ||
    !in.File || in.Last->window != in.Window)
  {
    return;
  }
  in.Window->MakeCurrent();
  Frame frame = *in.Last;
  this->PickCell(frame);
}

void vtkMultiresolutionSurfaceMapper::ForgetLastFrame()
{
  this->Internal->Last.reset();
}
const int* vtkMultiresolutionSurfaceMapper::GetPickedCell() const
{
  return this->Internal->Pick.cell.data();
}
int vtkMultiresolutionSurfaceMapper::GetPickedActive() const
{
  return this->Internal->Pick.active;
}
const double* vtkMultiresolutionSurfaceMapper::GetPickedPoint() const
{
  return this->Internal->Pick.point.data();
}
const double* vtkMultiresolutionSurfaceMapper::GetPickedCorners() const
{
  return this->Internal->Pick.corners.data();
}
const char* vtkMultiresolutionSurfaceMapper::GetPickedValues() const
{
  return this->Internal->Pick.values.c_str();
}

const char* vtkMultiresolutionSurfaceMapper::GetLastError() const
{
  if (this->Internal->Error.empty() && !this->Internal->LayerError.empty())
  {
    return this->Internal->LayerError.c_str();
  }
  if (this->Internal->Error.empty() && this->Internal->Cache)
  {
    static thread_local std::string cacheError;
    cacheError = this->Internal->Cache->LastError();
    return cacheError.c_str();
  }
  return this->Internal->Error.c_str();
}

double* vtkMultiresolutionSurfaceMapper::GetBounds()
{
  vtkPolyData* input = vtkPolyData::SafeDownCast(this->GetInputDataObject(0, 0));
  if (input && input->GetNumberOfPoints() > 0)
  {
    input->GetBounds(this->Bounds);
  }
  else
  {
    vtkMath::UninitializeBounds(this->Bounds);
  }
  return this->Bounds;
}

void vtkMultiresolutionSurfaceMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  Internals& in = *this->Internal;
  in.Last.reset();
  in.ReleaseGpu();
  in.Tables.ReleaseGraphicsResources(window);
  in.Timer.Release();
  in.Window = nullptr;
  this->Modified();
}

namespace
{
/// (.resmr path, .resmrp path, step, map axes) from the descriptor; false if it has none.
/// A plane along which a range cuts the grid, with its place in the shader's order (K low,
/// K high, I low, I high, J low, J high).
struct CutPlaneSlot
{
  int slot;
  int axis;
  int64_t index;
};

/// The planes along which `range` (if `ranged`) cuts a grid of `dims`.
std::vector<CutPlaneSlot> CutPlaneSlots(bool ranged, const resmr::CellRange& range, const int64_t* dims)
{
  std::vector<CutPlaneSlot> slots;
  for (int a = 0; ranged && a < 3; ++a)
  {
    const int first = a == 2 ? 0 : 2 * a + 2;
    if (range.lo[a] > 0)
    {
      slots.push_back({ first, a, range.lo[a] });
    }
    if (range.hi[a] < dims[a] - 1)
    {
      slots.push_back({ first + 1, a, range.hi[a] });
    }
  }
  return slots;
}

/// Where a region lies against a range and property filters together, for the selection: the
/// filters remove what they leave nothing of; a region they cross splits by its filter error
/// (ViewSelector::SetFilterErrors), not down to the leaves as one a range's side crosses.
resmr::RangeClass Combine(resmr::RangeClass range, resmr::RangeClass values)
{
  using C = resmr::RangeClass;
  return range != C::Unknown && values == C::Outside ? C::Outside : range;
}

} // namespace

bool vtkMultiresolutionSurfaceMapper::ReadSource(Frame& frame)
{
  vtkDataObject* input = this->GetInputDataObject(0, 0);
  vtkFieldData* fields = input ? input->GetFieldData() : nullptr;
  vtkStringArray* source = fields
    ? vtkStringArray::SafeDownCast(fields->GetAbstractArray(vtkMultiresolutionSurfaceMapper::SourceArrayName()))
    : nullptr;
  if (!source || source->GetNumberOfValues() < 3)
  {
    return false;
  }
  frame.filePath = source->GetValue(0);
  frame.propertyPath = source->GetValue(1);
  frame.step = static_cast<int32_t>(std::stol(source->GetValue(2)));
  frame.applyMapAxes = source->GetNumberOfValues() > 3 && source->GetValue(3) == "1";
  frame.propertyStamp = source->GetNumberOfValues() > 4 ? source->GetValue(4) : std::string();
  frame.rangeText = source->GetNumberOfValues() > 5 ? source->GetValue(5) : std::string();
  frame.filterText = source->GetNumberOfValues() > 6 ? source->GetValue(6) : std::string();
  return true;
}

void vtkMultiresolutionSurfaceMapper::Render(vtkRenderer* renderer, vtkActor* actor)
{
  Frame frame(renderer, actor);
  this->BeginFrame(frame);
  if (renderer->GetSelector())
  {
    return; // hardware picking: the descriptor has no cells to name
  }
  if (!this->ReadSource(frame))
  {
    return; // an empty piece (another rank) or no file yet
  }
  if (!this->OpenFiles(frame) || !this->SelectLayer(frame))
  {
    return;
  }
  this->RequestProperty(frame);
  this->ComputeView(frame);
  this->SelectRegions(frame);
  Internals& in = *this->Internal;
  // GPU copies follow the cache: what it evicted (or another layer replaced) goes.
  in.Regions.ReleaseEvicted(*in.Cache);

  // The meshes' vertex layouts are bound against the property variant, which reads both
  // attributes (a variant that does not read the cell coordinate drops it when linking), at
  // the locations every variant shares; the frame's own variant draws.
  frame.program = this->ReadyProgram(frame, PropertyColors);
  if (!frame.program)
  {
    return;
  }
  // The model's tables go first, a few slabs a frame, then meshes with what is left of the
  // frame's upload allowance, so both progress; the frame draws what is on the GPU.
  this->StreamTables(frame);
  this->UploadMeshes(frame);
  if (frame.drawnProperty)
  {
    in.Tables.UpdateColorMap(frame.window, this->GetLookupTable());
  }

  // Property colours need the hash (a layer's 2D table does not) and a table on the GPU;
  // until then the solid colour.
  const bool hashReady = in.Tables.HashReady() || frame.layer >= 0;
  const bool paintable = frame.drawnProperty && hashReady;
  frame.colorMode = this->ColorMode == PropertyColors && !paintable ? SolidColor : this->ColorMode;
  frame.program = this->ReadyProgram(frame, frame.colorMode);
  if (!frame.program)
  {
    return;
  }
  // Fill-bound moving frames are drawn at a reduced resolution and stretched onto the view.
  const bool reduced = frame.scale < 1 && in.Reduced.Begin(frame.window, frame.renderer, frame.scale);
  frame.scale = reduced ? frame.scale : 1;
  this->DrawRegions(frame);
  if (reduced)
  {
    in.Reduced.End(frame.window);
  }
  this->PickCell(frame);
  if (in.Last)
  {
    *in.Last = frame; // reuses the selection's storage: no allocation a frame
  }
  else
  {
    in.Last = std::make_unique<Frame>(frame);
  }
  in.LastRenderer = frame.renderer;
  in.LastActor = frame.actor;
  this->FinishFrame(frame);
}

void vtkMultiresolutionSurfaceMapper::BeginFrame(Frame& frame)
{
  Internals& in = *this->Internal;
  // The whole frame is what the user waits for: the renderer's time for the last frame, and
  // while frames come back to back the interval between them (resmr::MeasuredFrameMs).
  frame.rendererMs = frame.renderer->GetLastRenderTimeInSeconds() * 1000;
  frame.intervalMs =
    in.HaveFrameStart ? std::chrono::duration<double, std::milli>(frame.start - in.FrameStart).count() : 0;
  in.FrameStart = frame.start;
  in.HaveFrameStart = true;
  // The renderer's time and the interval both still hold the last frame.
  frame.afterAllocation = in.Tables.Allocated();
  in.Tables.ClearAllocated();
  in.Triangles = 0;
  in.Drawn = 0;
  in.Substituted = 0;
  // Still renders (a script asked to wait for detail) copy whatever it takes.
  frame.bounded = this->WaitForDetailMs == 0;
}

void vtkMultiresolutionSurfaceMapper::Fail(const Frame& frame, const std::string& message)
{
  // A file that cannot be drawn is closed; the next frame tries again, so a mended file draws.
  Internals& in = *this->Internal;
  in.Close();
  in.FilePath = frame.filePath;
  in.PropertyPath = frame.propertyPath;
  in.PropertyStamp = frame.propertyStamp;
  in.Error = message;
  if (message != in.Reported)
  {
    in.Reported = message;
    vtkErrorMacro(<< message);
  }
}

bool vtkMultiresolutionSurfaceMapper::OpenFiles(Frame& frame)
{
  Internals& in = *this->Internal;
  // (Re)open the files when the descriptor names others, or the property file was rewritten
  // (steps added to a run still being written).
  if (frame.filePath != in.FilePath || frame.propertyPath != in.PropertyPath ||
    frame.propertyStamp != in.PropertyStamp || !in.Cache)
  {
    in.Close();
    in.ReleaseGpu();
    in.Error.clear();
    try
    {
      in.File = std::make_shared<const resmr::MultiresolutionFile>(frame.filePath);
      if (!frame.propertyPath.empty())
      {
        auto properties = std::make_shared<const resmr::PropertyFile>(frame.propertyPath);
        properties->CheckGeometry(*in.File);
        in.Properties = properties;
      }
      in.Selector.reset(new resmr::ViewSelector(*in.File));
      in.Footprints.clear();
      try
      {
        in.Footprints = in.File->ReadFootprints();
      }
      catch (const resmr::FileFormatError& error)
      {
        // Ranges still draw, deciding regions by their own widened boxes as they load.
        vtkWarningMacro(<< error.what() << "; I/J/K ranges decide regions as they load");
      }
      in.Cache.reset(
        new resmr::RegionCache(in.File, in.Properties, resmr::MainMemoryShare(this->MemoryBudgetMB), true));
      in.FilePath = frame.filePath;
      in.PropertyPath = frame.propertyPath;
      in.PropertyStamp = frame.propertyStamp;
      in.Reported.clear();
      in.WallsWarned = false;
    }
    catch (const std::exception& error)
    {
      this->Fail(frame, error.what());
      return false;
    }
  }
  if (!in.Cache)
  {
    return false;
  }
  in.Cache->SetBudget(resmr::MainMemoryShare(this->MemoryBudgetMB));
  return true;
}

bool vtkMultiresolutionSurfaceMapper::SelectLayer(Frame& frame)
{
  Internals& in = *this->Internal;
  const resmr::MultiresolutionHeader& header = in.File->Header();
  // Out of range: nothing is drawn, and LastError says why, rather than a layer the user did
  // not ask for.
  if (this->Layer < 0 || this->Layer > header.dims[2])
  {
    const std::string message = "Layer " + std::to_string(this->Layer) + " is out of range: " + in.FilePath + " has " +
      std::to_string(header.dims[2]) + " layers (1 to " + std::to_string(header.dims[2]) + "; 0 draws the whole model)";
    if (message != in.LayerError)
    {
      vtkWarningMacro(<< message);
      in.LayerError = message;
    }
    in.Pending = false;
    return false;
  }
  in.LayerError.clear();
  frame.layer = this->Layer - 1;
  in.Cache->SetLayer(frame.layer);
  return this->SelectRange(frame);
}

bool vtkMultiresolutionSurfaceMapper::SelectRange(Frame& frame)
{
  Internals& in = *this->Internal;
  const auto& dims = in.File->Header().dims;
  frame.ranged = !frame.rangeText.empty();
  if (!frame.ranged)
  {
    frame.range.lo = { 0, 0, 0 };
    frame.range.hi = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
    // A layer under a property filter: that layer's cells, filtered, painted as a range.
    frame.ranged = frame.layer >= 0 && !frame.filterText.empty();
  }
  else if (!resmr::ParseCellRange(frame.rangeText, { dims[0], dims[1], dims[2] }, frame.range))
  {
    in.LayerError = "the I/J/K range '" + frame.rangeText + "' is not six whole numbers and 'exclude' lines of six";
    in.Pending = false;
    return false;
  }
  if (frame.ranged && frame.layer >= 0)
  {
    // A layer shown within a range: the range's cells of that layer, painted as a range.
    frame.range.lo[2] = std::max<int64_t>(frame.range.lo[2], frame.layer);
    frame.range.hi[2] = std::min<int64_t>(frame.range.hi[2], frame.layer);
    frame.layer = -1;
  }
  const std::array<int64_t, 3> grid{ dims[0], dims[1], dims[2] };
  frame.ranged = frame.ranged && !frame.range.Whole(grid);
  if (frame.ranged && frame.range.Empty(grid))
  {
    in.Pending = false;
    return false; // no cell in it: nothing to draw
  }
  if (!this->SelectFilters(frame))
  {
    return false;
  }
  const bool filtered = !frame.filters.empty();
  frame.ranged = frame.ranged || filtered;
  resmr::CellFilter filter;
  filter.range = frame.range;
  if (in.ValueFilters)
  {
    filter.values = in.ValueFilters;
    // The faces a filter exposes carry the painted array's values (the packed table has none).
    filter.paintTable = this->ColorMode == PropertyColors && this->ArrayName
      ? resmr::FindFilterTable(*in.Properties, this->ArrayName, frame.step)
      : -1;
    if (filter.paintTable != in.PaintBlocksTable)
    {
      in.PaintBlocksTable = filter.paintTable;
      in.PaintBlocks = filter.paintTable < 0 ? nullptr
                                             : std::make_shared<const std::vector<resmr::BlockSummary>>(
                                                 in.Properties->ReadLayerBlocks(std::size_t(filter.paintTable)));
    }
    filter.paintBlocks = in.PaintBlocks;
  }
  in.Cache->SetFilter(frame.ranged ? &filter : nullptr);
  std::string shown = frame.ranged ? frame.range.Describe() : std::string("the whole grid");
  for (const resmr::ValueFilter& f : frame.filters)
  {
    shown += ", " + f.name + " " + std::to_string(f.low) + " to " + std::to_string(f.high);
  }
  if (shown != in.RangeShown)
  {
    vtkLogF(TRACE, "multiresolution range shown: %s of %s", shown.c_str(), in.FilePath.c_str());
    in.RangeShown = shown;
  }
  if (!frame.ranged)
  {
    in.Selector->SetRangeClassifier({});
    in.Selector->SetFilterErrors({});
    return true;
  }
  this->SetFilterErrors(frame, filtered ? in.ValueFilters : nullptr);
  // Where the range lies against a region is known once the region was decoded (its
  // footprint comes with its buffers); ancestors are decoded before their children.
  resmr::RegionCache* cache = in.Cache.get();
  const resmr::CellRange range = frame.range;
  const std::shared_ptr<const resmr::ValueFilterSet> values = filtered ? in.ValueFilters : nullptr;
  const auto classify = [range, grid, values](const std::array<float, 4>& footprint, float margin) {
    const resmr::RangeClass byRange = resmr::ClassifyFootprint(footprint, range, grid, margin);
    return values ? Combine(byRange, values->Classify(footprint, 1)) : byRange;
  };
  if (!in.Footprints.empty())
  {
    // The file's footprints: every region is classified before anything loads.
    const std::vector<std::array<float, 4>>* footprints = &in.Footprints;
    in.Selector->SetRangeClassifier([footprints, classify](std::vector<resmr::RangeClass>& classes) {
      for (std::size_t r = 0; r < classes.size() && r < footprints->size(); ++r)
      {
        classes[r] = classify((*footprints)[r], 1);
      }
    });
    return true;
  }
  in.Selector->SetRangeClassifier([cache, classify](std::vector<resmr::RangeClass>& classes) {
    cache->VisitFootprints([&](std::size_t region, const std::array<float, 4>& footprint) {
      if (region < classes.size())
      {
        classes[region] = classify(footprint, 0);
      }
    });
  });
  return true;
}

void vtkMultiresolutionSurfaceMapper::SetFilterErrors(
  Frame&, const std::shared_ptr<const resmr::ValueFilterSet>& values)
{
  Internals& in = *this->Internal;
  if (!values)
  {
    in.Selector->SetFilterErrors({});
    return;
  }
  // Coarse regions a filter crosses: the width its masking by layer blocks may widen the cells
  // drawn by. Leaves are exact.
  const resmr::MultiresolutionFile* file = in.File.get();
  const auto widen = [file, values](std::size_t region, const std::array<float, 4>& footprint, float& width) {
    const resmr::RegionRecord& record = file->Regions()[region];
    if (record.level < file->Header().leafLevel && values->Classify(footprint, 1) == resmr::RangeClass::Crossed)
    {
      width = resmr::FilterError(record, footprint);
    }
  };
  if (!in.Footprints.empty())
  {
    const std::vector<std::array<float, 4>>* footprints = &in.Footprints;
    in.Selector->SetFilterErrors([footprints, widen](std::vector<float>& widths) {
      for (std::size_t r = 0; r < widths.size() && r < footprints->size(); ++r)
      {
        widen(r, (*footprints)[r], widths[r]);
      }
    });
    return;
  }
  resmr::RegionCache* cache = in.Cache.get();
  in.Selector->SetFilterErrors([cache, widen](std::vector<float>& widths) {
    cache->VisitFootprints([&](std::size_t region, const std::array<float, 4>& footprint) {
      if (region < widths.size())
      {
        widen(region, footprint, widths[region]);
      }
    });
  });
}

bool vtkMultiresolutionSurfaceMapper::SelectFilters(Frame& frame)
{
  Internals& in = *this->Internal;
  frame.filters.clear();
  if (!resmr::ParseValueFilters(frame.filterText, frame.filters))
  {
    in.LayerError = "the property filter '" + frame.filterText + "' is not lines of 'low high name'";
    in.Pending = false;
    return false;
  }
  // Cells an excluded box takes out expose faces inside the model, painted from their cells'
  // values as a property filter's are: the set (no filter of its own) reads them.
  const bool excluding = frame.ranged && !frame.range.excluded.empty();
  if (frame.filters.empty() && (!excluding || !in.Properties))
  {
    in.ValueFilters.reset();
    return true;
  }
  if (!in.Properties)
  {
    in.LayerError = "a property filter needs the property file (.resmrp) of " + in.FilePath;
    this->Fail(frame, in.LayerError);
    return false;
  }
  const bool same = in.ValueFilters && in.ValueFilters->Filters() == frame.filters &&
    in.ValueFilters->Step() == frame.step && &in.ValueFilters->File() == in.Properties.get();
  if (!same)
  {
    try
    {
      in.ValueFilters = std::make_shared<resmr::ValueFilterSet>(in.Properties, frame.filters, frame.step);
    }
    catch (const std::exception& error)
    {
      in.ValueFilters.reset();
      in.LayerError = error.what();
      this->Fail(frame, error.what());
      return false;
    }
  }
  return true;
}

void vtkMultiresolutionSurfaceMapper::RequestProperty(Frame& frame)
{
  Internals& in = *this->Internal;
  const resmr::PropertyFile* properties = this->ColorMode == PropertyColors ? in.Properties.get() : nullptr;
  frame.property = resmr::RequestFor(properties, this->ArrayName ? this->ArrayName : "", frame.step, frame.layer);
  if (frame.property.wanted)
  {
    in.Cache->RequestProperty(frame.property.name, frame.property.step, frame.layer);
  }
  // A range's cut faces show cells inside the model, which the packed table does not hold:
  // their values come from the planes of cells along each cut.
  std::vector<std::array<int64_t, 2>> planes;
  for (const CutPlaneSlot& slot : CutPlaneSlots(frame.ranged, frame.range, in.File->Header().dims.data()))
  {
    planes.push_back({ slot.axis, slot.index });
  }
  // (None when no range or no property: what an earlier range asked for is not read.)
  in.Cache->RequestCutPlanes(
    frame.property.name, frame.property.step, frame.property.wanted ? planes : std::vector<std::array<int64_t, 2>>{});
}

void vtkMultiresolutionSurfaceMapper::ComputeView(Frame& frame)
{
  Internals& in = *this->Internal;
  // The view in model coordinates: the actor's matrix and MAPAXES folded into the
  // projection, in double (map coordinates are large).
  resmr::Matrix4 mapAxes = resmr::IdentityMatrix();
  std::array<double, 6> map;
  if (frame.applyMapAxes && resmr::CornerPointGeometry::PlacementTransform(in.File->Header().map, map))
  {
    mapAxes = resmr::PlacementMatrix(map);
  }
  frame.window = vtkOpenGLRenderWindow::SafeDownCast(frame.renderer->GetRenderWindow());
  if (in.Window != frame.window)
  {
    in.ReleaseGpu();
    in.Window = frame.window;
  }
  vtkOpenGLCamera* camera = vtkOpenGLCamera::SafeDownCast(frame.renderer->GetActiveCamera());
  vtkMatrix4x4 *worldToView, *worldToClip, *viewToClip;
  vtkMatrix3x3* normalMatrix;
  camera->GetKeyMatrices(frame.renderer, worldToView, normalMatrix, viewToClip, worldToClip);
  vtkNew<vtkMatrix4x4> actorMatrix;
  frame.actor->GetMatrix(actorMatrix);
  frame.modelToWorld = resmr::Multiply(RowMajor(actorMatrix), mapAxes);
  // VTK's OpenGL key matrices are stored transposed (ready for column-major upload).
  frame.modelToView = resmr::Multiply(resmr::Transpose(RowMajor(worldToView)), frame.modelToWorld);
  int width = 0, height = 0, x0 = 0, y0 = 0;
  frame.renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  resmr::CameraState state;
  state.worldToClip = resmr::Transpose(RowMajor(worldToClip));
  camera->GetPosition(state.position.data());
  camera->GetDirectionOfProjection(state.directionOfProjection.data());
  state.nearClip = camera->GetClippingRange()[0];
  state.parallel = camera->GetParallelProjection() != 0;
  state.parallelScale = camera->GetParallelScale();
  state.viewAngleDegrees = camera->GetViewAngle();
  state.viewportHeight = height;
  frame.view = resmr::ViewFromCamera(state, frame.modelToWorld);
  frame.modelToClip = frame.view.worldToClip;
  frame.moving = in.HaveLastClip && frame.modelToClip != in.LastClip;
  in.LastClip = frame.modelToClip;
  in.HaveLastClip = true;
  this->ChooseTolerance(frame.moving);
  frame.controlled = this->TargetFrameRate > 0 && frame.moving;
  frame.view.tolerancePixels = in.Tolerance;
  // Only interactive moving frames under a target frame rate are drawn reduced: still frames,
  // screenshots and scripts waiting for detail get every pixel.
  frame.scale = this->TargetFrameRate > 0 && frame.bounded && frame.moving ? in.Controller.Scale() : 1;
}

void vtkMultiresolutionSurfaceMapper::ChooseTolerance(bool moving)
{
  Internals& in = *this->Internal;
  if (this->TargetFrameRate > 0)
  {
    // The controller holds the rate while the camera moves, within the quality floor; a still
    // frame is the user's picture at the user's tolerance, and the controller waits for the
    // next move where it was.
    in.Controller.SetMaximumPixels(std::max(this->MaximumPixelTolerance, this->PixelTolerance));
    in.Controller.SetMaximumEstimatedPixels(this->MaximumEstimatedError);
    if (!in.ControllerRunning)
    {
      in.Controller.Reset(resmr::ControllerStartTolerance(this->PixelTolerance));
      in.ControllerRunning = true;
    }
    in.Controller.SetTargetFramesPerSecond(this->TargetFrameRate);
    in.Controller.SetScaleFloor(this->MovingResolutionFloor);
    in.Tolerance = moving ? in.Controller.Tolerance() : this->PixelTolerance;
  }
  else
  {
    in.Tolerance = this->PixelTolerance;
    in.Controller.Reset(std::max(this->PixelTolerance, 1.0));
    in.ControllerRunning = false;
  }
}

void vtkMultiresolutionSurfaceMapper::SelectRegions(Frame& frame)
{
  Internals& in = *this->Internal;
  resmr::RegionCache& cache = *in.Cache;
  // Select, and ask for what is missing and what the next frame will probably want.
  const auto resident = [&cache](std::size_t region) { return cache.IsResident(region); };
  if (frame.controlled)
  {
    // Refined before it is drawn when the cut, once loaded, would be past the quality floor.
    frame.selection = resmr::SelectWithinFloor(*in.Selector, in.Controller, frame.view, resident);
    in.Tolerance = frame.view.tolerancePixels;
  }
  else
  {
    frame.selection = in.Selector->Select(frame.view, resident);
  }
  // Regions whose error shows draw their simplified side: their exact one is not loaded.
  std::vector<std::size_t> predicted, simplified;
  if (in.HavePreviousView)
  {
    const auto all = [](std::size_t) { return true; };
    const resmr::ViewParameters next = resmr::PredictNextView(in.PreviousView, frame.view);
    predicted = in.Selector->Select(next, all).wanted;
    simplified = resmr::RegionsWithSimplifiedSide(*in.File, predicted, next);
  }
  const auto request = [&]() {
    std::vector<std::size_t> lean = resmr::RegionsWithSimplifiedSide(*in.File, frame.selection.wanted, frame.view);
    const std::set<std::size_t> wanted(frame.selection.wanted.begin(), frame.selection.wanted.end());
    std::copy_if(simplified.begin(), simplified.end(), std::back_inserter(lean),
      [&](std::size_t r) { return !wanted.count(r); }); // this frame's choice first
    // Stand-ins that take the picture past its quality floor make the wanted regions as
    // urgent as the roots: read at this thread's priority, not only with what frames leave.
    const bool urgent = frame.selection.substituted > 0 && this->MaximumEstimatedError > 0 &&
      frame.selection.estimatedErrorPixels > this->MaximumEstimatedError;
    cache.Request(frame.selection.wanted, predicted, lean, urgent);
  };
  request();
  // The roots stand in for everything, so a frame missing them (the first of a file or a
  // layer) blocks until the loader has them, never polling: they are the smallest meshes
  // and load first, and no frame shows a hole where the model is. Detail never waits here.
  if (cache.RootsMissing())
  {
    cache.WaitForRoots(std::chrono::seconds(10));
    frame.selection = in.Selector->Select(frame.view, resident);
  }
  // Still renders (scripts, screenshots) wait for the wanted set, as long as they asked.
  if (this->WaitForDetailMs > 0)
  {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(this->WaitForDetailMs);
    while (cache.Pending() && std::chrono::steady_clock::now() < deadline)
    {
      cache.WaitIdle(
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()));
      frame.selection = in.Selector->Select(frame.view, resident);
      request();
    }
  }
  in.PreviousView = frame.view;
  in.HavePreviousView = true;
}

vtkShaderProgram* vtkMultiresolutionSurfaceMapper::ReadyProgram(Frame& frame, int colorMode, bool tableNormals)
{
  Internals& in = *this->Internal;
  vtkScalarsToColors* table = this->GetLookupTable();
  vtkProperty* look = frame.actor->GetProperty();
  vtkMultiresolutionShaderVariants::Painting painting;
  painting.colorMode = colorMode;
  painting.layerView = frame.layer >= 0;
  painting.logScale = colorMode == PropertyColors && table && table->UsingLogScale() != 0;
  painting.gridLines = this->GridLines && colorMode < CellIdColors;
  // The renderer's lights as stock surfaces use them; an actor with lighting off is unlit, and
  // so are the cell id colours.
  vtkOpenGLRenderer* lights = vtkOpenGLRenderer::SafeDownCast(frame.renderer);
  painting.lighting = look->GetLighting() && lights && colorMode < CellIdColors ? lights->GetLightingComplexity() : 0;
  painting.lightCount = painting.lighting > 0 ? lights->GetLightingCount() : 0;
  painting.lighting = painting.lightCount > 0 ? painting.lighting : 0;
  painting.specular = painting.lighting > 0 && look->GetSpecular() > 0;
  painting.tableNormals = tableNormals;
  painting.wallDepths = !tableNormals && frame.layer < 0 && in.Tables.WallsReady();
  painting.cellFilter = frame.ranged;
  frame.lit = painting.lighting > 0;
  vtkShaderProgram* ready =
    in.Shaders.Ready(frame.window, painting, painting.lighting > 0 ? lights->GetLightingUniforms() : nullptr);
  if (ready && painting.lighting > 0)
  {
    lights->UpdateLightingUniforms(ready);
  }
  if (!ready && in.Error.empty())
  {
    in.Error = "the multiresolution surface shaders did not compile (see the output window)";
    vtkErrorMacro(<< in.Error);
  }
  return ready;
}

void vtkMultiresolutionSurfaceMapper::StreamTables(Frame& frame)
{
  // The hash's offsets (once a file, when the loader has read them), then the property table
  // when another is current, then the cells' normals: colours before per-cell lighting.
  Internals& in = *this->Internal;
  frame.uploadMs = resmr::UploadBudgetMs(this->TargetFrameRate, in.FrameMs);
  const std::size_t cap = resmr::TableByteCap(frame.uploadMs);
  std::size_t budget = cap;
  frame.tablesStart = std::chrono::steady_clock::now();
  in.Tables.StreamHash(frame.window, *in.Cache, budget, !frame.bounded);
  std::shared_ptr<const resmr::PropertyTableData> loaded = frame.property.wanted ? in.Cache->Property() : nullptr;
  if (!resmr::IsRequested(loaded.get(), frame.property))
  {
    loaded.reset(); // still the previous property
  }
  in.Tables.StreamProperty(frame.window, loaded, in.File->Header(), budget, !frame.bounded);
  std::array<std::shared_ptr<const resmr::CutPlaneData>, 6> cuts;
  for (const CutPlaneSlot& slot : CutPlaneSlots(frame.ranged, frame.range, in.File->Header().dims.data()))
  {
    cuts[static_cast<std::size_t>(slot.slot)] = frame.property.wanted
      ? in.Cache->CutPlane(frame.property.name, frame.property.step, slot.axis, slot.index)
      : nullptr;
  }
  in.Tables.UploadCutPlanes(frame.window, cuts, in.File->Header());
  in.Tables.StreamNormals(frame.window, budget, !frame.bounded);
  in.Tables.UploadWalls(frame.window, *in.Cache);
  const auto tables = in.Cache->Tables();
  if (tables && !tables->wallsError.empty() && !in.WallsWarned)
  {
    // The rest paints; walls take their layers from the coordinates, as before the table.
    vtkWarningMacro(<< tables->wallsError << "; walls are painted without it");
    in.WallsWarned = true;
  }
  frame.tableBytes = cap - budget;
  // The wanted table once on the GPU; until then an earlier time step of the same property
  // and layer stands in (as an ancestor does for a mesh), anything else is drawn in the solid
  // colour rather than through another property's colour map.
  frame.drawnProperty = in.Tables.UploadedProperty();
  if (!resmr::MayStandIn(frame.drawnProperty.get(), frame.property))
  {
    frame.drawnProperty.reset();
  }
}

void vtkMultiresolutionSurfaceMapper::UploadMeshes(Frame& frame)
{
  // A bounded amount a frame while interacting (the roots and still renders whatever it
  // takes), in bytes and in predicted time, since fresh GPU memory costs far more than reused
  // memory; the tables' copies count against it.
  Internals& in = *this->Internal;
  in.Pacer.BeginFrame(frame.uploadMs, resmr::UploadByteCap(frame.uploadMs));
  in.Pacer.Spend(frame.tableBytes, ElapsedMs(frame.tablesStart));
  std::vector<std::size_t> order = in.Selector->Roots();
  order.insert(order.end(), frame.selection.wanted.begin(), frame.selection.wanted.end());
  in.UploadsDeferred = in.Regions.Upload(*in.Cache, order, in.Selector->Roots().size(), frame.bounded, in.Pacer,
                         resmr::GpuShare(this->MemoryBudgetMB), frame.program) ||
    in.Tables.Busy();
  // Drawn: what is on the GPU, ancestors standing in for the rest.
  const auto onGpu = [&in](std::size_t region) { return in.Regions.Ready(region); };
  frame.selection = in.Selector->Select(frame.view, onGpu);
}

namespace
{
// The actor's material as vtkOpenGLPolyDataMapper passes it: intensities, and colours times
// their intensities.
void SetMaterialUniforms(vtkShaderProgram* program, vtkProperty* look, bool parallel)
{
  const auto scaled = [](const double* color, double by) {
    return std::array<float, 3>{ float(color[0] * by), float(color[1] * by), float(color[2] * by) };
  };
  program->SetUniform3f("ambientColorUniform", scaled(look->GetAmbientColor(), look->GetAmbient()).data());
  program->SetUniformf("ambientIntensity", static_cast<float>(look->GetAmbient()));
  program->SetUniformf("diffuseIntensity", static_cast<float>(look->GetDiffuse()));
  program->SetUniform3f("specularColorUniform", scaled(look->GetSpecularColor(), look->GetSpecular()).data());
  program->SetUniformf("specularPower", static_cast<float>(look->GetSpecularPower()));
  program->SetUniformi("cameraParallel", parallel ? 1 : 0);
}
} // namespace

void vtkMultiresolutionSurfaceMapper::SetUniforms(Frame& frame)
{
  Internals& in = *this->Internal;
  vtkShaderProgram* program = frame.program;
  const resmr::MultiresolutionHeader& header = in.File->Header();
  // Vertices are relative to the cache's origin (float keeps millimetres over a field).
  const resmr::Matrix4 shift = resmr::TranslationMatrix(in.Cache->Origin());
  std::array<float, 16> packed = resmr::ColumnMajor(resmr::Multiply(frame.modelToClip, shift));
  program->SetUniformMatrix4x4("modelToClip", packed.data());
  packed = resmr::ColumnMajor(resmr::Multiply(frame.modelToView, shift));
  program->SetUniformMatrix4x4("modelToView", packed.data());
  std::array<float, 9> normal = resmr::NormalMatrix(frame.modelToView);
  program->SetUniformMatrix3x3("normalToView", normal.data());
  const GLuint handle = static_cast<GLuint>(program->GetHandle());
  glUniform3i(glGetUniformLocation(handle, "gridDims"), int(header.dims[0]), int(header.dims[1]), int(header.dims[2]));
  // Every face drawn is a face of a cell of the range (or of the grid).
  std::array<int, 6> cells{ 0, int(header.dims[0]) - 1, 0, int(header.dims[1]) - 1, 0, int(header.dims[2]) - 1 };
  for (int a = 0; frame.ranged && a < 3; ++a)
  {
    cells[2 * a] = std::max(cells[2 * a], int(frame.range.lo[a]));
    cells[2 * a + 1] = std::min(cells[2 * a + 1], int(frame.range.hi[a]));
  }
  glUniform3i(glGetUniformLocation(handle, "cellLow"), cells[0], cells[2], cells[4]);
  glUniform3i(glGetUniformLocation(handle, "cellHigh"), cells[1], cells[3], cells[5]);
  std::array<int, 6> cuts{ -1, -1, -1, -1, -1, -1 }; // low and high cut cell an axis
  for (int a = 0; frame.ranged && a < 3; ++a)
  {
    cuts[2 * a] = frame.range.lo[a] > 0 ? cells[2 * a] : -1;
    cuts[2 * a + 1] = frame.range.hi[a] < header.dims[a] - 1 ? cells[2 * a + 1] : -1;
  }
  glUniform3i(glGetUniformLocation(handle, "cutLow"), cuts[0], cuts[2], cuts[4]);
  glUniform3i(glGetUniformLocation(handle, "cutHigh"), cuts[1], cuts[3], cuts[5]);
  in.Tables.Bind(program, header);
  // The side a side fragment's cell lies on (RegionCache's offsets): by the handedness and
  // the triangle's turn on the screen, which gl_FrontFacing gives as glFrontFace sets it.
  const auto tables = in.Cache->Tables();
  program->SetUniformi("wallSideSign", (tables ? tables->handedness : 1) * (frame.clockwiseFront ? -1 : 1));
  program->SetUniformi("layer", frame.layer);
  vtkProperty* look = frame.actor->GetProperty();
  if (frame.colorMode == PropertyColors)
  {
    vtkScalarsToColors* table = this->GetLookupTable();
    const double* colorRange = in.Tables.ColorRange();
    float range[2] = { float(colorRange[0]), float(colorRange[1]) };
    if (table->UsingLogScale() != 0)
    {
      range[0] = float(std::log10(std::max(colorRange[0], 1e-30)));
      range[1] = float(std::log10(std::max(colorRange[1], 1e-30)));
    }
    program->SetUniform2f("scalarRange", range);
    const unsigned char* nan = table->MapValue(std::numeric_limits<double>::quiet_NaN());
    const float nanColor[4] = { nan[0] / 255.f, nan[1] / 255.f, nan[2] / 255.f, nan[3] / 255.f };
    program->SetUniform4f("nanColor", nanColor);
  }
  program->SetUniform3f("solidColor", look->GetDiffuseColor());
  program->SetUniformf("gridLineWidth", static_cast<float>(this->GridLineWidth));
  program->SetUniformf("renderScale", static_cast<float>(frame.scale));
  program->SetUniform3f("gridLineColor", this->GridLineColor);
  SetMaterialUniforms(program, look, frame.view.parallel);
}

void vtkMultiresolutionSurfaceMapper::BeginDrawing(Frame& frame)
{
  vtkOpenGLState* state = frame.window->GetState();
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthMask(GL_TRUE);
  // Back faces of the closed surface, hidden from outside, are culled (the bottom seen from
  // above is about a third of the triangles), part by part (DrawPart::cullBackFaces); a
  // mirroring transform turns the winding.
  frame.cullBackFaces = frame.selection.backFacesHidden && frame.layer < 0;
  if (frame.cullBackFaces)
  {
    state->vtkglCullFace(GL_BACK);
    // Restored after drawing (vtkOpenGLState does not track it).
    frame.clockwiseFront = resmr::LinearDeterminant(frame.modelToWorld) < 0;
    glFrontFace(frame.clockwiseFront ? GL_CW : GL_CCW);
  }
  else
  {
    state->vtkglDisable(GL_CULL_FACE);
  }
  state->vtkglDisable(GL_BLEND);
  // A side triangle's flat attributes come from its last vertex (RegionDrawBuffers::indices),
  // OpenGL's default, which vtkOpenGLState does not track.
  glProvokingVertex(GL_LAST_VERTEX_CONVENTION);
}

void vtkMultiresolutionSurfaceMapper::EndDrawing(Frame& frame)
{
  glFrontFace(GL_CCW);
  frame.window->GetState()->vtkglDisable(GL_CULL_FACE);
  this->Internal->Tables.Unbind();
}

void vtkMultiresolutionSurfaceMapper::DrawRegions(Frame& frame)
{
  Internals& in = *this->Internal;
  in.Timer.Begin();
  this->BeginDrawing(frame);
  // Lit tops and bottoms take their normals from the table, once it is loaded: they are
  // drawn first with a program that computes no facet normal, then the sides with one that
  // does; otherwise one program draws every face.
  // A range's caps are inside the model, where the normal table (hashed for the model's
  // external faces) has nothing: a range lights every face by its facet, as a layer does.
  if (frame.lit && frame.layer < 0 && !frame.ranged && in.Tables.NormalsReady())
  {
    vtkShaderProgram* sides = frame.program;
    frame.program = this->ReadyProgram(frame, frame.colorMode, true);
    in.Drawn = this->DrawFaces(frame, { true, true, false });
    frame.program = sides;
    frame.window->GetShaderCache()->ReadyShaderProgram(sides); // binds it again
    this->DrawFaces(frame, { false, false, true });
  }
  else
  {
    in.Drawn = this->DrawFaces(frame, { true, true, true });
  }

  in.Substituted = static_cast<int>(frame.selection.substituted + this->SidesStandingIn(frame));
  this->EndDrawing(frame);
  in.Timer.End();
  vtkOpenGLCheckErrorMacro("after drawing the multiresolution surface");
}

std::size_t vtkMultiresolutionSurfaceMapper::SidesStandingIn(const Frame& frame) const
{
  // A region whose exact side is wanted but not loaded yet draws its simplified one meanwhile.
  std::size_t count = 0;
  for (const resmr::DrawnRegion& drawn : frame.selection.drawn)
  {
    const auto buffers = this->Internal->Cache->Get(drawn.region);
    count += frame.layer < 0 && buffers && !buffers->exactSides &&
      !resmr::DrawsSimplifiedSide(this->Internal->File->Header().version, drawn.projectedError, frame.view);
  }
  return count;
}

int vtkMultiresolutionSurfaceMapper::DrawFaces(Frame& frame, const std::array<bool, 3>& kinds)
{
  Internals& in = *this->Internal;
  if (!frame.program)
  {
    return 0;
  }
  this->SetUniforms(frame);
  // A pick pass: of each part, the runs of triangle chunks that may cover its pixel (the
  // buffers hold positions about the cache's origin).
  const resmr::Matrix4 bufferToClip = resmr::Multiply(frame.modelToClip, resmr::TranslationMatrix(in.Cache->Origin()));
  const auto coveringPixel = [&](std::size_t region, const std::vector<resmr::DrawPart>& parts) {
    std::vector<resmr::DrawPart> runs;
    for (const resmr::DrawPart& part : parts)
    {
      for (const auto& [first, count] : resmr::IndexRunsCoveringPixel(in.Regions.ChunkBoxes(region), part.first,
             part.count, bufferToClip, frame.pickPixel[0], frame.pickPixel[1], frame.pickPixel[2], frame.pickPixel[3]))
      {
        runs.push_back(part);
        runs.back().first = first;
        runs.back().count = count;
      }
    }
    return runs;
  };
  int regions = 0;
  for (const resmr::DrawnRegion& drawn : frame.selection.drawn)
  {
    const resmr::RegionDrawBuffers* buffers = in.Regions.Prepare(drawn.region, *in.Cache, frame.program);
    if (!buffers || buffers->indices.empty())
    {
      continue;
    }
    const std::array<resmr::DrawPart, 3> all = resmr::PartsToDraw(
      *buffers, drawn, frame.layer >= 0, in.File->Regions()[drawn.region], frame.view, in.File->Header().version);
    std::vector<resmr::DrawPart> parts;
    for (const resmr::DrawPart& part : all)
    {
      if (part.shown && kinds[static_cast<std::size_t>(part.kind)])
      {
        parts.push_back(part);
      }
    }
    if (frame.pickPixel[0] >= 0)
    {
      parts = coveringPixel(drawn.region, parts);
    }
    // A leaf's sides are the original faces: their coordinates name the layer exactly.
    const bool leaf = in.File->Regions()[drawn.region].level == in.File->Header().leafLevel;
    frame.program->SetUniformi("wallLookup", leaf ? 0 : 1);
    in.Triangles +=
      static_cast<vtkIdType>(in.Regions.Draw(drawn.region, parts, frame.program, frame.window, frame.cullBackFaces));
    ++regions;
  }
  return regions;
}

namespace
{
/// "NAME=value" lines of a cell's values (%.9g, "nan" for none).
std::string ValueLines(const std::vector<resmr::CellValue>& values)
{
  std::string lines;
  for (const resmr::CellValue& v : values)
  {
    char number[32];
    std::snprintf(number, sizeof(number), "%.9g", static_cast<double>(v.value));
    lines += v.name + "=" + (std::isnan(v.value) ? std::string("nan") : std::string(number)) + "\n";
  }
  return lines;
}
} // namespace

void vtkMultiresolutionSurfaceMapper::PickCell(Frame& frame)
{
  Internals& in = *this->Internal;
  if (in.InspectPending)
  {
    // A cell named by I, J, K: no pixel, no drawing.
    in.InspectPending = false;
    in.Pick = Internals::Picked();
    const resmr::MultiresolutionHeader& header = in.File->Header();
    const std::array<int64_t, 3> cell{ in.Inspect[0] - 1, in.Inspect[1] - 1, in.Inspect[2] - 1 };
    if (cell[0] >= 0 && cell[1] >= 0 && cell[2] >= 0 && cell[0] < header.dims[0] && cell[1] < header.dims[1] &&
      cell[2] < header.dims[2])
    {
      this->DescribeCell(frame, cell, nullptr);
    }
    else
    {
      in.Pick.values = "error=" + in.FilePath + ": no cell (" + std::to_string(in.Inspect[0]) + ", " +
        std::to_string(in.Inspect[1]) + ", " + std::to_string(in.Inspect[2]) + "): the grid has " +
        std::to_string(header.dims[0]) + " x " + std::to_string(header.dims[1]) + " x " +
        std::to_string(header.dims[2]) + " cells (I, J, K from 1)\n";
    }
    ++in.PicksDone;
  }
  if (!in.PickPending)
  {
    return;
  }
  in.PickPending = false;
  in.Pick = Internals::Picked();
  ++in.PicksDone;
  int width = 0, height = 0, x0 = 0, y0 = 0;
  frame.renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  const double x = std::floor(in.PickPixel[0]) - x0, y = std::floor(in.PickPixel[1]) - y0;
  if (x < 0 || y < 0 || x >= width || y >= height)
  {
    return;
  }
  // The frame's cut once more, into the one pixel: only the regions whose boxes may cover it,
  // and of those only the triangle chunks that may (the whole cut would cost a frame's vertex
  // work). Drawn in the frame's order, ties fall as in the frame. The readout keeps the frame's
  // own counts.
  const vtkIdType triangles = in.Triangles;
  const std::vector<resmr::DrawnRegion> drawn = frame.selection.drawn;
  const auto beside = [&](const resmr::DrawnRegion& region) {
    return !resmr::RegionMayCoverPixel(
      in.File->Regions()[region.region].bounds, frame.modelToClip, x + 0.5, y + 0.5, width, height);
  };
  frame.selection.drawn.erase(
    std::remove_if(frame.selection.drawn.begin(), frame.selection.drawn.end(), beside), frame.selection.drawn.end());
  frame.colorMode = PickColors;
  frame.scale = 1;
  frame.program = this->ReadyProgram(frame, PickColors);
  frame.pickPixel = { x + 0.5, y + 0.5, double(width), double(height) };
  std::array<float, 4> rgba{ 0, 0, 0, 0 };
  float depth = 1;
  const auto drawStart = std::chrono::steady_clock::now();
  in.Triangles = 0;
  if (frame.program && in.Picker.Begin(frame.window, int(x), int(y), width, height))
  {
    this->BeginDrawing(frame);
    this->DrawFaces(frame, { true, true, true });
    this->EndDrawing(frame);
    in.Picker.End(frame.window, rgba, depth);
  }
  vtkLogF(TRACE, "multiresolution pick pass: %zu regions, %lld triangles, %.1f ms", frame.selection.drawn.size(),
    static_cast<long long>(in.Triangles), ElapsedMs(drawStart));
  frame.pickPixel = { -1, -1, 0, 0 };
  in.Triangles = triangles;
  frame.selection.drawn = drawn;
  std::array<int64_t, 3> cell{};
  if (!resmr::CellFromPickPixel(rgba, in.File->Header().dims, cell))
  {
    return;
  }
  // The point hit: the pixel's centre at its depth, back through the frame's transforms.
  resmr::Matrix4 toModel;
  resmr::Invert(frame.modelToClip, toModel);
  std::array<double, 4> model = resmr::Transform(
    toModel, { 2 * (x + 0.5) / width - 1, 2 * (y + 0.5) / height - 1, 2 * static_cast<double>(depth) - 1, 1 });
  for (double& c : model)
  {
    c /= model[3];
  }
  const std::array<double, 3> near{ model[0], model[1], model[2] };
  const auto describeStart = std::chrono::steady_clock::now();
  this->DescribeCell(frame, cell, &near);
  vtkLogF(TRACE, "multiresolution pick described in %.1f ms", ElapsedMs(describeStart));
}

void vtkMultiresolutionSurfaceMapper::DescribeCell(
  Frame& frame, const std::array<int64_t, 3>& cell, const std::array<double, 3>* near)
{
  Internals& in = *this->Internal;
  const auto toWorld = [&frame](const std::array<double, 3>& p) {
    const std::array<double, 4> w = resmr::Transform(frame.modelToWorld, { p[0], p[1], p[2], 1 });
    return std::array<double, 3>{ w[0], w[1], w[2] };
  };
  in.Pick.cell = { int(cell[0] + 1), int(cell[1] + 1), int(cell[2] + 1) };
  in.Pick.corners.fill(std::numeric_limits<double>::quiet_NaN());
  try
  {
    const resmr::CellReport report = resmr::InspectCell(*in.File, in.Properties.get(), cell, frame.step, near);
    const resmr::CellGeometry& geometry = report.geometry;
    in.Pick.active = geometry.found ? (geometry.active ? 1 : 0) : -1;
    for (std::size_t c = 0; geometry.found && c < 8; ++c)
    {
      const std::array<double, 3> w = toWorld(geometry.corners[c]);
      std::copy(w.begin(), w.end(), in.Pick.corners.begin() + 3 * static_cast<std::ptrdiff_t>(c));
    }
    if (near)
    {
      in.Pick.point = toWorld(*near);
    }
    else if (geometry.found)
    {
      in.Pick.point = toWorld(geometry.Centre());
    }
    in.Pick.values = ValueLines(report.values);
  }
  catch (const std::exception& error)
  {
    in.Pick.values += std::string("error=") + error.what() + "\n";
  }
}

void vtkMultiresolutionSurfaceMapper::FinishFrame(Frame& frame)
{
  Internals& in = *this->Internal;
  resmr::RegionCache& cache = *in.Cache;
  // Pending too: what the loader finished during this frame, after the frame took its state
  // (tables, the property, wanted meshes), and the next frame will copy. Without it a render
  // could report nothing pending and leave the GUI (and scripts waiting on LoadsPending) with
  // the picture before the property arrived.
  const auto arrivedLate = [&]() {
    if (!in.Tables.HashReady() && cache.Tables())
    {
      return true;
    }
    const std::shared_ptr<const resmr::PropertyTableData> now = frame.property.wanted ? cache.Property() : nullptr;
    if (now && now != in.Tables.UploadedProperty() && resmr::IsRequested(now.get(), frame.property))
    {
      return true;
    }
    return std::any_of(frame.selection.wanted.begin(), frame.selection.wanted.end(),
      [&](std::size_t region) { return !in.Regions.Ready(region) && cache.IsResident(region); });
  };
  in.LoadersBusy = cache.Pending();
  in.Pending = in.LoadersBusy || in.UploadsDeferred || arrivedLate();
  // The loader thread's errors (a damaged region or property table: the frame draws what it
  // can) go to the output window too, each once, not only to the LastError readout.
  const std::string loadError = cache.LastError();
  if (!loadError.empty() && loadError != in.Reported)
  {
    in.Reported = loadError;
    vtkErrorMacro(<< loadError);
  }
  vtkLogF(TRACE, "multiresolution surface: %d regions, %lld triangles at %.2f px", in.Drawn,
    static_cast<long long>(in.Triangles), in.Tolerance);
  in.FrameMs = ElapsedMs(frame.start) + in.Timer.Ms();
  in.RenderScale = frame.scale;
  in.EstimatedError = frame.selection.estimatedErrorPixels;
  in.Controlled = frame.controlled;
  if (frame.controlled)
  {
    const double measuredMs = resmr::MeasuredFrameMs(
      in.FrameMs, frame.rendererMs, frame.intervalMs, this->TargetFrameRate, frame.afterAllocation);
    // Ancestors drawn for meshes still on their way: not all the detail the tolerance selected.
    const bool complete = in.Substituted == 0 || !in.Pending;
    // A frame that allocated a table texture says nothing of the frames to come: coarsening
    // on it would hold a large model's tolerance far too coarse for many frames.
    if (!in.Tables.Allocated())
    {
      resmr::CutRange same;
      same.refineBelow = frame.selection.refineBelowPixels;
      same.coarsenAt = frame.selection.coarsenAtPixels;
      same.bound = frame.selection.largestProjectedError;
      same.estimate = frame.selection.estimatedErrorPixels;
      in.Controller.Update(measuredMs / 1000, complete, same, frame.bounded);
    }
  }
}

void vtkMultiresolutionSurfaceMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ColorMode: " << this->ColorMode << "\n";
  os << indent << "PixelTolerance: " << this->PixelTolerance << "\n";
  os << indent << "TargetFrameRate: " << this->TargetFrameRate << "\n";
  os << indent << "MaximumPixelTolerance: " << this->MaximumPixelTolerance << "\n";
  os << indent << "MaximumEstimatedError: " << this->MaximumEstimatedError << "\n";
  os << indent << "MovingResolutionFloor: " << this->MovingResolutionFloor << "\n";
  os << indent << "MemoryBudgetMB: " << this->MemoryBudgetMB << "\n";
  os << indent << "GridLines: " << this->GridLines << "\n";
  os << indent << "WaitForDetailMs: " << this->WaitForDetailMs << "\n";
  os << indent << "Layer: " << this->Layer << "\n";
}
