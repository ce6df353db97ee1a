/**
 * @class   vtkMultiresolutionSurfaceMapper
 * @brief   Draws a .resmr file's surfaces at the detail the camera needs (paper Sec. 5, 6.2, 6.3).
 *
 * Each render selects region meshes from the exact camera (Lindstrom's projected error
 * against a pixel tolerance, frustum and normal-cone culling; resmr::ViewSelector), asks a
 * loader thread for what is missing (resmr::RegionCache, under a memory budget) and draws
 * what is resident, standing in an ancestor for any region not loaded yet, so the render
 * thread never waits on disk for detail (only for the roots, the first frame of a file or
 * layer, and for everything when WaitForDetailMs asks). Fragments find their original cell
 * from the topological coordinate and paint its property through the perfect-hash tables and
 * the lookup table, the original grid lines and the cell's face normal. With a target frame
 * rate the pixel tolerance follows the measured frame times (resmr::FrameRateController).
 * With Layer set, the same regions show one layer alone (Sec. 4.1, 5.2, 6.1), painted from
 * its 2D tables.
 *
 * The input is a copy of the descriptor vtkMultiresolutionReader writes (its bounds are the
 * model's) with a string field array (SourceArrayName) naming the .resmr file, the property
 * file and the step, added by vtkMultiresolutionSurfaceRepresentation. Opaque only.
 */
#ifndef vtkMultiresolutionSurfaceMapper_h
#define vtkMultiresolutionSurfaceMapper_h

#include "ResMRRepresentationsModule.h"
#include "vtkMapper.h"

#include <memory>
#include <string>

class vtkShaderProgram;
namespace resmr
{
class ValueFilterSet;
}

class RESMRREPRESENTATIONS_EXPORT vtkMultiresolutionSurfaceMapper : public vtkMapper
{
public:
  static vtkMultiresolutionSurfaceMapper* New();
  vtkTypeMacro(vtkMultiresolutionSurfaceMapper, vtkMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The input's field array naming the files and step: .resmr path, .resmrp path (or
  /// empty), step number (decimal), then "1" to place the model by the file's MAPAXES (as
  /// the descriptor is) or "0" (absent: "0").
  static const char* SourceArrayName() { return "ResMR Source"; }

  /// MaximumPixelTolerance's default (see docs/user-guide.md for the measurements behind it).
  static constexpr double DefaultMaximumPixelTolerance = 128.0;
  /// MaximumEstimatedError's default (see docs/user-guide.md for the measurements behind it).
  static constexpr double DefaultMaximumEstimatedError = 1.5;

  enum ColorModes
  {
    SolidColor = 0,
    PropertyColors = 1,
    CellIdColors = 2, ///< debug: RGB = 1 + i + nx (j + ny k), unlit, for image comparisons
    PickColors = 3    ///< internal: the pick pass's (i, j, k) as floats (not a user setting)
  };

  /// What paints the surface (ColorModes). Property colours need a property (ColorArrayName,
  /// vtkMapper's ArrayName) and fall back to the solid colour until its table is loaded.
  vtkSetClampMacro(ColorMode, int, SolidColor, CellIdColors);
  vtkGetMacro(ColorMode, int);

  /// Projected error tolerance in pixels (0: full detail): of every frame when no frame rate is
  /// targeted, of still frames (the camera stopped) when one is. Any tolerance the frame-rate
  /// controller chose (GetCurrentTolerance) is accepted, so a frame seen can be drawn again.
  vtkSetClampMacro(PixelTolerance, double, 0.0, 65536.0);
  vtkGetMacro(PixelTolerance, double);

  /// The backstop of the quality floor: the coarsest tolerance, in pixels, the frame-rate
  /// controller may use while the camera moves (never below PixelTolerance), whatever
  /// MaximumEstimatedError allows; a frame still too slow there is late rather than coarser.
  /// 65536 (with MaximumEstimatedError 0) lets the controller coarsen as far as it likes.
  vtkSetClampMacro(MaximumPixelTolerance, double, 0.5, 65536.0);
  vtkGetMacro(MaximumPixelTolerance, double);

  /// The quality floor on what the picture shows: the largest estimated error, in pixels, a
  /// moving frame may have (the regions' typical errors seen at their centres, see
  /// GetCurrentEstimatedError); the controller refines a frame past it whatever its time. 0:
  /// no such floor, MaximumPixelTolerance alone.
  vtkSetClampMacro(MaximumEstimatedError, double, 0.0, 65536.0);
  vtkGetMacro(MaximumEstimatedError, double);

  /// Frames per second to hold by adjusting the tolerance (Sec. 6.3); 0: fixed tolerance.
  vtkSetClampMacro(TargetFrameRate, double, 0.0, 1000.0);
  vtkGetMacro(TargetFrameRate, double);

  /// While the camera moves and frames miss TargetFrameRate, the surface is first drawn at a
  /// lower resolution, down to this fraction of the view's width and height, and only then
  /// coarsened; 1 keeps full resolution. Still frames are always drawn at full resolution.
  vtkSetClampMacro(MovingResolutionFloor, double, 0.1, 1.0);
  vtkGetMacro(MovingResolutionFloor, double);

  /// Memory budget of resident meshes, MB, CPU and GPU together: the loader keeps at most half
  /// in main memory and the GPU mirrors at most what is resident (the other half). The
  /// model's tables (hash, normals, one property) are outside it: a fixed cost per file.
  vtkSetClampMacro(MemoryBudgetMB, int, 16, 1 << 20);
  vtkGetMacro(MemoryBudgetMB, int);

  /// Original grid lines (Sec. 5.1) and their width in pixels.
  vtkSetMacro(GridLines, bool);
  vtkGetMacro(GridLines, bool);
  vtkSetClampMacro(GridLineWidth, double, 0.5, 16.0);
  vtkGetMacro(GridLineWidth, double);
  vtkSetVector3Macro(GridLineColor, double);
  vtkGetVector3Macro(GridLineColor, double);

  /// Single-layer view: 0 (the default) draws the whole model; K in 1..nk (ECLIPSE's K, from 1)
  /// draws layer K alone: its active cells' top and bottom faces and the side faces bounding
  /// them within the layer, from the same regions the whole model would use, painted from the
  /// layer's 2D property table. Any other value draws nothing and GetLastError() says why.
  vtkSetMacro(Layer, int);
  vtkGetMacro(Layer, int);

  /// Still renders wait (at most this many ms) until every mesh the view wants is loaded:
  /// batch scripts and screenshots; 0 (interactive use) never waits.
  vtkSetClampMacro(WaitForDetailMs, int, 0, 600000);
  vtkGetMacro(WaitForDetailMs, int);

  ///@{
  /// Live readout, updated each render.
  double GetCurrentTolerance() const;
  /// The last frame's estimated error, pixels: the largest typical error of a drawn region seen
  /// at its centre (what the bound, the tolerance, overstates); 0 for leaves alone.
  double GetCurrentEstimatedError() const;
  /// The fraction of the view's width and height the last frame was drawn at (1: full).
  double GetCurrentRenderScale() const;
  /// Whether the last frame was a moving frame at the frame-rate controller's tolerance (a
  /// still frame uses PixelTolerance).
  bool GetCurrentFrameControlled() const;
  /// Mesh memory now: main memory plus GPU buffers, MB (within MemoryBudgetMB, see there).
  double GetResidentMB() const;
  vtkIdType GetTrianglesDrawn() const;
  int GetRegionsDrawn() const;
  /// Regions drawn in place of wanted descendants not resident yet.
  int GetRegionsSubstituted() const;
  /// Milliseconds the last frame took (CPU selection and submission, plus GPU time when the
  /// driver reports it, of the frame before).
  double GetLastFrameMs() const;
  /// Whether meshes or tables the view wants are still loading.
  bool GetLoadsPending() const;
  /// How long a still view's refresh waits before the next frame while loads are pending
  /// (resmr::RefreshWaitMs: the last frame's time while the loaders read, 30 ms when only
  /// copies to the GPU remain).
  double GetRefreshWaitMs() const;
  ///@}

  /// Why the files could not be used, empty if they could.
  const char* GetLastError() const;

  ///@{
  /// Picking (ours): PickAt names the original cell whose colour shows at display pixel (x, y)
  /// (VTK's display coordinates: pixels from the render window's lower left corner; the pixel
  /// holding (x, y)) in the last frame drawn: its cut is drawn once more into one pixel
  /// (resmr::CellFromPickPixel), at once, with no new frame, so the answer is the cell painted
  /// there at whatever level was drawn; the files then give its corners (the finest level's),
  /// whether it is active and its values (resmr::CellInspection). Before any frame, the next
  /// render picks. A negative x asks for nothing.
  void PickAt(double x, double y);
  /// Describes cell (I, J, K) (from 1) the same way, with no pixel: the Picked* readouts then
  /// hold it, PickedPoint its centre. Any index below 1 asks for nothing.
  void InspectCell(int i, int j, int k);
  /// Picks and inspections answered so far: a script that sees it unchanged renders once.
  int GetPicksDone() const;
  /// Forgets the last frame (its renderer is going away): picks then wait for a render.
  void ForgetLastFrame();
  /// ECLIPSE's I, J, K (from 1) of the cell picked last; 0, 0, 0 when the pick hit nothing.
  const int* GetPickedCell() const;
  /// 1: the picked cell is active, 0: inactive, -1: unknown (nothing picked, or its column not
  /// found).
  int GetPickedActive() const;
  /// The world point the pick hit on the surface.
  const double* GetPickedPoint() const;
  /// The picked cell's eight corners, world coordinates, ECLIPSE's order (24 values; NaN when
  /// no leaf region holds its column, which then has no active cell).
  const double* GetPickedCorners() const;
  /// The picked cell's values at the descriptor's step, one "NAME=value" a line (static arrays
  /// first; "nan" where the cell has none); empty without a property file. An error reading the
  /// files is a line "error=...".
  const char* GetPickedValues() const;
  ///@}

  void Render(vtkRenderer* renderer, vtkActor* actor) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;
  double* GetBounds() override;
  void GetBounds(double bounds[6]) override { this->vtkMapper::GetBounds(bounds); }
  bool HasOpaqueGeometry() override { return true; }
  bool HasTranslucentPolygonalGeometry() override { return false; }

protected:
  vtkMultiresolutionSurfaceMapper();
  ~vtkMultiresolutionSurfaceMapper() override;
  int FillInputPortInformation(int port, vtkInformation* info) override;

private:
  vtkMultiresolutionSurfaceMapper(const vtkMultiresolutionSurfaceMapper&) = delete;
  void operator=(const vtkMultiresolutionSurfaceMapper&) = delete;

  int ColorMode = PropertyColors;
  double PixelTolerance = 1.0;
  double TargetFrameRate = 0.0;
  double MaximumPixelTolerance = DefaultMaximumPixelTolerance;
  double MaximumEstimatedError = DefaultMaximumEstimatedError;
  double MovingResolutionFloor = 0.5;
  int MemoryBudgetMB = 1024;
  bool GridLines = true;
  double GridLineWidth = 1.0;
  double GridLineColor[3] = { 0.1, 0.1, 0.1 };
  int WaitForDetailMs = 0;
  int Layer = 0;

  struct Internals;
  std::unique_ptr<Internals> Internal;

  /// One frame's state, passed from stage to stage of Render.
  struct Frame;
  void BeginFrame(Frame& frame);
  /// (Re)opens the files the descriptor names; false when there is nothing to draw.
  bool OpenFiles(Frame& frame);
  /// Closes the files with `message` as the error (reported once while it stays the same).
  void Fail(const Frame& frame, const std::string& message);
  /// The layer shown; false (nothing drawn, LastError says why) when out of range.
  bool SelectLayer(Frame& frame);
  /// The I/J/K range the descriptor names, if any (with Layer set, that layer of it); false
  /// (nothing drawn) when it holds no cell or cannot be read (LastError says why).
  bool SelectRange(Frame& frame);
  /// The descriptor's property filters, resolved against the property file (SelectRange).
  bool SelectFilters(Frame& frame);
  /// The selection's filter errors for `values` (none when null).
  void SetFilterErrors(Frame& frame, const std::shared_ptr<const resmr::ValueFilterSet>& values);
  /// What the descriptor names; false without a descriptor (an empty piece, no file yet).
  bool ReadSource(Frame& frame);
  void RequestProperty(Frame& frame);
  /// The camera in model coordinates, and the tolerance.
  void ComputeView(Frame& frame);
  void ChooseTolerance(bool moving);
  /// Selects, asks the loader for what is missing, and waits where the frame must.
  void SelectRegions(Frame& frame);
  vtkShaderProgram* ReadyProgram(Frame& frame, int colorMode, bool tableNormals = false);
  void StreamTables(Frame& frame);
  void UploadMeshes(Frame& frame);
  void SetUniforms(Frame& frame);
  void DrawRegions(Frame& frame);
  /// Draws the selected regions' faces of the kinds flagged (top, bottom, side) with the
  /// frame's program; the regions drawn.
  int DrawFaces(Frame& frame, const std::array<bool, 3>& kinds);
  /// Drawn regions showing their simplified side while their exact one loads.
  std::size_t SidesStandingIn(const Frame& frame) const;
  /// The GL state every pass of the surface draws with (depth test, culling, provoking
  /// vertex), and its undoing.
  void BeginDrawing(Frame& frame);
  void EndDrawing(Frame& frame);
  /// The pick PickAt asked for: the frame's cut drawn again into the picked pixel, then the
  /// cell read from the files.
  void PickCell(Frame& frame);
  /// PickCell on the last frame drawn, when there is one.
  void PickFromLastFrame();
  /// The Picked* readouts for `cell` (0-based), from the files; `near`: the model point picked.
  void DescribeCell(Frame& frame, const std::array<int64_t, 3>& cell, const std::array<double, 3>* near);
  /// Loads pending, errors, readout and the frame-rate controller.
  void FinishFrame(Frame& frame);
};

#endif
