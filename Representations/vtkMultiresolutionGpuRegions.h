// The GPU mirror of the region cache (paper Sec. 6.1-6.2): the draw buffers of resident
// regions copied into GL buffers a piece at a time (resmr::DrawPieceCursor), so a frame's
// copies stay within the upload pacer's allowance, and a region drawn once all its pieces are
// on the GPU. The mirror follows the cache (a copy whose buffers the cache evicted goes) and
// stays within the GPU's share of the memory budget (resmr::GpuShare). Private to the
// Multiresolution Surface mapper; needs the mapper's GL context current.
#ifndef vtkMultiresolutionGpuRegions_h
#define vtkMultiresolutionGpuRegions_h

#include "Residency.h"

#include "vtkNew.h"
#include "vtkOpenGLBufferObject.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

class vtkOpenGLRenderWindow;
class vtkTextureObject;
class vtkShaderProgram;

namespace resmr
{
class RegionCache;
class UploadPacer;
}

class vtkMultiresolutionGpuRegions
{
public:
  vtkMultiresolutionGpuRegions();
  ~vtkMultiresolutionGpuRegions();
  vtkMultiresolutionGpuRegions(const vtkMultiresolutionGpuRegions&) = delete;
  vtkMultiresolutionGpuRegions& operator=(const vtkMultiresolutionGpuRegions&) = delete;

  /// Bytes of GL buffers held.
  std::size_t Bytes() const { return this->GpuBytes; }
  /// Whether all of a region's pieces are on the GPU.
  bool Ready(std::size_t region) const;

  /// Drops the copies whose buffers the cache no longer holds (evicted, or another layer's).
  void ReleaseEvicted(const resmr::RegionCache& cache);

  /// Copies the frame's regions, `order` (the `roots` roots first, then the wanted regions),
  /// piece by piece while resmr::MayCopyPiece allows (`bounded`: an interactive frame), within
  /// `gpuShare` bytes: copies the cache evicted meanwhile go first, then copies this frame
  /// does not want. Vertex layouts are bound against `program`. True when copies had to wait
  /// (the allowance or the share ran out) and the next frame will go on.
  bool Upload(const resmr::RegionCache& cache, const std::vector<std::size_t>& order, std::size_t roots, bool bounded,
    resmr::UploadPacer& pacer, std::size_t gpuShare, vtkShaderProgram* program);

  /// The buffers of a region about to be drawn, its copy completed now if the pacer left it
  /// unfinished; null when the cache no longer has it.
  const resmr::RegionDrawBuffers* Prepare(
    std::size_t region, const resmr::RegionCache& cache, vtkShaderProgram* program);
  /// Draws the shown parts of a Prepare'd region piece by piece, setting `faceKind` for each
  /// (and its face values' texture and first triangle, when the region has face values),
  /// with back faces culled where `cull` and the part allows it (DrawPart::cullBackFaces);
  /// the triangles drawn.
  std::size_t Draw(std::size_t region, const std::vector<resmr::DrawPart>& parts, vtkShaderProgram* program,
    vtkOpenGLRenderWindow* window, bool cull);
  /// The boxes of a Prepare'd region's triangle chunks (resmr::TriangleChunkBoxes), made at its
  /// first pick and kept with its copy, those of the regions picked longest ago dropped past
  /// resmr::MaxPickBoxBytes.
  const std::vector<std::array<float, 6>>& ChunkBoxes(std::size_t region);

  /// Frees every GL buffer.
  void ReleaseGraphicsResources();

private:
  class Region;
  using RegionMap = std::map<std::size_t, std::unique_ptr<Region>>;
  /// The region's copy, started from the cache's buffers if it has none; end() if neither.
  RegionMap::iterator Find(std::size_t region, const resmr::RegionCache& cache);
  void Erase(RegionMap::iterator entry);
  /// Frees copies not in `order`, then those after `position` in it, until the next piece of
  /// `entry` fits `gpuShare`.
  void ReleaseUnwanted(
    const std::vector<std::size_t>& order, std::size_t position, RegionMap::iterator entry, std::size_t gpuShare);

  /// A one-value buffer texture for the regions without face values (see Draw).
  vtkTextureObject* NoFaceValues(vtkOpenGLRenderWindow* window);

  RegionMap Regions;
  std::size_t GpuBytes = 0;
  std::vector<uint32_t> IndexScratch; ///< a piece's rebased indices, kept from piece to piece
  std::vector<std::size_t> Boxed;     ///< regions holding chunk boxes, picked longest ago first
  std::size_t BoxBytes = 0;
  vtkNew<vtkOpenGLBufferObject> EmptyFaceBuffer;
  vtkSmartPointer<vtkTextureObject> EmptyFaceTexture;
};

#endif
