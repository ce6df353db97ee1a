// resmr simplify: column-collapse simplification of a model (paper Sec. 4.1) with its quality
// measures, optionally side by side with uniform b x b coarsening at the same column count.
#include "ResmrCommands.h"

#include "AtomicOutputFile.h"

#include "ColumnCollapse.h"
#include "ColumnMesh.h"
#include "CornerPointGeometry.h"
#include "EclipseGrid.h"
#include "GrdeclParser.h"
#include "LayerSource.h"
#include "MeshQuality.h"
#include "SyntheticReservoir.h"
#include "UniformCoarsening.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <sys/resource.h>

namespace
{
const char* SimplifyUsage =
  "usage: resmr simplify MODEL [--fraction F | --columns N | --uniform B] [--seed S] [--no-hausdorff]\n"
  "  MODEL: an EGRID, a GRDECL/DATA deck, or synth:NIxNJxNK[:SEED] (generated in memory)\n"
  "  --fraction F   keep this fraction of the columns (default 0.1)\n"
  "  --columns N    keep N columns\n"
  "  --candidates N random candidates weighed per collapse (default 8, as the paper)\n"
  "  --greedy       always the cheapest collapse of the whole mesh (a priority queue)\n"
  "  --uniform B    also coarsen uniformly by B x B column blocks and simplify to the same\n"
  "                 column count, reporting both\n"
  "  --top-obj F    also write the simplified top surface (z up) as a Wavefront OBJ\n"
  "  Prints JSON: counts, operators used, quality (scaled Jacobian, inverted cells, lateral\n"
  "  valence, quadric error, boundary Hausdorff distance to the original), time.\n";

struct Model
{
  resmr::CornerPointModel deck;
  std::vector<bool> active;
};

Model Load(const std::string& source)
{
  Model model;
  if (resmr::IsSyntheticSpec(source))
  {
    const resmr::SyntheticParameters p = resmr::ParseSyntheticSpec(source);
    const resmr::SyntheticReservoir reservoir(p);
    model.deck.dims = { p.nx, p.ny, p.nz };
    model.deck.coord = reservoir.Coord();
    model.deck.zcornSingle.resize(static_cast<std::size_t>(8 * p.CellCount()));
    model.active.resize(static_cast<std::size_t>(p.CellCount()));
    resmr::SyntheticLayerStream stream(reservoir);
    resmr::SyntheticLayer layer;
    const int64_t columns = p.nx * p.ny;
    while (stream.Next(layer))
    {
      std::copy(layer.zcorn.begin(), layer.zcorn.end(), model.deck.zcornSingle.begin() + 8 * columns * layer.k);
      for (int64_t c = 0; c < columns; ++c)
      {
        model.active[layer.k * columns + c] = layer.state[c] == resmr::SyntheticCellState::Active;
      }
    }
    return model;
  }
  resmr::ReadCornerPointModel(source, model.deck, model.active);
  return model;
}

std::string QualityJson(const resmr::HexQuality& q)
{
  char text[256];
  std::snprintf(text, sizeof(text),
    "{\"cells\": %lld, \"degenerate\": %lld, \"inverted\": %lld, \"min_scaled_jacobian\": %.6f, "
    "\"mean_scaled_jacobian\": %.6f}",
    static_cast<long long>(q.cells), static_cast<long long>(q.degenerate), static_cast<long long>(q.inverted),
    q.minScaledJacobian, q.meanScaledJacobian);
  return text;
}

std::string DistanceJson(const resmr::BoundaryDistance& d)
{
  char text[512];
  std::snprintf(text, sizeof(text),
    "{\"hausdorff\": %.6g, \"relative\": %.6g, \"forward\": %.6g, \"backward\": %.6g, \"diagonal\": %.6g, "
    "\"samples\": %lld, \"worst_forward\": [%.2f, %.2f, %.2f], \"worst_backward\": [%.2f, %.2f, %.2f]}",
    d.hausdorff, d.relative, d.forward, d.backward, d.diagonal, static_cast<long long>(d.samples), d.worstForward[0],
    d.worstForward[1], d.worstForward[2], d.worstBackward[0], d.worstBackward[1], d.worstBackward[2]);
  return text;
}

int MaxValence(const resmr::ColumnMesh& mesh)
{
  int largest = 0;
  for (int32_t node = 0; node < mesh.NodeCount(); ++node)
  {
    if (mesh.IsNodeAlive(node) && !mesh.NodeColumns(node).empty())
    {
      largest = std::max(largest, mesh.LateralValence(node));
    }
  }
  return largest;
}
/// The top interface of every column as a quad, z up, for a look at the mesh from above;
/// written to a temporary and renamed, so a failed write leaves nothing half-written.
void WriteTopSurface(const resmr::ColumnMesh& mesh, const std::string& path)
{
  resmr::AtomicOutputFile out(path);
  std::vector<int32_t> index(static_cast<std::size_t>(mesh.NodeCount()), -1);
  int32_t next = 1;
  char line[160];
  auto put = [&](int length) {
    if (!out.Write(line, static_cast<std::size_t>(length)))
    {
      throw std::runtime_error(path + ": write failed");
    }
  };
  for (int32_t column = 0; column < mesh.ColumnSlots(); ++column)
  {
    if (!mesh.IsColumnAlive(column))
    {
      continue;
    }
    const auto& q = mesh.ColumnCorners(column);
    for (int32_t node : q)
    {
      if (index[node] < 0)
      {
        index[node] = next++;
        const glm::dvec3 p = mesh.Position(node, 0);
        put(std::snprintf(line, sizeof(line), "v %.3f %.3f %.3f\n", p.x, p.y, -p.z));
      }
    }
    put(std::snprintf(line, sizeof(line), "f %d %d %d %d\n", index[q[0]], index[q[1]], index[q[2]], index[q[3]]));
  }
  out.Commit();
}
} // namespace

int SimplifyCommand(int argc, char** argv)
{
  std::string source;
  double fraction = 0.1;
  long long columns = -1, uniform = 0;
  unsigned long long seed = 1;
  bool hausdorff = true;
  int candidates = 8;
  bool greedy = false;
  std::string topObj;
  try
  {
    for (int a = 2; a < argc; ++a)
    {
      const std::string option = argv[a];
      auto value = [&]() { return OptionValue(a, argc, argv); };
      if (option == "--fraction")
        fraction = std::atof(value());
      else if (option == "--columns")
        columns = std::atoll(value());
      else if (option == "--uniform")
        uniform = std::atoll(value());
      else if (option == "--seed")
        seed = std::strtoull(value(), nullptr, 10);
      else if (option == "--candidates")
        candidates = std::atoi(value());
      else if (option == "--greedy")
        greedy = true;
      else if (option == "--top-obj")
        topObj = value();
      else if (option == "--no-hausdorff")
        hausdorff = false;
      else if (option == "-h" || option == "--help")
      {
        std::fputs(SimplifyUsage, stdout);
        return 0;
      }
      else if (option.size() > 1 && option[0] == '-')
        throw std::invalid_argument("unknown option " + option);
      else
        source = option;
    }
    if (source.empty())
    {
      std::fputs(SimplifyUsage, stderr);
      return 2;
    }
    if (!(fraction > 0 && fraction <= 1))
    {
      throw std::invalid_argument("--fraction must be in (0, 1]");
    }
    Model model = Load(source);
    const resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(model.deck, false);
    const auto start = std::chrono::steady_clock::now();
    resmr::ColumnMesh mesh = resmr::ColumnMesh::FromCornerPoints(geometry, model.active);
    const auto built = std::chrono::steady_clock::now();
    const resmr::HexMesh original = resmr::ToHexMesh(mesh);
    const int64_t before = mesh.AliveColumns();
    const int64_t parts = mesh.ConnectedParts();
    resmr::HexMesh coarse;
    int64_t target =
      columns >= 0 ? columns : static_cast<int64_t>(std::llround(fraction * static_cast<double>(before)));
    if (uniform > 0)
    {
      coarse = resmr::CoarsenUniformly(geometry, model.active, uniform);
      target = coarse.CellCount() / std::max<int64_t>(1, coarse.layers);
    }
    const auto simplifyStart = std::chrono::steady_clock::now();
    resmr::ColumnCollapse collapse(mesh, seed);
    collapse.SetCandidates(candidates);
    const resmr::SimplifyReport report = greedy ? collapse.SimplifyGreedy(target) : collapse.Simplify(target);
    const auto done = std::chrono::steady_clock::now();
    const resmr::HexMesh simplified = resmr::ToHexMesh(mesh);
    if (!topObj.empty())
    {
      WriteTopSurface(mesh, topObj);
    }
    const double buildSeconds = std::chrono::duration<double>(built - start).count();
    const double simplifySeconds = std::chrono::duration<double>(done - simplifyStart).count();
    const int64_t inputCells = before * mesh.Layers();

    std::printf("{\"input\": \"%s\", \"dims\": [%lld, %lld, %lld], \"layers\": %d, \"columns_before\": %lld, "
                "\"cells_before\": %lld, \"connected_parts\": %lld, \"target_columns\": %lld, \"columns_after\": %lld, "
                "\"connected_parts_after\": %lld, \"cells_after\": %lld, "
                "\"reached_target\": %s, \"collapses\": %lld, \"doublets\": %lld, "
                "\"operators\": {\"internal\": %lld, \"boundary\": %lld, \"corner\": %lld, \"four_boundary\": %lld, "
                "\"doublet\": %lld, \"strip\": %lld, \"chord\": %lld}, \"rejected_foldover\": %lld, "
                "\"rejected_inverted\": %lld, \"rejected_topology\": %lld, "
                "\"relaxations\": %lld, \"rotations\": %lld, \"straightened_columns\": %lld, "
                "\"straightened_max_move\": %.3f, \"inverted_columns_collapsed\": %lld, \"max_quadric_error\": %.6g, "
                "\"max_lateral_valence\": %d, \"seconds_build\": %.3f, "
                "\"seconds_simplify\": %.3f, \"input_cells_per_second\": %.0f",
      source.c_str(), static_cast<long long>(model.deck.dims[0]), static_cast<long long>(model.deck.dims[1]),
      static_cast<long long>(model.deck.dims[2]), mesh.Layers(), static_cast<long long>(before),
      static_cast<long long>(inputCells), static_cast<long long>(parts), static_cast<long long>(target),
      static_cast<long long>(mesh.AliveColumns()), static_cast<long long>(mesh.ConnectedParts()),
      static_cast<long long>(mesh.CellCount()), report.reachedTarget ? "true" : "false",
      static_cast<long long>(report.collapses), static_cast<long long>(report.doublets),
      static_cast<long long>(report.operatorCounts[0]), static_cast<long long>(report.operatorCounts[1]),
      static_cast<long long>(report.operatorCounts[2]), static_cast<long long>(report.operatorCounts[3]),
      static_cast<long long>(report.operatorCounts[4]), static_cast<long long>(report.operatorCounts[5]),
      static_cast<long long>(report.operatorCounts[6]), static_cast<long long>(report.rejectedFoldOver),
      static_cast<long long>(report.rejectedInverted), static_cast<long long>(report.rejectedTopology),
      static_cast<long long>(report.relaxations), static_cast<long long>(report.rotations),
      static_cast<long long>(report.straightenedColumns), report.straightenedMove,
      static_cast<long long>(report.invertedColumnsCollapsed), report.maxError, MaxValence(mesh), buildSeconds,
      simplifySeconds, static_cast<double>(inputCells) / std::max(1e-9, buildSeconds + simplifySeconds));
    std::printf(", \"quality_before\": %s, \"quality_after\": %s",
      QualityJson(resmr::MeasureHexahedra(original, mesh.Orientation())).c_str(),
      QualityJson(resmr::MeasureHexahedra(simplified, mesh.Orientation())).c_str());
    if (hausdorff)
    {
      std::printf(
        ", \"boundary_distance\": %s", DistanceJson(resmr::MeasureBoundaryDistance(original, simplified)).c_str());
    }
    if (uniform > 0)
    {
      std::printf(", \"uniform\": {\"block\": %lld, \"columns\": %lld, \"quality\": %s", uniform,
        static_cast<long long>(coarse.CellCount() / std::max<int64_t>(1, coarse.layers)),
        QualityJson(resmr::MeasureHexahedra(coarse, mesh.Orientation())).c_str());
      if (hausdorff)
      {
        std::printf(
          ", \"boundary_distance\": %s", DistanceJson(resmr::MeasureBoundaryDistance(original, coarse)).c_str());
      }
      std::printf("}");
    }
    struct rusage usage;
    getrusage(RUSAGE_SELF, &usage);
    std::printf(", \"peak_rss_mb\": %.1f}\n", usage.ru_maxrss / 1024.0);
    return 0;
  }
  catch (const std::exception& error)
  {
    std::fprintf(stderr, "resmr simplify: error: %s\n", error.what());
    return 1;
  }
}
