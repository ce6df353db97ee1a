// Column-collapse simplification of a reservoir hexahedral mesh (paper Sec. 4.1): the five
// operators (internal, boundary, corner, four-boundary-vertex, doublet) plus a strip collapse
// for columns between two opposite boundary edges and a chord collapse, local Laplacian
// smoothing per layer with z at the quadric minimum, fold-over rejection, and Wu-Kobbelt
// multiple-choice selection (8 random candidates, the cheapest performed). When no candidate
// is valid any more (slivers fanned around heavy boundary nodes fold whatever collapses next
// to them), edges are rotated, the mesh is smoothed within the error already spent, and
// rejected collapses may smooth their whole 1-ring, and placed vertices lean no further from
// the one above than the layer's thickness allows; when that frees nothing either, whole
// chords of columns collapse; it gives up only when no chord can. Cells the input brings
// inverted are repaired first (reflex outline corners straightened, then collapses).
//
// Contract:
// - Works in place on a ColumnMesh; every collapse removes one column of nk hexahedra and
//   keeps every other column a hexahedral column (layers are never merged).
// - A collapse is rejected if it would fold a top or bottom face over (seen from above, any
//   corner triangle turning against the mesh orientation), leave a column with a repeated
//   node, or make a node non-manifold (an edge of three columns, or a pinched fan).
// - Quadrics of merged vertices add; a collapse costs the largest error of the vertices it
//   creates or moves. Locked columns are never removed.
// - Deterministic for a seed.
#pragma once

#include "ColumnMesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

namespace resmr
{

struct SimplifyReport
{
  int64_t columnsBefore = 0, columnsAfter = 0;
  int64_t collapses = 0;           ///< operators 1-4, strip and chord collapses performed
  int64_t doublets = 0;            ///< doublet collapses performed
  int64_t operatorCounts[7] = {};  ///< by operator: 0 internal, 1 boundary, 2 corner, 3 four-boundary, 4 doublet, 5
                                   ///< strip, 6 chord
  int64_t rejectedFoldOver = 0;    ///< candidate options rejected by the fold-over test
  int64_t rejectedInverted = 0;    ///< candidate options rejected for inverting a hexahedron
  int64_t rejectedTopology = 0;    ///< candidate options rejected as non-manifold or degenerate
  int64_t relaxations = 0;         ///< times the whole mesh was smoothed to unblock collapses
  int64_t rotations = 0;           ///< edge rotations made to unblock collapses
  int64_t straightenedColumns = 0; ///< inverted input columns made valid by moving a reflex outline corner
  double straightenedMove = 0;     ///< farthest a straightened corner moved (x, y)
  int64_t invertedColumnsCollapsed = 0; ///< columns removed first for holding an inverted input cell
  double maxError = 0;                  ///< largest cost of a performed collapse
  bool reachedTarget = false;           ///< false: no valid collapse was left
};

class ColumnCollapse
{
public:
  /// Operators, as the paper numbers them (Figs. 5, 6, 7).
  enum Operator
  {
    Internal = 0,
    Boundary = 1,
    Corner = 2,
    FourBoundary = 3,
    Doublet = 4,
    /// Ours, not the paper's: a column with two opposite boundary edges (a strip one column
    /// wide) loses both internal edges, each boundary edge becoming one node.
    Strip = 5,
    /// Ours, not the paper's (poly-chord collapse, Daniels et al. 2008): a chord of columns,
    /// each entered and left through opposite edges, from boundary to boundary (or round a
    /// loop); every edge it crosses becomes one node, and the columns on its two sides become
    /// neighbours. Used only once nothing else is valid: a straight fault otherwise keeps
    /// its nodes at the original spacing, for no single collapse merges two of them without
    /// folding the slivers that stand on it.
    Chord = 6
  };

  /// One way of collapsing a column: `merged` nodes become one, placed at node `placeAt`
  /// (one of them) or, if -1, smoothed; `kept` nodes stay and are smoothed if not on the
  /// boundary.
  struct Plan
  {
    int32_t column = -1;
    Operator op = Internal;
    int32_t merged[3] = { -1, -1, -1 };
    int mergedCount = 0;
    int32_t placeAt = -1;
    int32_t kept[2] = { -1, -1 };
    int keptCount = 0;
    /// Strip collapses only: the second boundary edge's nodes, merged at `placeSecondAt`.
    int32_t mergedSecond[2] = { -1, -1 };
    int32_t placeSecondAt = -1;
    /// The fallback when the paper's smoothing folds a face: no smoothing of kept nodes, and
    /// a smoothed survivor placed at the merged nodes' midpoint instead.
    bool gentle = false;
    /// The fallback once the simplification stalls: the whole 1-ring of the moved nodes is
    /// smoothed as well, a few times over.
    bool ring = false;
    double cost = 0;
  };

  ColumnCollapse(ColumnMesh& mesh, uint64_t seed);

  /// Collapses until at most `targetColumns` columns are left or no collapse is valid.
  /// `progress` (optional) gets the fraction done.
  SimplifyReport Simplify(int64_t targetColumns, const std::function<void(double)>& progress = {});

  /// The cheapest valid plan for one column by the operator its topology calls for; false if
  /// none is valid (or the column is locked or dead).
  bool PlanColumn(int32_t column, Plan& best);
  /// Performs a plan found by PlanColumn, then removes the doublets it forms.
  void Perform(const Plan& plan);

  const SimplifyReport& Report() const { return this->Stats; }

  /// Random candidates weighed before each collapse (Wu-Kobbelt; the paper uses 8).
  void SetCandidates(int candidates) { this->Candidates = candidates < 1 ? 1 : candidates; }

  /// Instead of random candidates, always perform the cheapest collapse of the whole mesh: a
  /// lazily updated priority queue in which only the columns a collapse touches are planned
  /// again.
  SimplifyReport SimplifyGreedy(int64_t targetColumns, const std::function<void(double)>& progress = {});

  /// Edge rotation (Tarini et al. 2010; ours, not the paper's), which Simplify runs when
  /// collapses run out: the edge two unlocked columns share turns to another diagonal of
  /// their hexagon, moving no node, where that rounds out the thinner of them without folding
  /// or inverting anything. A layer of either new column is active where it was in either
  /// old one. Returns the rotations made.
  int64_t RotateEdges();

  /// Collapses the chord through `column` across its edges `axis` and `axis + 2` (0 or 1)
  /// if that is valid (the same rules as the other operators, with the crossed edges'
  /// interior nodes smoothed), then removes the doublets it forms. Returns the columns
  /// removed (0: not valid, or the chord crosses itself or a locked column).
  int64_t CollapseChord(int32_t column, int axis);

  /// Ours, not the paper's, which Simplify runs once nothing else is valid: slivers fanned
  /// on a straight stretch of boundary (faults collapse last, their side planes weighing
  /// 10,000) have one boundary edge each, and no operator merges two of their boundary
  /// nodes. Two such columns sharing an edge from a boundary node h are split the other way
  /// (an edge rotation), which leaves h and its two boundary neighbours in one column; the
  /// corner operator removes that column, judged by its own tests. Stops at
  /// `targetColumns`; returns the columns removed.
  int64_t MergeAlongBoundaries(int64_t targetColumns);

  /// Ours, not the paper's; Simplify and SimplifyGreedy run it first. Input cells that are
  /// inverted already (reflex outline corners in Brugge and Emerald) would block every
  /// collapse around them, for no collapse may leave an inverted cell: those corners are
  /// straightened (a node of one column only moves out past the chord of its neighbours),
  /// then the columns still inverted are collapsed. Does nothing if at most `targetColumns`
  /// columns are alive.
  void RepairInvertedColumns(int64_t targetColumns);

private:
  // Undo log of the last Apply or ApplyChord: the merged nodes as they were.
  struct NodeState
  {
    int32_t node;
    uint8_t alive;
    std::array<double, 2> topology;
    std::vector<double> positions;
    std::vector<Quadric> quadrics; ///< saved only once a merge is about to change them
    bool quadricsSaved = false;
    std::vector<int32_t> columns;
  };
  /// A chord: its columns in order and the L + 1 edges they cross (L for a loop).
  struct ChordPath
  {
    std::vector<int32_t> columns;
    std::vector<std::array<int32_t, 2>> edges;
    bool closed = false;
  };
  /// The chord through a column; false if it crosses itself. `visited` (optional, two flags
  /// a column slot, one per axis) is marked along it.
  bool TraceChord(int32_t column, int axis, ChordPath& chord, std::vector<uint8_t>* visited) const;
  /// Like Apply, for a chord; `ring` also smooths the 1-ring of the moved nodes.
  bool ApplyChord(const ChordPath& chord, bool ring, double& cost);
  /// Applies and commits the cheaper valid way of collapsing a chord; the columns removed.
  int64_t PerformChord(const ChordPath& chord);
  /// Chord collapses, cheapest first, until a quarter of the columns still to go are gone;
  /// the columns removed.
  int64_t CollapseChords(int64_t targetColumns);
  void SaveNodeState(NodeState& state, int32_t node) const;
  /// No column at the node repeats a node, and the node is manifold.
  bool TopologyValidAt(int32_t node) const;
  /// Neither a fold nor an inverted cell in any column around the nodes (folds tested first,
  /// for all of them: cheap, and where most rejections happen); counts the rejection.
  bool ShapeKeptAround(const std::vector<int32_t>& nodes);
  /// Node `node` merges into `into`: quadrics add, columns are rewired (logged for Undo).
  void MergeNode(int32_t node, int32_t into);
  /// Places a node at the average of saved nodes (positions and topology), z at the
  /// quadric minimum within their depths.
  void PlaceAtAverage(int32_t node, const NodeState* const* states, int count);
  bool RotateEdge(int32_t column, int corner);
  /// The other column at edge `corner` of a column and their hexagon (see RotateEdge);
  /// false if there is none, either is locked, or the hexagon repeats a node.
  bool EdgeHexagon(int32_t column, int corner, int32_t& other, int32_t hexagon[6]) const;
  /// Whether the diagonal from hexagon[shift] to hexagon[shift + 3] is an edge already.
  bool DiagonalIsEdge(const int32_t hexagon[6], int shift) const;
  bool HexagonManifold(const int32_t hexagon[6]) const;
  static std::pair<std::array<int32_t, 4>, std::array<int32_t, 4>> SplitHexagon(const int32_t hexagon[6], int shift);
  void Rewire(int32_t column, int32_t other, const int32_t hexagon[6], const std::array<int32_t, 4>& first,
    const std::array<int32_t, 4>& second);
  /// Two columns sharing an edge from a boundary node become one (see
  /// MergeAlongBoundaries); kept only if valid.
  bool MergeAlongBoundary(int32_t column, int corner);
  bool Apply(const Plan& plan, double& cost);
  SimplifyReport Finish(int64_t targetColumns, const std::function<void(double)>& progress);
  void Undo();
  void Commit();
  /// Removes doublets at the nodes given and their neighbours, and at any a removal forms.
  void RemoveDoublets(std::vector<int32_t> worklist);
  void Smooth(int32_t node);
  bool SlideAlongBoundary(int32_t node, double allowed);
  /// Smooths every movable node once (Laplacian and quadric z inside, sliding along the
  /// boundary), each move kept only if it folds and inverts nothing and costs at most
  /// `allowed`. Returns the number of moves kept.
  int64_t Relax(double allowed);
  /// Plans every column once and performs the valid plans, cheapest first, each planned
  /// again before it goes; the collapses performed.
  int64_t SweepCollapses(int64_t targetColumns);
  /// When collapses ran out: rotations, three relaxations, boundary slivers merged in pairs.
  /// If the last time freed no column (`relaxedAt`, the column count then): only pairs and
  /// chord collapses, false if neither removed anything.
  bool Unblock(int64_t& relaxedAt, int64_t targetColumns);
  /// Moves the reflex outline corners of inverted columns (see the definition); the columns
  /// made valid.
  int64_t StraightenReflexCorners();
  /// Collapses the columns that hold an inverted cell before anything else (see the
  /// definition); the columns removed.
  int64_t CollapseInvertedColumns(int64_t targetColumns);
  /// Neither folds a face over nor inverts a cell of the column.
  bool KeepsShape(int32_t column) const;
  /// A node of a locked column: it never moves or merges into another node.
  bool Pinned(int32_t node) const;
  /// Smooths the interior 1-ring of the nodes in Scratch with them (ring plans), logging the
  /// ring for Undo and adding it to Scratch.
  void SmoothRing(bool smoothSurvivor);
  double NodeError(int32_t node) const;
  /// Depths of an interface around a node being placed, and the thicknesses and leans of the
  /// layer above it there.
  struct DepthBounds
  {
    double low = std::numeric_limits<double>::infinity(), high = -std::numeric_limits<double>::infinity();
    double thinnest = std::numeric_limits<double>::infinity(), thickest = -std::numeric_limits<double>::infinity();
    double steepest = 0; ///< largest lean (x, y offset over depth) from the vertex above
    glm::dvec2 lowXY = glm::dvec2(std::numeric_limits<double>::infinity());
    glm::dvec2 highXY = glm::dvec2(-std::numeric_limits<double>::infinity());
    /// How much the interface slopes there: its depth range over its lateral extent.
    double Slope() const
    {
      const double extent = glm::length(highXY - lowXY);
      return extent > 0 ? (high - low) / extent : 0;
    }
    /// `lean`: also the lean and the lateral extent, which only a stalled simplification's
    /// LimitLean reads (skipping them keeps the square root out of every smoothing step).
    void Add(const glm::dvec3& p, const glm::dvec3& pAbove, bool lean)
    {
      const double thickness = p.z - pAbove.z;
      low = std::min(low, p.z);
      high = std::max(high, p.z);
      thinnest = std::min(thinnest, thickness);
      thickest = std::max(thickest, thickness);
      if (!lean)
      {
        return;
      }
      const double dx = p.x - pAbove.x, dy = p.y - pAbove.y;
      lowXY = glm::min(lowXY, glm::dvec2(p.x, p.y));
      highXY = glm::max(highXY, glm::dvec2(p.x, p.y));
      if (thickness > 0)
      {
        steepest = std::max(steepest, std::sqrt(dx * dx + dy * dy) / thickness); // not hypot: slow
      }
    }
  };
  double PlaceDepth(int32_t node, int32_t k, const glm::dvec3& xy, const DepthBounds& bounds, double above) const;
  bool Manifold(int32_t node) const;
  bool FoldsOver(int32_t column) const;
  bool InvertsCells(int32_t column) const;
  void TryOption(const Plan& option, Plan& best, bool& found);
  double RandomUnit();

  ColumnMesh& Mesh;
  uint64_t RandomState;
  uint64_t Seed;
  int Candidates = 8;
  SimplifyReport Stats;
  std::vector<int32_t> AliveList;  ///< unlocked alive columns, for random picks
  std::vector<int32_t> AliveIndex; ///< position of a column in AliveList, -1 if absent

  std::vector<NodeState> SavedNodes;
  std::vector<std::pair<int32_t, std::array<int32_t, 4>>> SavedCorners;
  struct MovedNode
  {
    int32_t node;
    std::array<double, 2> topology;
    std::vector<double> positions;
  };
  std::vector<MovedNode> SavedMoves; ///< ring nodes a ring plan smoothed
  MovedNode SaveNode(int32_t node) const;
  void RestoreNode(const MovedNode& saved);
  std::vector<uint8_t> Exempt;         ///< columns the shape tests skip (CollapseInvertedColumns)
  bool Stalled = false;                ///< ring plans are tried (set once collapses run out)
  std::vector<int32_t> RemovedColumns; ///< by the last Apply or ApplyChord
  bool Pending = false;                ///< an Apply or ApplyChord awaits Undo or Commit
  std::vector<int32_t> Scratch;
  std::vector<int32_t> Around;
  // Buffers reused by the hot helpers (planning calls them for every option tried).
  std::vector<int32_t> SmoothNeighbours, SlideNeighbours;
  std::vector<uint8_t> SmoothBoundary, SlideBoundary;
  mutable std::vector<int32_t> ManifoldEnds;
  mutable std::vector<int> ManifoldComponents;
  std::vector<uint8_t> ScratchFlags;
  std::vector<double> SlideSaved;
};

} // namespace resmr
