#include "vtkMultiresolutionSurfaceMapper.h"

#include "CornerPointGeometry.h"
#include "FrameRateController.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "RegionCache.h"
#include "UploadPacer.h"
#include "ViewSelection.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLCamera.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLBufferObject.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkOpenGLVertexArrayObject.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkScalarsToColors.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include "MultiresolutionSurfaceFS.h"
#include "MultiresolutionSurfaceVS.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

vtkStandardNewMacro(vtkMultiresolutionSurfaceMapper);

namespace
{
using Matrix = std::array<double, 16>; // row-major

Matrix Multiply(const Matrix& a, const Matrix& b)
{
  Matrix c{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      for (int k = 0; k < 4; ++k)
      {
        c[4 * i + j] += a[4 * i + k] * b[4 * k + j];
      }
    }
  }
  return c;
}

/// VTK's OpenGL key matrices are stored transposed (ready for column-major upload).
Matrix FromTransposed(vtkMatrix4x4* m)
{
  Matrix r{};
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      r[4 * i + j] = m->GetElement(j, i);
    }
  }
  return r;
}

Matrix FromRowMajor(vtkMatrix4x4* m)
{
  Matrix r{};
  for (int i = 0; i < 16; ++i)
  {
    r[i] = m->GetElement(i / 4, i % 4);
  }
  return r;
}

void ColumnMajor(const Matrix& m, float out[16])
{
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      out[4 * j + i] = static_cast<float>(m[4 * i + j]);
    }
  }
}

/// Most bytes of one GPU piece of a region's mesh (the vertices its triangles use and their
/// indices). A leaf region's mesh reaches 17-26 MB on the 100M-cell model, and llvmpipe in a
/// VM allocates fresh buffer storage at about 4.4 ms a MB: copied whole, one mesh held a
/// frame 60-110 ms past its budget. In pieces, the upload pacer admits a frame's copies a
/// piece at a time, and a region is drawn once all its pieces are on the GPU.
constexpr std::size_t PieceBytes = std::size_t(1) << 20;

/// Triangles [first, first + count) of a region's indices, with the vertices they use
/// (vertex numbers rebased to the piece's first), in GL buffers of their own.
struct GpuPiece
{
  vtkNew<vtkOpenGLBufferObject> vertices;
  vtkNew<vtkOpenGLBufferObject> indices;
  vtkNew<vtkOpenGLVertexArrayObject> layout;
  uint32_t first = 0, count = 0;

  void Release()
  {
    this->layout->ReleaseGraphicsResources();
    this->vertices->ReleaseGraphicsResources();
    this->indices->ReleaseGraphicsResources();
  }
};

/// A region's draw buffers on their way to the GPU, a piece at a time.
struct GpuRegion
{
  explicit GpuRegion(std::shared_ptr<const resmr::RegionDrawBuffers> drawBuffers)
    : buffers(std::move(drawBuffers))
  {
  }

  std::shared_ptr<const resmr::RegionDrawBuffers> buffers;
  std::vector<std::unique_ptr<GpuPiece>> pieces;
  std::size_t bytes = 0; ///< copied so far

  bool Ready() const { return this->Copied >= this->buffers->indices.size(); }

  /// Bytes the next piece will copy.
  std::size_t NextPieceBytes()
  {
    this->Measure();
    return this->Next.bytes;
  }

  /// Copies the next piece; the bytes copied. The vertices go straight from the region's
  /// buffer; the indices, rebased to the piece's first vertex, through `scratch`, which the
  /// caller keeps from piece to piece: a fresh megabyte costs this VM about 0.6 ms in page
  /// faults, forty times what rewriting touched memory does.
  std::size_t UploadNextPiece(vtkShaderProgram* program, std::vector<uint32_t>& scratch)
  {
    this->Measure();
    const std::vector<float>& vertices = this->buffers->vertices;
    const std::vector<uint32_t>& indices = this->buffers->indices;
    auto piece = std::make_unique<GpuPiece>();
    piece->first = static_cast<uint32_t>(this->Next.first);
    piece->count = static_cast<uint32_t>(this->Next.end - this->Next.first);
    scratch.assign(indices.begin() + this->Next.first, indices.begin() + this->Next.end);
    for (uint32_t& index : scratch)
    {
      index -= this->Next.lowVertex;
    }
    piece->layout->Bind();
    piece->vertices->Upload(vertices.data() + std::size_t(this->Next.lowVertex) * 6,
      (std::size_t(this->Next.highVertex) - this->Next.lowVertex + 1) * 6, vtkOpenGLBufferObject::ArrayBuffer);
    piece->indices->Upload(scratch, vtkOpenGLBufferObject::ElementArrayBuffer);
    piece->layout->AddAttributeArray(program, piece->vertices, "vertexPosition", 0, 24, VTK_FLOAT, 3, false);
    piece->layout->AddAttributeArray(program, piece->vertices, "cellCoordinate", 12, 24, VTK_FLOAT, 3, false);
    piece->layout->Release();
    this->pieces.push_back(std::move(piece));
    this->bytes += this->Next.bytes;
    this->Copied = this->Next.end;
    return this->Next.bytes;
  }

  /// Copies whatever is left (a region drawn before the pacer let it finish).
  void UploadRest(vtkShaderProgram* program, std::vector<uint32_t>& scratch)
  {
    while (!this->Ready())
    {
      this->UploadNextPiece(program, scratch);
    }
  }

  void Release()
  {
    for (auto& piece : this->pieces)
    {
      piece->Release();
    }
  }

private:
  /// The next piece (resmr::NextDrawPiece), measured once.
  void Measure()
  {
    if (!this->Ready() && this->Next.first != this->Copied)
    {
      this->Next = resmr::NextDrawPiece(*this->buffers, this->Copied, PieceBytes);
    }
  }

  std::size_t Copied = 0; ///< indices copied so far
  resmr::DrawPiece Next{ ~std::size_t(0) };
};

bool ReadyOnGpu(const std::map<std::size_t, std::unique_ptr<GpuRegion>>& gpu, std::size_t region)
{
  const auto found = gpu.find(region);
  return found != gpu.end() && found->second->Ready();
}

/// A 3D table texture filled a slab of z-slices at a time (glTexSubImage3D) into a texture of
/// its own, which replaces the one drawn only once complete: copied in one call, a 300M-cell
/// model's tables (hundreds of MB) stalled a frame for about a second on llvmpipe.
class SlabUpload
{
public:
  /// Allocates the texture, or copies over `spare` (a texture of these sides and format no
  /// longer drawn), and takes the table (x fastest, then y, then z); `owner` keeps the table
  /// alive until the copy ends. Allocating is most of the cost under llvmpipe, which zeroes
  /// new storage (about 2 ms a MB, 0.4 s for 209 MB; copying the same takes 0.1 s), so a
  /// property's tables are copied turn about into two textures. True if it allocated.
  bool Start(vtkOpenGLRenderWindow* window, const std::array<uint32_t, 3>& sides, int components, int vtkType,
    unsigned int internalFormat, unsigned int format, unsigned int type, std::size_t texelBytes, const void* data,
    std::shared_ptr<const void> owner, vtkSmartPointer<vtkTextureObject> spare = nullptr)
  {
    this->Sides = sides;
    this->Format = format;
    this->Type = type;
    this->SliceBytes = std::size_t(sides[0]) * sides[1] * texelBytes;
    this->Data = static_cast<const unsigned char*>(data);
    this->Keeper = std::move(owner);
    this->NextSlice = 0;
    if (spare && spare->GetHandle() != 0 && Fits(spare, sides))
    {
      this->Texture = spare;
      return false;
    }
    this->Texture = vtkSmartPointer<vtkTextureObject>::New();
    this->Texture->SetContext(window);
    this->Texture->ResetFormatAndType();
    if (internalFormat != 0)
    {
      this->Texture->SetInternalFormat(internalFormat);
    }
    this->Texture->SetFormat(format);
    this->Texture->SetDataType(type);
    this->Texture->SetMinificationFilter(vtkTextureObject::Nearest);
    this->Texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    this->Texture->Create3DFromRaw(sides[0], sides[1], sides[2], components, vtkType, nullptr); // storage only
    return true;
  }

  /// Whether `texture` has these sides (and so can take a table of them).
  static bool Fits(vtkTextureObject* texture, const std::array<uint32_t, 3>& sides)
  {
    return texture && texture->GetWidth() == sides[0] && texture->GetHeight() == sides[1] &&
      texture->GetDepth() == sides[2];
  }

  bool Busy() const { return this->Texture != nullptr; }
  /// The table being copied (null when idle).
  const void* Source() const { return this->Keeper.get(); }

  /// Copies whole slices while `budget` (bytes, spent here) lasts, at least one if any budget
  /// is left, or all of them when `unbounded`. True when the texture is complete.
  bool Continue(vtkOpenGLState* state, std::size_t& budget, bool unbounded)
  {
    const uint32_t left = this->Sides[2] - this->NextSlice;
    if (left == 0 || (!unbounded && budget == 0))
    {
      return left == 0;
    }
    uint32_t slices = left;
    if (!unbounded && this->SliceBytes > 0)
    {
      slices = static_cast<uint32_t>(std::min<std::size_t>(std::max<std::size_t>(budget / this->SliceBytes, 1), left));
    }
    {
      state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      this->Texture->Activate();
      glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, static_cast<GLint>(this->NextSlice), static_cast<GLsizei>(this->Sides[0]),
        static_cast<GLsizei>(this->Sides[1]), static_cast<GLsizei>(slices), this->Format, this->Type,
        this->Data + this->NextSlice * this->SliceBytes);
      this->Texture->Deactivate();
      this->NextSlice += slices;
      budget -= std::min(budget, slices * this->SliceBytes);
    }
    return this->NextSlice == this->Sides[2];
  }

  /// The complete texture (the upload is then idle).
  vtkSmartPointer<vtkTextureObject> Take()
  {
    return this->Cancel();
  }

  /// Stops the copy; returns the texture (partly filled) for reuse as a spare.
  vtkSmartPointer<vtkTextureObject> Cancel()
  {
    vtkSmartPointer<vtkTextureObject> texture = this->Texture;
    this->Texture = nullptr;
    this->Keeper.reset();
    this->Data = nullptr;
    return texture;
  }

  /// Stops the copy and frees its texture.
  void Release(vtkWindow* window)
  {
    if (this->Texture && window)
    {
      this->Texture->ReleaseGraphicsResources(window);
    }
    this->Cancel();
  }

private:
  vtkSmartPointer<vtkTextureObject> Texture;
  std::array<uint32_t, 3> Sides{};
  unsigned int Format = 0, Type = 0;
  std::size_t SliceBytes = 0;
  const unsigned char* Data = nullptr;
  std::shared_ptr<const void> Keeper;
  uint32_t NextSlice = 0;
};
} // namespace

struct vtkMultiresolutionSurfaceMapper::Internals
{
  // Files (reopened when the descriptor names others).
  std::string FilePath, PropertyPath, PropertyStamp;
  int32_t Step = 0;
  std::shared_ptr<const resmr::MultiresolutionFile> File;
  std::shared_ptr<const resmr::PropertyFile> Properties;
  std::unique_ptr<resmr::ViewSelector> Selector;
  std::unique_ptr<resmr::RegionCache> Cache;
  std::string Error;
  std::string LayerError; ///< why Layer cannot be drawn, empty if it can
  std::string Reported; ///< the last error sent to vtkErrorMacro (each failure once)
  double Bounds[6] = { 0, 0, 0, 0, 0, 0 };

  // GPU side.
  std::map<std::size_t, std::unique_ptr<GpuRegion>> Gpu;
  std::size_t GpuBytes = 0;
  std::vector<uint32_t> IndexScratch; ///< a piece's rebased indices (see GpuRegion::UploadNextPiece)
  vtkSmartPointer<vtkTextureObject> OffsetTexture = vtkSmartPointer<vtkTextureObject>::New();
  vtkSmartPointer<vtkTextureObject> NormalTexture = vtkSmartPointer<vtkTextureObject>::New();
  vtkSmartPointer<vtkTextureObject> PropertyTexture = vtkSmartPointer<vtkTextureObject>::New();
  vtkNew<vtkTextureObject> ColorTexture;
  vtkNew<vtkTextureObject> LayerPropertyTexture; ///< nx x ny R32F: one layer's table
  bool HashUploaded = false;
  std::shared_ptr<const resmr::PropertyTableData> UploadedProperty;
  // Tables being copied a slab a frame (see SlabUpload).
  SlabUpload OffsetUpload, NormalUpload, PropertyUpload;
  /// The property texture drawn before the current one, copied over by the next table.
  vtkSmartPointer<vtkTextureObject> SparePropertyTexture;
  vtkMTimeType ColorTableTime = 0;
  vtkScalarsToColors* ColorTable = nullptr;
  double ColorRange[2] = { 0, 1 };
  vtkOpenGLRenderWindow* Window = nullptr;
  /// Fragment shader sources by variant (FragmentVariant's switches as bits).
  std::map<int, std::string> FragmentSources;
  unsigned int TimerQuery = 0;
  bool TimerPending = false;
  double GpuMs = 0;

  // View state and readout.
  resmr::FrameRateController Controller;
  bool ControllerRunning = false; ///< holding a frame rate since the file opened
  bool UploadsDeferred = false;   ///< loaded meshes wait for the next frame's upload
  resmr::UploadPacer Pacer;       ///< predicts what mesh copies cost (fresh GPU memory is slow)
  bool Allocated = false;         ///< the frame allocated a table texture (see SlabUpload)
  bool HavePreviousView = false;
  resmr::ViewParameters PreviousView;
  double Tolerance = 1;
  vtkIdType Triangles = 0;
  int Drawn = 0, Substituted = 0;
  double FrameMs = 0;
  bool Pending = false;
  std::chrono::steady_clock::time_point FrameStart;
  bool HaveFrameStart = false;

  void Close()
  {
    this->ControllerRunning = false;
    this->Cache.reset();
    this->Selector.reset();
    this->Properties.reset();
    this->File.reset();
    this->FilePath.clear();
    this->PropertyPath.clear();
    this->PropertyStamp.clear();
    this->HashUploaded = false;
    this->UploadedProperty.reset();
    this->CancelUploads();
  }

  void CancelUploads()
  {
    this->OffsetUpload.Release(this->Window);
    this->NormalUpload.Release(this->Window);
    this->PropertyUpload.Release(this->Window);
    if (this->SparePropertyTexture && this->Window)
    {
      this->SparePropertyTexture->ReleaseGraphicsResources(this->Window);
    }
    this->SparePropertyTexture = nullptr;
  }

  void ReleaseGpu()
  {
    for (auto& entry : this->Gpu)
    {
      entry.second->Release();
    }
    this->Gpu.clear();
    this->GpuBytes = 0;
    this->HashUploaded = false;
    this->UploadedProperty.reset();
    this->CancelUploads();
    this->ColorTableTime = 0;
  }
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
double vtkMultiresolutionSurfaceMapper::GetResidentMB() const
{
  const std::size_t bytes = this->Internal->Cache ? this->Internal->Cache->ResidentBytes() : 0;
  return double(bytes + this->Internal->GpuBytes) / (1 << 20);
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
  in.ReleaseGpu();
  in.OffsetTexture->ReleaseGraphicsResources(window);
  in.NormalTexture->ReleaseGraphicsResources(window);
  in.PropertyTexture->ReleaseGraphicsResources(window);
  in.LayerPropertyTexture->ReleaseGraphicsResources(window);
  in.ColorTexture->ReleaseGraphicsResources(window);
  if (in.TimerQuery != 0)
  {
    glDeleteQueries(1, &in.TimerQuery);
    in.TimerQuery = 0;
    in.TimerPending = false;
  }
  in.Window = nullptr;
  this->Modified();
}

namespace
{
/// (.resmr path, .resmrp path, step, map axes) from the descriptor; false if it has none.
bool ReadSource(vtkDataObject* input, std::string& file, std::string& properties, int32_t& step, bool& mapAxes,
  std::string& propertiesStamp)
{
  vtkFieldData* fields = input ? input->GetFieldData() : nullptr;
  vtkStringArray* source =
    fields ? vtkStringArray::SafeDownCast(fields->GetAbstractArray(vtkMultiresolutionSurfaceMapper::SourceArrayName()))
           : nullptr;
  if (!source || source->GetNumberOfValues() < 3)
  {
    return false;
  }
  file = source->GetValue(0);
  properties = source->GetValue(1);
  step = static_cast<int32_t>(std::stol(source->GetValue(2)));
  mapAxes = source->GetNumberOfValues() > 3 && source->GetValue(3) == "1";
  propertiesStamp = source->GetNumberOfValues() > 4 ? source->GetValue(4) : std::string();
  return true;
}

/// Most bytes copied to the GPU in one interactive frame (see Render), and the part of it the
/// model's tables may take while they are being copied.
constexpr std::size_t UploadBytesPerFrame = std::size_t(8) << 20;
constexpr std::size_t TableBytesPerFrame = std::size_t(4) << 20;
/// The time an interactive frame may spend copying meshes (see resmr::UploadPacer): a tenth of
/// the target frame time, or this many milliseconds at a fixed tolerance.
constexpr double UploadShareOfFrame = 0.1;
constexpr double UploadMsAtFixedTolerance = 10.0;

/// Tolerance (pixels) the frame-rate controller starts from. From 8 px the first detail of the
/// 10M and 100M models arrived faster than the controller backed off: 4-6 frames of 100-170 ms
/// in the first 150 of a path; from 64 px, 2. Reek and Brugge still reach 0.5 px within 25
/// frames, and 10M and 100M hold 20-500 px later on anyway.
constexpr double ControllerStartPixels = 64.0;

/// Projected error (pixels) past which a region's simplified side replaces its exact one.
constexpr double CoarseSidePixels = 2.0;

/// The loader's share of the mesh budget: the GPU mirrors at most what is resident, so half
/// each keeps both together within the budget.
std::size_t MainMemoryShare(int budgetMB)
{
  return (std::size_t(budgetMB) << 20) / 2;
}

/// The fragment shader's source for one painting state (see MultiresolutionSurfaceFS.glsl):
/// the variant's switches defined after the version line VTK puts in.
std::string FragmentVariant(int colorMode, bool layerView, bool logScale, bool gridLines, bool specular)
{
  const std::string source = MultiresolutionSurfaceFS;
  const std::string versionLine = "//VTK::System::Dec\n";
  const std::size_t at = source.find(versionLine);
  std::string defines = "#define COLOR_MODE " + std::to_string(colorMode) + "\n#define LAYER_VIEW " +
    std::to_string(layerView ? 1 : 0) + "\n#define LOG_SCALE " + std::to_string(logScale ? 1 : 0) +
    "\n#define GRID_LINES " + std::to_string(gridLines ? 1 : 0) + "\n#define SPECULAR " +
    std::to_string(specular ? 1 : 0) + "\n";
  return at == std::string::npos ? source : source.substr(0, at + versionLine.size()) + defines + source.substr(at + versionLine.size());
}

void UploadInteger3D(vtkTextureObject* texture, vtkOpenGLRenderWindow* window, const std::array<uint32_t, 3>& sides,
  int components, unsigned int internalFormat, unsigned int format, const void* data)
{
  texture->SetContext(window);
  texture->ResetFormatAndType();
  texture->SetInternalFormat(internalFormat);
  texture->SetFormat(format);
  texture->SetDataType(GL_UNSIGNED_SHORT);
  texture->SetMinificationFilter(vtkTextureObject::Nearest);
  texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  texture->Create3DFromRaw(sides[0], sides[1], sides[2], components, VTK_UNSIGNED_SHORT, const_cast<void*>(data));
}
} // namespace

void vtkMultiresolutionSurfaceMapper::Render(vtkRenderer* renderer, vtkActor* actor)
{
  Internals& in = *this->Internal;
  const auto start = std::chrono::steady_clock::now();
  // The whole frame is what the user waits for: the renderer's time for the last frame, and
  // while frames come back to back (interaction, a fly-through) the interval between them,
  // which also holds compositing, buffer swaps and ParaView's own work.
  const double rendererMs = renderer->GetLastRenderTimeInSeconds() * 1000;
  const double intervalMs =
    in.HaveFrameStart ? std::chrono::duration<double, std::milli>(start - in.FrameStart).count() : 0;
  in.FrameStart = start;
  in.HaveFrameStart = true;
  // The renderer's time and the interval both still hold the last frame.
  const bool afterAllocation = in.Allocated;
  in.Allocated = false;
  in.Triangles = 0;
  in.Drawn = 0;
  in.Substituted = 0;
  if (renderer->GetSelector())
  {
    return; // hardware picking: the descriptor has no cells to name
  }
  vtkDataObject* input = this->GetInputDataObject(0, 0);
  std::string filePath, propertyPath, propertyStamp;
  int32_t step = 0;
  bool applyMapAxes = false;
  if (!ReadSource(input, filePath, propertyPath, step, applyMapAxes, propertyStamp))
  {
    return; // an empty piece (another rank) or no file yet
  }

  // A file that cannot be drawn is closed, with its error (reported once while it stays the
  // same); the next frame tries again, so a mended file draws.
  const auto fail = [&](const std::string& message) {
    in.Close();
    in.FilePath = filePath;
    in.PropertyPath = propertyPath;
    in.PropertyStamp = propertyStamp;
    in.Error = message;
    if (message != in.Reported)
    {
      in.Reported = message;
      vtkErrorMacro(<< message);
    }
  };

  // (Re)open the files when the descriptor names others, or the property file was rewritten
  // (steps added to a run still being written).
  if (filePath != in.FilePath || propertyPath != in.PropertyPath || propertyStamp != in.PropertyStamp || !in.Cache)
  {
    in.Close();
    in.ReleaseGpu();
    in.Error.clear();
    try
    {
      in.File = std::make_shared<const resmr::MultiresolutionFile>(filePath);
      if (!propertyPath.empty())
      {
        auto properties = std::make_shared<const resmr::PropertyFile>(propertyPath);
        properties->CheckGeometry(*in.File);
        in.Properties = properties;
      }
      in.Selector.reset(new resmr::ViewSelector(*in.File));
      in.Cache.reset(new resmr::RegionCache(in.File, in.Properties, MainMemoryShare(this->MemoryBudgetMB)));
      in.FilePath = filePath;
      in.PropertyPath = propertyPath;
      in.PropertyStamp = propertyStamp;
      in.Reported.clear();
    }
    catch (const std::exception& error)
    {
      fail(error.what());
      return;
    }
  }
  if (!in.Cache)
  {
    return;
  }
  resmr::RegionCache& cache = *in.Cache;
  cache.SetBudget(MainMemoryShare(this->MemoryBudgetMB));
  const resmr::MultiresolutionHeader& header = in.File->Header();

  // The layer shown (0-based; -1 the whole model). Out of range: nothing is drawn, and
  // LastError says why, rather than a layer the user did not ask for.
  if (this->Layer < 0 || this->Layer > header.dims[2])
  {
    const std::string message = "Layer " + std::to_string(this->Layer) + " is out of range: " + in.FilePath +
      " has " + std::to_string(header.dims[2]) + " layers (1 to " + std::to_string(header.dims[2]) +
      "; 0 draws the whole model)";
    if (message != in.LayerError)
    {
      vtkWarningMacro(<< message);
      in.LayerError = message;
    }
    in.Pending = false;
    return;
  }
  in.LayerError.clear();
  const int32_t layer = this->Layer - 1;
  cache.SetLayer(layer);

  // Property table wanted this frame.
  // (a static property has one table, step -1, for every step)
  int32_t tableStep = step;
  bool wantProperty = false;
  if (this->ColorMode == PropertyColors && in.Properties && this->ArrayName && *this->ArrayName)
  {
    tableStep = in.Properties->Find(this->ArrayName, step) >= 0 ? step : -1;
    wantProperty = in.Properties->Find(this->ArrayName, tableStep) >= 0;
  }
  if (wantProperty)
  {
    cache.RequestProperty(this->ArrayName, tableStep, layer);
  }

  // The view, in model coordinates (the actor's matrix and MAPAXES folded into the projection,
  // in double: map coordinates are large).
  Matrix mapAxes{ 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  std::array<double, 6> map;
  if (applyMapAxes && resmr::CornerPointGeometry::PlacementTransform(header.map, map))
  {
    mapAxes = { map[2], map[4], 0, map[0], map[3], map[5], 0, map[1], 0, 0, 1, 0, 0, 0, 0, 1 };
  }
  vtkOpenGLRenderWindow* window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (in.Window != window)
  {
    in.ReleaseGpu();
    in.Window = window;
  }
  vtkOpenGLCamera* camera = vtkOpenGLCamera::SafeDownCast(renderer->GetActiveCamera());
  vtkMatrix4x4 *worldToView, *worldToClip;
  vtkMatrix3x3* normalMatrix;
  vtkMatrix4x4* viewToClip;
  camera->GetKeyMatrices(renderer, worldToView, normalMatrix, viewToClip, worldToClip);
  vtkNew<vtkMatrix4x4> actorMatrix;
  actor->GetMatrix(actorMatrix);
  const Matrix modelToWorld = Multiply(FromRowMajor(actorMatrix), mapAxes);
  const Matrix modelToClip = Multiply(FromTransposed(worldToClip), modelToWorld);
  const Matrix modelToView = Multiply(FromTransposed(worldToView), modelToWorld);
  int width = 0, height = 0, x0 = 0, y0 = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  resmr::ViewParameters view;
  view.worldToClip = modelToClip;
  {
    vtkNew<vtkMatrix4x4> inverse;
    inverse->DeepCopy(modelToWorld.data());
    inverse->Invert();
    double eye[4] = { 0, 0, 0, 1 }, position[4];
    camera->GetPosition(eye);
    inverse->MultiplyPoint(eye, position);
    view.eye = { position[0], position[1], position[2] };
    double direction[4] = { 0, 0, 0, 0 }, modelDirection[4];
    camera->GetDirectionOfProjection(direction);
    inverse->MultiplyPoint(direction, modelDirection);
    view.nearDistance = camera->GetClippingRange()[0] * vtkMath::Norm(modelDirection); // in model units
    vtkMath::Normalize(modelDirection);
    view.direction = { modelDirection[0], modelDirection[1], modelDirection[2] };
  }
  view.parallel = camera->GetParallelProjection() != 0;
  view.pixelsPerUnit = view.parallel
    ? height / (2.0 * std::max(camera->GetParallelScale(), 1e-30))
    : height / (2.0 * std::tan(vtkMath::RadiansFromDegrees(camera->GetViewAngle()) / 2));
  if (this->TargetFrameRate > 0)
  {
    if (!in.ControllerRunning)
    {
      // Start coarse and refine a step a frame: starting fine, the first frames after the
      // roots would draw whatever detail has loaded before the controller can catch up.
      in.Controller.Reset(std::max(this->PixelTolerance, ControllerStartPixels));
      in.ControllerRunning = true;
    }
    in.Controller.SetTargetFramesPerSecond(this->TargetFrameRate);
    in.Tolerance = in.Controller.Tolerance();
  }
  else
  {
    in.Tolerance = this->PixelTolerance;
    in.Controller.Reset(std::max(this->PixelTolerance, 1.0));
    in.ControllerRunning = false;
  }
  view.tolerancePixels = in.Tolerance;

  // Select, ask for what is missing (and what the next frame will probably want), and for
  // still renders wait until the wanted set is resident.
  const auto resident = [&cache](std::size_t region) { return cache.IsResident(region); };
  resmr::ViewSelection selection = in.Selector->Select(view, resident);
  std::vector<std::size_t> predicted;
  if (in.HavePreviousView)
  {
    const auto all = [](std::size_t) { return true; };
    predicted = in.Selector->Select(resmr::PredictNextView(in.PreviousView, view), all).wanted;
  }
  cache.Request(selection.wanted, predicted);
  // The roots are the stand-in of last resort: the first frame waits for them (they are the
  // smallest meshes and load first), so no frame shows a hole where the model is.
  {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    const auto missingRoot = [&]() {
      for (std::size_t root : in.Selector->Roots())
      {
        if (!cache.IsResident(root) && cache.LastError().empty())
        {
          return true;
        }
      }
      return false;
    };
    if (missingRoot())
    {
      while (missingRoot() && std::chrono::steady_clock::now() < deadline)
      {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      selection = in.Selector->Select(view, resident);
    }
  }
  if (this->WaitForDetailMs > 0)
  {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(this->WaitForDetailMs);
    while (cache.Pending() && std::chrono::steady_clock::now() < deadline)
    {
      cache.WaitIdle(std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()));
      selection = in.Selector->Select(view, resident);
      cache.Request(selection.wanted, predicted);
    }
  }
  in.PreviousView = view;
  in.HavePreviousView = true;

  // GPU buffers follow the cache: drop what it evicted (or what another layer replaced),
  // upload what is drawn. The loader thread evicts while a frame runs, so the uploads below
  // sweep again before passing the GPU's share of the budget.
  const auto releaseEvicted = [&in, &cache]() {
    for (auto entry = in.Gpu.begin(); entry != in.Gpu.end();)
    {
      if (cache.Get(entry->first) != entry->second->buffers)
      {
        in.GpuBytes -= entry->second->bytes;
        entry->second->Release();
        entry = in.Gpu.erase(entry);
      }
      else
      {
        ++entry;
      }
    }
  };
  releaseEvicted();

  vtkOpenGLState* state = window->GetState();
  // The painting this frame, and the fragment shader compiled for it (a variant a state: see
  // the shader). The meshes' vertex layouts are bound against the property variant, which
  // reads both attributes (a variant that does not read the cell coordinate drops it when
  // linking), at the locations every variant shares; the frame's own variant draws.
  vtkScalarsToColors* table = this->GetLookupTable();
  vtkProperty* look = actor->GetProperty();
  const auto paintingMode = [&](bool hashReady, bool haveProperty) {
    return this->ColorMode == PropertyColors && (!haveProperty || !hashReady) ? SolidColor : this->ColorMode;
  };
  const auto readyProgram = [&](int colorMode) -> vtkShaderProgram* {
    const bool logScale = colorMode == PropertyColors && table && table->UsingLogScale() != 0;
    const bool gridLines = this->GridLines && colorMode != CellIdColors;
    const bool specular = look->GetLighting() && look->GetSpecular() > 0;
    const int key = colorMode | (layer >= 0 ? 4 : 0) | (logScale ? 8 : 0) | (gridLines ? 16 : 0) | (specular ? 32 : 0);
    auto found = in.FragmentSources.find(key);
    if (found == in.FragmentSources.end())
    {
      found = in.FragmentSources.emplace(key, FragmentVariant(colorMode, layer >= 0, logScale, gridLines, specular)).first;
    }
    vtkShaderProgram* ready =
      window->GetShaderCache()->ReadyShaderProgram(MultiresolutionSurfaceVS, found->second.c_str(), "");
    if (!ready && in.Error.empty())
    {
      in.Error = "the multiresolution surface shaders did not compile (see the output window)";
      vtkErrorMacro(<< in.Error);
    }
    return ready;
  };
  vtkShaderProgram* program = readyProgram(PropertyColors);
  if (!program)
  {
    return;
  }
  // Uploads, a bounded amount a frame while interacting (the roots and still renders whatever
  // it takes): a burst of loaded meshes copied in one frame stalled it (76 MB took 100 ms on
  // llvmpipe). The bound is in bytes and in predicted time, since fresh GPU memory costs
  // fifty times what reused memory does. The frame then draws what is on the GPU, ancestors
  // standing in for the rest. The model's tables go first, a few slabs a frame, so meshes and
  // tables both progress.
  const bool bounded = this->WaitForDetailMs == 0;
  std::size_t tableBudget = TableBytesPerFrame;
  const auto tablesStart = std::chrono::steady_clock::now();

  // Model tables: the hash's offsets and the cells' normals (once a file, when the loader has
  // read them), the property table when another is current, the colour map when the lookup
  // table changes. Until the hash is in, the whole model is drawn in the solid colour, lit by
  // facet normals, with 1-texel stand-ins for the samplers.
  if (in.OffsetTexture->GetHandle() == 0)
  {
    state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    const std::array<uint32_t, 3> one{ 1, 1, 1 };
    const uint16_t zeros[3] = { 0, 0, 0 };
    UploadInteger3D(in.OffsetTexture, window, one, 3, GL_RGB16UI, GL_RGB_INTEGER, zeros);
    UploadInteger3D(in.NormalTexture, window, one, 2, GL_RG16UI, GL_RG_INTEGER, zeros);
  }
  if (!in.HashUploaded)
  {
    const std::shared_ptr<const resmr::ModelTables> tables = cache.Tables();
    if (tables && !in.OffsetUpload.Busy() && !in.NormalUpload.Busy())
    {
      const resmr::PerfectSpatialHash& hash = tables->hash;
      in.Allocated = true;
      in.OffsetUpload.Start(window, hash.offsetSides, 3, VTK_UNSIGNED_SHORT, GL_RGB16UI, GL_RGB_INTEGER,
        GL_UNSIGNED_SHORT, 6, hash.offsets.data(), tables);
      if (tables->normals.size() == hash.TableSize() * 4)
      {
        in.NormalUpload.Start(window, hash.tableSides, 2, VTK_UNSIGNED_SHORT, GL_RG16UI, GL_RG_INTEGER,
          GL_UNSIGNED_SHORT, 4, tables->normals.data(), tables);
      }
      else
      {
        auto up = std::make_shared<std::vector<uint16_t>>(hash.TableSize() * 2, 0); // code 0 is +z
        in.NormalUpload.Start(window, hash.tableSides, 2, VTK_UNSIGNED_SHORT, GL_RG16UI, GL_RG_INTEGER,
          GL_UNSIGNED_SHORT, 4, up->data(), up);
      }
    }
    if (in.OffsetUpload.Busy() && in.OffsetUpload.Continue(state, tableBudget, !bounded) &&
      in.NormalUpload.Continue(state, tableBudget, !bounded))
    {
      in.OffsetTexture->ReleaseGraphicsResources(window);
      in.NormalTexture->ReleaseGraphicsResources(window);
      in.OffsetTexture = in.OffsetUpload.Take();
      in.NormalTexture = in.NormalUpload.Take();
      in.HashUploaded = true;
    }
  }
  if (in.PropertyTexture->GetHandle() == 0)
  {
    // Until a property loads, every sampler still needs a texture of its type.
    float none = std::numeric_limits<float>::quiet_NaN();
    in.PropertyTexture->SetContext(window);
    in.PropertyTexture->Create3DFromRaw(1, 1, 1, 1, VTK_FLOAT, &none);
    in.LayerPropertyTexture->SetContext(window);
    in.LayerPropertyTexture->Create2DFromRaw(1, 1, 1, VTK_FLOAT, &none);
    unsigned char white[4] = { 255, 255, 255, 255 };
    in.ColorTexture->SetContext(window);
    in.ColorTexture->Create2DFromRaw(1, 1, 4, VTK_UNSIGNED_CHAR, white);
  }
  std::shared_ptr<const resmr::PropertyTableData> loaded = wantProperty ? cache.Property() : nullptr;
  if (loaded && (loaded->name != this->ArrayName || loaded->step != tableStep || loaded->layer != layer))
  {
    loaded.reset(); // still the previous property
  }
  if (!loaded || loaded->layer >= 0 || in.PropertyUpload.Source() != loaded.get())
  {
    // Another table is wanted now: its copy goes over this one's texture.
    vtkSmartPointer<vtkTextureObject> partial = in.PropertyUpload.Cancel();
    if (partial)
    {
      if (in.SparePropertyTexture && in.SparePropertyTexture != partial)
      {
        in.SparePropertyTexture->ReleaseGraphicsResources(window);
      }
      in.SparePropertyTexture = partial;
    }
  }
  if (loaded && loaded != in.UploadedProperty && loaded->layer >= 0)
  {
    // A layer's table is a 2D texture of nx x ny, indexed by (i, j): no hash (Sec. 5.4); at
    // most a few MB, copied at once.
    state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    in.LayerPropertyTexture->SetContext(window);
    in.LayerPropertyTexture->ResetFormatAndType();
    in.LayerPropertyTexture->SetMinificationFilter(vtkTextureObject::Nearest);
    in.LayerPropertyTexture->SetMagnificationFilter(vtkTextureObject::Nearest);
    in.LayerPropertyTexture->Create2DFromRaw(static_cast<unsigned int>(header.dims[0]),
      static_cast<unsigned int>(header.dims[1]), 1, VTK_FLOAT, const_cast<float*>(loaded->values.data()));
    in.UploadedProperty = loaded;
  }
  else if (loaded && loaded != in.UploadedProperty)
  {
    if (!in.PropertyUpload.Busy())
    {
      in.Allocated = in.PropertyUpload.Start(window, header.hashTableSides, 1, VTK_FLOAT, 0, GL_RED, GL_FLOAT,
        sizeof(float), loaded->values.data(), loaded, in.SparePropertyTexture);
      in.SparePropertyTexture = nullptr; // taken (a spare always has the table's sides)
    }
    if (in.PropertyUpload.Continue(state, tableBudget, !bounded))
    {
      vtkSmartPointer<vtkTextureObject> previous = in.PropertyTexture;
      in.PropertyTexture = in.PropertyUpload.Take();
      if (SlabUpload::Fits(previous, header.hashTableSides))
      {
        in.SparePropertyTexture = previous;
      }
      else
      {
        previous->ReleaseGraphicsResources(window);
      }
      in.UploadedProperty = loaded;
    }
  }
  // The table drawn: the wanted one once on the GPU; until then an earlier time step of the
  // same property and layer stands in (as an ancestor does for a mesh), anything else is
  // drawn in the solid colour rather than through another property's colour map.
  std::shared_ptr<const resmr::PropertyTableData> property = in.UploadedProperty;
  if (!wantProperty || !property || property->name != this->ArrayName || property->layer != layer)
  {
    property.reset();
  }

  // Meshes, with what the tables left of the frame's upload budget, bytes and time.
  {
    const auto elapsedMs = [](std::chrono::steady_clock::time_point since) {
      return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
    };
    in.Pacer.BeginFrame(
      this->TargetFrameRate > 0 ? UploadShareOfFrame * 1000 / this->TargetFrameRate : UploadMsAtFixedTolerance,
      UploadBytesPerFrame);
    in.Pacer.Spend(TableBytesPerFrame - tableBudget, elapsedMs(tablesStart));
    in.UploadsDeferred = false;
    std::vector<std::size_t> order = in.Selector->Roots();
    order.insert(order.end(), selection.wanted.begin(), selection.wanted.end());
    const std::size_t roots = in.Selector->Roots().size();
    const std::size_t gpuShare = (std::size_t(this->MemoryBudgetMB) << 20) - MainMemoryShare(this->MemoryBudgetMB);
    for (std::size_t n = 0; n < order.size(); ++n)
    {
      const std::size_t region = order[n];
      auto found = in.Gpu.find(region);
      if (found == in.Gpu.end())
      {
        std::shared_ptr<const resmr::RegionDrawBuffers> buffers = cache.Get(region);
        if (!buffers)
        {
          continue;
        }
        found = in.Gpu.emplace(region, std::make_unique<GpuRegion>(buffers)).first;
      }
      const auto overShare = [&]() {
        return !found->second->Ready() && in.GpuBytes + found->second->NextPieceBytes() > gpuShare;
      };
      if (overShare())
      {
        // The loader may have evicted regions since the sweep above: their copies go first.
        releaseEvicted();
        found = in.Gpu.find(region);
        if (found == in.Gpu.end())
        {
          continue; // evicted itself
        }
      }
      if (overShare())
      {
        // Pieces copy a little more than the cache holds (shared vertices at piece seams: 0.1%
        // on the 100M-cell model), so mirroring the cache can still pass the share. Copies
        // this frame does not want go next (the cache still has them), then uploads wait.
        const std::unordered_set<std::size_t> wanted(order.begin(), order.end());
        for (auto entry = in.Gpu.begin(); entry != in.Gpu.end() && overShare();)
        {
          if (wanted.count(entry->first) == 0)
          {
            in.GpuBytes -= entry->second->bytes;
            entry->second->Release();
            entry = in.Gpu.erase(entry);
          }
          else
          {
            ++entry;
          }
        }
        if (overShare())
        {
          in.UploadsDeferred = true;
          break;
        }
      }
      GpuRegion& gpu = *found->second;
      while (!gpu.Ready() && !(bounded && n >= roots && !in.Pacer.Admit(gpu.NextPieceBytes())) &&
        in.GpuBytes + gpu.NextPieceBytes() <= gpuShare)
      {
        const auto copyStart = std::chrono::steady_clock::now();
        const std::size_t bytes = gpu.UploadNextPiece(program, in.IndexScratch);
        in.Pacer.Record(bytes, elapsedMs(copyStart));
        in.GpuBytes += bytes;
      }
      if (!gpu.Ready())
      {
        in.UploadsDeferred = true;
        break;
      }
    }
    in.UploadsDeferred = in.UploadsDeferred || in.OffsetUpload.Busy() || in.PropertyUpload.Busy();
    const auto onGpu = [&in](std::size_t region) { return ReadyOnGpu(in.Gpu, region); };
    selection = in.Selector->Select(view, onGpu);
  }
  if (property && (table != in.ColorTable || table->GetMTime() != in.ColorTableTime))
  {
    const int size = 1024;
    const double* range = table->GetRange();
    in.ColorRange[0] = range[0];
    in.ColorRange[1] = range[1];
    const bool logScale = table->UsingLogScale() != 0;
    std::vector<double> values(size);
    for (int i = 0; i < size; ++i)
    {
      const double t = (i + 0.5) / size;
      values[i] = logScale ? std::pow(10.0, std::log10(range[0]) + t * (std::log10(range[1]) - std::log10(range[0])))
                           : range[0] + t * (range[1] - range[0]);
    }
    std::vector<unsigned char> rgba(size * 4);
    for (int i = 0; i < size; ++i)
    {
      const unsigned char* color = table->MapValue(values[i]);
      std::copy(color, color + 4, &rgba[4 * i]);
    }
    state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    in.ColorTexture->SetContext(window);
    in.ColorTexture->ResetFormatAndType();
    in.ColorTexture->SetMinificationFilter(vtkTextureObject::Nearest);
    in.ColorTexture->SetMagnificationFilter(vtkTextureObject::Nearest);
    in.ColorTexture->Create2DFromRaw(size, 1, 4, VTK_UNSIGNED_CHAR, rgba.data());
    in.ColorTable = table;
    in.ColorTableTime = table->GetMTime();
  }
  const bool hashReady = in.HashUploaded || layer >= 0; // a layer's 2D table needs no hash
  const int colorMode = paintingMode(hashReady, property != nullptr);
  program = readyProgram(colorMode);
  if (!program)
  {
    return;
  }
  const GLuint handle = static_cast<GLuint>(program->GetHandle());
  const auto uniform3i = [handle](const char* name, int a, int b, int c) {
    glUniform3i(glGetUniformLocation(handle, name), a, b, c);
  };

  // GPU time of an earlier frame, when the driver has it (never waits).
  if (in.TimerQuery != 0 && in.TimerPending)
  {
    GLint available = 0;
    glGetQueryObjectiv(in.TimerQuery, GL_QUERY_RESULT_AVAILABLE, &available);
    if (available)
    {
      GLuint64 nanoseconds = 0;
      glGetQueryObjectui64v(in.TimerQuery, GL_QUERY_RESULT, &nanoseconds);
      in.GpuMs = nanoseconds * 1e-6;
      in.TimerPending = false;
    }
  }
  if (in.TimerQuery == 0)
  {
    glGenQueries(1, &in.TimerQuery);
  }
  const bool timing = !in.TimerPending;
  if (timing)
  {
    glBeginQuery(GL_TIME_ELAPSED, in.TimerQuery);
  }

  // Uniforms.
  const std::array<double, 3> origin = cache.Origin();
  Matrix shift{ 1, 0, 0, origin[0], 0, 1, 0, origin[1], 0, 0, 1, origin[2], 0, 0, 0, 1 };
  float packed[16];
  ColumnMajor(Multiply(modelToClip, shift), packed);
  program->SetUniformMatrix4x4("modelToClip", packed);
  ColumnMajor(Multiply(modelToView, shift), packed);
  program->SetUniformMatrix4x4("modelToView", packed);
  {
    // Normals: the inverse transpose of model-to-view's linear part.
    vtkNew<vtkMatrix4x4> linear;
    for (int i = 0; i < 4; ++i)
    {
      for (int j = 0; j < 4; ++j)
      {
        linear->SetElement(i, j, i < 3 && j < 3 ? modelToView[4 * i + j] : (i == j ? 1 : 0));
      }
    }
    linear->Invert();
    float normal[9];
    for (int i = 0; i < 3; ++i)
    {
      for (int j = 0; j < 3; ++j)
      {
        normal[3 * j + i] = static_cast<float>(linear->GetElement(j, i)); // transpose, column-major
      }
    }
    program->SetUniformMatrix3x3("normalToView", normal);
  }
  uniform3i("gridDims", int(header.dims[0]), int(header.dims[1]), int(header.dims[2]));
  if (in.HashUploaded)
  {
    uniform3i("tableSides", int(header.hashTableSides[0]), int(header.hashTableSides[1]), int(header.hashTableSides[2]));
    uniform3i(
      "offsetSides", int(header.hashOffsetSides[0]), int(header.hashOffsetSides[1]), int(header.hashOffsetSides[2]));
  }
  else
  {
    uniform3i("tableSides", 1, 1, 1);
    uniform3i("offsetSides", 1, 1, 1);
  }
  program->SetUniformi("cellTables", in.HashUploaded ? 1 : 0);
  in.OffsetTexture->Activate();
  program->SetUniformi("hashOffsets", in.OffsetTexture->GetTextureUnit());
  in.NormalTexture->Activate();
  program->SetUniformi("cellNormals", in.NormalTexture->GetTextureUnit());
  in.PropertyTexture->Activate();
  program->SetUniformi("propertyTable", in.PropertyTexture->GetTextureUnit());
  in.LayerPropertyTexture->Activate();
  program->SetUniformi("layerProperty", in.LayerPropertyTexture->GetTextureUnit());
  program->SetUniformi("layer", layer);
  in.ColorTexture->Activate();
  program->SetUniformi("colorMap", in.ColorTexture->GetTextureUnit());
  if (colorMode == PropertyColors)
  {
    const bool logScale = table->UsingLogScale() != 0;
    float range[2] = { float(in.ColorRange[0]), float(in.ColorRange[1]) };
    if (logScale)
    {
      range[0] = float(std::log10(std::max(in.ColorRange[0], 1e-30)));
      range[1] = float(std::log10(std::max(in.ColorRange[1], 1e-30)));
    }
    program->SetUniform2f("scalarRange", range);
    const unsigned char* nan = table->MapValue(std::numeric_limits<double>::quiet_NaN());
    const float nanColor[4] = { nan[0] / 255.f, nan[1] / 255.f, nan[2] / 255.f, nan[3] / 255.f };
    program->SetUniform4f("nanColor", nanColor);
  }
  program->SetUniform3f("solidColor", look->GetDiffuseColor());
  program->SetUniformf("gridLineWidth", static_cast<float>(this->GridLineWidth));
  program->SetUniform3f("gridLineColor", this->GridLineColor);
  program->SetUniformf("ambient", static_cast<float>(look->GetAmbient() + (look->GetLighting() ? 0 : 1)));
  program->SetUniformf("diffuse", static_cast<float>(look->GetLighting() ? look->GetDiffuse() : 0));
  program->SetUniformf("specular", static_cast<float>(look->GetLighting() ? look->GetSpecular() : 0));
  program->SetUniformf("specularPower", static_cast<float>(std::max(1.0, look->GetSpecularPower())));

  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthMask(GL_TRUE);
  // Back faces of the closed surface, hidden from outside, are culled (the bottom seen from
  // above is about a third of the triangles); a mirroring transform turns the winding.
  if (selection.backFacesHidden && layer < 0)
  {
    const double determinant = vtkMath::Determinant3x3(modelToWorld[0], modelToWorld[1], modelToWorld[2], modelToWorld[4],
      modelToWorld[5], modelToWorld[6], modelToWorld[8], modelToWorld[9], modelToWorld[10]);
    state->vtkglEnable(GL_CULL_FACE);
    state->vtkglCullFace(GL_BACK);
    glFrontFace(determinant < 0 ? GL_CW : GL_CCW); // restored after drawing (not in vtkOpenGLState)
  }
  else
  {
    state->vtkglDisable(GL_CULL_FACE);
  }
  state->vtkglDisable(GL_BLEND);

  // Draw.
  for (const resmr::DrawnRegion& drawn : selection.drawn)
  {
    auto found = in.Gpu.find(drawn.region);
    if (found == in.Gpu.end())
    {
      std::shared_ptr<const resmr::RegionDrawBuffers> buffers = cache.Get(drawn.region);
      if (!buffers)
      {
        continue; // evicted since the selection: its ancestor is not drawn either this frame
      }
      found = in.Gpu.emplace(drawn.region, std::make_unique<GpuRegion>(buffers)).first;
    }
    GpuRegion& gpu = *found->second;
    if (!gpu.Ready())
    {
      const std::size_t before = gpu.bytes;
      gpu.UploadRest(program, in.IndexScratch);
      in.GpuBytes += gpu.bytes - before;
    }
    const resmr::RegionDrawBuffers& buffers = *gpu.buffers;
    if (buffers.indices.empty())
    {
      continue;
    }
    // The selection culled the stored top and bottom by their cones; a layer's own top and
    // bottom have their own cones.
    const resmr::RegionRecord& record = in.File->Regions()[drawn.region];
    const bool top = layer < 0 ? drawn.top : !resmr::SurfaceCulled(buffers.topCone, record, view);
    const bool bottom = layer < 0 ? drawn.bottom : !resmr::SurfaceCulled(buffers.bottomCone, record, view);
    // Where the region's error already shows (a few pixels), its side is drawn simplified
    // (Sec. 4.3): on models of many layers that is most of the triangles, and the geometry is
    // no closer than that error anyway. Exact sides keep k exact for close and 1 px views.
    const bool coarseSide = buffers.coarseSideIndices > 0 && drawn.projectedError > CoarseSidePixels;
    struct Part
    {
      bool shown;
      uint32_t first, count;
      int kind;
    };
    const Part parts[3] = { { top, 0, buffers.topIndices, 0 }, { bottom, buffers.topIndices, buffers.bottomIndices, 1 },
      coarseSide ? Part{ drawn.side, buffers.topIndices + buffers.bottomIndices + buffers.sideIndices,
                     buffers.coarseSideIndices, 2 }
                 : Part{ drawn.side, buffers.topIndices + buffers.bottomIndices, buffers.sideIndices, 2 } };
    for (const auto& piece : gpu.pieces)
    {
      piece->layout->Bind();
      piece->indices->Bind();
      for (const auto& part : parts)
      {
        // The part's indices that lie in this piece.
        const uint32_t begin = std::max(part.first, piece->first);
        const uint32_t end = std::min(part.first + part.count, piece->first + piece->count);
        if (part.shown && end > begin)
        {
          program->SetUniformi("faceKind", part.kind);
          glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(end - begin), GL_UNSIGNED_INT,
            reinterpret_cast<const void*>(std::size_t(begin - piece->first) * sizeof(uint32_t)));
          in.Triangles += (end - begin) / 3;
        }
      }
      piece->indices->Release();
      piece->layout->Release();
    }
    ++in.Drawn;
  }
  glFrontFace(GL_CCW);
  state->vtkglDisable(GL_CULL_FACE);
  in.Substituted = static_cast<int>(selection.substituted);
  in.PropertyTexture->Deactivate();
  in.LayerPropertyTexture->Deactivate();
  in.ColorTexture->Deactivate();
  in.OffsetTexture->Deactivate();
  in.NormalTexture->Deactivate();
  if (timing)
  {
    glEndQuery(GL_TIME_ELAPSED);
    in.TimerPending = true;
  }
  vtkOpenGLCheckErrorMacro("after drawing the multiresolution surface");

  // Pending too: what the loader finished during this frame, after the frame took its state
  // (tables, the property, wanted meshes), and the next frame will copy. Without it a render
  // could report nothing pending and leave the GUI (and scripts waiting on LoadsPending) with
  // the picture before the property arrived.
  const auto arrivedLate = [&]() {
    if (!in.HashUploaded && cache.Tables())
    {
      return true;
    }
    const std::shared_ptr<const resmr::PropertyTableData> now = wantProperty ? cache.Property() : nullptr;
    if (now && now != in.UploadedProperty && now->name == this->ArrayName && now->step == tableStep &&
      now->layer == layer)
    {
      return true;
    }
    return std::any_of(selection.wanted.begin(), selection.wanted.end(),
      [&](std::size_t region) { return !ReadyOnGpu(in.Gpu, region) && cache.IsResident(region); });
  };
  in.Pending = cache.Pending() || in.UploadsDeferred || arrivedLate();
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
  const double cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  in.FrameMs = cpuMs + in.GpuMs;
  if (this->TargetFrameRate > 0)
  {
    double measuredMs = afterAllocation ? in.FrameMs : std::max(in.FrameMs, rendererMs);
    if (intervalMs < 3000 / this->TargetFrameRate && !afterAllocation)
    {
      measuredMs = std::max(measuredMs, intervalMs);
    }
    // Ancestors drawn for meshes still on their way: not all the detail the tolerance selected.
    const bool complete = in.Substituted == 0 || !in.Pending;
    // A frame that allocated a table texture (once or twice a model, up to a second under
    // llvmpipe) says nothing of the frames to come: coarsening on it held a 300M model's
    // tolerance tenfold for a hundred frames.
    if (!in.Allocated)
    {
      resmr::CutRange same;
      same.refineBelow = selection.refineBelowPixels;
      same.coarsenAt = selection.coarsenAtPixels;
      in.Controller.Update(measuredMs / 1000, complete, same);
    }
  }
}

void vtkMultiresolutionSurfaceMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ColorMode: " << this->ColorMode << "\n";
  os << indent << "PixelTolerance: " << this->PixelTolerance << "\n";
  os << indent << "TargetFrameRate: " << this->TargetFrameRate << "\n";
  os << indent << "MemoryBudgetMB: " << this->MemoryBudgetMB << "\n";
  os << indent << "GridLines: " << this->GridLines << "\n";
  os << indent << "WaitForDetailMs: " << this->WaitForDetailMs << "\n";
  os << indent << "Layer: " << this->Layer << "\n";
}
