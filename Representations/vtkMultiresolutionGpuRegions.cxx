#include "vtkMultiresolutionGpuRegions.h"

#include "CellInspection.h"
#include "FramePlanning.h"
#include "RegionCache.h"
#include "UploadPacer.h"

#include "vtkNew.h"
#include "vtkOpenGLBufferObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkOpenGLVertexArrayObject.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <algorithm>
#include <chrono>
#include <set>
#include <utility>

namespace
{
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

double ElapsedMs(std::chrono::steady_clock::time_point since)
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}
} // namespace

/// A region's draw buffers on their way to the GPU, a piece at a time.
class vtkMultiresolutionGpuRegions::Region
{
public:
  explicit Region(std::shared_ptr<const resmr::RegionDrawBuffers> drawBuffers)
    : Buffers(std::move(drawBuffers))
    , Cursor(*this->Buffers)
  {
  }

  std::shared_ptr<const resmr::RegionDrawBuffers> Buffers;
  std::vector<std::unique_ptr<GpuPiece>> Pieces;
  std::size_t Bytes = 0;                        ///< copied so far
  std::vector<std::array<float, 6>> ChunkBoxes; ///< made at the region's first pick
  /// The buffers' face values (a property filter's leaves), one a triangle, as a buffer
  /// texture the fragment stage reads by gl_PrimitiveID; made at the region's first draw.
  vtkNew<vtkOpenGLBufferObject> FaceBuffer;
  vtkSmartPointer<vtkTextureObject> FaceTexture;

  /// Copies the face values, once; the bytes copied.
  std::size_t UploadFaceValues(vtkOpenGLRenderWindow* window)
  {
    const std::vector<float>& values = this->Buffers->faceValues;
    if (this->FaceTexture || values.empty() || !window)
    {
      return 0;
    }
    this->FaceBuffer->Upload(values, vtkOpenGLBufferObject::TextureBuffer);
    this->FaceTexture = vtkSmartPointer<vtkTextureObject>::New();
    this->FaceTexture->SetContext(window);
    this->FaceTexture->CreateTextureBuffer(static_cast<unsigned int>(values.size()), 1, VTK_FLOAT, this->FaceBuffer);
    return values.size() * 4;
  }

  bool Ready() const { return this->Cursor.Done(); }
  /// Bytes the next piece will copy.
  std::size_t NextPieceBytes() { return this->Cursor.Next().bytes; }

  /// Copies the next piece; the bytes copied. The vertices go straight from the region's
  /// buffer; the indices, rebased to the piece's first vertex, through `scratch`, which the
  /// caller keeps from piece to piece: rewriting touched memory is far cheaper than faulting
  /// in fresh pages for every piece.
  std::size_t UploadNextPiece(vtkShaderProgram* program, std::vector<uint32_t>& scratch)
  {
    const resmr::DrawPiece next = this->Cursor.Next();
    const std::vector<float>& vertices = this->Buffers->vertices;
    const std::vector<uint32_t>& indices = this->Buffers->indices;
    auto piece = std::make_unique<GpuPiece>();
    piece->first = static_cast<uint32_t>(next.first);
    piece->count = static_cast<uint32_t>(next.end - next.first);
    scratch.assign(indices.begin() + next.first, indices.begin() + next.end);
    for (uint32_t& index : scratch)
    {
      index -= next.lowVertex;
    }
    piece->layout->Bind();
    piece->vertices->Upload(vertices.data() + std::size_t(next.lowVertex) * 6,
      (std::size_t(next.highVertex) - next.lowVertex + 1) * 6, vtkOpenGLBufferObject::ArrayBuffer);
    piece->indices->Upload(scratch, vtkOpenGLBufferObject::ElementArrayBuffer);
    piece->layout->AddAttributeArray(program, piece->vertices, "vertexPosition", 0, 24, VTK_FLOAT, 3, false);
    piece->layout->AddAttributeArray(program, piece->vertices, "cellCoordinate", 12, 24, VTK_FLOAT, 3, false);
    piece->layout->Release();
    this->Pieces.push_back(std::move(piece));
    this->Bytes += next.bytes;
    this->Cursor.Advance();
    return next.bytes;
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
    for (auto& piece : this->Pieces)
    {
      piece->Release();
    }
    if (this->FaceTexture)
    {
      this->FaceTexture->ReleaseGraphicsResources(this->FaceTexture->GetContext());
      this->FaceTexture = nullptr;
    }
    this->FaceBuffer->ReleaseGraphicsResources();
  }

private:
  resmr::DrawPieceCursor Cursor;
};

vtkMultiresolutionGpuRegions::vtkMultiresolutionGpuRegions() = default;

vtkMultiresolutionGpuRegions::~vtkMultiresolutionGpuRegions() = default;

bool vtkMultiresolutionGpuRegions::Ready(std::size_t region) const
{
  const auto found = this->Regions.find(region);
  return found != this->Regions.end() && found->second->Ready();
}

void vtkMultiresolutionGpuRegions::Erase(RegionMap::iterator entry)
{
  this->BoxBytes -= entry->second->ChunkBoxes.size() * sizeof(std::array<float, 6>);
  this->Boxed.erase(std::remove(this->Boxed.begin(), this->Boxed.end(), entry->first), this->Boxed.end());
  this->GpuBytes -= entry->second->Bytes;
  entry->second->Release();
  this->Regions.erase(entry);
}

void vtkMultiresolutionGpuRegions::ReleaseEvicted(const resmr::RegionCache& cache)
{
  for (auto entry = this->Regions.begin(); entry != this->Regions.end();)
  {
    if (cache.Get(entry->first) != entry->second->Buffers)
    {
      this->Erase(entry++);
    }
    else
    {
      ++entry;
    }
  }
}

vtkMultiresolutionGpuRegions::RegionMap::iterator vtkMultiresolutionGpuRegions::Find(
  std::size_t region, const resmr::RegionCache& cache)
{
  auto found = this->Regions.find(region);
  if (found == this->Regions.end())
  {
    std::shared_ptr<const resmr::RegionDrawBuffers> buffers = cache.Get(region);
    if (buffers)
    {
      found = this->Regions.emplace(region, std::make_unique<Region>(std::move(buffers))).first;
    }
  }
  return found;
}

void vtkMultiresolutionGpuRegions::ReleaseUnwanted(
  const std::vector<std::size_t>& order, std::size_t position, RegionMap::iterator entry, std::size_t gpuShare)
{
  std::vector<std::pair<std::size_t, std::size_t>> mirrored;
  for (const auto& copy : this->Regions)
  {
    mirrored.emplace_back(copy.first, copy.second->Bytes);
  }
  for (std::size_t region :
    resmr::CopiesToRelease(mirrored, order, position, this->GpuBytes, entry->second->NextPieceBytes(), gpuShare))
  {
    this->Erase(this->Regions.find(region));
  }
}

bool vtkMultiresolutionGpuRegions::Upload(const resmr::RegionCache& cache, const std::vector<std::size_t>& order,
  std::size_t roots, bool bounded, resmr::UploadPacer& pacer, std::size_t gpuShare, vtkShaderProgram* program)
{
  for (std::size_t n = 0; n < order.size(); ++n)
  {
    const std::size_t region = order[n];
    auto found = this->Find(region, cache);
    if (found == this->Regions.end())
    {
      continue;
    }
    const auto overShare = [&]() {
      return !found->second->Ready() && this->GpuBytes + found->second->NextPieceBytes() > gpuShare;
    };
    if (overShare())
    {
      // The loader thread evicts while a frame runs: its evictions' copies go first.
      this->ReleaseEvicted(cache);
      found = this->Regions.find(region);
      if (found == this->Regions.end())
      {
        continue; // evicted itself
      }
    }
    if (overShare())
    {
      // Pieces copy a little more than the cache holds (vertices shared at piece seams), so
      // mirroring the cache can still pass the share: copies this frame does not want go
      // next (the cache still has them), then copies it needs less, then uploads wait.
      this->ReleaseUnwanted(order, n, found, gpuShare);
      if (overShare())
      {
        return true;
      }
    }
    Region& gpu = *found->second;
    while (
      !gpu.Ready() && resmr::MayCopyPiece(bounded, n < roots, pacer, gpu.NextPieceBytes(), this->GpuBytes, gpuShare))
    {
      const auto copyStart = std::chrono::steady_clock::now();
      const std::size_t bytes = gpu.UploadNextPiece(program, this->IndexScratch);
      pacer.Record(bytes, ElapsedMs(copyStart));
      this->GpuBytes += bytes;
    }
    if (!gpu.Ready())
    {
      return true;
    }
  }
  return false;
}

const resmr::RegionDrawBuffers* vtkMultiresolutionGpuRegions::Prepare(
  std::size_t region, const resmr::RegionCache& cache, vtkShaderProgram* program)
{
  const auto found = this->Find(region, cache);
  if (found == this->Regions.end())
  {
    return nullptr; // evicted since the selection: its ancestor is not drawn either this frame
  }
  Region& gpu = *found->second;
  if (!gpu.Ready())
  {
    const std::size_t before = gpu.Bytes;
    gpu.UploadRest(program, this->IndexScratch);
    this->GpuBytes += gpu.Bytes - before;
  }
  return gpu.Buffers.get();
}

const std::vector<std::array<float, 6>>& vtkMultiresolutionGpuRegions::ChunkBoxes(std::size_t region)
{
  Region& gpu = *this->Regions.at(region);
  if (gpu.ChunkBoxes.empty())
  {
    gpu.ChunkBoxes = resmr::TriangleChunkBoxes(*gpu.Buffers);
    this->BoxBytes += gpu.ChunkBoxes.size() * sizeof(std::array<float, 6>);
    this->Boxed.push_back(region);
    while (this->BoxBytes > resmr::MaxPickBoxBytes && this->Boxed.front() != region)
    {
      auto& boxes = this->Regions.at(this->Boxed.front())->ChunkBoxes;
      this->BoxBytes -= boxes.size() * sizeof(std::array<float, 6>);
      std::vector<std::array<float, 6>>().swap(boxes);
      this->Boxed.erase(this->Boxed.begin());
    }
  }
  return gpu.ChunkBoxes;
}

std::size_t vtkMultiresolutionGpuRegions::Draw(std::size_t region, const std::vector<resmr::DrawPart>& parts,
  vtkShaderProgram* program, vtkOpenGLRenderWindow* window, bool cull)
{
  vtkOpenGLState* state = window->GetState();
  Region& gpu = *this->Regions.at(region);
  const std::size_t faceBytes = gpu.UploadFaceValues(window);
  gpu.Bytes += faceBytes;
  this->GpuBytes += faceBytes;
  // The sampler always names a buffer texture: left on a unit that holds a texture of another
  // kind, it makes every draw an invalid operation.
  vtkTextureObject* faces = gpu.FaceTexture ? gpu.FaceTexture.Get() : this->NoFaceValues(window);
  faces->Activate();
  program->SetUniformi("faceValues", faces->GetTextureUnit());
  program->SetUniformi("faceValuesOn", gpu.FaceTexture ? 1 : 0);
  std::size_t triangles = 0;
  for (const auto& piece : gpu.Pieces)
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
        if (cull && part.cullBackFaces)
        {
          state->vtkglEnable(GL_CULL_FACE);
        }
        else
        {
          state->vtkglDisable(GL_CULL_FACE);
        }
        program->SetUniformi("faceKind", part.kind);
        program->SetUniformi("sideOneLayer", part.oneLayer ? 1 : 0);
        program->SetUniformi("primitiveBase", static_cast<int>(begin / 3)); // gl_PrimitiveID counts from 0
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(end - begin), GL_UNSIGNED_INT,
          reinterpret_cast<const void*>(std::size_t(begin - piece->first) * sizeof(uint32_t)));
        triangles += (end - begin) / 3;
      }
    }
    piece->indices->Release();
    piece->layout->Release();
  }
  faces->Deactivate();
  return triangles;
}

vtkTextureObject* vtkMultiresolutionGpuRegions::NoFaceValues(vtkOpenGLRenderWindow* window)
{
  if (!this->EmptyFaceTexture)
  {
    const std::vector<float> one{ 0.f };
    this->EmptyFaceBuffer->Upload(one, vtkOpenGLBufferObject::TextureBuffer);
    this->EmptyFaceTexture = vtkSmartPointer<vtkTextureObject>::New();
    this->EmptyFaceTexture->SetContext(window);
    this->EmptyFaceTexture->CreateTextureBuffer(1, 1, VTK_FLOAT, this->EmptyFaceBuffer);
  }
  return this->EmptyFaceTexture;
}

void vtkMultiresolutionGpuRegions::ReleaseGraphicsResources()
{
  if (this->EmptyFaceTexture)
  {
    this->EmptyFaceTexture->ReleaseGraphicsResources(this->EmptyFaceTexture->GetContext());
    this->EmptyFaceTexture = nullptr;
  }
  this->EmptyFaceBuffer->ReleaseGraphicsResources();
  for (auto& entry : this->Regions)
  {
    entry.second->Release();
  }
  this->Regions.clear();
  this->Boxed.clear();
  this->BoxBytes = 0;
  this->GpuBytes = 0;
}
