// View-dependent selection of region meshes, paper Sec. 6.2: Lindstrom's projected error bound,
// a stateless top-down traversal of the diamond hierarchy, frustum and normal-cone culling, and
// resident ancestors standing in for regions still loading.
#include "ViewSelection.h"

#include "DiamondHierarchy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace resmr
{
namespace
{
using Box = std::array<std::array<double, 3>, 8>;

/// The 8 corners of a region's bounding volume in world coordinates (z = -depth).
Box Corners(const RegionRecord& record)
{
  const auto& b = record.bounds;
  Box corners;
  for (int c = 0; c < 8; ++c)
  {
    corners[c] = { static_cast<double>((c & 1) ? b[3] : b[0]), static_cast<double>((c & 2) ? b[4] : b[1]),
      -static_cast<double>((c & 4) ? b[2] : b[5]) };
  }
  return corners;
}

/// Whether every corner lies outside one of the six clip planes (-w <= x, y, z <= w).
bool OutsideFrustum(const Box& corners, const std::array<double, 16>& m)
{
  int outside[6] = { 0, 0, 0, 0, 0, 0 };
  for (const auto& p : corners)
  {
    double clip[4];
    for (int r = 0; r < 4; ++r)
    {
      clip[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      outside[2 * axis] += clip[axis] < -clip[3];
      outside[2 * axis + 1] += clip[axis] > clip[3];
    }
  }
  return std::any_of(std::begin(outside), std::end(outside), [](int n) { return n == 8; });
}

/// Distance from the eye to the nearest point of the region's box (0 inside).
double Distance(const RegionRecord& record, const std::array<double, 3>& eye)
{
  const auto& b = record.bounds;
  const double low[3] = { b[0], b[1], -static_cast<double>(b[5]) };
  const double high[3] = { b[3], b[4], -static_cast<double>(b[2]) };
  double squared = 0;
  for (int a = 0; a < 3; ++a)
  {
    const double d = std::max({ low[a] - eye[a], 0.0, eye[a] - high[a] });
    squared += d * d;
  }
  return std::sqrt(squared);
}

/// Lindstrom's bound: the apparent size in pixels of a sphere of radius `error` at the point of
/// the box nearest the eye, but no nearer than the near clipping plane: nothing nearer is
/// drawn, so a box around the eye (a low flight over a dipping region, a camera inside the
/// model) need not be refined to its leaves. An error of 0 projects to 0 even from inside.
/// A model-space `error` of the region's, in pixels at the box's nearest point.
double ProjectedErrorOf(const RegionRecord& record, double error, const ViewParameters& view)
{
  if (!(error > 0))
  {
    return 0;
  }
  if (view.parallel)
  {
    return error * view.pixelsPerUnit;
  }
  const double d = std::max(Distance(record, view.eye), std::max(view.nearDistance, 0.0));
  return d > 0 ? error * view.pixelsPerUnit / d : std::numeric_limits<double>::infinity();
}

double ProjectedError(const RegionRecord& record, const ViewParameters& view)
{
  return ProjectedErrorOf(record, record.error, view);
}

/// The region's typical error (its own where the file has none) at the box's centre (no
/// nearer than the near plane).
double EstimatedError(const RegionRecord& record, const ViewParameters& view)
{
  const double error = record.typicalError >= 0 ? record.typicalError : record.ownError;
  if (!(error > 0))
  {
    return 0;
  }
  if (view.parallel)
  {
    return error * view.pixelsPerUnit;
  }
  const auto& b = record.bounds;
  const double centre[3] = { 0.5 * (double(b[0]) + b[3]), 0.5 * (double(b[1]) + b[4]), -0.5 * (double(b[2]) + b[5]) };
  double squared = 0;
  for (int a = 0; a < 3; ++a)
  {
    squared += (centre[a] - view.eye[a]) * (centre[a] - view.eye[a]);
  }
  const double d = std::max({ std::sqrt(squared), view.nearDistance, 0.0 }); // never below the nearest point's
  return d > 0 ? error * view.pixelsPerUnit / d : std::numeric_limits<double>::infinity();
}

/// The share of the viewport the box's screen rectangle covers, in [0, 1]; 1 for a box reaching
/// behind the eye (it may fill the view).
double ScreenShare(const Box& corners, const std::array<double, 16>& m)
{
  double low[2] = { 1, 1 }, high[2] = { -1, -1 };
  for (const auto& p : corners)
  {
    double clip[4];
    for (int r = 0; r < 4; ++r)
    {
      clip[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
    }
    if (!(clip[3] > 0))
    {
      return 1;
    }
    for (int a = 0; a < 2; ++a)
    {
      low[a] = std::min(low[a], clip[a] / clip[3]);
      high[a] = std::max(high[a], clip[a] / clip[3]);
    }
  }
  double share = 1;
  for (int a = 0; a < 2; ++a)
  {
    share *= std::max(0.0, std::min(high[a], 1.0) - std::max(low[a], -1.0)) / 2;
  }
  return share;
}

/// Sort key of the loading order within a level: nearest first.
double Nearness(const RegionRecord& record, const Box& corners, const ViewParameters& view)
{
  if (!view.parallel)
  {
    return Distance(record, view.eye);
  }
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& c : corners)
  {
    nearest = std::min(nearest,
      (c[0] - view.eye[0]) * view.direction[0] + (c[1] - view.eye[1]) * view.direction[1] +
        (c[2] - view.eye[2]) * view.direction[2]);
  }
  return nearest;
}

/// Whether a surface whose normals lie in `cone` faces away from the eye seen from every point
/// of the box: for every corner c, the angle between the axis and eye - c exceeds 90 degrees
/// plus the half angle. The set of such directions is a convex cone (half angle at most 90),
/// so the corners decide for the whole box. Only culls what is surely invisible.
bool BackFacing(const std::array<float, 4>& cone, const Box& corners, const ViewParameters& view)
{
  const double cosine = cone[3];
  if (cosine < 0)
  {
    return false; // half angle of 90 degrees or more (or empty: handled by the caller)
  }
  const double sine = std::sqrt(std::max(0.0, 1 - cosine * cosine));
  const double axis[3] = { cone[0], cone[1], cone[2] };
  const double margin = 1e-6;
  const auto away = [&](double x, double y, double z) {
    const double length = std::sqrt(x * x + y * y + z * z);
    return length > 0 && axis[0] * x + axis[1] * y + axis[2] * z < -(sine + margin) * length;
  };
  if (view.parallel)
  {
    return away(-view.direction[0], -view.direction[1], -view.direction[2]);
  }
  for (const auto& c : corners)
  {
    if (!away(view.eye[0] - c[0], view.eye[1] - c[1], view.eye[2] - c[2]))
    {
      return false;
    }
  }
  return true;
}

struct Visit
{
  std::size_t region;
  bool culled;
};

/// The regions' estimated errors, weighted by the share of the view each one's box covers.
double WeightedEstimate(
  const std::vector<RegionRecord>& regions, const std::vector<std::size_t>& shown, const ViewParameters& view)
{
  double estimateSum = 0, shareSum = 0;
  for (std::size_t r : shown)
  {
    const double share = ScreenShare(Corners(regions[r]), view.worldToClip);
    estimateSum += share * EstimatedError(regions[r], view);
    shareSum += share;
  }
  return shareSum > 0 ? estimateSum / shareSum : 0;
}

/// What the traversal leaves: the regions it shows and the regions it split.
struct Traversal
{
  std::vector<std::size_t> shown;
  std::vector<std::vector<std::size_t>> visibleByLevel; ///< every region reached and not culled
  std::vector<uint8_t> split;                           ///< per region
  double largest = 0;
  double refineBelow = 0; ///< largest error of a diamond that only the tolerance kept whole
  double coarsenAt = std::numeric_limits<double>::infinity(); ///< smallest error of a split diamond
};
} // namespace

ViewSelector::ViewSelector(const MultiresolutionFile& file)
  : File(&file)
{
  const auto& regions = file.Regions();
  const auto& header = file.Header();
  this->Nodes.resize(regions.size());
  std::map<std::pair<int32_t, int64_t>, std::size_t> byName;
  int deepest = 0;
  const double infinity = std::numeric_limits<double>::infinity();
  this->ModelBox = { infinity, -infinity, infinity, -infinity, infinity, -infinity };
  for (std::size_t r = 0; r < regions.size(); ++r)
  {
    const auto& b = regions[r].bounds;
    const double low[3] = { b[0], b[1], -static_cast<double>(b[5]) };
    const double high[3] = { b[3], b[4], -static_cast<double>(b[2]) };
    for (int a = 0; a < 3; ++a)
    {
      this->ModelBox[2 * a] = std::min(this->ModelBox[2 * a], low[a]);
      this->ModelBox[2 * a + 1] = std::max(this->ModelBox[2 * a + 1], high[a]);
    }
    byName[{ regions[r].level, regions[r].index }] = r;
    deepest = std::max(deepest, static_cast<int>(regions[r].level));
    if (regions[r].level == 0)
    {
      this->RootRegions.push_back(r);
    }
  }
  const auto find = [&](int32_t level, int64_t index) -> int64_t {
    const auto found = byName.find({ level, index });
    return found == byName.end() ? -1 : static_cast<int64_t>(found->second);
  };
  for (std::size_t r = 0; r < regions.size(); ++r)
  {
    if (regions[r].level < header.leafLevel)
    {
      this->Nodes[r].children = { find(regions[r].level + 1, 2 * regions[r].index),
        find(regions[r].level + 1, 2 * regions[r].index + 1) };
      for (const int64_t child : this->Nodes[r].children)
      {
        if (child >= 0)
        {
          this->Nodes[static_cast<std::size_t>(child)].parent = static_cast<int64_t>(r);
        }
      }
    }
  }
  const DiamondHierarchy tree(header.box[0], header.box[1], header.box[2], header.box[3], header.leafLevel);
  for (int level = 0; level <= std::min(deepest, static_cast<int>(header.leafLevel)); ++level)
  {
    for (const auto& diamond : tree.Diamonds(level))
    {
      if (diamond.second < 0)
      {
        continue;
      }
      const int64_t a = find(level, diamond.first), b = find(level, diamond.second);
      if (a >= 0 && b >= 0)
      {
        this->Nodes[static_cast<std::size_t>(a)].partner = b;
        this->Nodes[static_cast<std::size_t>(b)].partner = a;
      }
    }
  }
}

namespace
{
/// The traversal of Sec. 6.2, level by level. A region "in the cut" at a level is one whose
/// parent was split (or a root). A culled region in the cut is neither drawn nor requested,
/// but it splits along with its diamond when its partner does (its children, inside its box,
/// are culled too), so that visible regions near the frustum's sides refine as far as they
/// need. A diamond splits when its projected error exceeds the tolerance, it is above the
/// leaf level, each of its triangles present in the file is in the cut and not a root that
/// is missing, at least one is visible, and every visible child of its visible triangles is
/// resident (a culled child is never drawn, so it need not be).
template<typename Nodes>
Traversal Traverse(const MultiresolutionFile& file, const Nodes& nodes, const std::vector<std::size_t>& roots,
  const ViewParameters& view, const std::function<bool(std::size_t)>& resident, const std::vector<RangeClass>& classes,
  const std::vector<uint8_t>& forced, const std::vector<float>& filterErrors, bool ideal)
{
  const auto& regions = file.Regions();
  const int leaves = file.Header().leafLevel;
  Traversal out;
  out.split.assign(regions.size(), 0);
  std::vector<int8_t> culled(regions.size(), -1); // -1: not computed yet
  std::vector<uint8_t> inCut(regions.size(), 0);
  const auto isCulled = [&](std::size_t r) {
    if (culled[r] < 0)
    {
      const bool outside = !classes.empty() && classes[r] == RangeClass::Outside;
      culled[r] = outside || OutsideFrustum(Corners(regions[r]), view.worldToClip) ? 1 : 0;
    }
    return culled[r] == 1;
  };
  std::vector<std::size_t> level = roots;
  for (std::size_t r : level)
  {
    inCut[r] = 1;
  }
  for (int depth = 0; !level.empty(); ++depth)
  {
    out.visibleByLevel.emplace_back();
    std::vector<std::size_t> next;
    for (std::size_t r : level)
    {
      if (!isCulled(r))
      {
        out.visibleByLevel.back().push_back(r);
      }
    }
    for (std::size_t r : level)
    {
      const int64_t partner = nodes[r].partner;
      if (partner >= 0 && static_cast<std::size_t>(partner) < r && inCut[static_cast<std::size_t>(partner)])
      {
        continue; // decided with its partner
      }
      std::vector<std::size_t> diamond{ r };
      bool complete = true;
      if (partner >= 0)
      {
        if (inCut[static_cast<std::size_t>(partner)])
        {
          diamond.push_back(static_cast<std::size_t>(partner));
        }
        else
        {
          complete = false; // the partner's area is still covered by a coarser region
        }
      }
      bool anyVisible = false, ready = true, crossed = false, filtered = false;
      double error = 0;
      for (std::size_t t : diamond)
      {
        error = std::max(error, ProjectedError(regions[t], view));
        if (t < filterErrors.size() && filterErrors[t] > 0)
        {
          const double filterError = ProjectedErrorOf(regions[t], filterErrors[t], view);
          error = std::max(error, filterError);
          filtered = filtered || filterError > view.tolerancePixels;
        }
        crossed = crossed || (!forced.empty() && forced[t]);
        if (isCulled(t))
        {
          continue;
        }
        anyVisible = true;
        if (!ideal && regions[t].level == 0 && !resident(t))
        {
          ready = false; // a missing root is not drawn and not split
        }
        for (int64_t c : nodes[t].children)
        {
          if (c >= 0 && !ideal && !isCulled(static_cast<std::size_t>(c)) && !resident(static_cast<std::size_t>(c)))
          {
            ready = false;
          }
        }
      }
      // A range may need a diamond with no triangle in view split: a neighbour's is in the cut
      // only once it is.
      // So may a property filter's (its errors reach the diamonds a crossed one needs split).
      const bool splittable = depth < leaves && complete && (anyVisible || crossed || filtered) && ready;
      const bool split = splittable && (error > view.tolerancePixels || crossed);
      // A range's split is no tolerance's.
      if (split && !crossed)
      {
        out.coarsenAt = std::min(out.coarsenAt, error);
      }
      else if (splittable && !crossed)
      {
        out.refineBelow = std::max(out.refineBelow, error);
      }
      for (std::size_t t : diamond)
      {
        if (split)
        {
          out.split[t] = 1;
          for (int64_t c : nodes[t].children)
          {
            if (c >= 0)
            {
              inCut[static_cast<std::size_t>(c)] = 1;
              next.push_back(static_cast<std::size_t>(c));
            }
          }
        }
        else if (!isCulled(t) && (ideal || resident(t)))
        {
          out.shown.push_back(t);
          out.largest = std::max(out.largest, error);
        }
      }
    }
    level = std::move(next);
  }
  return out;
}
} // namespace

bool SurfaceCulled(const std::array<float, 4>& cone, const RegionRecord& region, const ViewParameters& view)
{
  return !(cone[3] > -1.5f) || BackFacing(cone, Corners(region), view);
}

double ProjectedErrorPixels(const RegionRecord& region, const ViewParameters& view)
{
  return ProjectedError(region, view);
}

double EstimatedErrorPixels(const RegionRecord& region, const ViewParameters& view)
{
  return EstimatedError(region, view);
}

void ViewSelector::PropagateFilterErrors(std::vector<float>& widths) const
{
  // Deepest level first: a diamond's two triangles share the larger width, then their parents
  // take it, so a region that must split finds its diamond in the cut (as ForcedSplits does).
  const auto& regions = this->File->Regions();
  std::vector<std::vector<std::size_t>> byLevel;
  for (std::size_t r = 0; r < widths.size() && r < regions.size(); ++r)
  {
    const std::size_t level = static_cast<std::size_t>(std::max(regions[r].level, 0));
    byLevel.resize(std::max(byLevel.size(), level + 1));
    byLevel[level].push_back(r);
  }
  for (std::size_t level = byLevel.size(); level-- > 0;)
  {
    for (const std::size_t r : byLevel[level])
    {
      const int64_t partner = this->Nodes[r].partner;
      if (partner >= 0 && static_cast<std::size_t>(partner) < widths.size())
      {
        const float both = std::max(widths[r], widths[static_cast<std::size_t>(partner)]);
        widths[r] = widths[static_cast<std::size_t>(partner)] = both;
      }
    }
    for (const std::size_t r : byLevel[level])
    {
      const int64_t parent = this->Nodes[r].parent;
      if (parent >= 0 && static_cast<std::size_t>(parent) < widths.size())
      {
        widths[static_cast<std::size_t>(parent)] = std::max(widths[static_cast<std::size_t>(parent)], widths[r]);
      }
    }
  }
}

std::vector<uint8_t> ViewSelector::ForcedSplits(const std::vector<RangeClass>& classes) const
{
  const int leaves = this->File->Header().leafLevel;
  const auto& regions = this->File->Regions();
  std::vector<uint8_t> forced(classes.size(), 0);
  // Splitting a region needs its diamond in the cut: its parent and its partner's split.
  std::vector<int64_t> work;
  const auto need = [&](int64_t region) {
    if (region >= 0 && this->Nodes[static_cast<std::size_t>(region)].parent >= 0)
    {
      work.push_back(this->Nodes[static_cast<std::size_t>(region)].parent);
    }
  };
  for (std::size_t r = 0; r < classes.size(); ++r)
  {
    if (classes[r] == RangeClass::Crossed)
    {
      regions[r].level < leaves ? work.push_back(static_cast<int64_t>(r)) : need(static_cast<int64_t>(r));
    }
  }
  while (!work.empty())
  {
    const std::size_t r = static_cast<std::size_t>(work.back());
    work.pop_back();
    if (forced[r])
    {
      continue;
    }
    forced[r] = 1;
    need(static_cast<int64_t>(r));
    need(this->Nodes[r].partner);
  }
  return forced;
}

ViewSelection ViewSelector::Select(const ViewParameters& view, const std::function<bool(std::size_t)>& resident) const
{
  const auto& regions = this->File->Regions();
  std::vector<RangeClass> classes;
  std::vector<uint8_t> forced;
  if (this->Ranged)
  {
    classes.assign(regions.size(), RangeClass::Unknown);
    this->Ranged(classes);
    forced = this->ForcedSplits(classes);
  }
  std::vector<float> filterErrors;
  if (this->FilterErrors)
  {
    filterErrors.assign(regions.size(), 0.f);
    this->FilterErrors(filterErrors);
    this->PropagateFilterErrors(filterErrors);
  }
  const Traversal actual =
    Traverse(*this->File, this->Nodes, this->RootRegions, view, resident, classes, forced, filterErrors, false);
  const Traversal ideal =
    Traverse(*this->File, this->Nodes, this->RootRegions, view, resident, classes, forced, filterErrors, true);

  ViewSelection selection;
  selection.largestProjectedError = actual.largest;
  selection.refineBelowPixels = actual.refineBelow;
  selection.coarsenAtPixels = actual.coarsenAt;
  if (!view.parallel && !regions.empty())
  {
    const auto& box = this->ModelBox;
    double squared = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double d = std::max({ box[2 * a] - view.eye[a], 0.0, view.eye[a] - box[2 * a + 1] });
      squared += d * d;
    }
    // A margin of a millionth of the box: float bounds, double eye.
    const double margin =
      1e-6 * std::max({ box[1] - box[0], box[3] - box[2], box[5] - box[4], std::abs(box[0]), std::abs(box[2]) });
    selection.backFacesHidden = std::sqrt(squared) > 2 * std::max(view.nearDistance, 0.0) + margin;
  }
  // Front to back: nearer regions fill the depth buffer first, so the hidden fragments of
  // farther ones fail the early depth test before the (costly) fragment shader runs.
  std::vector<std::pair<double, std::size_t>> nearFirst;
  nearFirst.reserve(actual.shown.size());
  for (std::size_t r : actual.shown)
  {
    nearFirst.emplace_back(Nearness(regions[r], Corners(regions[r]), view), r);
  }
  std::sort(nearFirst.begin(), nearFirst.end());
  double estimateSum = 0, shareSum = 0;
  for (const auto& entry : nearFirst)
  {
    const std::size_t r = entry.second;
    const RegionRecord& record = regions[r];
    const Box corners = Corners(record);
    DrawnRegion drawn;
    drawn.region = r;
    drawn.projectedError = ProjectedError(record, view);
    drawn.estimatedError = EstimatedError(record, view);
    drawn.screenShare = ScreenShare(corners, view.worldToClip);
    estimateSum += drawn.screenShare * drawn.estimatedError;
    shareSum += drawn.screenShare;
    drawn.top = record.topCone[3] > -1.5f && !BackFacing(record.topCone, corners, view);
    drawn.bottom = record.bottomCone[3] > -1.5f && !BackFacing(record.bottomCone, corners, view);
    selection.drawn.push_back(drawn);
    if (ideal.split[r])
    {
      ++selection.substituted;
    }
  }
  selection.estimatedErrorPixels = shareSum > 0 ? estimateSum / shareSum : 0;
  selection.ideal.largestProjectedError = ideal.largest;
  selection.ideal.refineBelowPixels = ideal.refineBelow;
  selection.ideal.estimatedErrorPixels = WeightedEstimate(regions, ideal.shown, view);
  // The loading order: the ideal cut and its ancestors, level by level, nearest first.
  for (const auto& level : ideal.visibleByLevel)
  {
    std::vector<std::pair<double, std::size_t>> order;
    order.reserve(level.size());
    for (std::size_t r : level)
    {
      order.emplace_back(Nearness(regions[r], Corners(regions[r]), view), r);
    }
    std::sort(order.begin(), order.end());
    for (const auto& entry : order)
    {
      selection.wanted.push_back(entry.second);
    }
  }
  return selection;
}

ViewParameters PredictNextView(const ViewParameters& previous, const ViewParameters& current)
{
  ViewParameters next = current;
  for (int a = 0; a < 3; ++a)
  {
    next.eye[a] = 2 * current.eye[a] - previous.eye[a];
  }
  for (int e = 0; e < 16; ++e)
  {
    next.worldToClip[e] = 2 * current.worldToClip[e] - previous.worldToClip[e];
  }
  return next;
}

} // namespace resmr
