// Residency and stand-ins (paper Sec. 6.2); see Residency.h.
#include "Residency.h"

#include <algorithm>
#include <map>

namespace resmr
{

std::size_t MainMemoryShare(int budgetMB)
{
  return (std::size_t(budgetMB) << 20) / 2;
}

std::size_t GpuShare(int budgetMB)
{
  return (std::size_t(budgetMB) << 20) - MainMemoryShare(budgetMB);
}

std::vector<std::size_t> CopiesToRelease(const std::vector<std::pair<std::size_t, std::size_t>>& mirrored,
  const std::vector<std::size_t>& order, std::size_t position, std::size_t gpuBytes, std::size_t pieceBytes,
  std::size_t gpuShare)
{
  std::map<std::size_t, std::size_t> rank; // a region's first place in the order
  for (std::size_t n = order.size(); n-- > 0;)
  {
    rank[order[n]] = n;
  }
  std::vector<std::pair<std::size_t, std::size_t>> later; // (rank, bytes) of copies after `position`
  std::vector<std::size_t> release;
  for (const auto& copy : mirrored)
  {
    const auto found = rank.find(copy.first);
    if (found == rank.end())
    {
      if (gpuBytes + pieceBytes > gpuShare)
      {
        release.push_back(copy.first);
        gpuBytes -= copy.second;
      }
    }
    else if (found->second > position)
    {
      later.emplace_back(found->second, copy.second);
    }
  }
  std::sort(later.rbegin(), later.rend());
  for (const auto& copy : later)
  {
    if (gpuBytes + pieceBytes <= gpuShare)
    {
      break;
    }
    release.push_back(order[copy.first]);
    gpuBytes -= copy.second;
  }
  return release;
}

PropertyRequest RequestFor(const PropertyFile* properties, const std::string& name, int32_t step, int32_t layer)
{
  PropertyRequest request;
  request.name = name;
  request.step = step;
  request.layer = layer;
  if (properties && !name.empty())
  {
    request.step = properties->Find(name, step) >= 0 ? step : -1;
    request.wanted = properties->Find(name, request.step) >= 0;
  }
  return request;
}

bool IsRequested(const PropertyTableData* table, const PropertyRequest& request)
{
  return table && table->name == request.name && table->step == request.step && table->layer == request.layer;
}

bool MayStandIn(const PropertyTableData* table, const PropertyRequest& request)
{
  return request.wanted && table && table->name == request.name && table->layer == request.layer;
}

bool DrawsSimplifiedSide(uint32_t fileVersion, double projectedError, const ViewParameters& view)
{
  // The simplified side strays from the exact one by up to the region's own error: from
  // SidesInPlaceVersion on it is also drawn in frames coarser than CoarseSidePixels where
  // that error, twice over, still projects within the tolerance.
  return projectedError > CoarseSidePixels ||
    (fileVersion >= MultiresolutionHeader::SidesInPlaceVersion && view.tolerancePixels > CoarseSidePixels &&
      2 * projectedError <= view.tolerancePixels);
}

std::vector<std::size_t> RegionsWithSimplifiedSide(
  const MultiresolutionFile& file, const std::vector<std::size_t>& regions, const ViewParameters& view)
{
  std::vector<std::size_t> simplified;
  for (std::size_t r : regions)
  {
    if (r < file.Regions().size() &&
      DrawsSimplifiedSide(file.Header().version, ProjectedErrorPixels(file.Regions()[r], view), view))
    {
      simplified.push_back(r);
    }
  }
  return simplified;
}

std::array<DrawPart, 3> PartsToDraw(const RegionDrawBuffers& buffers, const DrawnRegion& drawn, bool layerView,
  const RegionRecord& region, const ViewParameters& view, uint32_t fileVersion)
{
  const bool ownCones = layerView || buffers.ranged; // faces that are not the stored surfaces
  const bool top = !ownCones ? drawn.top : !SurfaceCulled(buffers.topCone, region, view);
  const bool bottom = !ownCones ? drawn.bottom : !SurfaceCulled(buffers.bottomCone, region, view);
  const bool coarseSide = buffers.coarseSideIndices > 0 &&
    (DrawsSimplifiedSide(fileVersion, drawn.projectedError, view) || !buffers.exactSides);
  const uint32_t exactSide = buffers.topIndices + buffers.bottomIndices;
  DrawPart side{ drawn.side, exactSide, buffers.sideIndices, 2, true };
  if (coarseSide)
  {
    side = DrawPart{ drawn.side, exactSide + buffers.sideIndices, buffers.coarseSideIndices, 2 };
  }
  // Parallel views look from below when their direction points up.
  const bool eyeBelow = view.parallel ? view.direction[2] > 0 : view.eye[2] < -static_cast<double>(region.bounds[5]);
  const bool eyeAbove = view.parallel ? view.direction[2] < 0 : view.eye[2] > -static_cast<double>(region.bounds[2]);
  DrawPart topPart{ top, 0, buffers.topIndices, 0 }, bottomPart{ bottom, buffers.topIndices, buffers.bottomIndices, 1 };
  topPart.cullBackFaces = eyeBelow;
  bottomPart.cullBackFaces = eyeAbove;
  return { topPart, bottomPart, side };
}

} // namespace resmr
