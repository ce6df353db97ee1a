// The model's lookup tables on the GPU for painting (paper Sec. 5.3-5.4): the perfect hash's
// offsets and each slot's normals, the current property's table (packed by the hash, or one
// layer's nx x ny table) and the colour map. The hash and property tables are 3D textures too
// large to copy in one frame: each is streamed a slab of slices at a time
// (resmr::SlicesThisFrame) into a texture of its own, which replaces the drawn one only once
// complete; until then 1-texel stand-ins (no hash: the solid colour; no normals: facet
// normals) or the previous table (an earlier step of the same property) are drawn. Offsets go
// first, then the property, then the normals. Private to the Multiresolution Surface
// mapper; needs the mapper's GL context current.
#ifndef vtkMultiresolutionTableTextures_h
#define vtkMultiresolutionTableTextures_h

#include "vtkNew.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkType.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

class vtkOpenGLRenderWindow;
class vtkScalarsToColors;
class vtkShaderProgram;
class vtkWindow;

namespace resmr
{
class RegionCache;
struct MultiresolutionHeader;
struct PropertyTableData;
struct CutPlaneData;
}

class vtkMultiresolutionTableTextures
{
public:
  vtkMultiresolutionTableTextures();
  ~vtkMultiresolutionTableTextures();
  vtkMultiresolutionTableTextures(const vtkMultiresolutionTableTextures&) = delete;
  vtkMultiresolutionTableTextures& operator=(const vtkMultiresolutionTableTextures&) = delete;

  /// Streams the hash's offsets once the loader has read them (`cache.Tables()`), spending
  /// `budget` bytes (all of it when `unbounded`); a frame that allocates the offset and normal
  /// textures says so in Allocated().
  void StreamHash(vtkOpenGLRenderWindow* window, const resmr::RegionCache& cache, std::size_t& budget, bool unbounded);
  /// Streams the cells' normals once the offsets are in, after the property: colours come
  /// first, per-cell lighting (facet normals until then) next. At a billion cells each table
  /// is over a GB, streamed a few MB a frame.
  void StreamNormals(vtkOpenGLRenderWindow* window, std::size_t& budget, bool unbounded);
  /// Streams `loaded` (the requested property table, or null) the same way: a layer's 2D
  /// table at once, a packed table a slab at a time over the texture no longer drawn.
  void StreamProperty(vtkOpenGLRenderWindow* window, const std::shared_ptr<const resmr::PropertyTableData>& loaded,
    const resmr::MultiresolutionHeader& header, std::size_t& budget, bool unbounded);
  /// Copies the wall depth table (WallDepthTable.h) once the normals are in, at once (a few
  /// MB to tens of MB); nothing for files without one.
  void UploadWalls(vtkOpenGLRenderWindow* window, const resmr::RegionCache& cache);
  /// The planes an I/J/K range's cut faces are painted from (CellRange.h), in the order K low,
  /// K high, I low, I high, J low, J high; null where the range does not cut the grid or the
  /// plane is not loaded yet. A plane that changed is copied at once (K planes nx x ny, the
  /// others a few MB together). Called every frame: the samplers need textures either way.
  void UploadCutPlanes(vtkOpenGLRenderWindow* window,
    const std::array<std::shared_ptr<const resmr::CutPlaneData>, 6>& planes,
    const resmr::MultiresolutionHeader& header);
  /// Bit p: plane p of the last UploadCutPlanes is on the GPU.
  int CutPlanesReady() const { return this->CutReady; }
  /// Refills the colour map when the lookup table changed.
  void UpdateColorMap(vtkOpenGLRenderWindow* window, vtkScalarsToColors* table);

  /// The hash's offsets are complete on the GPU (cell lookups can be drawn).
  bool HashReady() const { return this->HashUploaded; }
  /// The top and bottom normal table is complete on the GPU (after the hash and property).
  bool NormalsReady() const { return this->NormalsUploaded; }
  /// The wall depth table is on the GPU: side fragments may find their layer from their depth.
  bool WallsReady() const { return this->WallsUploaded; }
  /// The property table on the GPU (null: none yet).
  const std::shared_ptr<const resmr::PropertyTableData>& UploadedProperty() const { return this->Uploaded; }
  /// A table is still being streamed.
  bool Busy() const;
  /// The colour map's range (the lookup table's when last filled).
  const double* ColorRange() const { return this->Range; }
  /// Whether this frame allocated a table texture (a slow frame, not one to learn from).
  bool Allocated() const { return this->AllocatedThisFrame; }
  void ClearAllocated() { this->AllocatedThisFrame = false; }

  /// Binds the tables to `program`'s samplers and sets their sides (`header`'s, or 1 while
  /// the hash is not complete).
  void Bind(vtkShaderProgram* program, const resmr::MultiresolutionHeader& header);
  void Unbind();

  /// Forgets what was uploaded and stops the copies (another file, or GL state lost); the
  /// textures drawn stay until replaced.
  void Forget(vtkWindow* window);
  /// Forget, and the colour map is refilled on the next frame.
  void ForgetAll(vtkWindow* window);
  /// Frees every texture.
  void ReleaseGraphicsResources(vtkWindow* window);

private:
  class SlabUpload;
  void CancelUploads(vtkWindow* window);

  vtkSmartPointer<vtkTextureObject> OffsetTexture = vtkSmartPointer<vtkTextureObject>::New();
  vtkSmartPointer<vtkTextureObject> NormalTexture = vtkSmartPointer<vtkTextureObject>::New();
  vtkSmartPointer<vtkTextureObject> PropertyTexture = vtkSmartPointer<vtkTextureObject>::New();
  vtkNew<vtkTextureObject> ColorTexture;
  vtkNew<vtkTextureObject> LayerPropertyTexture; ///< nx x ny R32F: one layer's table
  vtkNew<vtkTextureObject> CutLowKTexture;       ///< nx x ny R32F: a range's K low plane
  vtkNew<vtkTextureObject> CutHighKTexture;      ///< nx x ny R32F: its K high plane
  vtkNew<vtkTextureObject> CutSidesTexture;      ///< max(nx, ny) x 4 nk R32F: its I and J planes
  std::array<std::shared_ptr<const resmr::CutPlaneData>, 6> UploadedCuts;
  int CutReady = 0;
  vtkNew<vtkTextureObject> WallOffsetTexture; ///< the wall hash's offsets, RGB16UI
  vtkNew<vtkTextureObject> WallKeyTexture;    ///< rows x slabs RG32UI: each slot's key and row
  vtkNew<vtkTextureObject> WallDepthTexture;  ///< (nk + 1) x rows x slabs RGB32F: the faces
  bool WallsUploaded = false;
  bool WallsTried = false; ///< uploaded, or found none or too large for 3D textures
  std::array<uint32_t, 3> WallTableSides{ 1, 1, 1 }, WallOffsetSides{ 1, 1, 1 };
  int WallRows = 1;             ///< slots a slab of the key texture
  int WallFaceRows = 1;         ///< faces a slab of the depth texture
  int WallSearchSteps = 0;      ///< binary search steps over the layers
  bool HashUploaded = false;    ///< the offsets
  bool NormalsUploaded = false; ///< the cells' normals (after the offsets)
  std::shared_ptr<const resmr::PropertyTableData> Uploaded;
  std::unique_ptr<SlabUpload> OffsetUpload, NormalUpload, PropertyUpload;
  /// The property texture drawn before the current one, copied over by the next table.
  vtkSmartPointer<vtkTextureObject> SparePropertyTexture;
  vtkMTimeType ColorTableTime = 0;
  vtkScalarsToColors* ColorTable = nullptr;
  double Range[2] = { 0, 1 };
  bool AllocatedThisFrame = false;
};

#endif
