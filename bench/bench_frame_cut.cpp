// The triangles one frame of the Multiresolution Surface draws, written as a legacy VTK
// polydata file, so stock ParaView can draw the very same geometry (bench/run_frame_peer.py).
// The cut is the ideal one (every region resident) at the given tolerance and camera, with
// the parts the mapper draws for it (PartsToDraw: the normal cones' culling, the simplified
// side where its error allows); a cell array names each triangle's cell.
//
//   bench_frame_cut FILE.resmr OUT.vtk TOLERANCE_PX VIEWPORT_HEIGHT VIEW_ANGLE NEAR
//       EYE_X EYE_Y EYE_Z DOP_X DOP_Y DOP_Z M00 M01 ... M33
//
// M: the world-to-clip matrix, row-major (vtkCamera::GetCompositeProjectionTransformMatrix).
// Prints one JSON line: regions, triangles by part, and the file written.
#include "CornerPointGeometry.h"
#include "MultiresolutionFile.h"
#include "RegionCache.h"
#include "Residency.h"
#include "ViewSelection.h"
#include "ViewTransforms.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace
{
/// Legacy VTK binary files are big-endian.
template<typename T>
void WriteBigEndian(std::ofstream& out, const std::vector<T>& values)
{
  std::vector<char> bytes(values.size() * sizeof(T));
  for (std::size_t n = 0; n < values.size(); ++n)
  {
    const char* v = reinterpret_cast<const char*>(&values[n]);
    for (std::size_t b = 0; b < sizeof(T); ++b)
    {
      bytes[n * sizeof(T) + b] = v[sizeof(T) - 1 - b];
    }
  }
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

struct Cut
{
  std::vector<float> points;
  std::vector<int32_t> polys; ///< 3, a, b, c per triangle
  std::vector<int32_t> cells; ///< the triangle's cell, i + ni * (j + nj * k)
  std::size_t parts[3] = { 0, 0, 0 };
};

void AddPart(
  const resmr::RegionDrawBuffers& buffers, const resmr::DrawPart& part, const std::array<int64_t, 3>& dims, Cut& cut)
{
  for (uint32_t n = part.first; n + 3 <= part.first + part.count; n += 3)
  {
    const int32_t first = static_cast<int32_t>(cut.points.size() / 3);
    double centre[3] = { 0, 0, 0 };
    for (int v = 0; v < 3; ++v)
    {
      const float* vertex = &buffers.vertices[std::size_t(buffers.indices[n + v]) * 6];
      cut.points.insert(cut.points.end(), vertex, vertex + 3);
      for (int a = 0; a < 3; ++a)
      {
        centre[a] += vertex[3 + a] / 3.0;
      }
    }
    cut.polys.insert(cut.polys.end(), { 3, first, first + 1, first + 2 });
    int64_t c[3];
    for (int a = 0; a < 3; ++a)
    {
      c[a] = std::min<int64_t>(std::max<int64_t>(static_cast<int64_t>(std::floor(centre[a])), 0), dims[a] - 1);
    }
    cut.cells.push_back(static_cast<int32_t>((c[0] + dims[0] * (c[1] + dims[1] * c[2])) % 2147483647));
    ++cut.parts[part.kind];
  }
}
} // namespace

int main(int argc, char** argv)
{
  if (argc != 29)
  {
    std::fprintf(stderr,
      "usage: %s FILE.resmr OUT.vtk TOLERANCE_PX VIEWPORT_HEIGHT VIEW_ANGLE NEAR "
      "EYE(3) DOP(3) WORLD_TO_CLIP(16, row-major)\n",
      argv[0]);
    return 2;
  }
  try
  {
    const resmr::MultiresolutionFile file(argv[1]);
    resmr::CameraState camera;
    camera.viewportHeight = std::atof(argv[4]);
    camera.viewAngleDegrees = std::atof(argv[5]);
    camera.nearClip = std::atof(argv[6]);
    for (int a = 0; a < 3; ++a)
    {
      camera.position[a] = std::atof(argv[7 + a]);
      camera.directionOfProjection[a] = std::atof(argv[10 + a]);
    }
    for (int e = 0; e < 16; ++e)
    {
      camera.worldToClip[e] = std::atof(argv[13 + e]);
    }
    resmr::Matrix4 modelToWorld = resmr::IdentityMatrix();
    std::array<double, 6> map;
    if (resmr::CornerPointGeometry::PlacementTransform(file.Header().map, map))
    {
      modelToWorld = resmr::PlacementMatrix(map);
    }
    resmr::ViewParameters view = resmr::ViewFromCamera(camera, modelToWorld);
    view.tolerancePixels = std::atof(argv[3]);
    const resmr::ViewSelector selector(file);
    const resmr::ViewSelection selection = selector.Select(view, [](std::size_t) { return true; });
    const int handedness = resmr::TopologyHandedness(file);
    const std::array<int64_t, 3> dims{ file.Header().dims[0], file.Header().dims[1], file.Header().dims[2] };
    const uint32_t version = file.Header().version;
    Cut cut;
    for (const resmr::DrawnRegion& drawn : selection.drawn)
    {
      const resmr::RegionRecord& record = file.Regions()[drawn.region];
      const bool exactSides = !resmr::DrawsSimplifiedSide(version, drawn.projectedError, view);
      const resmr::RegionDrawBuffers buffers =
        resmr::LoadRegionDrawBuffers(file, drawn.region, { 0, 0, 0 }, handedness, -1, exactSides);
      for (const resmr::DrawPart& part : resmr::PartsToDraw(buffers, drawn, false, record, view, version))
      {
        if (part.shown)
        {
          AddPart(buffers, part, dims, cut);
        }
      }
    }
    const std::size_t triangles = cut.cells.size();
    std::ofstream out(argv[2], std::ios::binary);
    out << "# vtk DataFile Version 3.0\nbench_frame_cut\nBINARY\nDATASET POLYDATA\n";
    out << "POINTS " << cut.points.size() / 3 << " float\n";
    WriteBigEndian(out, cut.points);
    out << "\nPOLYGONS " << triangles << " " << cut.polys.size() << "\n";
    WriteBigEndian(out, cut.polys);
    out << "\nCELL_DATA " << triangles << "\nSCALARS cell int 1\nLOOKUP_TABLE default\n";
    WriteBigEndian(out, cut.cells);
    out << "\n";
    if (!out)
    {
      std::fprintf(stderr, "bench_frame_cut: cannot write %s\n", argv[2]);
      return 1;
    }
    std::printf("{\"regions\": %zu, \"triangles\": %zu, \"top\": %zu, \"bottom\": %zu, \"side\": %zu, "
                "\"estimated_px\": %.4f, \"largest_px\": %.4f, \"back_faces_hidden\": %s}\n",
      selection.drawn.size(), triangles, cut.parts[0], cut.parts[1], cut.parts[2], selection.estimatedErrorPixels,
      selection.largestProjectedError, selection.backFacesHidden ? "true" : "false");
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "bench_frame_cut: %s\n", error.what());
    return 1;
  }
  return 0;
}
