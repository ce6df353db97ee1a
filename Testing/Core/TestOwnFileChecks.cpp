// Our own files checked for sense, not only for damage: a small .resmr and .resmrp made at
// test time (resmr synth, build, add-properties), then for each header and index field a copy
// with that field set to nonsense and every checksum recomputed (chunk CRCs, index CRC,
// trailer, geometry id, header CRC: Testing/Fuzz/FuzzResmrRepair.h, as the fuzz targets do),
// which must be refused with a FileFormatError naming the file and the field. The
// depth lattice step 0.0 is also given to `resmr info`, which must fail with that message.
#include "CoreTesting.h"

#include "FuzzResmrRepair.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <sys/stat.h>
#include <vector>

using namespace resmr;
using resmr_fuzz::Load;
using resmr_fuzz::Store;
using Bytes = std::vector<uint8_t>;

namespace
{
std::string Tool, Temp;

int Run(const std::string& command)
{
  std::fprintf(stderr, "$ %s\n", command.c_str());
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

Bytes Slurp(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Spill(const std::string& path, const Bytes& bytes)
{
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

const double NaN = std::numeric_limits<double>::quiet_NaN();
const double Infinity = std::numeric_limits<double>::infinity();

/// Where the index of a valid file starts (its trailer).
uint64_t IndexAt(const Bytes& file)
{
  return Load<uint64_t>(file, file.size() - IndexTrailerBytes);
}

using Change = std::function<void(Bytes&)>;

/// `valid` with `change` made and every checksum recomputed; `late` is made after that (for
/// what the repair recomputes itself: the geometry id, the trailer), with the header CRC
/// recomputed again.
Bytes Changed(const Bytes& valid, const resmr_fuzz::FileLayout& layout, const Change& change, const Change& late = {})
{
  Bytes file = valid;
  if (change)
  {
    change(file);
  }
  file = resmr_fuzz::Repair(file.data(), file.size(), layout, false);
  if (late)
  {
    late(file);
    Store<uint32_t>(file, layout.headerBytes - 4, Crc32(file.data(), layout.headerBytes - 4));
  }
  return file;
}

/// The geometry file with the change must be refused at open with the file and `fragment`
/// named.
void ExpectGeometryRefused(const std::string& label, const Bytes& valid, const std::string& fragment,
  const Change& change, const Change& late = {})
{
  const std::string path = Temp + "/changed.resmr";
  Spill(path, Changed(valid, resmr_fuzz::ResmrLayout(), change, late));
  resmr_testing::ExpectError<FileFormatError>(
    "resmr " + label, [&] { MultiresolutionFile file(path); }, { path, fragment });
}

void ExpectPropertiesRefused(const std::string& label, const Bytes& valid, const std::string& fragment,
  const Change& change, const Change& late = {})
{
  const std::string path = Temp + "/changed.resmrp";
  Spill(path, Changed(valid, resmr_fuzz::ResmrpLayout(), change, late));
  resmr_testing::ExpectError<FileFormatError>("resmrp " + label, [&] { PropertyFile file(path); }, { path, fragment });
}

template<typename T>
Change Set(std::size_t at, T value)
{
  return [=](Bytes& file) { Store<T>(file, at, value); };
}

/// A field of index record `record` (192 bytes each) of a geometry file.
template<typename T>
Change SetRecord(std::size_t record, std::size_t field, T value)
{
  return [=](Bytes& file) { Store<T>(file, static_cast<std::size_t>(IndexAt(file)) + record * 192 + field, value); };
}

// .resmr header fields (MultiresolutionFile.cpp, PutHeader).
constexpr std::size_t Version = 8, HeaderSize = 12, Dims = 16, Box = 40, Origin = 72, Step = 96, LeafLevel = 120,
                      Cmax = 124, Regions = 128, ModelChunks = 136, TableSides = 144, OffsetSides = 156,
                      HashedCells = 168, GeometryId = 176, MapFlags = 184;

void GeometryFields(const Bytes& valid, const std::string& validPath)
{
  {
    // The repair alone changes nothing in a valid file, which opens.
    const Bytes same = Changed(valid, resmr_fuzz::ResmrLayout(), [](Bytes&) {});
    CHECK(same == valid);
    MultiresolutionFile file(validPath);
    CHECK(file.Regions().size() == 6);
    CHECK(file.Header().leafLevel == 1);
  }
  const MultiresolutionFile file(validPath);
  const auto& h = file.Header();
  const uint64_t slots = uint64_t(h.hashTableSides[0]) * h.hashTableSides[1] * h.hashTableSides[2];

  ExpectGeometryRefused("version 11", valid, "format version 11", Set<uint32_t>(Version, 11));
  ExpectGeometryRefused("version 2", valid, "format version 2", Set<uint32_t>(Version, 2));
  ExpectGeometryRefused("header size", valid, "'header size'", Set<uint32_t>(HeaderSize, 255));
  ExpectGeometryRefused("nx 0", valid, "'dimensions (nx)' is 0", Set<int64_t>(Dims, 0));
  ExpectGeometryRefused("ny -1", valid, "'dimensions (ny)' is -1", Set<int64_t>(Dims + 8, -1));
  ExpectGeometryRefused("nz 2^25", valid, "'dimensions (nz)'", Set<int64_t>(Dims + 16, int64_t(1) << 25));
  ExpectGeometryRefused("nx ny nz 2^24", valid, "'dimensions' is 16777216 x 16777216 x 16777216", [](Bytes& f) {
    for (int a = 0; a < 3; ++a)
    {
      Store<int64_t>(f, Dims + 8 * a, int64_t(1) << 24);
    }
  });
  ExpectGeometryRefused("nz 8 (of 2)", valid, "'model chunk count'", Set<int64_t>(Dims + 16, 8));
  ExpectGeometryRefused("box xmin NaN", valid, "'hierarchy box (x)'", Set<double>(Box, NaN));
  ExpectGeometryRefused("box ymax < ymin", valid, "'hierarchy box (y)'", Set<double>(Box + 24, h.box[1] - 1));
  ExpectGeometryRefused("box xmax = xmin", valid, "'hierarchy box (x)'", Set<double>(Box + 16, h.box[0]));
  ExpectGeometryRefused("origin inf", valid, "'lattice origin (y)'", Set<double>(Origin + 8, Infinity));
  ExpectGeometryRefused("depth step 0", valid, "'lattice step (depth)' is 0", Set<double>(Step + 16, 0.0));
  ExpectGeometryRefused("x step -1", valid, "'lattice step (x)' is -1", Set<double>(Step, -1.0));
  ExpectGeometryRefused("y step NaN", valid, "'lattice step (y)' is nan", Set<double>(Step + 8, NaN));
  ExpectGeometryRefused("x step too fine", valid, "'lattice step (x)'", Set<double>(Step, 1e-300));
  ExpectGeometryRefused(
    "x step 1e300", valid, "'lattice step (x)' is 1.0000000000000001e+300", Set<double>(Step, 1e300));
  ExpectGeometryRefused(
    "y step 2000", valid, "'lattice step (y)' is 2000, must be at most", Set<double>(Step + 8, 2000.0));
  ExpectGeometryRefused("depth step 1e300", valid, "'lattice step (depth)' is 1.0000000000000001e+300, must be at most",
    Set<double>(Step + 16, 1e300));
  ExpectGeometryRefused("leaf level -1", valid, "'leaf level' is -1", Set<int32_t>(LeafLevel, -1));
  ExpectGeometryRefused("leaf level 41", valid, "'leaf level' is 41", Set<int32_t>(LeafLevel, 41));
  // Leaf level 0 holds at most 2 regions; at level 2 no region of the index lies there.
  ExpectGeometryRefused("leaf level 0", valid, "'region count'", Set<int32_t>(LeafLevel, 0));
  ExpectGeometryRefused("leaf level 2", valid, "'leaf level' is 2", Set<int32_t>(LeafLevel, 2));
  ExpectGeometryRefused("Cmax 0", valid, "'Cmax' is 0", Set<int32_t>(Cmax, 0));
  ExpectGeometryRefused("region count 0", valid, "'region count' is 0", Set<uint64_t>(Regions, 0));
  ExpectGeometryRefused("region count 7", valid, "'region count'", Set<uint64_t>(Regions, 7));
  ExpectGeometryRefused("region count 5", valid, "'region count'", Set<uint64_t>(Regions, 5));
  ExpectGeometryRefused(
    "model chunk count + 1", valid, "'model chunk count'", Set<uint64_t>(ModelChunks, h.modelChunkCount + 1));
  ExpectGeometryRefused("table side 0", valid, "'hash table sides' is 0", Set<uint32_t>(TableSides, 0));
  ExpectGeometryRefused("table side 4096", valid, "'hash table sides' is 4096", Set<uint32_t>(TableSides + 8, 4096));
  ExpectGeometryRefused("table side + 1", valid, "hash cell table", Set<uint32_t>(TableSides, h.hashTableSides[0] + 1));
  ExpectGeometryRefused("offset side 0", valid, "'hash offset sides' is 0", Set<uint32_t>(OffsetSides + 4, 0));
  ExpectGeometryRefused(
    "offset side + 1", valid, "hash offset table", Set<uint32_t>(OffsetSides, h.hashOffsetSides[0] + 1));
  ExpectGeometryRefused("hashed cells 0", valid, "'hashed cells' is 0", Set<uint64_t>(HashedCells, 0));
  ExpectGeometryRefused("hashed cells > slots", valid, "'hashed cells'", Set<uint64_t>(HashedCells, slots + 1));
  ExpectGeometryRefused("geometry id", valid, "'geometry id'", {}, Set<uint64_t>(GeometryId, h.geometryId ^ 1));
  ExpectGeometryRefused("map flags", valid, "map placement", Set<uint32_t>(MapFlags, 4));
  ExpectGeometryRefused(
    "trailer reserved", valid, "(reserved) are not zero", {}, [](Bytes& f) { Store<uint32_t>(f, f.size() - 12, 1); });

  // Index records: level 4, typical error 4, index 8, columns 8, active cells 8, vertices 8,
  // bounds 6 floats, error, own error, two cones of 4 floats, four chunk references.
  ExpectGeometryRefused("record level", valid, "level or region index", SetRecord<int32_t>(0, 0, 2));
  ExpectGeometryRefused("record typical error NaN", valid, "typical error nan", SetRecord<float>(0, 4, NAN));
  ExpectGeometryRefused("record typical error -1", valid, "typical error -1", SetRecord<float>(0, 4, -1.0f));
  ExpectGeometryRefused("record typical error > own", valid, "not between 0 and the own error", [](Bytes& f) {
    const std::size_t at = static_cast<std::size_t>(IndexAt(f)) + 2 * 192;
    Store<float>(f, at + 4, 2 * Load<float>(f, at + 68) + 1);
  });
  ExpectGeometryRefused("record layer groups", valid, "layer groups at byte", SetRecord<uint64_t>(0, 184, 1));
  ExpectGeometryRefused(
    "record layer groups past the data", valid, "layer groups at byte", SetRecord<uint64_t>(0, 184, 1ull << 40));
  ExpectGeometryRefused("record index", valid, "level or region index", SetRecord<int64_t>(0, 8, 4));
  ExpectGeometryRefused("record columns 0", valid, "0 columns", SetRecord<int64_t>(0, 16, 0));
  ExpectGeometryRefused("record active cells", valid, "-1 active cells", SetRecord<int64_t>(0, 24, -1));
  ExpectGeometryRefused("record vertices", valid, "7 vertices", SetRecord<int64_t>(0, 32, 7));
  ExpectGeometryRefused("record bounds NaN", valid, "bounding volume", SetRecord<float>(1, 40, NAN));
  ExpectGeometryRefused("record bounds empty", valid, "bounding volume", SetRecord<float>(1, 48, 1e30f));
  ExpectGeometryRefused("record error", valid, "error -1", SetRecord<float>(2, 64, -1.0f));
  ExpectGeometryRefused("record own error", valid, "own error inf", SetRecord<float>(2, 68, INFINITY));
  ExpectGeometryRefused("record cone", valid, "normal cone", SetRecord<float>(3, 72 + 12, 3.0f));
  ExpectGeometryRefused("record cone axis", valid, "normal cone", [](Bytes& f) {
    const std::size_t at = static_cast<std::size_t>(IndexAt(f)) + 3 * 192 + 88; // the bottom cone
    if (Load<float>(f, at + 12) == -2.0f)
    {
      Store<float>(f, at + 12, 0.5f);
    }
    Store<float>(f, at + 8, Load<float>(f, at + 8) + 0.5f);
  });
  ExpectGeometryRefused("record chunk offset", valid, "mesh at byte", SetRecord<uint64_t>(0, 104, 1u << 30));
  ExpectGeometryRefused(
    "record chunk raw", valid, "cannot decompress", SetRecord<uint32_t>(0, 104 + 20 + 12, 1u << 30));
  ExpectGeometryRefused("record duplicate", valid, "a second record", [](Bytes& f) {
    const std::size_t index = static_cast<std::size_t>(IndexAt(f));
    std::memcpy(&f[index + 192], &f[index], 16);
  });

  // Model chunk records (after the regions, 32 bytes each: kind, part, reference, reserved).
  const std::size_t model = 6 * 192;
  const auto setModel = [&](std::size_t record, std::size_t field, uint32_t value) -> Change {
    return
      [=](Bytes& f) { Store<uint32_t>(f, static_cast<std::size_t>(IndexAt(f)) + model + record * 32 + field, value); };
  };
  ExpectGeometryRefused("model kind", valid, "unknown kind", setModel(0, 0, 9));
  ExpectGeometryRefused("model reserved", valid, "reserved bytes set", setModel(0, 28, 1));
  ExpectGeometryRefused("model layer", valid, "no such layer", setModel(0, 4, 5));
  ExpectGeometryRefused("model layer twice", valid, "a second chunk", setModel(1, 4, 0));
  ExpectGeometryRefused("model layer size", valid, "active flags part 0: 11 bytes", setModel(0, 20, 11));
}

/// The geometry file with the change opens, but region `region` is refused when read, naming
/// the file, the region and `fragment`; every other region still reads.
void ExpectRegionRefused(const std::string& label, const Bytes& file, std::size_t region, const std::string& fragment)
{
  const std::string path = Temp + "/region.resmr";
  Spill(path, file);
  const MultiresolutionFile opened(path);
  const auto& record = opened.Regions()[region];
  resmr_testing::ExpectError<FileFormatError>("region " + label, [&] { opened.ReadRegion(region); },
    { path, "region (level " + std::to_string(record.level) + ", index " + std::to_string(record.index) + ")",
      fragment });
  for (std::size_t r = 0; r < opened.Regions().size(); ++r)
  {
    if (r != region)
    {
      CHECK(opened.ReadRegion(r).ColumnCount() == opened.Regions()[r].columns);
    }
  }
}

/// What the region decoder checks inside a chunk against the index (chunks changed in the
/// unpacked form, then compressed again with their CRCs).
void RegionContents(const Bytes& valid)
{
  const auto layout = resmr_fuzz::ResmrLayout();
  ExpectRegionRefused(
    "active cells", Changed(valid, layout, SetRecord<int64_t>(1, 24, 0)), 1, "active cells, the index says 0");
  Bytes unpacked = resmr_fuzz::UnpackChunks(valid, layout);
  const std::size_t record = static_cast<std::size_t>(IndexAt(unpacked)) + 2 * 192;
  const uint64_t mesh = Load<uint64_t>(unpacked, record + 104);
  const uint32_t meshBytes = Load<uint32_t>(unpacked, record + 104 + 8);
  // The mesh chunk ends with one byte of cut edges a column (bits 0-3).
  Bytes cut = unpacked;
  cut[static_cast<std::size_t>(mesh + meshBytes - 1)] = 0x10;
  ExpectRegionRefused("cut edges", resmr_fuzz::Repair(cut.data(), cut.size(), layout), 2, "cut edges 16 of column");
  // Its magic (MESH), then the layer count.
  Bytes layers = unpacked;
  Store<uint32_t>(layers, static_cast<std::size_t>(mesh + 4), 3);
  ExpectRegionRefused("layers", resmr_fuzz::Repair(layers.data(), layers.size(), layout), 2, "3 layers");
  // Then the layer groups' table: interfaces a group, groups, and per group its stored bytes,
  // raw bytes and CRC (the groups' chunks stay packed in the unpacked form). 2 layers: one group.
  Bytes each = unpacked;
  Store<uint32_t>(each, static_cast<std::size_t>(mesh + 16), 0);
  ExpectRegionRefused("interfaces a group", resmr_fuzz::Repair(each.data(), each.size(), layout), 2,
    "1 layer groups of 0 interfaces for 3 interfaces a node");
  Bytes groups = unpacked;
  Store<uint32_t>(groups, static_cast<std::size_t>(mesh + 20), 2);
  ExpectRegionRefused(
    "layer groups", resmr_fuzz::Repair(groups.data(), groups.size(), layout), 2, "2 layer groups of 8");
  Bytes raw = unpacked;
  Store<uint32_t>(
    raw, static_cast<std::size_t>(mesh + 28), Load<uint32_t>(raw, static_cast<std::size_t>(mesh + 28)) + 12);
  ExpectRegionRefused("layer group size", resmr_fuzz::Repair(raw.data(), raw.size(), layout), 2, "layer group 0 of");
  Bytes crc = unpacked;
  Store<uint32_t>(
    crc, static_cast<std::size_t>(mesh + 32), Load<uint32_t>(crc, static_cast<std::size_t>(mesh + 32)) ^ 1);
  ExpectRegionRefused(
    "layer group checksum", resmr_fuzz::Repair(crc.data(), crc.size(), layout), 2, "mesh layer group 0 at byte");
  ExpectRegionRefused("layer groups moved",
    Changed(valid, layout,
      SetRecord<uint64_t>(2, 184, Load<uint64_t>(valid, static_cast<std::size_t>(IndexAt(valid)) + 2 * 192 + 184) + 1)),
    2, "checksum mismatch");
  // Unchanged, the unpacked form packs into a file that reads as the original.
  const Bytes repacked = resmr_fuzz::Repair(unpacked.data(), unpacked.size(), layout);
  Spill(Temp + "/repacked.resmr", repacked);
  const MultiresolutionFile file(Temp + "/repacked.resmr");
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
  {
    CHECK(file.ReadRegion(r).VertexCount() == file.Regions()[r].vertices);
  }
}

/// A file of version 8 (the fuzz corpus's seed of the same model: positions in the mesh chunk)
/// reads as this build's file of version 10 (positions in layer groups) does, whole and by
/// windows of layers.
void OlderVersionReadsTheSame(const std::string& geometry, const std::string& seed)
{
  const MultiresolutionFile now(geometry), eight(seed);
  CHECK(eight.Header().version == 8 && now.Header().version == MultiresolutionHeader::LayerGroupsVersion);
  CHECK(now.Regions().size() == eight.Regions().size());
  for (std::size_t r = 0; r < now.Regions().size() && r < eight.Regions().size(); ++r)
  {
    for (const std::array<int32_t, 2> window : { std::array<int32_t, 2>{ 0, 1 }, { 0, 0 }, { 1, 1 } })
    {
      const RegionMesh a = now.ReadRegionLayers(r, window[0], window[1]);
      const RegionMesh b = eight.ReadRegionLayers(r, window[0], window[1]);
      CHECK(a.firstLayer == b.firstLayer && a.layers == b.layers && a.positions == b.positions &&
        a.topology == b.topology && a.corners == b.corners && a.active == b.active && a.openSides == b.openSides &&
        a.cutEdges == b.cutEdges && a.top.quads == b.top.quads && a.bottom.quads == b.bottom.quads &&
        a.sideTriangles == b.sideTriangles);
    }
  }
}

// .resmrp header fields (PropertyFile.cpp, HeaderOf).
constexpr std::size_t PVersion = 8, PDims = 20, PSides = 44, PTables = 56, PBandRows = 60, PBandColumns = 64;

void PropertyFields(const Bytes& valid, const std::string& validPath, const std::string& geometryPath)
{
  {
    const Bytes same = Changed(valid, resmr_fuzz::ResmrpLayout(), [](Bytes&) {});
    CHECK(same == valid);
    PropertyFile file(validPath);
    CHECK(file.Tables().size() == Load<uint32_t>(valid, PTables));
    CHECK(file.Tables().size() > 2);
  }
  const uint32_t tables = Load<uint32_t>(valid, PTables);
  const uint64_t index = IndexAt(valid);
  const std::size_t table = 56 + 20 * 5; // nz = 2: packed table, block ranges, layer blocks, 2 layers
  const auto setTable = [&](std::size_t t, std::size_t field, auto value) -> Change {
    return [=](Bytes& f) { Store(f, static_cast<std::size_t>(index + t * table + field), value); };
  };
  ExpectPropertiesRefused("version 6", valid, "format version 6", Set<uint32_t>(PVersion, 6));
  ExpectPropertiesRefused("version 1", valid, "format version 1", Set<uint32_t>(PVersion, 1));
  ExpectPropertiesRefused("band rows 0", valid, "'rows a band' is 0", Set<uint32_t>(PBandRows, 0));
  ExpectPropertiesRefused("band rows ny + 1", valid, "'rows a band'",
    [](Bytes& f) { Store<uint32_t>(f, PBandRows, static_cast<uint32_t>(Load<int64_t>(f, PDims + 8) + 1)); });
  ExpectPropertiesRefused("band columns 0", valid, "'columns a band' is 0", Set<uint32_t>(PBandColumns, 0));
  ExpectPropertiesRefused("band columns nx + 1", valid, "'columns a band'",
    [](Bytes& f) { Store<uint32_t>(f, PBandColumns, static_cast<uint32_t>(Load<int64_t>(f, PDims) + 1)); });
  {
    // A version 4 file (bands of whole rows, no columns a band) reads the same: this grid's
    // layers are one band either way.
    const std::string old = Temp + "/version4.resmrp";
    Spill(old, Changed(valid, resmr_fuzz::ResmrpLayout(), [&](Bytes& f) {
      Store<uint32_t>(f, PVersion, 4);
      Store<uint32_t>(f, PBandColumns, 0);
    }));
    const PropertyFile now(validPath), before(old);
    CHECK(before.Bands() == 1 && before.BandColumns() == now.BandColumns() && now.BandColumns() == 9);
    for (std::size_t t = 0; t < now.Tables().size(); ++t)
    {
      const auto a = now.ReadLayer(t, 1), b = before.ReadLayer(t, 1);
      CHECK(std::memcmp(a.data(), b.data(), a.size() * 4) == 0 && a.size() == b.size());
    }
    ExpectPropertiesRefused("version 4 band columns", valid, "'reserved bytes'", Set<uint32_t>(PVersion, 4));
  }
  {
    // A version 2 file (a chunk a layer, no band rows) reads as one band a layer.
    // Its index has no block ranges: each table's reference to them taken out.
    const std::string old = Temp + "/version2.resmrp";
    Spill(old, Changed(valid, resmr_fuzz::ResmrpLayout(), [&](Bytes& f) {
      Store<uint32_t>(f, PVersion, 2);
      Store<uint32_t>(f, PBandRows, 0);
      Store<uint32_t>(f, PBandColumns, 0);
      const uint64_t at = IndexAt(f);
      std::vector<uint8_t> index;
      for (uint32_t t = 0; t < tables; ++t)
      {
        const auto record = f.begin() + static_cast<std::ptrdiff_t>(at + t * table);
        index.insert(index.end(), record, record + 76);
        index.insert(index.end(), record + 116, record + static_cast<std::ptrdiff_t>(table));
      }
      f.resize(static_cast<std::size_t>(at));
      f.insert(f.end(), index.begin(), index.end());
      const char magic[8] = { 'R', 'E', 'S', 'M', 'R', 'P', 'I', 'X' };
      const auto trailer = IndexTrailer(at, index, magic);
      f.insert(f.end(), trailer.begin(), trailer.end());
    }));
    const PropertyFile now(validPath), before(old);
    CHECK(before.Bands() == 1 && now.Bands() == 1 && before.BandRows() == now.BandRows());
    CHECK(before.Tables().size() == now.Tables().size());
    CHECK(!before.HasBlockRanges() && before.ReadBlockRanges(0).empty() && now.ReadBlockRanges(0).size() == 2);
    CHECK(before.ReadLayerBlocks(0).empty() && now.ReadLayerBlocks(0).size() == 2); // 1 x 1 blocks, 2 layers
    for (std::size_t t = 0; t < now.Tables().size(); ++t)
    {
      const auto a = now.ReadLayer(t, 1), b = before.ReadLayer(t, 1);
      CHECK(std::memcmp(a.data(), b.data(), a.size() * 4) == 0 && a.size() == b.size());
    }
    ExpectPropertiesRefused("version 2 band rows", valid, "'reserved bytes'", [](Bytes& f) {
      Store<uint32_t>(f, PVersion, 2);
      Store<uint32_t>(f, PBandRows, 1);
    });
  }
  ExpectPropertiesRefused("0 tables", valid, "'table count' is 0", Set<uint32_t>(PTables, 0));
  ExpectPropertiesRefused("tables + 1", valid, "'table count'", Set<uint32_t>(PTables, tables + 1));
  ExpectPropertiesRefused("tables - 1", valid, "'table count'", Set<uint32_t>(PTables, tables - 1));
  ExpectPropertiesRefused("nx 0", valid, "'dimensions (nx)' is 0", Set<int64_t>(PDims, 0));
  ExpectPropertiesRefused("ny -3", valid, "'dimensions (ny)' is -3", Set<int64_t>(PDims + 8, -3));
  ExpectPropertiesRefused("nz 2^25", valid, "'dimensions (nz)'", Set<int64_t>(PDims + 16, int64_t(1) << 25));
  ExpectPropertiesRefused("nz 3 (of 2)", valid, "'table count'", Set<int64_t>(PDims + 16, 3));
  ExpectPropertiesRefused("nx ny 2^24", valid, "'dimensions' is 16777216 x 16777216",
    [](Bytes& f) { Store<int64_t>(f, PDims, int64_t(1) << 24), Store<int64_t>(f, PDims + 8, int64_t(1) << 24); });
  ExpectPropertiesRefused("side 0", valid, "'hash table sides' is 0", Set<uint32_t>(PSides + 4, 0));
  ExpectPropertiesRefused("side 4096", valid, "'hash table sides' is 4096", Set<uint32_t>(PSides, 4096));
  ExpectPropertiesRefused("sides 2048^3", valid, "at most 2^30 slots", [](Bytes& f) {
    for (int a = 0; a < 3; ++a)
    {
      Store<uint32_t>(f, PSides + 4 * a, 2048);
    }
  });
  ExpectPropertiesRefused(
    "side + 1", valid, "packed table of", [&](Bytes& f) { Store<uint32_t>(f, PSides, Load<uint32_t>(f, PSides) + 1); });
  ExpectPropertiesRefused("reserved", valid, "'reserved bytes'", Set<uint8_t>(100, 1));
  // Index: name 32, step, report, days, minimum, maximum, then the references.
  ExpectPropertiesRefused("name empty", valid, "the name is not", setTable(0, 0, uint8_t(0)));
  ExpectPropertiesRefused("name control", valid, "the name is not", setTable(0, 1, uint8_t(7)));
  ExpectPropertiesRefused("name unterminated", valid, "the name is not",
    [&](Bytes& f) { std::memset(&f[static_cast<std::size_t>(index)], 'A', 32); });
  ExpectPropertiesRefused("name padding", valid, "NUL-padded", setTable(0, 31, uint8_t('x')));
  ExpectPropertiesRefused("step -5", valid, "step -5", setTable(0, 32, int32_t(-5)));
  ExpectPropertiesRefused("report -1", valid, "report -1", setTable(tables - 1, 36, int32_t(-1)));
  ExpectPropertiesRefused("days NaN", valid, "day", setTable(tables - 1, 40, NaN));
  ExpectPropertiesRefused("static with days", valid, "day", [&](Bytes& f) {
    for (uint32_t t = 0; t < tables; ++t)
    {
      if (Load<int32_t>(f, static_cast<std::size_t>(index + t * table + 32)) < 0)
      {
        Store<double>(f, static_cast<std::size_t>(index + t * table + 40), 3.0);
        return;
      }
    }
  });
  ExpectPropertiesRefused("range reversed", valid, "value range", [&](Bytes& f) {
    Store<float>(f, static_cast<std::size_t>(index + 48), 5.0f);
    Store<float>(f, static_cast<std::size_t>(index + 52), 1.0f);
  });
  ExpectPropertiesRefused("range half NaN", valid, "value range", setTable(1, 48, NAN));
  ExpectPropertiesRefused("packed raw", valid, "packed table of", setTable(0, 56 + 12, uint32_t(12)));
  ExpectPropertiesRefused("blocks raw", valid, "block ranges at byte", setTable(0, 56 + 20 + 12, uint32_t(8)));
  ExpectPropertiesRefused("layer blocks raw", valid, "layer blocks at byte", setTable(0, 56 + 40 + 12, uint32_t(8)));
  ExpectPropertiesRefused("layer raw", valid, "layer 2 of", setTable(0, 56 + 80 + 12, uint32_t(8)));
  ExpectPropertiesRefused("layer offset", valid, "layer 1 at byte", setTable(0, 56 + 60, uint64_t(1) << 40));
  ExpectPropertiesRefused("duplicate table", valid, "a second table", [&](Bytes& f) {
    std::memcpy(&f[static_cast<std::size_t>(index + table)], &f[static_cast<std::size_t>(index)], 48);
  });

  // Valid on its own, but made for another grid: refused against the geometry.
  const std::string other = Temp + "/other-grid.resmrp";
  Spill(other, Changed(valid, resmr_fuzz::ResmrpLayout(), [](Bytes& f) { f[12] ^= 1; }));
  const PropertyFile otherFile(other);
  const MultiresolutionFile geometry(geometryPath);
  resmr_testing::ExpectError<FileFormatError>(
    "resmrp other grid", [&] { otherFile.CheckGeometry(geometry); }, { other, "another geometry" });
}

/// The two cases the checks were written for, through the tool too.
void ToolRefusesFlatModel(const Bytes& valid)
{
  const std::string flat = Temp + "/flat.resmr", report = Temp + "/flat-info.txt";
  Spill(flat, Changed(valid, resmr_fuzz::ResmrLayout(), Set<double>(Step + 16, 0.0)));
  CHECK(Run("'" + Tool + "' info '" + flat + "' > /dev/null 2> '" + report + "'") == 1);
  const Bytes text = Slurp(report);
  const std::string message(text.begin(), text.end());
  CHECK(message.find(flat) != std::string::npos);
  CHECK(message.find("'lattice step (depth)' is 0, must be positive and finite") != std::string::npos);
  std::fprintf(stderr, "%s", message.c_str());
}
} // namespace

int main(int argc, char** argv)
{
  if (argc != 4)
  {
    std::fprintf(stderr, "usage: %s RESMR_TOOL TEMP_DIR SEED_DIR\n", argv[0]);
    return 2;
  }
  Tool = argv[1];
  Temp = argv[2];
  CHECK(Run("rm -rf '" + Temp + "' && mkdir -p '" + Temp + "'") == 0); // nothing of an earlier run
  const std::string egrid = Temp + "/synth.EGRID", geometry = Temp + "/synth.resmr",
                    properties = Temp + "/synth.resmrp";
  // 9 x 8 x 2 cells, Cmax 16: two levels, 6 regions; one report step.
  CHECK(Run("'" + Tool + "' synth 9 8 2 --seed 11 --steps 1 -o '" + egrid + "' --quiet > /dev/null") == 0);
  CHECK(Run("'" + Tool + "' build '" + egrid + "' -o '" + geometry + "' --cmax 16 --quiet > /dev/null") == 0);
  CHECK(Run("'" + Tool + "' add-properties '" + geometry + "' '" + egrid + "' -o '" + properties +
          "' > /dev/null 2>&1") == 0);
  const Bytes validGeometry = Slurp(geometry), validProperties = Slurp(properties);
  CHECK(validGeometry.size() > 1000 && validProperties.size() > 1000);
  if (resmr_testing::Failures > 0)
  {
    return 1;
  }
  const bool ok = resmr_testing::RunNamedTests({
    { "geometry header and index fields", [&] { GeometryFields(validGeometry, geometry); } },
    { "region decoder against the index", [&] { RegionContents(validGeometry); } },
    { "version 8 reads as version 10",
      [&] { OlderVersionReadsTheSame(geometry, std::string(argv[3]) + "/valid_synth_9x8x2_cmax16_v8.resmr"); } },
    { "property header and index fields", [&] { PropertyFields(validProperties, properties, geometry); } },
    { "resmr info refuses a flat lattice", [&] { ToolRefusesFlatModel(validGeometry); } },
  });
  return ok ? 0 : 1;
}
