// The partition pass of the hierarchy builder (paper Sec. 4.2, 7) with compressed tiles:
// ReadBox gives bit for bit the layers the source streams (boxes across tile borders and the
// grid's edges, from several threads), the tiles stay under a few bytes a cell, a pass
// stopped part-way resumes from its checkpoint to the partition made in one go (the caller's
// note handed back, a changed input refused), Release removes a tile once every box holding
// it let go, and damaged or missing tiles fail naming the file.
#include "CoreTesting.h"

#include "LayerSource.h"
#include "LeafPartition.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>
#include <vector>

using namespace resmr;

namespace
{
std::string Temp; // this run's folder
const std::string Spec = "synth:150x110x20:3";
const int64_t TileSize = 32;

/// Every layer of the model, as the source streams them.
struct Layers
{
  std::array<int64_t, 3> dims{};
  std::vector<std::vector<float>> zcorn;
  std::vector<std::vector<uint8_t>> active;
};

const Layers& Direct()
{
  static Layers layers;
  if (layers.zcorn.empty())
  {
    auto source = OpenLayerSource(Spec);
    layers.dims = source->Dims();
    std::vector<float> z;
    std::vector<uint8_t> a;
    while (source->Next(z, a))
    {
      layers.zcorn.push_back(z);
      layers.active.push_back(a);
    }
  }
  return layers;
}

/// Delegates to a source of the model; throws when asked for layer `failAt` (0-based), or
/// changes one depth of layer `changeAt`.
class FaultySource : public LayerSource
{
public:
  explicit FaultySource(int64_t failAt, int64_t changeAt = -1)
    : Inner(OpenLayerSource(Spec))
    , FailAt(failAt)
    , ChangeAt(changeAt)
  {
  }
  std::array<int64_t, 3> Dims() const override { return this->Inner->Dims(); }
  const std::vector<double>& Coord() const override { return this->Inner->Coord(); }
  std::string Name() const override { return "faulty " + this->Inner->Name(); }
  bool Next(std::vector<float>& zcorn, std::vector<uint8_t>& active) override
  {
    if (this->K == this->FailAt)
    {
      throw std::runtime_error("source stopped at layer " + std::to_string(this->K));
    }
    const bool more = this->Inner->Next(zcorn, active);
    if (this->K++ == this->ChangeAt)
    {
      zcorn[zcorn.size() / 2] += 1.0f;
    }
    return more;
  }

private:
  std::unique_ptr<LayerSource> Inner;
  int64_t FailAt, ChangeAt, K = 0;
};

/// ReadBox equals the direct layers, bit for bit.
bool BoxMatches(const LeafPartition& partition, int64_t i0, int64_t i1, int64_t j0, int64_t j1)
{
  const Layers& layers = Direct();
  const int64_t nx = layers.dims[0], ny = layers.dims[1], nz = layers.dims[2];
  std::vector<float> zcorn;
  std::vector<uint8_t> active;
  partition.ReadBox(i0, i1, j0, j1, zcorn, active);
  const int64_t w = i1 - i0, h = j1 - j0;
  if (static_cast<int64_t>(zcorn.size()) != 8 * w * h * nz || static_cast<int64_t>(active.size()) != w * h * nz)
  {
    return false;
  }
  for (int64_t k = 0; k < nz; ++k)
  {
    for (int64_t j = j0; j < j1; ++j)
    {
      for (int64_t i = i0; i < i1; ++i)
      {
        const std::size_t to = static_cast<std::size_t>((k * h + (j - j0)) * w + (i - i0));
        if (active[to] != layers.active[k][static_cast<std::size_t>(j * nx + i)])
        {
          return false;
        }
        for (int c = 0; c < 8; ++c)
        {
          const float expected = layers.zcorn[k][static_cast<std::size_t>(
            (c >> 2) * 4 * nx * ny + (2 * j + ((c >> 1) & 1)) * 2 * nx + 2 * i + (c & 1))];
          if (std::memcmp(&zcorn[to * 8 + c], &expected, 4) != 0)
          {
            return false;
          }
        }
      }
    }
  }
  return true;
}

/// Boxes inside one tile, across tile borders, along the grid's edges, and the whole grid.
const std::vector<std::array<int64_t, 4>> Boxes = { { 0, 150, 0, 110 }, { 0, 1, 0, 1 }, { 31, 33, 31, 33 },
  { 5, 20, 7, 30 }, { 30, 70, 20, 50 }, { 63, 129, 63, 97 }, { 140, 150, 100, 110 }, { 149, 150, 0, 110 },
  { 0, 150, 109, 110 }, { 96, 150, 64, 110 } };

bool AllBoxesMatch(const LeafPartition& partition)
{
  bool all = true;
  for (const auto& box : Boxes)
  {
    const bool same = BoxMatches(partition, box[0], box[1], box[2], box[3]);
    if (!same)
    {
      std::fprintf(stderr, "box [%ld, %ld) x [%ld, %ld) differs from the source\n", long(box[0]), long(box[1]),
        long(box[2]), long(box[3]));
    }
    all = all && same;
  }
  return all;
}

bool Exists(const std::string& path)
{
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

std::string TileFile(const std::string& folder, int ti, int tj)
{
  return folder + "/tile-" + std::to_string(ti) + "-" + std::to_string(tj) + ".bin";
}

void TestExactAndSmall()
{
  auto source = OpenLayerSource(Spec);
  LeafPartition partition(*source, Temp + "/exact", TileSize);
  CHECK(AllBoxesMatch(partition));
  const auto& dims = Direct().dims;
  const double cells = double(dims[0]) * dims[1] * dims[2];
  const double perCell = partition.TileBytes() / cells;
  std::printf("%s, tiles of %ld: %.2f bytes a cell on disk (33 raw)\n", Spec.c_str(), long(TileSize), perCell);
  CHECK(perCell > 0 && perCell < 6);
  // Several readers at once, as the builder's workers read.
  bool same[2] = { false, false };
  std::thread other([&] { same[0] = BoxMatches(partition, 10, 90, 10, 90); });
  same[1] = BoxMatches(partition, 40, 150, 30, 110);
  other.join();
  CHECK(same[0] && same[1]);
  // A reader in another object sees the same (it gets the finished state the writer saved).
  partition.SaveState();
  bool complete = false;
  CHECK(LeafPartition::HasCheckpoint(Temp + "/exact", &complete) && complete);
  LeafPartition reader(Temp + "/exact");
  CHECK(reader.ActiveCells() == partition.ActiveCells() && reader.Extent() == partition.Extent());
  CHECK(reader.ColumnHasActive() == partition.ColumnHasActive() && reader.Coord() == partition.Coord());
  CHECK(AllBoxesMatch(reader));
}

void TestResume()
{
  const std::string folder = Temp + "/resume";
  const int64_t stopAt = 7;
  PartitionHooks hooks;
  hooks.checkpointSeconds = 0; // a checkpoint after every layer
  int64_t seen = 0;
  hooks.onLayer = [&](int64_t, const std::vector<uint8_t>&) { ++seen; };
  hooks.checkpointNote = [&] { return std::vector<uint8_t>{ 'n', static_cast<uint8_t>(seen) }; };
  {
    FaultySource failing(stopAt);
    resmr_testing::ExpectError<std::runtime_error>(
      "stopped pass", [&] { LeafPartition partition(failing, folder, TileSize, hooks); }, { "stopped at layer 7" });
  }
  bool complete = true;
  CHECK(LeafPartition::HasCheckpoint(folder, &complete) && !complete);
  resmr_testing::ExpectError<std::runtime_error>(
    "reading a stopped pass", [&] { LeafPartition reader(folder); }, { "partition.state", "7 of 20 layers" });

  // A changed input is refused, and the checkpoint stays for the right one.
  {
    FaultySource changed(-1, stopAt - 1);
    resmr_testing::ExpectError<std::runtime_error>(
      "changed input", [&] { LeafPartition partition(changed, folder, TileSize, hooks); }, { "differs", folder });
  }

  int64_t resumedLayers = -1, firstLayer = -1;
  std::vector<uint8_t> resumedNote;
  hooks.onResume = [&](int64_t layers, const std::vector<uint8_t>& note) {
    resumedLayers = layers;
    resumedNote = note;
  };
  hooks.onLayer = [&](int64_t k, const std::vector<uint8_t>&) { firstLayer = firstLayer < 0 ? k : firstLayer; };
  FaultySource fresh(-1);
  LeafPartition resumed(fresh, folder, TileSize, hooks);
  CHECK(resumedLayers == stopAt);
  CHECK((resumedNote == std::vector<uint8_t>{ 'n', static_cast<uint8_t>(stopAt) }));
  CHECK(firstLayer == stopAt);
  CHECK(LeafPartition::HasCheckpoint(folder, &complete) && complete);
  CHECK(AllBoxesMatch(resumed));
  auto source = OpenLayerSource(Spec);
  LeafPartition whole(*source, Temp + "/whole", TileSize);
  CHECK(resumed.ActiveCells() == whole.ActiveCells() && resumed.Extent() == whole.Extent());
  CHECK(resumed.ColumnHasActive() == whole.ColumnHasActive());
  CHECK(resumed.TileBytes() == whole.TileBytes());

  // Without a checkpoint (stopped in its first layer), a stopped pass starts over.
  PartitionHooks rarely;
  bool called = false;
  rarely.onResume = [&](int64_t, const std::vector<uint8_t>&) { called = true; };
  {
    FaultySource failing(0);
    resmr_testing::ExpectError<std::runtime_error>("stopped pass without checkpoint",
      [&] { LeafPartition partition(failing, Temp + "/rarely", TileSize, rarely); }, { "stopped at layer" });
  }
  CHECK(!LeafPartition::HasCheckpoint(Temp + "/rarely", &complete));
  FaultySource again(-1);
  LeafPartition restarted(again, Temp + "/rarely", TileSize, rarely);
  CHECK(!called);
  CHECK(AllBoxesMatch(restarted));
}

void TestRelease()
{
  const std::string folder = Temp + "/release";
  auto source = OpenLayerSource(Spec);
  LeafPartition partition(*source, folder, TileSize);
  const uint64_t before = partition.TileBytes();
  partition.Retain(0, 20, 0, 20);   // tile (0, 0)
  partition.Retain(10, 40, 10, 20); // tiles (0, 0) and (1, 0)
  partition.Release(0, 20, 0, 20);
  CHECK(Exists(TileFile(folder, 0, 0)) && Exists(TileFile(folder, 1, 0)));
  CHECK(partition.TileBytes() == before);
  CHECK(BoxMatches(partition, 10, 40, 10, 20));
  partition.Release(10, 40, 10, 20);
  CHECK(!Exists(TileFile(folder, 0, 0)) && !Exists(TileFile(folder, 1, 0)));
  CHECK(partition.TileBytes() < before);
  partition.Release(64, 80, 0, 10); // tile (2, 0), never retained
  CHECK(Exists(TileFile(folder, 2, 0)));
  CHECK(BoxMatches(partition, 64, 150, 0, 110));
  std::vector<float> z;
  std::vector<uint8_t> a;
  resmr_testing::ExpectError<std::runtime_error>(
    "reading a released tile", [&] { partition.ReadBox(0, 5, 0, 5, z, a); }, { TileFile(folder, 0, 0), "gone" });

  // A reader does not remove, and opens a partition some of whose tiles are gone.
  partition.SaveState();
  LeafPartition reader(folder);
  CHECK(BoxMatches(reader, 64, 150, 0, 110));
  reader.Retain(64, 80, 0, 10);
  reader.Release(64, 80, 0, 10);
  CHECK(Exists(TileFile(folder, 2, 0)));
  resmr_testing::ExpectError<std::runtime_error>(
    "reading a tile already gone", [&] { reader.ReadBox(32, 40, 0, 5, z, a); }, { TileFile(folder, 1, 0), "gone" });
}

void TestDamage()
{
  const std::string folder = Temp + "/damage";
  auto source = OpenLayerSource(Spec);
  LeafPartition partition(*source, folder, TileSize);
  partition.SetRemoveOnDestroy(false);
  const std::string flipped = TileFile(folder, 1, 1), cut = TileFile(folder, 2, 2);
  {
    std::FILE* file = std::fopen(flipped.c_str(), "r+b");
    std::fseek(file, 0, SEEK_END);
    const long size = std::ftell(file);
    std::fseek(file, size / 2, SEEK_SET);
    const int byte = std::fgetc(file);
    std::fseek(file, size / 2, SEEK_SET);
    std::fputc(byte ^ 0x10, file);
    std::fclose(file);
    struct stat info;
    stat(cut.c_str(), &info);
    CHECK(truncate(cut.c_str(), info.st_size - 3) == 0);
  }
  LeafPartition reader(folder);
  std::vector<float> z;
  std::vector<uint8_t> a;
  resmr_testing::ExpectError<std::runtime_error>(
    "flipped byte", [&] { reader.ReadBox(40, 50, 40, 50, z, a); }, { flipped, "layer", "corrupt" });
  resmr_testing::ExpectError<std::runtime_error>(
    "cut tile", [&] { reader.ReadBox(70, 80, 70, 80, z, a); }, { cut, "layer 20", "shorter" });
  CHECK(BoxMatches(reader, 0, 32, 0, 32));
  // A damaged state is no checkpoint, and a reader refuses it.
  const std::string state = folder + "/partition.state";
  std::FILE* file = std::fopen(state.c_str(), "r+b");
  std::fseek(file, 100, SEEK_SET);
  const int byte = std::fgetc(file);
  std::fseek(file, 100, SEEK_SET);
  std::fputc(byte ^ 0x5a, file);
  std::fclose(file);
  bool complete = false;
  CHECK(!LeafPartition::HasCheckpoint(folder, &complete));
  resmr_testing::ExpectError<std::runtime_error>(
    "damaged state", [&] { LeafPartition damaged(folder); }, { state, "corrupt" });
  reader.SetRemoveOnDestroy(true);
}
} // namespace

int main(int argc, char** argv)
{
  if (argc != 2)
  {
    std::fprintf(stderr, "usage: %s TEMP_DIR\n", argv[0]);
    return 2;
  }
  Temp = argv[1];
  std::system(("rm -rf '" + Temp + "' && mkdir -p '" + Temp + "'").c_str());
  const bool passed = resmr_testing::RunNamedTests({
    { "ExactAndSmall", TestExactAndSmall },
    { "Resume", TestResume },
    { "Release", TestRelease },
    { "Damage", TestDamage },
  });
  if (passed)
  {
    std::system(("rm -rf '" + Temp + "'").c_str());
  }
  return passed ? 0 : 1;
}
