#include "vtkMultiresolutionTableTextures.h"

#include "FramePlanning.h"
#include "MultiresolutionFile.h"
#include "RegionCache.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkScalarsToColors.h"
#include "vtkShaderProgram.h"
#include "vtk_glew.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

/// A 3D table texture filled a slab of z-slices at a time (glTexSubImage3D) into a texture of
/// its own, which replaces the one drawn only once complete: a large model's tables copied in
/// one call would stall a frame for a long time.
class vtkMultiresolutionTableTextures::SlabUpload
{
public:
  /// Allocates the texture, or copies over `spare` (a texture of these sides and format no
  /// longer drawn), and takes the table (x fastest, then y, then z); `owner` keeps the table
  /// alive until the copy ends. Allocating is most of the cost on drivers that zero new
  /// storage (llvmpipe), so a property's tables are copied turn about into two textures. True
  /// if it allocated.
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

  /// Copies the slices resmr::SlicesThisFrame allows of `budget` (bytes, spent here). True
  /// when the texture is complete.
  bool Continue(vtkOpenGLState* state, std::size_t& budget, bool unbounded)
  {
    const uint32_t slices =
      resmr::SlicesThisFrame(this->Sides[2] - this->NextSlice, this->SliceBytes, budget, unbounded);
    if (slices > 0)
    {
      state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      this->Texture->Activate();
      glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, static_cast<GLint>(this->NextSlice), static_cast<GLsizei>(this->Sides[0]),
        static_cast<GLsizei>(this->Sides[1]), static_cast<GLsizei>(slices), this->Format, this->Type,
        this->Data + this->NextSlice * this->SliceBytes);
      this->Texture->Deactivate();
      this->NextSlice += slices;
    }
    return this->NextSlice == this->Sides[2];
  }

  /// Stops the copy; returns the texture (complete, or partly filled for reuse as a spare).
  vtkSmartPointer<vtkTextureObject> Take()
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
    this->Take();
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

namespace
{
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

vtkMultiresolutionTableTextures::vtkMultiresolutionTableTextures()
  : OffsetUpload(new SlabUpload)
  , NormalUpload(new SlabUpload)
  , PropertyUpload(new SlabUpload)
{
}

vtkMultiresolutionTableTextures::~vtkMultiresolutionTableTextures() = default;

bool vtkMultiresolutionTableTextures::Busy() const
{
  return this->OffsetUpload->Busy() || this->NormalUpload->Busy() || this->PropertyUpload->Busy();
}

void vtkMultiresolutionTableTextures::StreamHash(
  vtkOpenGLRenderWindow* window, const resmr::RegionCache& cache, std::size_t& budget, bool unbounded)
{
  // Until the hash is in, the whole model is drawn in the solid colour, lit by facet normals,
  // with 1-texel stand-ins for the samplers.
  vtkOpenGLState* state = window->GetState();
  if (this->OffsetTexture->GetHandle() == 0)
  {
    state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    const std::array<uint32_t, 3> one{ 1, 1, 1 };
    const uint16_t zeros[3] = { 0, 0, 0 };
    UploadInteger3D(this->OffsetTexture, window, one, 3, GL_RGB16UI, GL_RGB_INTEGER, zeros);
    UploadInteger3D(this->NormalTexture, window, one, 2, GL_RG16UI, GL_RG_INTEGER, zeros);
  }
  if (this->HashUploaded)
  {
    return;
  }
  const std::shared_ptr<const resmr::ModelTables> tables = cache.Tables();
  if (tables && !this->OffsetUpload->Busy() && !this->NormalUpload->Busy())
  {
    const resmr::PerfectSpatialHash& hash = tables->hash;
    this->AllocatedThisFrame = true;
    this->OffsetUpload->Start(window, hash.offsetSides, 3, VTK_UNSIGNED_SHORT, GL_RGB16UI, GL_RGB_INTEGER,
      GL_UNSIGNED_SHORT, 6, hash.offsets.data(), tables);
    if (tables->normals.size() == hash.TableSize() * 4)
    {
      this->NormalUpload->Start(window, hash.tableSides, 2, VTK_UNSIGNED_SHORT, GL_RG16UI, GL_RG_INTEGER,
        GL_UNSIGNED_SHORT, 4, tables->normals.data(), tables);
    }
    else
    {
      auto up = std::make_shared<std::vector<uint16_t>>(hash.TableSize() * 2, 0); // code 0 is +z
      this->NormalUpload->Start(
        window, hash.tableSides, 2, VTK_UNSIGNED_SHORT, GL_RG16UI, GL_RG_INTEGER, GL_UNSIGNED_SHORT, 4, up->data(), up);
    }
  }
  if (this->OffsetUpload->Busy() && this->OffsetUpload->Continue(state, budget, unbounded))
  {
    this->OffsetTexture->ReleaseGraphicsResources(window);
    this->OffsetTexture = this->OffsetUpload->Take();
    this->HashUploaded = true;
  }
}

void vtkMultiresolutionTableTextures::StreamNormals(vtkOpenGLRenderWindow* window, std::size_t& budget, bool unbounded)
{
  if (this->HashUploaded && this->NormalUpload->Busy() &&
    this->NormalUpload->Continue(window->GetState(), budget, unbounded))
  {
    this->NormalTexture->ReleaseGraphicsResources(window);
    this->NormalTexture = this->NormalUpload->Take();
    this->NormalsUploaded = true;
  }
}

void vtkMultiresolutionTableTextures::StreamProperty(vtkOpenGLRenderWindow* window,
  const std::shared_ptr<const resmr::PropertyTableData>& loaded, const resmr::MultiresolutionHeader& header,
  std::size_t& budget, bool unbounded)
{
  vtkOpenGLState* state = window->GetState();
  if (this->PropertyTexture->GetHandle() == 0)
  {
    // Until a property loads, every sampler still needs a texture of its type.
    float none = std::numeric_limits<float>::quiet_NaN();
    this->PropertyTexture->SetContext(window);
    this->PropertyTexture->Create3DFromRaw(1, 1, 1, 1, VTK_FLOAT, &none);
    this->LayerPropertyTexture->SetContext(window);
    this->LayerPropertyTexture->Create2DFromRaw(1, 1, 1, VTK_FLOAT, &none);
    unsigned char white[4] = { 255, 255, 255, 255 };
    this->ColorTexture->SetContext(window);
    this->ColorTexture->Create2DFromRaw(1, 1, 4, VTK_UNSIGNED_CHAR, white);
  }
  if (!loaded || loaded->layer >= 0 || this->PropertyUpload->Source() != loaded.get())
  {
    // Another table is wanted now: its copy goes over this one's texture.
    vtkSmartPointer<vtkTextureObject> partial = this->PropertyUpload->Take();
    if (partial)
    {
      if (this->SparePropertyTexture && this->SparePropertyTexture != partial)
      {
        this->SparePropertyTexture->ReleaseGraphicsResources(window);
      }
      this->SparePropertyTexture = partial;
    }
  }
  if (!loaded || loaded == this->Uploaded)
  {
    return;
  }
  if (loaded->layer >= 0)
  {
    // A layer's table is a 2D texture of nx x ny, indexed by (i, j): no hash (Sec. 5.4); at
    // most a few MB, copied at once.
    state->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    this->LayerPropertyTexture->SetContext(window);
    this->LayerPropertyTexture->ResetFormatAndType();
    this->LayerPropertyTexture->SetMinificationFilter(vtkTextureObject::Nearest);
    this->LayerPropertyTexture->SetMagnificationFilter(vtkTextureObject::Nearest);
    this->LayerPropertyTexture->Create2DFromRaw(static_cast<unsigned int>(header.dims[0]),
      static_cast<unsigned int>(header.dims[1]), 1, VTK_FLOAT, const_cast<float*>(loaded->values.data()));
    this->Uploaded = loaded;
    return;
  }
  if (!this->PropertyUpload->Busy())
  {
    this->AllocatedThisFrame = this->PropertyUpload->Start(window, header.hashTableSides, 1, VTK_FLOAT, 0, GL_RED,
      GL_FLOAT, sizeof(float), loaded->values.data(), loaded, this->SparePropertyTexture);
    this->SparePropertyTexture = nullptr; // taken (a spare always has the table's sides)
  }
  if (this->PropertyUpload->Continue(state, budget, unbounded))
  {
    vtkSmartPointer<vtkTextureObject> previous = this->PropertyTexture;
    this->PropertyTexture = this->PropertyUpload->Take();
    if (SlabUpload::Fits(previous, header.hashTableSides))
    {
      this->SparePropertyTexture = previous;
    }
    else
    {
      previous->ReleaseGraphicsResources(window);
    }
    this->Uploaded = loaded;
  }
}

void vtkMultiresolutionTableTextures::UploadWalls(vtkOpenGLRenderWindow* window, const resmr::RegionCache& cache)
{
  const std::shared_ptr<const resmr::ModelTables> tables = cache.Tables();
  if (this->WallsTried || !this->NormalsUploaded || !tables)
  {
    return;
  }
  this->WallsTried = true;
  const resmr::WallDepthTable& walls = tables->walls;
  // Slot s lies at (s mod rows, s / rows) of the key texture; face row r, k along x, at
  // (r mod rows, r / rows) of the depth texture: 3D textures of at most 2048 a side.
  const uint64_t slots = walls.hash.TableSize();
  const uint32_t interfaces = static_cast<uint32_t>(walls.layers + 1);
  const uint32_t slotRows = static_cast<uint32_t>(std::min<uint64_t>(slots, 1024));
  const uint32_t faceRows = static_cast<uint32_t>(std::min<uint64_t>(walls.faces, 1024));
  const uint64_t slotSlabs = (slots + slotRows - 1) / std::max<uint32_t>(slotRows, 1);
  const uint64_t faceSlabs = (walls.faces + faceRows - 1) / std::max<uint32_t>(faceRows, 1);
  const uint64_t most = resmr::PerfectSpatialHash::MaxSide;
  if (walls.Empty() || interfaces > most || slotSlabs > most || faceSlabs > most)
  {
    return;
  }
  std::vector<std::array<uint32_t, 2>> keys(static_cast<std::size_t>(slotRows * slotSlabs), { 0, 0 });
  std::copy(walls.slots.begin(), walls.slots.end(), keys.begin());
  std::vector<float> texels(static_cast<std::size_t>(faceRows * faceSlabs) * interfaces * 3, 0.f);
  std::copy(walls.texels.begin(), walls.texels.end(), texels.begin());
  window->GetState()->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  UploadInteger3D(
    this->WallOffsetTexture, window, walls.hash.offsetSides, 3, GL_RGB16UI, GL_RGB_INTEGER, walls.hash.offsets.data());
  const auto setup = [window](
                       vtkTextureObject* texture, unsigned int internalFormat, unsigned int format, unsigned int type) {
    texture->SetContext(window);
    texture->ResetFormatAndType();
    texture->SetInternalFormat(internalFormat);
    texture->SetFormat(format);
    texture->SetDataType(type);
    texture->SetMinificationFilter(vtkTextureObject::Nearest);
    texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  };
  setup(this->WallKeyTexture, GL_RG32UI, GL_RG_INTEGER, GL_UNSIGNED_INT);
  this->WallKeyTexture->Create3DFromRaw(
    slotRows, static_cast<unsigned int>(slotSlabs), 1, 2, VTK_UNSIGNED_INT, keys.data());
  setup(this->WallDepthTexture, GL_RGB32F, GL_RGB, GL_FLOAT);
  this->WallDepthTexture->Create3DFromRaw(
    interfaces, faceRows, static_cast<unsigned int>(faceSlabs), 3, VTK_FLOAT, texels.data());
  this->WallTableSides = walls.hash.tableSides;
  this->WallOffsetSides = walls.hash.offsetSides;
  this->WallRows = static_cast<int>(slotRows);
  this->WallFaceRows = static_cast<int>(faceRows);
  this->WallSearchSteps = 0;
  while ((1 << this->WallSearchSteps) < walls.layers)
  {
    ++this->WallSearchSteps;
  }
  this->WallsUploaded = true;
  this->AllocatedThisFrame = true;
}

void vtkMultiresolutionTableTextures::UpdateColorMap(vtkOpenGLRenderWindow* window, vtkScalarsToColors* table)
{
  if (table == this->ColorTable && table->GetMTime() == this->ColorTableTime)
  {
    return;
  }
  const int size = 1024;
  const double* range = table->GetRange();
  this->Range[0] = range[0];
  this->Range[1] = range[1];
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
  window->GetState()->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  this->ColorTexture->SetContext(window);
  this->ColorTexture->ResetFormatAndType();
  this->ColorTexture->SetMinificationFilter(vtkTextureObject::Nearest);
  this->ColorTexture->SetMagnificationFilter(vtkTextureObject::Nearest);
  this->ColorTexture->Create2DFromRaw(size, 1, 4, VTK_UNSIGNED_CHAR, rgba.data());
  this->ColorTable = table;
  this->ColorTableTime = table->GetMTime();
}

void vtkMultiresolutionTableTextures::UploadCutPlanes(vtkOpenGLRenderWindow* window,
  const std::array<std::shared_ptr<const resmr::CutPlaneData>, 6>& planes, const resmr::MultiresolutionHeader& header)
{
  const auto create = [window](
                        vtkTextureObject* texture, unsigned int width, unsigned int height, const float* values) {
    window->GetState()->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    texture->SetContext(window);
    texture->ResetFormatAndType();
    texture->SetMinificationFilter(vtkTextureObject::Nearest);
    texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    texture->Create2DFromRaw(width, height, 1, VTK_FLOAT, const_cast<float*>(values));
  };
  const float none = std::numeric_limits<float>::quiet_NaN();
  if (this->CutSidesTexture->GetHandle() == 0)
  {
    create(this->CutLowKTexture, 1, 1, &none);
    create(this->CutHighKTexture, 1, 1, &none);
    create(this->CutSidesTexture, 1, 1, &none);
  }
  const unsigned int nx = static_cast<unsigned int>(header.dims[0]), ny = static_cast<unsigned int>(header.dims[1]);
  const unsigned int nk = static_cast<unsigned int>(header.dims[2]);
  vtkTextureObject* layers[2] = { this->CutLowKTexture, this->CutHighKTexture };
  for (int p = 0; p < 2; ++p)
  {
    if (planes[p] && planes[p] != this->UploadedCuts[p] && planes[p]->values.size() == std::size_t(nx) * ny)
    {
      create(layers[p], nx, ny, planes[p]->values.data());
      this->UploadedCuts[p] = planes[p];
    }
  }
  // I and J planes share one texture: row band p - 2 of nk rows, indexed (j or i, k).
  bool sidesChanged = false;
  for (int p = 2; p < 6; ++p)
  {
    sidesChanged = sidesChanged || (planes[p] && planes[p] != this->UploadedCuts[p]);
  }
  if (sidesChanged)
  {
    const unsigned int width = std::max(nx, ny);
    std::vector<float> sides(std::size_t(width) * 4 * nk, none);
    for (int p = 2; p < 6; ++p)
    {
      this->UploadedCuts[p] = planes[p];
      const unsigned int along = p < 4 ? ny : nx;
      if (!planes[p] || planes[p]->values.size() != std::size_t(along) * nk)
      {
        this->UploadedCuts[p].reset();
        continue;
      }
      for (unsigned int k = 0; k < nk; ++k)
      {
        std::copy_n(planes[p]->values.begin() + std::ptrdiff_t(k) * along, along,
          sides.begin() + (std::ptrdiff_t(p - 2) * nk + k) * width);
      }
    }
    create(this->CutSidesTexture, width, 4 * nk, sides.data());
  }
  this->CutReady = 0;
  for (int p = 0; p < 6; ++p)
  {
    this->CutReady |= planes[p] && planes[p] == this->UploadedCuts[p] ? 1 << p : 0;
  }
}

void vtkMultiresolutionTableTextures::Bind(vtkShaderProgram* program, const resmr::MultiresolutionHeader& header)
{
  const GLuint handle = static_cast<GLuint>(program->GetHandle());
  const auto uniform3i = [handle](const char* name, const std::array<uint32_t, 3>& sides) {
    glUniform3i(glGetUniformLocation(handle, name), int(sides[0]), int(sides[1]), int(sides[2]));
  };
  const std::array<uint32_t, 3> one{ 1, 1, 1 };
  uniform3i("tableSides", this->HashUploaded ? header.hashTableSides : one);
  uniform3i("offsetSides", this->HashUploaded ? header.hashOffsetSides : one);
  const auto bind = [program](vtkTextureObject* texture, const char* sampler) {
    texture->Activate();
    program->SetUniformi(sampler, texture->GetTextureUnit());
  };
  bind(this->OffsetTexture, "hashOffsets");
  bind(this->NormalTexture, "cellNormals");
  bind(this->PropertyTexture, "propertyTable");
  bind(this->LayerPropertyTexture, "layerProperty");
  bind(this->ColorTexture, "colorMap");
  bind(this->CutLowKTexture, "cutLowK");
  bind(this->CutHighKTexture, "cutHighK");
  bind(this->CutSidesTexture, "cutSides");
  program->SetUniformi("cutReady", this->CutReady);
  if (this->WallsUploaded)
  {
    uniform3i("wallTableSides", this->WallTableSides);
    uniform3i("wallOffsetSides", this->WallOffsetSides);
    program->SetUniformi("wallRows", this->WallRows);
    program->SetUniformi("wallFaceRows", this->WallFaceRows);
    program->SetUniformi("wallSearchSteps", this->WallSearchSteps);
    bind(this->WallOffsetTexture, "wallOffsets");
    bind(this->WallKeyTexture, "wallKeys");
    bind(this->WallDepthTexture, "wallDepths");
  }
}

void vtkMultiresolutionTableTextures::Unbind()
{
  this->PropertyTexture->Deactivate();
  this->LayerPropertyTexture->Deactivate();
  this->ColorTexture->Deactivate();
  this->CutLowKTexture->Deactivate();
  this->CutHighKTexture->Deactivate();
  this->CutSidesTexture->Deactivate();
  this->OffsetTexture->Deactivate();
  this->NormalTexture->Deactivate();
  if (this->WallsUploaded)
  {
    this->WallOffsetTexture->Deactivate();
    this->WallKeyTexture->Deactivate();
    this->WallDepthTexture->Deactivate();
  }
}

void vtkMultiresolutionTableTextures::CancelUploads(vtkWindow* window)
{
  this->OffsetUpload->Release(window);
  this->NormalUpload->Release(window);
  this->PropertyUpload->Release(window);
  if (this->SparePropertyTexture && window)
  {
    this->SparePropertyTexture->ReleaseGraphicsResources(window);
  }
  this->SparePropertyTexture = nullptr;
}

void vtkMultiresolutionTableTextures::Forget(vtkWindow* window)
{
  this->HashUploaded = false;
  this->NormalsUploaded = false;
  this->WallsUploaded = false;
  this->WallsTried = false;
  this->Uploaded.reset();
  this->UploadedCuts = {};
  this->CutReady = 0;
  this->CancelUploads(window);
}

void vtkMultiresolutionTableTextures::ForgetAll(vtkWindow* window)
{
  this->Forget(window);
  this->ColorTableTime = 0;
}

void vtkMultiresolutionTableTextures::ReleaseGraphicsResources(vtkWindow* window)
{
  this->OffsetTexture->ReleaseGraphicsResources(window);
  this->NormalTexture->ReleaseGraphicsResources(window);
  this->PropertyTexture->ReleaseGraphicsResources(window);
  this->LayerPropertyTexture->ReleaseGraphicsResources(window);
  this->CutLowKTexture->ReleaseGraphicsResources(window);
  this->CutHighKTexture->ReleaseGraphicsResources(window);
  this->CutSidesTexture->ReleaseGraphicsResources(window);
  this->UploadedCuts = {};
  this->CutReady = 0;
  this->ColorTexture->ReleaseGraphicsResources(window);
  this->WallOffsetTexture->ReleaseGraphicsResources(window);
  this->WallKeyTexture->ReleaseGraphicsResources(window);
  this->WallDepthTexture->ReleaseGraphicsResources(window);
  this->WallsUploaded = false;
  this->WallsTried = false;
}
