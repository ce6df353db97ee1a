// Fuzz target for the .resmr reader (MultiresolutionFile: header, trailer, index) and its
// region decoder (ReadRegion of every region), with the model chunks (active flags of every
// layer, the perfect spatial hash and its cell and normal tables, the wall depth table).
//
// libFuzzer build (see run_fuzz.sh):
//   clang++ -fsanitize=fuzzer,address,undefined -std=c++17 -I Core Core/*.cpp FuzzResmrFile.cpp -llzo2
// Standalone replay build (ctest FuzzResmrFile.SeedCorpus): compile with
// -DRESMR_FUZZ_STANDALONE; the executable runs the target over every file (or every file in
// every directory) named on its command line; `--unpack IN OUT` writes a valid file with its
// chunks unpacked (how seeds/resmr/*.unpacked.resmr are made).
//
// Per input: the checksums are made right again (FuzzResmrRepair.h: chunk CRCs, index CRC,
// trailer, geometry id, header CRC; unpacked chunks compressed), the file is written to a
// private folder and opened, and each region is decoded, its mesh checked against the header
// and the index (the promises the viewer relies on) and its surfaces extracted again as the
// reader does. Expected outcomes: data, or a resmr::FileFormatError (or another
// std::exception) for bad input, a region's failure costing that region only. Anything else
// -- a crash, a sanitizer report, a hang, a runaway allocation or a broken invariant -- is a
// finding. Inputs whose name starts with "valid" must open and decode without an error.
#include "FuzzReplay.h"
#include "FuzzResmrRepair.h"
#include "MultiresolutionFile.h"
#include "RegionMesh.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

namespace
{
#ifdef RESMR_FUZZ_STANDALONE
std::string LastOutcome;
bool MustBeValid = false; // the replayed file's name starts with "valid"
#define RESMR_FUZZ_OUTCOME(text) (LastOutcome = (text))
#else
constexpr bool MustBeValid = false;
#define RESMR_FUZZ_OUTCOME(text) ((void)0)
#endif

[[noreturn]] void BrokenInvariant(const std::string& what)
{
  resmr_fuzz::BrokenInvariant("FuzzResmrFile", what);
}

/// What the viewer relies on in a decoded region (MultiresolutionFile.h, RegionMesh.h).
void CheckRegion(
  const resmr::MultiresolutionFile& file, const resmr::RegionRecord& record, const resmr::RegionMesh& mesh)
{
  if (!resmr_fuzz::InvariantsChecked())
  {
    return;
  }
  const auto& header = file.Header();
  const std::string region = "region (" + std::to_string(record.level) + ", " + std::to_string(record.index) + ")";
  if (mesh.layers != header.dims[2] || mesh.ColumnCount() != record.columns || mesh.VertexCount() != record.vertices)
  {
    BrokenInvariant(region + ": layers, columns or vertices disagree with the header or index");
  }
  if (mesh.positions.size() != static_cast<std::size_t>(mesh.VertexCount()) * 3 ||
    mesh.active.size() != static_cast<std::size_t>(mesh.ColumnCount() * mesh.layers) ||
    mesh.openSides.size() != mesh.active.size() || mesh.cutEdges.size() != mesh.corners.size())
  {
    BrokenInvariant(region + ": array sizes disagree");
  }
  for (double p : mesh.positions)
  {
    if (!std::isfinite(p))
    {
      BrokenInvariant(region + ": a position is not finite");
    }
  }
  for (const auto& corner : mesh.corners)
  {
    for (uint32_t node : corner)
    {
      if (node >= static_cast<uint64_t>(mesh.NodeCount()))
      {
        BrokenInvariant(region + ": a column names node " + std::to_string(node));
      }
    }
  }
  const uint64_t vertices = static_cast<uint64_t>(mesh.VertexCount());
  for (const resmr::RegionSurface* surface : { &mesh.top, &mesh.bottom })
  {
    for (const auto& quad : surface->quads)
    {
      for (uint32_t v : quad)
      {
        if (v >= vertices)
        {
          BrokenInvariant(region + ": a quad names vertex " + std::to_string(v));
        }
      }
    }
  }
  for (const auto& triangle : mesh.sideTriangles)
  {
    for (uint32_t v : triangle)
    {
      if (v >= vertices)
      {
        BrokenInvariant(region + ": a side triangle names vertex " + std::to_string(v));
      }
    }
  }
}

/// What an opened file's header promises (the fields a reader draws with).
void CheckHeader(const resmr::MultiresolutionFile& file)
{
  if (!resmr_fuzz::InvariantsChecked())
  {
    return;
  }
  const auto& h = file.Header();
  for (int a = 0; a < 3; ++a)
  {
    if (!(h.latticeStep[a] > 0) || !std::isfinite(h.latticeStep[a]) || !std::isfinite(h.latticeOrigin[a]) ||
      h.dims[a] <= 0)
    {
      BrokenInvariant("opened with lattice step " + std::to_string(h.latticeStep[a]) + ", origin " +
        std::to_string(h.latticeOrigin[a]) + " or dimension " + std::to_string(h.dims[a]) + " on axis " +
        std::to_string(a));
    }
  }
  if (!(h.box[0] < h.box[2]) || !(h.box[1] < h.box[3]) || !std::isfinite(h.box[0] + h.box[1] + h.box[2] + h.box[3]))
  {
    BrokenInvariant("opened with an empty or infinite hierarchy box");
  }
  int32_t deepest = -1;
  for (const auto& r : file.Regions())
  {
    deepest = std::max(deepest, r.level);
  }
  if (deepest != h.leafLevel)
  {
    BrokenInvariant(
      "opened with leaf level " + std::to_string(h.leafLevel) + ", deepest region at " + std::to_string(deepest));
  }
}

/// Decodes every region and model array; returns the number of parts refused.
int ReadEverything(const resmr::MultiresolutionFile& file, std::string& firstError)
{
  int refused = 0;
  const auto refuse = [&](const std::exception& error) {
    if (refused++ == 0)
    {
      firstError = error.what();
    }
  };
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
  {
    try
    {
      resmr::RegionMesh mesh = file.ReadRegion(r);
      CheckRegion(file, file.Regions()[r], mesh);
      // As the reader does with a loaded region.
      resmr::ExtractSurfaces(mesh);
      resmr::RegionSurface top, bottom, side;
      resmr::ExtractLayerSurfaces(mesh, 0, top, bottom, side);
    }
    catch (const resmr::FileFormatError& error)
    {
      refuse(error);
    }
  }
  const int64_t layers = file.Header().dims[2];
  for (int64_t k = 0; k < layers; ++k)
  {
    try
    {
      const auto flags = file.ReadActiveLayer(k);
      if (resmr_fuzz::InvariantsChecked() &&
        static_cast<int64_t>(flags.size()) != file.Header().dims[0] * file.Header().dims[1])
      {
        BrokenInvariant("active flags of layer " + std::to_string(k) + ": " + std::to_string(flags.size()) + " cells");
      }
    }
    catch (const resmr::FileFormatError& error)
    {
      refuse(error);
    }
  }
  try
  {
    file.ReadHash();
    file.ReadModelArray(resmr::ModelChunk::HashCells);
    file.ReadModelArray(resmr::ModelChunk::CellNormals);
  }
  catch (const resmr::FileFormatError& error)
  {
    refuse(error);
  }
  try
  {
    // The wall depth table: a damaged one costs only itself.
    const resmr::WallDepthTable walls = file.ReadWallDepths();
    const std::size_t stride = static_cast<std::size_t>(walls.layers + 1) * 3;
    if (!walls.Empty() && (walls.slots.size() != walls.hash.TableSize() || walls.texels.size() != walls.faces * stride))
    {
      BrokenInvariant("wall depth table of " + std::to_string(walls.slots.size()) + " slots for " +
        std::to_string(walls.hash.TableSize()) + ", " + std::to_string(walls.texels.size()) + " texel values");
    }
  }
  catch (const resmr::FileFormatError& error)
  {
    refuse(error);
  }
  return refused;
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size)
{
  static resmr_fuzz::ScratchInput input("input.resmr");
  static const resmr_fuzz::FileLayout layout = resmr_fuzz::ResmrLayout();
  const std::string& path = input.Write(resmr_fuzz::Repair(data, size, layout));
  try
  {
    const resmr::MultiresolutionFile file(path);
    CheckHeader(file);
    std::string firstError;
    const int refused = ReadEverything(file, firstError);
    if (MustBeValid && refused > 0)
    {
      BrokenInvariant("a valid seed refused: " + firstError);
    }
    RESMR_FUZZ_OUTCOME("opened, " + std::to_string(file.Regions().size()) + " regions, " + std::to_string(refused) +
      " parts refused" + (refused ? ", first: " + firstError : std::string()));
  }
  catch (const std::bad_alloc&)
  {
    // A file of at most a few MiB never needs a GiB: a size taken from the file unchecked.
    BrokenInvariant("std::bad_alloc: an allocation beyond the file's means");
  }
  catch (const std::exception& error)
  {
    if (MustBeValid)
    {
      BrokenInvariant(std::string("a valid seed refused: ") + error.what());
    }
    // expected: bad input reported as such (FileFormatError, or std::bad_alloc and
    // the like from the standard library)
    RESMR_FUZZ_OUTCOME(std::string("refused: ") + error.what());
  }
  return 0;
}

#ifdef RESMR_FUZZ_STANDALONE
int main(int argc, char** argv)
{
  return resmr_fuzz::ResmrReplayMain(
    "FuzzResmrFileReplay", argc, argv, resmr_fuzz::ResmrLayout(), MustBeValid, LastOutcome, LLVMFuzzerTestOneInput);
}
#endif
