// Residency and stand-ins (paper Sec. 6.2); see Residency.h.
#include "Residency.h"

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
  const std::set<std::size_t>& wanted, std::size_t gpuBytes, std::size_t pieceBytes, std::size_t gpuShare)
{
  std::vector<std::size_t> release;
  for (const auto& copy : mirrored)
  {
    if (gpuBytes + pieceBytes <= gpuShare)
    {
      break;
    }
    if (wanted.count(copy.first) == 0)
    {
      release.push_back(copy.first);
      gpuBytes -= copy.second;
    }
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

std::array<DrawPart, 3> PartsToDraw(const RegionDrawBuffers& buffers, const DrawnRegion& drawn, bool layerView,
  const RegionRecord& region, const ViewParameters& view)
{
  const bool top = !layerView ? drawn.top : !SurfaceCulled(buffers.topCone, region, view);
  const bool bottom = !layerView ? drawn.bottom : !SurfaceCulled(buffers.bottomCone, region, view);
  const bool coarseSide = buffers.coarseSideIndices > 0 && drawn.projectedError > CoarseSidePixels;
  const uint32_t exactSide = buffers.topIndices + buffers.bottomIndices;
  DrawPart side{ drawn.side, exactSide, buffers.sideIndices, 2 };
  if (coarseSide)
  {
    side = DrawPart{ drawn.side, exactSide + buffers.sideIndices, buffers.coarseSideIndices, 2 };
  }
  return { DrawPart{ top, 0, buffers.topIndices, 0 }, DrawPart{ bottom, buffers.topIndices, buffers.bottomIndices, 1 },
    side };
}

} // namespace resmr
