// External surfaces of a region mesh for the whole-model and single-layer views, paper Sec. 4.3
// (and Sec. 6.1: normal cones of top and bottom meshes for back-face culling).
#include "RegionMesh.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace resmr
{
namespace
{
glm::dvec3 ZUp(const RegionMesh& mesh, uint32_t vertex)
{
  const double* p = &mesh.positions[static_cast<std::size_t>(vertex) * 3];
  return { p[0], p[1], -p[2] };
}

/// Columns across each edge (-1: none), found through the edge's two nodes.
std::vector<std::array<int64_t, 4>> EdgeNeighbours(const RegionMesh& mesh)
{
  std::unordered_map<uint64_t, int64_t> edges;
  edges.reserve(mesh.corners.size() * 4);
  std::vector<std::array<int64_t, 4>> across(mesh.corners.size(), { -1, -1, -1, -1 });
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      const uint64_t a = mesh.corners[c][e], b = mesh.corners[c][(e + 1) % 4];
      const uint64_t key = (std::min(a, b) << 32) | std::max(a, b);
      const auto inserted = edges.emplace(key, static_cast<int64_t>(c * 4 + e));
      if (!inserted.second)
      {
        const int64_t other = inserted.first->second;
        across[c][e] = other / 4;
        across[other / 4][other % 4] = static_cast<int64_t>(c);
      }
    }
  }
  return across;
}

void AddTopBottom(
  const RegionMesh& mesh, std::size_t column, int32_t interface, bool top, int orientation, RegionSurface& surface)
{
  const auto& q = mesh.corners[column];
  std::array<uint32_t, 4> quad;
  // Counter-clockwise from above is outward for a top face, inward for a bottom face.
  const bool reverse = (orientation > 0) != top;
  for (int i = 0; i < 4; ++i)
  {
    quad[i] = mesh.Vertex(q[reverse ? 3 - i : i], interface);
  }
  surface.quads.push_back(quad);
}

void AddSide(
  const RegionMesh& mesh, std::size_t column, int edge, int32_t layer, int orientation, RegionSurface& surface)
{
  uint32_t a = mesh.corners[column][edge], b = mesh.corners[column][(edge + 1) % 4];
  if (orientation < 0)
  {
    std::swap(a, b);
  }
  // The column lies left of a -> b seen from above: a-top, a-bottom, b-bottom, b-top faces right.
  surface.quads.push_back(
    { mesh.Vertex(a, layer), mesh.Vertex(a, layer + 1), mesh.Vertex(b, layer + 1), mesh.Vertex(b, layer) });
}

/// Cells of the pinched-out runs to seal (see RegionMesh.h), one flag a cell: inactive runs
/// between two active cells of the column, no thicker than the region's error at any corner,
/// in columns without a cut edge (so that two regions always agree on the faces between them).
std::vector<uint8_t> SealedCells(const RegionMesh& mesh)
{
  const std::size_t layers = static_cast<std::size_t>(mesh.layers);
  std::vector<uint8_t> sealed(mesh.corners.size() * layers, 0);
  if (!(mesh.sealedPinchThickness > 0) || mesh.cutEdges.size() != mesh.corners.size() ||
    mesh.openSides.size() != sealed.size())
  {
    return sealed;
  }
  const auto depth = [&](uint32_t node, std::size_t interface) {
    return mesh.positions[static_cast<std::size_t>(mesh.Vertex(node, static_cast<int32_t>(interface))) * 3 + 2];
  };
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    if (mesh.cutEdges[c])
    {
      continue;
    }
    const uint8_t* active = &mesh.active[c * layers];
    for (std::size_t k = 1; k + 1 < layers; ++k)
    {
      if (active[k] || !active[k - 1])
      {
        continue;
      }
      std::size_t end = k; // one past the run
      while (end < layers && !active[end])
      {
        ++end;
      }
      if (end < layers)
      {
        double thickest = 0;
        for (const uint32_t node : mesh.corners[c])
        {
          const double thickness = depth(node, end) - depth(node, k);
          thickest = std::isfinite(thickness) ? std::max(thickest, thickness) : HUGE_VAL;
        }
        if (thickest <= mesh.sealedPinchThickness)
        {
          std::fill(&sealed[c * layers + k], &sealed[c * layers + end], uint8_t(1));
        }
      }
      k = end;
    }
  }
  return sealed;
}

void ComputeCone(const RegionMesh& mesh, RegionSurface& surface)
{
  std::vector<glm::dvec3> normals;
  normals.reserve(surface.quads.size());
  glm::dvec3 sum(0.0);
  for (const auto& q : surface.quads)
  {
    const glm::dvec3 n = glm::cross(ZUp(mesh, q[2]) - ZUp(mesh, q[0]), ZUp(mesh, q[3]) - ZUp(mesh, q[1]));
    const double length = glm::length(n);
    if (length > 0 && std::isfinite(length))
    {
      normals.push_back(n / length);
      sum += n / length;
    }
  }
  const double length = glm::length(sum);
  if (normals.empty() || !(length > 0))
  {
    surface.cone = { 0.f, 0.f, 1.f, normals.empty() ? -2.f : -1.f };
    return;
  }
  const glm::dvec3 axis = sum / length;
  double lowest = 1.0;
  for (const auto& n : normals)
  {
    lowest = std::min(lowest, glm::dot(n, axis));
  }
  // Rounded outward so the cone still holds every normal after the cast to float.
  surface.cone = { static_cast<float>(axis.x), static_cast<float>(axis.y), static_cast<float>(axis.z),
    static_cast<float>(std::max(-1.0, lowest - 1e-6)) };
}
} // namespace

void ComputeOpenSides(RegionMesh& mesh)
{
  const std::size_t layers = static_cast<std::size_t>(mesh.layers);
  mesh.openSides.resize(mesh.corners.size() * layers, 0);
  const auto across = EdgeNeighbours(mesh);
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    for (int e = 0; e < 4; ++e)
    {
      if (mesh.cutEdges[c] & (1u << e))
      {
        continue;
      }
      const int64_t other = across[c][e];
      for (std::size_t k = 0; k < layers; ++k)
      {
        uint8_t& flags = mesh.openSides[c * layers + k];
        const bool open = other < 0 || !mesh.active[static_cast<std::size_t>(other) * layers + k];
        flags = static_cast<uint8_t>(open ? flags | (1u << e) : flags & ~(1u << e));
      }
    }
  }
}

std::array<float, 4> TopologyBox(const RegionMesh& mesh)
{
  if (mesh.corners.empty())
  {
    return { 0.f, -1.f, 0.f, -1.f };
  }
  std::array<float, 4> box{ HUGE_VALF, -HUGE_VALF, HUGE_VALF, -HUGE_VALF };
  for (const auto& corners : mesh.corners)
  {
    for (const uint32_t node : corners)
    {
      const auto& t = mesh.topology[node];
      box = { std::min(box[0], t[0]), std::max(box[1], t[0]), std::min(box[2], t[1]), std::max(box[3], t[1]) };
    }
  }
  return box;
}

int RegionOrientation(const RegionMesh& mesh)
{
  double area = 0;
  for (const auto& q : mesh.corners)
  {
    for (int e = 0; e < 4; ++e)
    {
      const double* a = &mesh.positions[static_cast<std::size_t>(mesh.Vertex(q[e], 0)) * 3];
      const double* b = &mesh.positions[static_cast<std::size_t>(mesh.Vertex(q[(e + 1) % 4], 0)) * 3];
      area += a[0] * b[1] - b[0] * a[1];
    }
  }
  return area >= 0 ? 1 : -1;
}

void ExtractSurfaces(RegionMesh& mesh)
{
  mesh.top = {};
  mesh.bottom = {};
  mesh.side = {};
  const int orientation = RegionOrientation(mesh);
  const int32_t layers = mesh.layers;
  const std::vector<uint8_t> sealed = SealedCells(mesh);
  const bool sealing = std::find(sealed.begin(), sealed.end(), 1) != sealed.end();
  const auto across = sealing ? EdgeNeighbours(mesh) : std::vector<std::array<int64_t, 4>>{};
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    const std::size_t cells = c * static_cast<std::size_t>(layers);
    const uint8_t* active = &mesh.active[cells];
    for (int32_t k = 0; k < layers; ++k)
    {
      if (!active[k] && !sealed[cells + k])
      {
        continue;
      }
      if (active[k] && (k == 0 || !(active[k - 1] || sealed[cells + k - 1])))
      {
        AddTopBottom(mesh, c, k, true, orientation, mesh.top);
      }
      if (active[k] && (k == layers - 1 || !(active[k + 1] || sealed[cells + k + 1])))
      {
        AddTopBottom(mesh, c, k + 1, false, orientation, mesh.bottom);
      }
      for (int e = 0; e < 4; ++e)
      {
        // Solid across (a sealed cell, or for a sealed cell an active one): the face is
        // inside. No cell next to a cut edge is sealed, on either side of it.
        const bool open = mesh.openSides[cells + k] & (1u << e);
        const int64_t other = sealing ? across[c][e] : -1;
        const bool solidAcross = other >= 0 && sealed[static_cast<std::size_t>(other) * layers + k];
        if (open && !solidAcross)
        {
          AddSide(mesh, c, e, k, orientation, mesh.side);
        }
      }
    }
  }
  ComputeCone(mesh, mesh.top);
  ComputeCone(mesh, mesh.bottom);
}

void ExtractLayerSurfaces(
  const RegionMesh& mesh, int32_t layer, RegionSurface& top, RegionSurface& bottom, RegionSurface& side)
{
  top = {};
  bottom = {};
  side = {};
  const int orientation = RegionOrientation(mesh);
  for (std::size_t c = 0; c < mesh.corners.size(); ++c)
  {
    const std::size_t cell = c * static_cast<std::size_t>(mesh.layers) + layer;
    if (!mesh.active[cell])
    {
      continue;
    }
    AddTopBottom(mesh, c, layer, true, orientation, top);
    AddTopBottom(mesh, c, layer + 1, false, orientation, bottom);
    for (int e = 0; e < 4; ++e)
    {
      if (mesh.openSides[cell] & (1u << e))
      {
        AddSide(mesh, c, e, layer, orientation, side);
      }
    }
  }
  ComputeCone(mesh, top);
  ComputeCone(mesh, bottom);
}

} // namespace resmr
