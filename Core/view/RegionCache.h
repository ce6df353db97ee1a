// Out-of-core loading of region meshes, paper Sec. 6.2 (Fig. 10): loader threads receive
// each frame's wanted regions, decompresses their meshes from the memory-mapped file,
// prepares draw buffers and marks them resident; a least-recently-used budget bounds what
// stays resident. The render thread looks up what is ready; it waits on disk only when it
// asks to (WaitForRoots: the first frame of a file or layer; WaitIdle: still renders).
//
// Contract:
// - Draw buffers (RegionDrawBuffers): per vertex x, y, z (z = -depth, relative to the
//   model origin the cache reports, so float32 keeps millimetres over a whole field) and the
//   cell coordinate c (the topological coordinate moved half a cell inward along the face's
//   constant axis: floor(c) at any point of a face is the 0-based (i, j, k) of the cell the
//   face belongs to, and c is an integer + 0.5 on that axis). Triangles: the top surface,
//   then the bottom, then the side (the file's simplified side triangles), counter-clockwise
//   seen from outside in the z-up frame. The side is the region mesh's side faces, not the
//   file's simplified side (UseOriginalSideFaces says why).
// - Single-layer view (Sec. 4.1, 6.1): every column keeps all nk layers, so the buffers of
//   layer k come from the same decoded mesh (PrepareLayerDrawBuffers). SetLayer picks the
//   layer that Get, IsResident and Request deal in; buffers are cached per (region, layer)
//   under the one budget, and the current layer's roots take the roots' place below.
// - Resident bytes (the buffers' sizes) stay within the budget, except that the roots are
//   never evicted, nor the regions requested by the newest frame to load others it needs
//   less: when the wanted set outgrows the budget, loading stops there (the selection then
//   draws ancestors). Least recently requested regions are evicted first. Precisely: roots
//   load whatever the budget; any other region becomes resident only if the total then is
//   within the budget (after evicting, least recently requested first, regions neither roots
//   nor wanted by the newest Request; predicted ones only for a wanted one; and for a wanted
//   one, then, the wanted regions after it in the request, the last first), so
//   ResidentBytes() <= max(budget, bytes of the roots). SetBudget evicts at once what may go; what stays (roots,
//   the newest frame's regions) may exceed a lowered budget until the next Request. When the
//   next region of the request cannot fit, loading stops there (Pending() false) until the
//   next Request or SetBudget.
// - Buffers are made from MultiresolutionFile::ReadRegion (ReadRegionSurfaces drops the
//   positions). Leaves are drawn with their runs of no thickness sealed (RegionMesh.h) and no
//   side face of no area. With simplified sides (ours), a whole-model region above the leaves
//   may be held without its exact side (see Request): on models of many layers that side is
//   most of a coarse region's bytes, and a region whose error shows draws the simplified one.
// - Property tables (Sec. 5.4: one value a hash slot) load the same way, off the render
//   thread; the previous table stays current until the new one is ready.
// - Loading runs on threads below the render thread (nice 19 on Linux: they take little of
//   the cores the frames need), one a core up to IdleLoaders (ours: the paper has one; a
//   second core then decodes while the first draws or waits, and a filtered view's leaves,
//   hundreds of them, arrive about twice as fast on two cores). Each holds at most one
//   region's buffers outside the budget while it reads. When the machine's other work keeps
//   every core busy, those threads get almost nothing; then (work waiting 300 ms, under a
//   tenth of it used by them together, checked by Request, Pending and WaitIdle) a standby
//   thread at nice 10 loads until nothing is pending: detail still arrives, a share slower.
// - What the picture cannot do without is loaded at the process's own priority, by a third
//   thread that does nothing else (ours): the topology's handedness, the roots, the model's
//   tables and a property no earlier step of it stands in for. Without them a frame draws
//   nothing or the solid colour; with two other processes keeping both cores busy, the nice
//   10 standby took about 30 s to bring a 100M-cell model's colours. So are the wanted
//   regions of an urgent request (a frame that stood in for them past its quality floor):
//   frames drawn back to back leave a nice 19 loader little, and the picture stayed past
//   the floor for as long as it starved.
// - Errors reading the file (damaged chunk) are kept, not thrown on the render thread:
//   LastError() names the file and the region; the region is never resident.
#pragma once

#include "CellRange.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "PropertyFilter.h"

#include <array>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <ctime>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_set>
#include <vector>

namespace resmr
{

struct RegionDrawBuffers
{
  std::vector<float> vertices; ///< per vertex: x, y, z, ci, cj, ck
  /// Triangles: top, bottom, side, coarse side. A side triangle has its own three vertices,
  /// the one of largest k last: drawn, that vertex provokes the triangle's flat attributes, so
  /// a fragment knows the lowest layer its triangle reaches. An edge-on sliver's interpolated
  /// k strays past its interfaces, to a cell no face shows (and the hash does not hold).
  std::vector<uint32_t> indices;
  uint32_t topIndices = 0, bottomIndices = 0, sideIndices = 0; ///< index counts of each part
  /// The file's simplified side (Sec. 4.3), after the exact one: far fewer triangles on models
  /// of many layers, within the region's error, but its layer boundaries are interpolated
  /// (see UseOriginalSideFaces); for regions whose error projects to a few pixels or more.
  /// 0 when absent (a layer's buffers).
  uint32_t coarseSideIndices = 0;
  /// false: the exact side was left out (sideIndices 0; RegionCache's simplified sides), the
  /// coarse side stands for it.
  bool exactSides = true;
  int32_t layer = -1;  ///< the layer drawn (0-based), -1: the whole model
  bool ranged = false; ///< the cells of a range or filter (CellFilter), not the whole model
  /// With a property filter, in a region it crosses: one value a triangle, the painted table's
  /// value of the triangle's cell (FaceValues; a coarse region's: its block's mean, FaceMeans);
  /// empty otherwise (painted through the tables).
  std::vector<float> faceValues;
  /// The region's footprint in (i, j) (RegionFootprint): where a range lies against it.
  std::array<float, 4> footprint{ 0.f, -1.f, 0.f, -1.f };
  /// Normal cones of the top and bottom parts (RegionSurface::cone). A layer's faces are not
  /// the region's stored surfaces, so their culling needs their own cones.
  std::array<float, 4> topCone{ 0.f, 0.f, 1.f, -2.f }, bottomCone{ 0.f, 0.f, 1.f, -2.f };
  std::size_t Bytes() const
  {
    return this->vertices.size() * 4 + this->indices.size() * 4 + this->faceValues.size() * 4;
  }
};

/// +1 or -1: the sign of the determinant of d(x, y, z) / d(i, j, k) over the model (z up),
/// which tells which side of a side face its cell lies on. From the first cell found.
int TopologyHandedness(const MultiresolutionFile& file);

/// Replaces the file's simplified side triangles (Sec. 4.3) by the side faces of the region's
/// own column mesh, two triangles a quad. The simplified side keeps the geometry within the
/// region's error but not the layer boundaries its topological coordinates interpolate, so
/// side faces would be painted with the wrong cells. Column collapse keeps every layer interface, so the
/// mesh's side faces carry exact k; what they cost is triangles.
void UseOriginalSideFaces(RegionMesh& mesh);

/// Appends `simplifiedSide` (the file's side triangles of the region, before
/// UseOriginalSideFaces) as the coarse side of `out`.
void AddCoarseSide(const RegionMesh& mesh, const std::vector<std::array<uint32_t, 3>>& simplifiedSide,
  const std::array<double, 3>& origin, int handedness, RegionDrawBuffers& out);

/// Draw buffers of a decoded region (surfaces and topological coordinates are enough).
RegionDrawBuffers PrepareRegionDrawBuffers(const RegionMesh& mesh, const std::array<double, 3>& origin, int handedness);

/// Draw buffers of layer `layer` (0-based, the model's; the mesh holds it) of a decoded region,
/// laid out as the whole model's:
/// the top and bottom faces of the layer's active cells and their side faces open in that
/// layer (no active cell across in the same layer, a fault, the model's limit;
/// ExtractLayerSurfaces). Cell coordinates lie in the layer: k + 0.5 on top and bottom faces,
/// k to k + 1 (its interfaces) on side faces.
RegionDrawBuffers PrepareLayerDrawBuffers(
  const RegionMesh& mesh, int32_t layer, const std::array<double, 3>& origin, int handedness);

/// What the cache loads for a region: its mesh read and checked, its own side faces, buffers;
/// of one layer (0-based) when `layer` >= 0. Without `exactSides` (the whole model only) the
/// region's own side faces are left out when the file has its simplified side: on models of
/// many layers they are most of a coarse region's bytes. With `filter` (and `layer` -1), the
/// cells it keeps alone (MaskToFilter), with their exact side faces and no simplified side
/// (its triangles span every layer); at a leaf its values cross, read for the region's box,
/// with face values when it paints a table; a coarse region its values cross masked by layer
/// blocks, its faces carrying their blocks' means (PropertyFilter.h).
RegionDrawBuffers LoadRegionDrawBuffers(const MultiresolutionFile& file, std::size_t region,
  const std::array<double, 3>& origin, int handedness, int32_t layer = -1, bool exactSides = true,
  const CellFilter* filter = nullptr);

/// A run of a region's triangles copied to the GPU as one piece: indices [first, end) and
/// the vertices [lowVertex, highVertex] they use.
struct DrawPiece
{
  std::size_t first = 0, end = 0;
  uint32_t lowVertex = 0, highVertex = 0;
  std::size_t bytes = 0; ///< (highVertex - lowVertex + 1) * 24 + (end - first) * 4
};

/// The piece of `buffers` from index `first` (a multiple of 3, below indices.size()): whole
/// triangles while the piece's vertex range and indices take at most maxBytes, at least one.
/// Top and bottom vertices are numbered as their quads come and side triangles have their own,
/// so a piece's range is compact: pieces repeat few shared vertices (Core.ViewSelection
/// checks the total).
DrawPiece NextDrawPiece(const RegionDrawBuffers& buffers, std::size_t first, std::size_t maxBytes);

/// The property values of a plane of cells (PropertyFile::ReadPlane): where an I/J/K range
/// cuts the grid, the cut faces' cells.
struct CutPlaneData
{
  std::string name;
  int32_t step = -1;
  int axis = 0;      ///< 0: I, 1: J, 2: K
  int64_t index = 0; ///< 0-based
  std::vector<float> values;
};

struct PropertyTableData
{
  std::string name;
  int32_t step = -1;
  int32_t layer = -1;        ///< -1: the packed table; else that layer's 2D table
  std::vector<float> values; ///< one a hash slot (packed), or nx ny values (a layer, i fastest)
};

/// The model's lookup tables for painting (Sec. 5.3-5.4): the hash and each slot's normals,
/// and the wall depths (ours, WallDepthTable.h) with depths below the cache's origin.
struct ModelTables
{
  PerfectSpatialHash hash;
  std::vector<uint8_t> normals; ///< 4 bytes a hash slot (top, bottom); empty in older files
  WallDepthTable walls;         ///< empty in older files, or when damaged (wallsError)
  int handedness = 1;           ///< the topology's (TopologyHandedness), for the side faces' offsets
  std::string wallsError;       ///< why a damaged wall table was left out (the rest paints)
};

class RegionCache
{
public:
  /// Most loader threads below the render thread (one a core up to this many).
  static constexpr unsigned IdleLoaders = 4;
  /// Starts the loader threads. `properties` may be null. With `simplifiedSides`, whole-model
  /// regions above the leaves may be loaded without their exact side (see Request).
  RegionCache(std::shared_ptr<const MultiresolutionFile> file, std::shared_ptr<const PropertyFile> properties,
    std::size_t budgetBytes, bool simplifiedSides = false);
  ~RegionCache(); ///< stops and joins the loader threads
  RegionCache(const RegionCache&) = delete;
  RegionCache& operator=(const RegionCache&) = delete;

  /// World position of the vertices' origin: (latticeOrigin x, y, -depth).
  std::array<double, 3> Origin() const { return this->ModelOrigin; }

  /// The layer shown: 0-based, or -1 (the default) for the whole model. Get, IsResident and
  /// Request then deal in that layer's buffers, and its roots are the ones loaded whatever the
  /// budget. Other layers' buffers stay resident until evicted (least recently requested
  /// first); the previous request is dropped, so nothing of the old layer is loaded any more.
  /// In a layer, each Request also asks for the roots of the layers above and below, after
  /// the predicted regions: stepping through the layers finds its first meshes ready. Returns
  /// false, changing nothing, for a layer the model does not have. Never blocks on loading.
  bool SetLayer(int32_t layer);
  int32_t Layer() const;
  /// The I/J/K range view (CellRange.h): with `range`, Get, IsResident and Request deal in the
  /// buffers of the range's cells (the layer set by SetLayer is left); null goes back to the
  /// whole model. A new range makes new buffers; those of an earlier one are evicted first as
  /// nothing requests them. Never blocks on loading.
  void SetRange(const CellRange* range);
  /// The same for a range with property filters and painted face values (PropertyFilter.h).
  void SetFilter(const CellFilter* filter);
  bool Ranged() const;
  /// Calls `visit(region, footprint)` for each region resident in the current layer or range
  /// (RegionDrawBuffers::footprint), under the cache's lock: `visit` must not call the cache.
  void VisitFootprints(const std::function<void(std::size_t, const std::array<float, 4>&)>& visit) const;

  /// The buffers of a resident region (of the current layer, or of `layer`), or null. Never
  /// blocks on loading. Of the whole model: with its exact side when resident so, else
  /// without (RegionDrawBuffers::exactSides).
  std::shared_ptr<const RegionDrawBuffers> Get(std::size_t region) const;
  std::shared_ptr<const RegionDrawBuffers> Get(std::size_t region, int32_t layer) const;
  bool IsResident(std::size_t region) const;

  /// The frame's wanted regions in loading order (replaces the previous request), then regions
  /// wanted by predicted frames, loaded after and evicted first. With simplified sides (see
  /// the constructor), regions in `simplified` above the leaves are wanted without their
  /// exact side unless they are resident with it; the roots always are (they stand in for
  /// everything, and their exact side is most of their bytes); the rest are wanted whole, and
  /// Get returns them without their exact side until they are.
  /// With `urgent` (ours), the wanted regions are work the picture cannot do without, as the
  /// roots are: the caller's frame stood in for them past its quality floor, and the
  /// essential loader reads them too, in order, beside the idle one, until a request without.
  void Request(const std::vector<std::size_t>& wanted, const std::vector<std::size_t>& predicted = {},
    const std::vector<std::size_t>& simplified = {}, bool urgent = false);
  /// Asks for a property table (name, step): the packed table, or the 2D table of `layer`
  /// (0-based); Property() keeps the previous one until it loads.
  void RequestProperty(const std::string& name, int32_t step, int32_t layer = -1);
  std::shared_ptr<const PropertyTableData> Property() const;
  /// Asks for the values of property (name, step) on the planes `planes` ((axis, index), at
  /// most MaxCutPlanes): the cells a range's cut faces show, which the packed table (the
  /// model's outside) does not hold. Loaded after the property table, before regions; planes
  /// of earlier requests stay until MaxCutPlanes newer ones push them out.
  void RequestCutPlanes(const std::string& name, int32_t step, const std::vector<std::array<int64_t, 2>>& planes);
  /// A plane's values once loaded (null before, or when it could not be read: LastError).
  std::shared_ptr<const CutPlaneData> CutPlane(const std::string& name, int32_t step, int axis, int64_t index) const;
  static constexpr std::size_t MaxCutPlanes = 12;
  /// The hash and normal tables, or null until the loader has read them (right after the
  /// roots: on a large model they are tens of MB to decompress, never the render thread's job).
  std::shared_ptr<const ModelTables> Tables() const;

  /// True while a requested region or property table is not loaded yet and can still be
  /// (not over budget, no error).
  bool Pending() const;
  /// Waits until nothing is pending or `timeout` passes; true if nothing is pending.
  bool WaitIdle(std::chrono::milliseconds timeout) const;
  /// Whether a root of the current layer is neither loaded nor failed while no error was met
  /// (roots are what a frame draws when nothing else is resident).
  bool RootsMissing() const;
  /// Waits while RootsMissing(), at most `timeout`, blocked on the loader rather than
  /// polling; true when no root is missing any more. Meanwhile the calling thread reads a root
  /// no loader reads yet (ours: the frame waits on them all, and the essential loader reads
  /// one at a time; a filter change's two masked roots of the 100M model came in one after
  /// the other).
  bool WaitForRoots(std::chrono::milliseconds timeout);

  void SetBudget(std::size_t bytes);
  std::size_t Budget() const;
  std::size_t ResidentBytes() const;
  std::size_t ResidentCount() const;
  /// Bumped whenever a region becomes resident or is evicted (mirrors drop what changed).
  uint64_t Generation() const;
  std::string LastError() const;
  /// How often the standby loader took over from the idle one (see the contract).
  uint64_t StandbyRescues() const;
  /// How long work waits, the idle loaders almost without CPU, before the standby takes over
  /// (300 ms by default).
  void SetStarvationWindow(std::chrono::milliseconds window);

private:
  /// Entries are keyed by (region, layer): region * (nk + 3) + layer + 1, the whole model's
  /// buffers without their exact side at layer nk, a range's at nk + 1 with the range's
  /// generation above bit RangeShift.
  using Key = uint64_t;
  static constexpr int RangeShift = 44;
  Key KeyOf(std::size_t region, int32_t layer) const
  {
    const Key generation = layer == this->RangeLayer() ? this->RangeGeneration << RangeShift : 0;
    return generation | (static_cast<Key>(region) * this->LayerSlots + static_cast<Key>(layer + 1));
  }
  static Key Unranged(Key key) { return key & ((Key(1) << RangeShift) - 1); }
  std::size_t RegionOf(Key key) const { return static_cast<std::size_t>(Unranged(key) / this->LayerSlots); }
  int32_t LayerOf(Key key) const { return static_cast<int32_t>(Unranged(key) % this->LayerSlots) - 1; }
  enum class Role
  {
    Idle,     ///< below every other thread (nice 19 on Linux)
    Standby,  ///< nice 10, only while the idle loaders are starved
    Essential ///< the process's priority, only what the picture cannot do without
  };
  /// A loader's loop.
  void Run(Role role);
  /// Loads the next item (the topology's handedness, the tables, the property, a region),
  /// the lock released while reading; false when there is nothing this loader can load.
  /// As the essential loader (`role`) only what EssentialPendingLocked names, and
  /// only it reads that; the others, the other regions and a property something stands in for.
  bool LoadNextLocked(std::unique_lock<std::mutex>& lock, Role role);
  // Its steps, each reading with the lock released and recording the result under it.
  void LoadHandednessLocked(std::unique_lock<std::mutex>& lock);
  void LoadTablesLocked(std::unique_lock<std::mutex>& lock);
  void LoadPropertyLocked(std::unique_lock<std::mutex>& lock);
  /// The first requested cut plane neither held nor failed, or -1. Lock held.
  int64_t NextCutPlaneLocked() const;
  void LoadCutPlaneLocked(std::unique_lock<std::mutex>& lock, std::size_t wanted);
  void LoadRegionLocked(std::unique_lock<std::mutex>& lock, Key key, Role role);
  /// For the essential loader, an urgent request's next wanted region: one nobody reads, else
  /// one an idle loader reads and nobody reads again; -1 if none. Lock held.
  int64_t NextUrgentLocked() const;
  /// Work the picture cannot do without is waiting, not being read: the handedness, a root,
  /// the tables, a property table with no earlier step of it standing in, or an urgent
  /// request's wanted region. Lock held.
  bool EssentialPendingLocked() const;
  /// The current property table is an earlier step of the one wanted, which stands in for
  /// it meanwhile. Lock held.
  bool StandsInLocked() const;
  /// Sets the standby loading when work has waited a while and the idle loaders got almost no
  /// CPU meanwhile. Lock held.
  void RescueIfStarvedLocked() const;
  /// The next entry to load (roots, then wanted, then predicted), or -1; may mark loading
  /// blocked when an entry whose size is known cannot fit. Without `roots` (a loader other
  /// than the essential one) -1 while a root waits to be read. Lock held.
  int64_t NextRegionLocked(bool roots);
  bool PendingLocked() const;
  bool RootsMissingLocked() const;
  /// Waits (the lock released) while `busy` holds, at most `timeout`; false on timeout.
  bool WaitWhile(std::chrono::milliseconds timeout, bool (RegionCache::*busy)() const) const;
  /// One slice of such a wait: rescues a starved loader, then waits for a load to end (half a
  /// starvation window at most); false, without waiting, once `deadline` has passed.
  bool WaitSliceLocked(std::unique_lock<std::mutex>& lock, std::chrono::steady_clock::time_point deadline) const;
  /// Neither loaded nor failed (it may be being read). Lock held.
  bool MissingLocked(Key key) const;
  /// The current layer's roots are pinned. Lock held.
  bool IsPinnedLocked(Key key) const;
  /// Resident entries that may be evicted to load `key`, least recently requested first; for a
  /// wanted `key`, then the wanted ones after it, the last first.
  std::vector<Key> EvictableLocked(Key key) const;
  /// Makes room and inserts, or refuses (blocking the rest of the request). Lock held.
  void InsertLocked(Key key, std::shared_ptr<const RegionDrawBuffers> buffers);
  void EvictLocked(Key key);
  // (members are the implementation's)
  std::shared_ptr<const MultiresolutionFile> File;
  std::shared_ptr<const PropertyFile> Properties;
  std::array<double, 3> ModelOrigin{};
  int Handedness = 1;
  uint64_t LayerSlots = 1; ///< nk + 3
  int32_t CurrentLayer = -1;
  int32_t ChosenLayer = -1; ///< SetLayer's, shown again when the range goes
  CellFilter CurrentFilter;
  Key RangeGeneration = 0;
  /// Makes `layer` the one Get and Request deal in (SetLayer, SetRange). Lock held.
  void SwitchLayerLocked(int32_t layer);
  bool SimplifiedSides = false;
  std::vector<std::size_t> Roots;
  std::vector<uint8_t> IsRoot, IsLeaf; ///< per region
  /// The layer a key of the whole model without its exact side has (nk).
  int32_t SimplifiedLayer() const { return static_cast<int32_t>(this->LayerSlots) - 3; }
  /// The layer a key of the range view has (nk + 1).
  int32_t RangeLayer() const { return static_cast<int32_t>(this->LayerSlots) - 2; }
  /// The key of `region` in `layer` as a request wants it (`simplified`: its exact side may
  /// be left out). Lock held.
  Key RequestKeyLocked(std::size_t region, int32_t layer, bool simplified) const;
  mutable std::mutex Lock;
  mutable std::condition_variable Wake, Idle, StandbyWake;
  std::vector<std::thread> Loaders; ///< the idle role's
  std::thread Standby, Essential;
  std::unordered_set<Key> Loading;     ///< being read by a loader
  std::unordered_set<Key> IdleLoading; ///< of those, by an idle loader
  /// Of those, read again by the essential loader for an urgent request: an idle loader may
  /// hold one for seconds on a busy machine, the picture past its floor meanwhile.
  std::unordered_set<Key> ReadAgain;
  bool HandednessKnown = false, TablesLoading = false, PropertyLoading = false;
  // Starvation of the idle loaders (see RescueIfStarvedLocked).
  mutable bool Rescuing = false;
  mutable uint64_t Rescues = 0;
  mutable std::chrono::steady_clock::time_point WindowStart;
  mutable double WindowCpuSeconds = 0;
  std::chrono::milliseconds StarvationWindow{ 300 };
  std::vector<clockid_t> LoaderClocks; ///< the idle loaders' CPU clocks
  bool Stopping = false;
  std::size_t BudgetBytes = 0;
  std::size_t Bytes = 0;
  uint64_t Changes = 0;
  uint64_t Clock = 0;
  struct Entry
  {
    std::shared_ptr<const RegionDrawBuffers> buffers;
    uint64_t lastRequested = 0;
    std::size_t bytes = 0; ///< known once prepared (also for a region refused for the budget)
    bool failed = false;
  };
  std::map<Key, Entry> Entries;
  std::vector<Key> Wanted, Predicted;
  std::unordered_set<Key> InWanted, InPredicted;
  bool WantedBlocked = false, PredictedBlocked = false; ///< loading stopped for the budget
  bool WantedUrgent = false;                            ///< the newest request was urgent
  std::size_t WantedBlockedAt = 0;                      ///< where in Wanted, while WantedBlocked
  /// A key's place in Wanted (its size if absent). Lock held.
  std::size_t WantedIndexLocked(Key key) const;
  /// Resident, unpinned entries of Wanted from place `first` on, the last first. Lock held.
  std::vector<Key> ResidentWantedFromLocked(std::size_t first) const;
  /// Another loader is reading a region the newest frame wants before `key`; with `passIdle`,
  /// not counting the idle loaders' reads (the machine's other work may starve them for
  /// seconds). Lock held.
  bool EarlierWantedLoadingLocked(Key key, bool passIdle) const;
  std::size_t Resident = 0;
  std::vector<Key> Pinned; ///< the current layer's roots
  std::string Error;
  std::string PropertyName;
  int32_t PropertyStep = -1;
  int32_t PropertyLayer = -1;
  bool PropertyWanted = false;
  std::shared_ptr<const PropertyTableData> CurrentProperty;
  std::shared_ptr<const ModelTables> LoadedTables;
  bool TablesTried = false; ///< read once, loaded or failed
  std::string CutName;
  int32_t CutStep = -1;
  std::vector<std::array<int64_t, 2>> CutWanted;
  std::vector<std::shared_ptr<const CutPlaneData>> CutPlanes; ///< held, the newest last
  std::vector<std::string> CutFailed;                         ///< planes that could not be read
  bool CutLoading = false;
  /// A cut plane's name in CutFailed.
  static std::string CutKey(const std::string& name, int32_t step, int axis, int64_t index)
  {
    return name + "/" + std::to_string(step) + "/" + std::to_string(axis) + "/" + std::to_string(index);
  }
};

} // namespace resmr
