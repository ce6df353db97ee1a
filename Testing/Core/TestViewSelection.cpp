// View-dependent selection and out-of-core loading (paper Sec. 6.2-6.3) on .resmr files built
// by the resmr tool from real models (Reek, Brugge, SPE9, the six-cell handedness grids) and
// a synthetic one: the extremes of the projected error against SelectByError, conformity
// under random residency, frustum and normal-cone culling, resident ancestors standing in,
// draw buffers whose cell coordinates land in the right active cell, and the region cache's
// budget, LRU eviction, damaged chunks, prompt shutdown and property tables; single-layer
// buffers (exactly the layer's active cells and the faces bounding them) and the cache's
// layers (switching never waits, buffers kept per layer under the one budget); the I/J/K range
// view's footprints, forced splits and masked leaves.
#include "CoreTesting.h"

#include "CellRange.h"
#include "ConformalCut.h"
#include "DiamondHierarchy.h"
#include "FramePlanning.h"
#include "FrameRateController.h"
#include "MergedSides.h"
#include "MultiresolutionFile.h"
#include "PropertyFile.h"
#include "RegionCache.h"
#include "RegionMesh.h"
#include "UploadPacer.h"
#include "ViewSelection.h"

#include <cerrno>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <sys/resource.h>
#include <sys/stat.h>
#include <thread>
#include <tuple>
#include <unistd.h>
#include <vector>

using namespace resmr;

namespace
{
std::string Tool, Data, Temp;

int Run(const std::string& command)
{
  std::fprintf(stderr, "$ %s\n", command.c_str());
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Build(const std::string& input, const std::string& name, const std::string& options = "")
{
  const std::string out = Temp + "/" + name + ".resmr";
  CHECK(Run(Tool + " build '" + input + "' -o '" + out + "' --quiet " + options + " > /dev/null") == 0);
  return out;
}

using Vec = std::array<double, 3>;
using Mat = std::array<double, 16>;

Mat Multiply(const Mat& a, const Mat& b)
{
  Mat m{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        m[4 * r + c] += a[4 * r + k] * b[4 * k + c];
  return m;
}

Vec Normalise(Vec v)
{
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return { v[0] / l, v[1] / l, v[2] / l };
}

Vec CrossProduct(const Vec& a, const Vec& b)
{
  return { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] };
}

Mat LookAt(const Vec& eye, const Vec& target, const Vec& up)
{
  const Vec f = Normalise({ target[0] - eye[0], target[1] - eye[1], target[2] - eye[2] });
  const Vec s = Normalise(CrossProduct(f, up)), u = CrossProduct(s, f);
  const auto dot = [](const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  return { s[0], s[1], s[2], -dot(s, eye), u[0], u[1], u[2], -dot(u, eye), -f[0], -f[1], -f[2], dot(f, eye), 0, 0, 0,
    1 };
}

/// A perspective camera (viewport 1000 pixels high, square).
ViewParameters Perspective(const Vec& eye, const Vec& target, const Vec& up, double fovyDegrees, double nearPlane,
  double farPlane, double tolerance)
{
  const double t = 1 / std::tan(fovyDegrees * M_PI / 360);
  const Mat projection{ t, 0, 0, 0, 0, t, 0, 0, 0, 0, (farPlane + nearPlane) / (nearPlane - farPlane),
    2 * farPlane * nearPlane / (nearPlane - farPlane), 0, 0, -1, 0 };
  ViewParameters view;
  view.worldToClip = Multiply(projection, LookAt(eye, target, up));
  view.eye = eye;
  view.direction = Normalise({ target[0] - eye[0], target[1] - eye[1], target[2] - eye[2] });
  view.pixelsPerUnit = 1000 * t / 2;
  view.tolerancePixels = tolerance;
  return view;
}

/// A clip matrix that holds every point of the model (no culling), with the eye given apart.
Mat Everything(double scale)
{
  return { scale, 0, 0, 0, 0, scale, 0, 0, 0, 0, scale, 0, 0, 0, 0, 1 };
}

struct Model
{
  std::string path;
  std::unique_ptr<MultiresolutionFile> file;
  std::unique_ptr<ViewSelector> selector;
  Vec centre{}, low{}, high{};
  double radius = 0;
  std::map<std::pair<int32_t, int64_t>, std::size_t> byName;

  explicit Model(const std::string& p)
    : path(p)
    , file(new MultiresolutionFile(p))
    , selector(new ViewSelector(*file))
  {
    low = { 1e300, 1e300, 1e300 };
    high = { -1e300, -1e300, -1e300 };
    for (std::size_t r = 0; r < file->Regions().size(); ++r)
    {
      const auto& b = file->Regions()[r].bounds;
      byName[{ file->Regions()[r].level, file->Regions()[r].index }] = r;
      const Vec lo{ b[0], b[1], -b[5] }, hi{ b[3], b[4], -b[2] };
      for (int a = 0; a < 3; ++a)
      {
        low[a] = std::min(low[a], lo[a]);
        high[a] = std::max(high[a], hi[a]);
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      centre[a] = (low[a] + high[a]) / 2;
      radius += (high[a] - low[a]) * (high[a] - low[a]) / 4;
    }
    radius = std::sqrt(radius);
  }
  int64_t Parent(std::size_t r) const
  {
    const auto& rec = file->Regions()[r];
    if (rec.level == 0)
      return -1;
    const auto found = byName.find({ rec.level - 1, rec.index / 2 });
    return found == byName.end() ? -1 : static_cast<int64_t>(found->second);
  }
  bool IsAncestor(std::size_t a, std::size_t r) const // strict
  {
    for (int64_t p = Parent(r); p >= 0; p = Parent(static_cast<std::size_t>(p)))
      if (static_cast<std::size_t>(p) == a)
        return true;
    return false;
  }
  std::vector<std::size_t> Leaves() const
  {
    std::vector<std::size_t> leaves;
    for (std::size_t r = 0; r < file->Regions().size(); ++r)
      if (file->Regions()[r].level == file->Header().leafLevel)
        leaves.push_back(r);
    return leaves;
  }
};

std::vector<std::size_t> DrawnSet(const ViewSelection& selection)
{
  std::vector<std::size_t> drawn;
  for (const auto& d : selection.drawn)
    drawn.push_back(d.region);
  std::sort(drawn.begin(), drawn.end());
  return drawn;
}

const auto AllResident = [](std::size_t) { return true; };

/// Independent frustum test of a region's box.
bool BoxOutside(const RegionRecord& record, const Mat& m)
{
  const auto& b = record.bounds;
  for (int plane = 0; plane < 6; ++plane)
  {
    int out = 0;
    for (int c = 0; c < 8; ++c)
    {
      const double p[4] = { (c & 1) ? b[3] : b[0], (c & 2) ? b[4] : b[1], -((c & 4) ? b[2] : b[5]), 1 };
      double clip[4] = { 0, 0, 0, 0 };
      for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k)
          clip[r] += m[4 * r + k] * p[k];
      const double v = clip[plane / 2];
      out += (plane % 2 == 0) ? v < -clip[3] : v > clip[3];
    }
    if (out == 8)
      return true;
  }
  return false;
}

/// Crack-freeness of a drawn set: no drawn region next to an ancestor or descendant, no drawn
/// triangle with another's vertex at the midpoint of one of its edges (T-junction), the
/// partner of a drawn region never split further, and (full view) every leaf covered once.
void CheckConformity(const Model& model, const ViewSelection& selection, bool fullView,
  const std::function<bool(std::size_t)>& resident, const char* label)
{
  const auto& header = model.file->Header();
  const DiamondHierarchy tree(header.box[0], header.box[1], header.box[2], header.box[3], header.leafLevel);
  const std::vector<std::size_t> drawn = DrawnSet(selection);
  const std::set<std::size_t> drawnSet(drawn.begin(), drawn.end());
  int failures = 0;
  std::set<std::pair<double, double>> vertices;
  for (std::size_t r : drawn)
  {
    failures += !resident(r);
    const auto& rec = model.file->Regions()[r];
    const auto t = tree.NormalisedTriangle(rec.level, rec.index);
    for (const auto& p : { t.apex, t.left, t.right })
      vertices.insert({ p[0], p[1] });
    for (int64_t p = model.Parent(r); p >= 0; p = model.Parent(static_cast<std::size_t>(p)))
      failures += drawnSet.count(static_cast<std::size_t>(p)) != 0;
  }
  for (std::size_t r : drawn)
  {
    const auto& rec = model.file->Regions()[r];
    const auto t = tree.NormalisedTriangle(rec.level, rec.index);
    const DiamondHierarchy::Point corners[3] = { t.apex, t.left, t.right };
    for (int e = 0; e < 3; ++e)
    {
      const auto& a = corners[e];
      const auto& b = corners[(e + 1) % 3];
      if (vertices.count({ (a[0] + b[0]) / 2, (a[1] + b[1]) / 2 }))
      {
        std::fprintf(stderr, "%s: T-junction on region (%d, %lld)\n", label, rec.level, (long long)rec.index);
        ++failures;
      }
    }
    // The partner: itself drawn or covered by a drawn ancestor, never by a drawn descendant.
    for (const auto& diamond : tree.Diamonds(rec.level))
    {
      if (diamond.first != rec.index && diamond.second != rec.index)
        continue;
      const int64_t other = diamond.first == rec.index ? diamond.second : diamond.first;
      const auto found = model.byName.find({ rec.level, other });
      if (other < 0 || found == model.byName.end())
        break;
      const std::size_t partner = found->second;
      for (std::size_t d : drawn)
        failures += model.IsAncestor(partner, d);
      if (fullView)
      {
        bool covered = drawnSet.count(partner) != 0;
        for (int64_t p = model.Parent(partner); p >= 0; p = model.Parent(static_cast<std::size_t>(p)))
          covered = covered || drawnSet.count(static_cast<std::size_t>(p));
        failures += !covered;
      }
      break;
    }
  }
  if (fullView)
  {
    for (std::size_t leaf : model.Leaves())
    {
      int covering = drawnSet.count(leaf) ? 1 : 0;
      for (int64_t p = model.Parent(leaf); p >= 0; p = model.Parent(static_cast<std::size_t>(p)))
        covering += drawnSet.count(static_cast<std::size_t>(p)) ? 1 : 0;
      failures += covering != 1;
    }
  }
  if (failures)
    std::fprintf(stderr, "%s: %d conformity failures among %zu drawn\n", label, failures, drawn.size());
  CHECK(failures == 0);
}

void TestExtremes(const Model& model)
{
  const auto& regions = model.file->Regions();
  ViewParameters view;
  view.worldToClip = Everything(1e-9);
  view.eye = { model.centre[0], model.centre[1], model.high[2] + model.radius };
  view.tolerancePixels = 1;
  view.pixelsPerUnit = 1e15;
  const auto finest = model.selector->Select(view, AllResident);
  CHECK(DrawnSet(finest) == SelectByError(*model.file, 0));
  CHECK(finest.substituted == 0);
  view.pixelsPerUnit = 1e-15;
  const auto coarsest = model.selector->Select(view, AllResident);
  std::vector<std::size_t> roots = model.selector->Roots();
  std::sort(roots.begin(), roots.end());
  CHECK(DrawnSet(coarsest) == roots);
  std::printf("  %s: %zu regions, leaf level %d, finest cut %zu, roots %zu\n", model.path.c_str(), regions.size(),
    model.file->Header().leafLevel, finest.drawn.size(), roots.size());
  // Parallel: projected error = e * pixelsPerUnit, so the cut is SelectByError(tol / ppu).
  view.parallel = true;
  view.direction = { 0, 0, -1 };
  view.pixelsPerUnit = 2.5;
  int distinct = 0;
  std::size_t previous = 0;
  for (double tolerance : { 0.7, 3.3, 17.0, 61.0, 240.0, 900.0, 4100.0 })
  {
    view.tolerancePixels = tolerance;
    const auto selection = model.selector->Select(view, AllResident);
    const auto expected = SelectByError(*model.file, tolerance / view.pixelsPerUnit);
    CHECK(DrawnSet(selection) == expected);
    double largest = 0, sum = 0, shares = 0;
    for (const auto& d : selection.drawn)
    {
      largest = std::max(largest, regions[d.region].error * view.pixelsPerUnit);
      CHECK(d.estimatedError == regions[d.region].typicalError * view.pixelsPerUnit);
      CHECK(d.screenShare >= 0 && d.screenShare <= 1);
      sum += d.screenShare * d.estimatedError;
      shares += d.screenShare;
    }
    CHECK(selection.largestProjectedError == largest);
    // The estimate: the regions' typical errors (parallel: at any distance) weighted by the
    // view they cover, never past the bound.
    CHECK(shares > 0 && std::abs(selection.estimatedErrorPixels - sum / shares) <= 1e-9 * (1 + sum / shares));
    CHECK(selection.estimatedErrorPixels <= largest * (1 + 1e-9));
    distinct += expected.size() != previous;
    previous = expected.size();
    CheckConformity(model, selection, true, AllResident, "parallel");
  }
  CHECK(distinct >= 3);
  // Typical errors: a mean, so at most the region's own error, and below it where the
  // simplification removed anything (a region whose every vertex moved as far is unlikely).
  int below = 0;
  for (const auto& r : regions)
  {
    CHECK(r.typicalError >= 0 && r.typicalError <= r.ownError);
    below += r.typicalError < 0.9 * r.ownError;
  }
  CHECK(below > 0);
  // Perspective: a region's estimate is at most its bound (a smaller error, seen farther).
  view.parallel = false;
  view.pixelsPerUnit = 1000;
  view.eye = { model.low[0], model.low[1], model.high[2] + 0.05 * model.radius };
  view.tolerancePixels = 8;
  const auto low = model.selector->Select(view, AllResident);
  double estimated = 0;
  for (const auto& d : low.drawn)
  {
    CHECK(d.estimatedError <= d.projectedError && d.estimatedError == EstimatedErrorPixels(regions[d.region], view));
    estimated = std::max(estimated, d.estimatedError);
  }
  CHECK(low.estimatedErrorPixels <= estimated * (1 + 1e-9));
}

void TestConformity(const Model& model)
{
  std::mt19937_64 random(11);
  const std::size_t count = model.file->Regions().size();
  int views = 0;
  std::size_t mostDrawn = 0;
  for (int trial = 0; trial < 40; ++trial)
  {
    std::vector<uint8_t> resident(count);
    const double fraction = (trial % 5) / 4.0;
    for (std::size_t r = 0; r < count; ++r)
      resident[r] =
        model.file->Regions()[r].level == 0 || std::uniform_real_distribution<double>(0, 1)(random) < fraction;
    const auto isResident = [&](std::size_t r) { return resident[r] != 0; };
    const double angle = trial * 0.7;
    const Vec eye{ model.centre[0] + 1.5 * model.radius * std::cos(angle),
      model.centre[1] + 1.5 * model.radius * std::sin(angle), model.centre[2] + model.radius * (0.2 + trial % 3) };
    // Full view (no culling), then a narrow frustum through the same eye.
    ViewParameters view;
    view.worldToClip = Everything(1e-9);
    view.eye = eye;
    view.pixelsPerUnit = 1000;
    view.tolerancePixels = std::pow(2.0, trial % 9);
    const auto full = model.selector->Select(view, isResident);
    CheckConformity(model, full, true, isResident, "full view");
    mostDrawn = std::max(mostDrawn, full.drawn.size());
    const Vec target{ model.centre[0] + 0.3 * model.radius * std::cos(3 * angle), model.centre[1], model.centre[2] };
    const auto narrow = model.selector->Select(
      Perspective(eye, target, { 0, 0, 1 }, 12, 1, 10 * model.radius, view.tolerancePixels), isResident);
    CheckConformity(model, narrow, false, isResident, "narrow frustum");
    views += 2;
  }
  std::printf("  conformity: %d views, up to %zu regions drawn\n", views, mostDrawn);
}

/// The cut stays the same for any tolerance in [refineBelowPixels, coarsenAtPixels) and
/// changes at either end: just below the first a diamond splits, at the second one merges.
void TestToleranceInterval(const Model& model)
{
  std::mt19937_64 random(23);
  const std::size_t count = model.file->Regions().size();
  int refined = 0, coarsened = 0;
  for (int trial = 0; trial < 24; ++trial)
  {
    std::vector<uint8_t> resident(count);
    const double fraction = trial % 3 == 0 ? 1.0 : 0.6;
    for (std::size_t r = 0; r < count; ++r)
      resident[r] =
        model.file->Regions()[r].level == 0 || std::uniform_real_distribution<double>(0, 1)(random) < fraction;
    const auto isResident = [&](std::size_t r) { return resident[r] != 0; };
    const double angle = trial * 0.9;
    const Vec eye{ model.centre[0] + 1.3 * model.radius * std::cos(angle),
      model.centre[1] + 1.3 * model.radius * std::sin(angle), model.centre[2] + model.radius * 0.4 };
    ViewParameters view = Perspective(eye, model.centre, { 0, 0, 1 }, 40, 1e-3 * model.radius, 10 * model.radius, 1);
    view.pixelsPerUnit = 1000;
    view.tolerancePixels = std::pow(2.0, trial % 8);
    const auto selection = model.selector->Select(view, isResident);
    const double below = selection.refineBelowPixels, at = selection.coarsenAtPixels;
    CHECK(below <= view.tolerancePixels && view.tolerancePixels < at);
    const auto cutAt = [&](double tolerance) {
      ViewParameters other = view;
      other.tolerancePixels = tolerance;
      return DrawnSet(model.selector->Select(other, isResident));
    };
    const std::vector<std::size_t> cut = DrawnSet(selection);
    if (below > 0)
    {
      CHECK(cutAt(below) == cut);
      CHECK(cutAt(below * (1 - 1e-9)) != cut);
      ++refined;
    }
    if (std::isfinite(at))
    {
      CHECK(cutAt(std::nextafter(at, 0.0)) == cut);
      CHECK(cutAt(at) != cut);
      ++coarsened;
    }
  }
  std::printf("  tolerance interval: %d views could refine, %d could coarsen\n", refined, coarsened);
  CHECK(refined >= 6 && coarsened >= 6);
}

void TestFrustum(const Model& model)
{
  const Vec above{ model.centre[0], model.centre[1], model.high[2] + model.radius };
  // Looking up, away from the model: nothing.
  const auto away = model.selector->Select(
    Perspective(above, { above[0], above[1], above[2] + 1 }, { 0, 1, 0 }, 60, 1, 10 * model.radius, 1), AllResident);
  CHECK(away.drawn.empty() && away.wanted.empty());
  // Everything in sight, then a narrow frustum at a corner.
  const Vec eye{ model.centre[0], model.centre[1], model.high[2] + 3 * model.radius };
  const auto wide =
    model.selector->Select(Perspective(eye, model.centre, { 0, 1, 0 }, 90, 1, 10 * model.radius, 1e-9), AllResident);
  CHECK(DrawnSet(wide) == SelectByError(*model.file, 0));
  const auto& b = model.file->Regions()[model.Leaves()[0]].bounds;
  const Vec target{ (b[0] + b[3]) / 2, (b[1] + b[4]) / 2, -(b[2] + b[5]) / 2 };
  const ViewParameters narrowView = Perspective(eye, target, { 0, 1, 0 }, 8, 1, 10 * model.radius, 1e-9);
  const auto narrow = model.selector->Select(narrowView, AllResident);
  CHECK(!narrow.drawn.empty() && narrow.drawn.size() < wide.drawn.size());
  const std::vector<std::size_t> drawn = DrawnSet(narrow);
  std::size_t culled = 0;
  for (std::size_t r : SelectByError(*model.file, 0))
  {
    if (!std::binary_search(drawn.begin(), drawn.end(), r))
    {
      ++culled;
      CHECK(BoxOutside(model.file->Regions()[r], narrowView.worldToClip));
    }
  }
  for (std::size_t r : drawn)
    CHECK(!BoxOutside(model.file->Regions()[r], narrowView.worldToClip));
  std::printf("  frustum: wide %zu drawn, narrow %zu drawn, %zu finest regions culled\n", wide.drawn.size(),
    narrow.drawn.size(), culled);
}

void TestNormalCones(const Model& model)
{
  const auto& regions = model.file->Regions();
  int topsShown = 0, bottomsCulled = 0, emptyHidden = 0;
  for (int parallel = 0; parallel < 2; ++parallel)
  {
    const Vec eye{ model.centre[0], model.centre[1], model.high[2] + 4 * model.radius };
    ViewParameters view = Perspective(eye, model.centre, { 0, 1, 0 }, 60, 1, 10 * model.radius, 1e-9);
    view.parallel = parallel == 1;
    const auto selection = model.selector->Select(view, AllResident);
    for (const auto& d : selection.drawn)
    {
      const auto& top = regions[d.region].topCone;
      const auto& bottom = regions[d.region].bottomCone;
      CHECK(d.side);
      if (bottom[3] > 0.9f && bottom[2] < -0.9f)
      {
        CHECK(!d.bottom);
        bottomsCulled += !d.bottom;
      }
      if (top[3] > -1.5f && top[2] > 0.5f && top[3] > 0.5f)
      {
        CHECK(d.top);
        topsShown += d.top;
      }
      if (top[3] < -1.5f)
      {
        CHECK(!d.top);
        ++emptyHidden;
      }
      if (bottom[3] < -1.5f)
        CHECK(!d.bottom);
    }
  }
  // From below, the other way round.
  const Vec below{ model.centre[0], model.centre[1], model.low[2] - 4 * model.radius };
  const auto fromBelow =
    model.selector->Select(Perspective(below, model.centre, { 0, 1, 0 }, 60, 1, 10 * model.radius, 1e-9), AllResident);
  int topsCulled = 0;
  for (const auto& d : fromBelow.drawn)
  {
    const auto& top = regions[d.region].topCone;
    if (top[3] > 0.9f && top[2] > 0.9f)
    {
      CHECK(!d.top);
      ++topsCulled;
    }
  }
  CHECK(topsShown > 0 && bottomsCulled > 0 && topsCulled > 0);
  std::printf("  normal cones: from above %d tops shown, %d bottoms culled; from below %d tops culled\n", topsShown,
    bottomsCulled, topsCulled);
}

void TestFallback(const Model& model)
{
  const auto& roots = model.selector->Roots();
  const auto onlyRoots = [&](std::size_t r) { return model.file->Regions()[r].level == 0; };
  const Vec eye{ model.centre[0], model.centre[1], model.high[2] + model.radius };
  const ViewParameters view = Perspective(eye, model.centre, { 0, 1, 0 }, 90, 1, 10 * model.radius, 0.5);
  const auto selection = model.selector->Select(view, onlyRoots);
  std::vector<std::size_t> sortedRoots(roots.begin(), roots.end());
  std::sort(sortedRoots.begin(), sortedRoots.end());
  CHECK(DrawnSet(selection) == sortedRoots);
  CHECK(selection.substituted == roots.size());
  CHECK(selection.wanted.size() > roots.size());
  std::set<std::size_t> seen;
  for (std::size_t i = 0; i < selection.wanted.size(); ++i)
  {
    const std::size_t r = selection.wanted[i];
    if (i < roots.size())
      CHECK(model.file->Regions()[r].level == 0);
    const int64_t parent = model.Parent(r);
    CHECK(parent < 0 || seen.count(static_cast<std::size_t>(parent)));
    if (i > 0)
      CHECK(model.file->Regions()[selection.wanted[i - 1]].level <= model.file->Regions()[r].level);
    seen.insert(r);
  }
  // No root resident: nothing drawn.
  CHECK(model.selector->Select(view, [](std::size_t) { return false; }).drawn.empty());
  // Loading what is wanted, frame after frame, reaches the ideal cut.
  const auto ideal = model.selector->Select(view, AllResident);
  std::set<std::size_t> loaded(roots.begin(), roots.end());
  int frames = 0;
  for (; frames < 20; ++frames)
  {
    const auto frame = model.selector->Select(view, [&](std::size_t r) { return loaded.count(r) != 0; });
    if (frame.substituted == 0)
    {
      CHECK(DrawnSet(frame) == DrawnSet(ideal));
      break;
    }
    for (std::size_t r : frame.wanted)
      loaded.insert(r);
  }
  CHECK(frames <= 2);
  // A frame drawing stand-ins tells what its ideal cut will show: the figures of the frame
  // with everything resident.
  CHECK(std::abs(selection.ideal.estimatedErrorPixels - ideal.estimatedErrorPixels) <=
    1e-9 * std::max(1.0, ideal.estimatedErrorPixels));
  CHECK(selection.ideal.largestProjectedError == ideal.largestProjectedError);
  CHECK(selection.ideal.refineBelowPixels == ideal.refineBelowPixels);
  CHECK(ideal.ideal.largestProjectedError == ideal.largestProjectedError);
  CHECK(selection.estimatedErrorPixels > ideal.estimatedErrorPixels);
  std::printf("  fallback: roots drawn for %zu wanted, ideal cut %zu after %d frames\n", selection.wanted.size(),
    ideal.drawn.size(), frames);
}

/// A moving frame selected within the estimated-error floor: from the controller's coarse
/// start, with only the roots resident, one selection puts the ideal cut within the floor.
void TestSelectWithinFloor(const Model& model)
{
  const auto onlyRoots = [&](std::size_t r) { return model.file->Regions()[r].level == 0; };
  const Vec eye{ model.centre[0] + model.radius, model.centre[1], model.high[2] + 0.5 * model.radius };
  const ViewParameters start = Perspective(eye, model.centre, { 0, 0, 1 }, 30, 1, 10 * model.radius, 64);
  const ViewSelection coarse = model.selector->Select(start, onlyRoots);
  const double floor = coarse.ideal.estimatedErrorPixels / 4;
  if (!(floor > 0))
  {
    return; // nothing simplified in view
  }
  FrameRateController controller;
  controller.SetTargetFramesPerSecond(10);
  controller.SetMaximumEstimatedPixels(floor);
  controller.Reset(64);
  ViewParameters view = start;
  const ViewSelection held = SelectWithinFloor(*model.selector, controller, view, onlyRoots);
  CHECK(view.tolerancePixels < 64 && view.tolerancePixels == controller.Tolerance());
  CHECK(held.ideal.estimatedErrorPixels <= floor || view.tolerancePixels == FrameRateController::MinimumPixels);
  // The frame draws what is resident either way; what it wants is finer.
  CHECK(DrawnSet(held) == DrawnSet(coarse));
  CHECK(held.wanted.size() > coarse.wanted.size());
  // Within the floor (or without one) the tolerance stays.
  FrameRateController loose;
  loose.SetTargetFramesPerSecond(10);
  loose.SetMaximumEstimatedPixels(2 * coarse.ideal.estimatedErrorPixels);
  loose.Reset(64);
  ViewParameters same = start;
  CHECK(SelectWithinFloor(*model.selector, loose, same, onlyRoots).wanted == coarse.wanted);
  CHECK(same.tolerancePixels == 64 && loose.Tolerance() == 64);
  std::printf("  within the floor: %.2f px estimated at 64 px, floor %.2f px: %.2f px at %.2f px\n",
    coarse.ideal.estimatedErrorPixels, floor, held.ideal.estimatedErrorPixels, view.tolerancePixels);
}

/// Back faces may be culled only from outside the model, with the near plane clear of it.
void TestBackFaces(const Model& model)
{
  const Vec above{ model.centre[0], model.centre[1], model.high[2] + model.radius };
  ViewParameters view = Perspective(above, model.centre, { 0, 1, 0 }, 30, 1, 10 * model.radius, 1);
  view.nearDistance = 0.01 * model.radius;
  CHECK(model.selector->Select(view, AllResident).backFacesHidden);
  view.nearDistance = 0.6 * model.radius; // the near plane may reach into the model
  CHECK(!model.selector->Select(view, AllResident).backFacesHidden);
  view.nearDistance = 0.01 * model.radius;
  view.parallel = true;
  CHECK(!model.selector->Select(view, AllResident).backFacesHidden);
  const Vec inside{ model.centre[0], model.centre[1], model.centre[2] };
  view = Perspective(
    inside, { model.centre[0] + 1, model.centre[1], model.centre[2] }, { 0, 0, 1 }, 30, 1e-3, 10 * model.radius, 1);
  view.nearDistance = 1e-3;
  CHECK(!model.selector->Select(view, AllResident).backFacesHidden);
  // Just above the top of the box: inside by less than the margin is still inside.
  const Vec grazing{ model.centre[0], model.centre[1], model.high[2] - 1e-9 * model.radius };
  view = Perspective(grazing, model.centre, { 0, 1, 0 }, 30, 1e-3, 10 * model.radius, 1);
  CHECK(!model.selector->Select(view, AllResident).backFacesHidden);
}

void TestPrediction()
{
  ViewParameters a, b;
  a.eye = { 1, 2, 3 };
  b.eye = { 2, 4, 5 };
  for (int e = 0; e < 16; ++e)
  {
    a.worldToClip[e] = e;
    b.worldToClip[e] = 2 * e + 1;
  }
  b.tolerancePixels = 3;
  b.pixelsPerUnit = 7;
  const ViewParameters next = PredictNextView(a, b);
  CHECK(next.eye == (Vec{ 3, 6, 7 }));
  CHECK(next.worldToClip[5] == 17 && next.worldToClip[0] == 2);
  CHECK(next.tolerancePixels == 3 && next.pixelsPerUnit == 7);
}

/// Cell coordinates of the draw buffers on every leaf region: the floor of an interior point
/// of every triangle is an active cell whose face it is (top: nothing active above, bottom:
/// nothing below, side: an open side of that cell on the face's plane).
void TestDrawBuffers(const std::string& path, int expectedHandedness)
{
  const MultiresolutionFile file(path);
  const int handedness = TopologyHandedness(file);
  CHECK(handedness == expectedHandedness || expectedHandedness == 0);
  const auto& dims = file.Header().dims;
  std::vector<std::vector<uint8_t>> active;
  for (int64_t k = 0; k < dims[2]; ++k)
    active.push_back(file.ReadActiveLayer(k));
  const auto isActive = [&](int64_t i, int64_t j, int64_t k) {
    return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2] &&
      active[static_cast<std::size_t>(k)][static_cast<std::size_t>(i + dims[0] * j)] != 0;
  };
  const auto& o = file.Header().latticeOrigin;
  const std::array<double, 3> origin{ o[0], o[1], -o[2] };
  // Generic barycentric weights: an interior point that never falls on a cell boundary.
  const double w[3] = { 1.0 / 3 + std::sqrt(2.0) * 1e-3, 1.0 / 3 + std::sqrt(3.0) * 1e-3, 0 };
  const double w2 = 1 - w[0] - w[1];
  std::size_t regions = 0, triangles = 0, bad = 0, spanning = 0, sideBad = 0, inwardTopBottom = 0, inwardSides = 0;
  double largestError = 0;
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
  {
    if (file.Regions()[r].level != file.Header().leafLevel)
      continue;
    ++regions;
    const RegionMesh mesh = file.ReadRegion(r);
    const RegionDrawBuffers buffers = PrepareRegionDrawBuffers(mesh, origin, handedness);
    const std::size_t vertexCount = buffers.vertices.size() / 6;
    CHECK(buffers.vertices.size() % 6 == 0 && buffers.indices.size() % 3 == 0);
    CHECK(buffers.topIndices + buffers.bottomIndices + buffers.sideIndices == buffers.indices.size());
    CHECK(buffers.topIndices == 6 * mesh.top.quads.size() && buffers.bottomIndices == 6 * mesh.bottom.quads.size());
    CHECK(buffers.sideIndices == 3 * mesh.sideTriangles.size());
    std::set<uint32_t> topUsed, bottomUsed;
    for (const auto& q : mesh.top.quads)
      topUsed.insert(q.begin(), q.end());
    for (const auto& q : mesh.bottom.quads)
      bottomUsed.insert(q.begin(), q.end());
    CHECK(vertexCount == topUsed.size() + bottomUsed.size() + 3 * mesh.sideTriangles.size());
    std::vector<uint8_t> referenced(vertexCount, 0);
    for (uint32_t i : buffers.indices)
    {
      CHECK(i < vertexCount);
      if (i < vertexCount)
        referenced[i] = 1;
    }
    CHECK(std::all_of(referenced.begin(), referenced.end(), [](uint8_t x) { return x != 0; }));
    // Positions: the first top vertex against the mesh.
    if (!mesh.top.quads.empty())
    {
      const double* p = &mesh.positions[mesh.top.quads[0][0] * 3];
      largestError = std::max({ largestError, std::fabs(buffers.vertices[0] + origin[0] - p[0]),
        std::fabs(buffers.vertices[1] + origin[1] - p[1]), std::fabs(buffers.vertices[2] + origin[2] + p[2]) });
    }
    // The region's columns by cell (i, j).
    std::map<std::pair<int64_t, int64_t>, std::size_t> columns;
    for (std::size_t c = 0; c < mesh.corners.size(); ++c)
    {
      double i = 1e300, j = 1e300;
      for (uint32_t n : mesh.corners[c])
      {
        i = std::min(i, double(mesh.topology[n][0]));
        j = std::min(j, double(mesh.topology[n][1]));
      }
      columns[{ int64_t(i), int64_t(j) }] = c;
    }
    for (std::size_t t = 0; t < buffers.indices.size(); t += 3)
    {
      ++triangles;
      // Winding: counter-clockwise seen from outside (the renderer culls back faces): tops
      // face up, bottoms down, sides away from their cell.
      {
        const float* a = &buffers.vertices[buffers.indices[t] * 6];
        const float* b = &buffers.vertices[buffers.indices[t + 1] * 6];
        const float* c = &buffers.vertices[buffers.indices[t + 2] * 6];
        const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] }, v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
        const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
        const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        double outward[3] = { 0, 0, 0 };
        if (t < buffers.topIndices)
          outward[2] = 1;
        else if (t < buffers.topIndices + buffers.bottomIndices)
          outward[2] = -1;
        else
        {
          // From the owning cell's centre to the face's.
          const uint32_t layers = static_cast<uint32_t>(mesh.layers + 1);
          double cellCoord[3] = { 0, 0, 0 };
          for (int w = 0; w < 3; ++w)
            for (int x = 0; x < 3; ++x)
              cellCoord[x] += buffers.vertices[buffers.indices[t + w] * 6 + 3 + x] / 3;
          const uint32_t k = static_cast<uint32_t>(std::floor(cellCoord[2]));
          const auto column = columns.find({ int64_t(std::floor(cellCoord[0])), int64_t(std::floor(cellCoord[1])) });
          if (column != columns.end())
          {
            for (uint32_t corner : mesh.corners[column->second])
              for (uint32_t level : { k, k + 1 })
                for (int x = 0; x < 3; ++x)
                {
                  const double p = mesh.positions[(corner * layers + level) * 3 + x]; // (x, y, depth)
                  outward[x] -= ((x == 2 ? -p : p) - origin[x]) / 8;
                }
            for (int x = 0; x < 3; ++x)
              outward[x] += (a[x] + b[x] + c[x]) / 3;
          }
        }
        const double along = n[0] * outward[0] + n[1] * outward[1] + n[2] * outward[2];
        const double outwardLength =
          std::sqrt(outward[0] * outward[0] + outward[1] * outward[1] + outward[2] * outward[2]);
        if (length > 0 && outwardLength > 0 && along < -1e-3 * length * outwardLength)
        {
          if (t < buffers.topIndices + buffers.bottomIndices)
            ++inwardTopBottom;
          else
            ++inwardSides;
        }
      }
      double point[3] = { 0, 0, 0 };
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a)
          point[a] += (v == 2 ? w2 : w[v]) * buffers.vertices[buffers.indices[t + v] * 6 + 3 + a];
      const int64_t i = int64_t(std::floor(point[0])), j = int64_t(std::floor(point[1])),
                    k = int64_t(std::floor(point[2]));
      bool ok = isActive(i, j, k);
      if (t < buffers.topIndices)
        ok = ok && !isActive(i, j, k - 1);
      else if (t < buffers.topIndices + buffers.bottomIndices)
        ok = ok && !isActive(i, j, k + 1);
      else
      {
        // The face's plane: the axis whose coordinate is an integer + 0.5 at every vertex.
        int axis = -1;
        for (int a = 0; a < 3 && axis < 0; ++a)
        {
          bool half = true;
          for (int v = 0; v < 3; ++v)
          {
            const double c = buffers.vertices[buffers.indices[t + v] * 6 + 3 + a];
            half = half && std::fabs(c - std::floor(c) - 0.5) < 1e-6 && std::fabs(c - point[a]) < 1e-6;
          }
          if (half)
            axis = a;
        }
        const auto column = columns.find({ i, j });
        ok = ok && column != columns.end();
        if (axis != 0 && axis != 1)
        {
          // Simplified across a pillar: the triangle spans an i face and a j face, so no one
          // cell owns it; counted, not checked.
          ++spanning;
          continue;
        }
        if (ok)
        {
          // The face plane: the vertices' topological coordinate along the axis, on the cell's
          // low or high side; the cell's edge lying there must be open.
          const auto& tv = mesh.topology;
          const std::size_t side = (t - buffers.topIndices - buffers.bottomIndices) / 3;
          const uint32_t node = mesh.sideTriangles[side][0] / static_cast<uint32_t>(mesh.layers + 1);
          const double plane = tv[node][axis];
          ok = plane == double(axis == 0 ? i : j) || plane == double(axis == 0 ? i : j) + 1;
          const auto& q = mesh.corners[column->second];
          bool open = false;
          for (int e = 0; e < 4; ++e)
          {
            if (tv[q[e]][axis] == plane && tv[q[(e + 1) % 4]][axis] == plane)
              open = (mesh.openSides[column->second * mesh.layers + k] >> e) & 1;
          }
          ok = ok && open;
        }
      }
      if (!ok && t >= buffers.topIndices + buffers.bottomIndices)
        ++sideBad;
      if (!ok && bad < 4)
      {
        const int part = t < buffers.topIndices ? 0 : t < buffers.topIndices + buffers.bottomIndices ? 1 : 2;
        std::fprintf(stderr,
          "    misplaced %s triangle in region %zu at (%.3f %.3f %.3f): active %d above %d below %d\n",
          part == 0     ? "top"
            : part == 1 ? "bottom"
                        : "side",
          r, point[0], point[1], point[2], int(isActive(i, j, k)), int(isActive(i, j, k - 1)),
          int(isActive(i, j, k + 1)));
        if (part == 2)
          for (int v = 0; v < 3; ++v)
          {
            const float* x = &buffers.vertices[buffers.indices[t + v] * 6];
            std::fprintf(stderr, "      %g %g %g | %g %g %g\n", x[0], x[1], x[2], x[3], x[4], x[5]);
          }
      }
      bad += !ok;
    }
  }
  std::printf("  draw buffers %s: handedness %+d, %zu leaf regions, %zu triangles, %zu misplaced, %zu side triangles "
              "across a pillar, position error %.3g; facing inward: %zu top/bottom, %zu side\n",
    path.c_str(), handedness, regions, triangles, bad, spanning, largestError, inwardTopBottom, inwardSides);
  // A few faces of warped cells (and simplified side triangles across a pillar, measured
  // against one cell) point past 90 degrees from their cell's centre: 2 in a thousand at most.
  CHECK(inwardTopBottom * 1000 <= triangles && inwardSides * 500 <= triangles);
  // Top and bottom faces are exact; a simplified side triangle may stray over a cell it does
  // not own (it approximates a staircase of open faces): a few in a thousand at most.
  CHECK(bad == sideBad && triangles > 0);
  CHECK(sideBad * 1000 < triangles && spanning * 100 < triangles);
  CHECK(largestError < 1e-2);
}

std::vector<std::size_t> RegionBytes(const MultiresolutionFile& file)
{
  const int handedness = TopologyHandedness(file);
  const auto& o = file.Header().latticeOrigin;
  std::vector<std::size_t> bytes;
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
    bytes.push_back(LoadRegionDrawBuffers(file, r, { o[0], o[1], -o[2] }, handedness).Bytes());
  return bytes;
}

/// Every region's buffers hold the exact side (its mesh's side quads) and, after it, the
/// file's simplified side as the coarse side; coarse levels' simplified sides are smaller.
void TestCoarseSides(const std::string& path)
{
  const MultiresolutionFile file(path);
  const int handedness = TopologyHandedness(file);
  const auto& o = file.Header().latticeOrigin;
  std::size_t exact = 0, coarse = 0;
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
  {
    const RegionDrawBuffers buffers = LoadRegionDrawBuffers(file, r, { o[0], o[1], -o[2] }, handedness);
    RegionMesh mesh = file.ReadRegion(r);
    const std::size_t simplified = mesh.sideTriangles.size();
    UseOriginalSideFaces(mesh);
    CHECK(buffers.sideIndices == 3 * mesh.sideTriangles.size());
    CHECK(buffers.coarseSideIndices == 3 * simplified);
    CHECK(buffers.topIndices + buffers.bottomIndices + buffers.sideIndices + buffers.coarseSideIndices ==
      buffers.indices.size());
    const std::size_t vertexCount = buffers.vertices.size() / 6;
    for (std::size_t i = buffers.indices.size() - buffers.coarseSideIndices; i < buffers.indices.size(); ++i)
      CHECK(buffers.indices[i] < vertexCount);
    // Every side triangle's last vertex has its largest k (the fragment stage's lowest layer
    // reached); an exact side triangle spans one layer, the one above that vertex.
    const std::size_t sides = buffers.topIndices + buffers.bottomIndices;
    for (std::size_t t = sides; t + 3 <= buffers.indices.size(); t += 3)
    {
      float k[3];
      for (int v = 0; v < 3; ++v)
        k[v] = buffers.vertices[std::size_t(buffers.indices[t + v]) * 6 + 5];
      CHECK(k[2] >= k[0] && k[2] >= k[1]);
      if (t < sides + buffers.sideIndices)
      {
        const bool oneLayer = k[2] == std::floor(k[2]) && std::min(k[0], k[1]) == k[2] - 1;
        if (!oneLayer)
          std::printf("region %zu exact side triangle at k %g %g %g\n", r, k[0], k[1], k[2]);
        CHECK(oneLayer);
      }
    }
    if (file.Regions()[r].level < file.Header().leafLevel)
    {
      exact += buffers.sideIndices;
      coarse += buffers.coarseSideIndices;
    }
  }
  std::printf("%s: coarse levels' sides %zu triangles exact, %zu simplified\n", path.c_str(), exact / 3, coarse / 3);
  CHECK(coarse > 0 && coarse < exact);
}

/// Positions of a quad's corners, as a sorted set (the same face walked either way).
std::array<std::array<double, 3>, 4> QuadPlace(const RegionMesh& mesh, const std::array<uint32_t, 4>& quad)
{
  std::array<std::array<double, 3>, 4> place;
  for (int v = 0; v < 4; ++v)
    for (int a = 0; a < 3; ++a)
      place[v][a] = mesh.positions[std::size_t(quad[v]) * 3 + a];
  std::sort(place.begin(), place.end());
  return place;
}

/// Leaves drawn with their runs of no thickness sealed lose only top and bottom faces lying
/// on one another (each removed top face has a removed bottom face at the same corners), and
/// on a model that pinches out, many. Regions loaded without their exact side keep the same
/// top, bottom and simplified side; leaves always keep their exact side. The cache with
/// simplified sides holds the roots and the regions wanted simplified without their exact
/// side, the others with it, and a region held with it serves a simplified request.
void TestSimplifiedSides(const std::string& path)
{
  const auto file = std::make_shared<const MultiresolutionFile>(path);
  const int handedness = TopologyHandedness(*file);
  const auto& o = file->Header().latticeOrigin;
  const std::array<double, 3> origin{ o[0], o[1], -o[2] };
  std::size_t unsealed = 0, sealed = 0, unpaired = 0, fullBytes = 0, leanBytes = 0;
  for (std::size_t r = 0; r < file->Regions().size(); ++r)
  {
    const bool leaf = file->Regions()[r].level == file->Header().leafLevel;
    const RegionDrawBuffers full = LoadRegionDrawBuffers(*file, r, origin, handedness);
    const RegionDrawBuffers lean = LoadRegionDrawBuffers(*file, r, origin, handedness, -1, false);
    CHECK(full.exactSides && (leaf || !lean.exactSides)); // the cache never asks it of a leaf
    CHECK(lean.topIndices == full.topIndices && lean.bottomIndices == full.bottomIndices);
    CHECK(lean.coarseSideIndices == full.coarseSideIndices && (leaf || lean.sideIndices == 0));
    fullBytes += leaf ? 0 : full.Bytes();
    leanBytes += leaf ? 0 : lean.Bytes();
    if (!leaf)
      continue;
    RegionMesh open = file->ReadRegion(r); // the file's leaves: nothing sealed
    ExtractSurfaces(open);
    RegionMesh closed = file->ReadRegion(r);
    closed.sealedPinchThickness = std::numeric_limits<double>::min();
    ExtractSurfaces(closed);
    CHECK(full.topIndices == 6 * closed.top.quads.size());
    unsealed += open.top.quads.size() + open.bottom.quads.size();
    sealed += closed.top.quads.size() + closed.bottom.quads.size();
    std::multiset<std::array<std::array<double, 3>, 4>> tops, bottoms;
    for (const auto& q : open.top.quads)
      tops.insert(QuadPlace(open, q));
    for (const auto& q : closed.top.quads)
      tops.erase(tops.find(QuadPlace(closed, q)));
    for (const auto& q : open.bottom.quads)
      bottoms.insert(QuadPlace(open, q));
    for (const auto& q : closed.bottom.quads)
      bottoms.erase(bottoms.find(QuadPlace(closed, q)));
    for (const auto& place : tops)
    {
      const auto match = bottoms.find(place);
      if (match == bottoms.end())
        ++unpaired;
      else
        bottoms.erase(match);
    }
    unpaired += bottoms.size();
  }
  std::printf("%s: leaves' tops and bottoms %zu, %zu with runs of no thickness sealed; coarse regions %zu bytes, "
              "%zu without their exact side\n",
    path.c_str(), unsealed, sealed, fullBytes, leanBytes);
  CHECK(unpaired == 0);
  CHECK(sealed < unsealed);
  CHECK(leanBytes < fullBytes);

  RegionCache cache(file, nullptr, SIZE_MAX, true);
  std::vector<std::size_t> wanted;
  for (std::size_t r = 0; r < file->Regions().size(); ++r)
    if (file->Regions()[r].level <= 1)
      wanted.push_back(r);
  cache.Request(wanted, {}, wanted);
  CHECK(cache.WaitIdle(std::chrono::seconds(20)));
  for (std::size_t r : wanted)
    CHECK(cache.Get(r) && !cache.Get(r)->exactSides);
  const std::size_t simplifiedBytes = cache.ResidentBytes();
  cache.Request(wanted); // with their exact sides, but the roots
  CHECK(cache.WaitIdle(std::chrono::seconds(20)));
  for (std::size_t r : wanted)
    CHECK(cache.Get(r) && cache.Get(r)->exactSides == (file->Regions()[r].level > 0));
  CHECK(cache.ResidentBytes() > simplifiedBytes);
  const std::size_t count = cache.ResidentCount();
  cache.Request(wanted, {}, wanted); // held with their exact side: nothing is read again
  CHECK(cache.WaitIdle(std::chrono::seconds(20)) && cache.ResidentCount() == count);
  for (std::size_t r : wanted)
    CHECK(cache.Get(r)->exactSides == (file->Regions()[r].level > 0));
}

/// Pieces a region's buffers go to the GPU in (NextDrawPiece): they cover the indices in
/// order, whole triangles, each within its byte limit unless one triangle, every index inside
/// its vertex range. Pieces of the size the mapper copies (PieceBytes) copy exactly the
/// buffers' bytes (consecutive vertex ranges abut); smaller ones repeat the vertices quads
/// share across their boundaries, at most as many again.
void TestDrawPieces(const std::string& path)
{
  const MultiresolutionFile file(path);
  const int handedness = TopologyHandedness(file);
  const auto& o = file.Header().latticeOrigin;
  for (const std::size_t limit : { std::size_t(4) << 10, std::size_t(64) << 10, std::size_t(1) << 20 })
  {
    std::size_t pieces = 0, copied = 0, bytes = 0;
    for (std::size_t r = 0; r < file.Regions().size(); ++r)
    {
      const RegionDrawBuffers buffers = LoadRegionDrawBuffers(file, r, { o[0], o[1], -o[2] }, handedness);
      bytes += buffers.Bytes();
      for (std::size_t first = 0; first < buffers.indices.size();)
      {
        const DrawPiece piece = NextDrawPiece(buffers, first, limit);
        CHECK(piece.first == first && piece.end > first && piece.end <= buffers.indices.size());
        CHECK((piece.end - first) % 3 == 0);
        CHECK(piece.bytes == (std::size_t(piece.highVertex - piece.lowVertex) + 1) * 24 + (piece.end - first) * 4);
        CHECK(piece.bytes <= limit || piece.end - first == 3);
        bool inside = true;
        for (std::size_t n = first; n < piece.end; ++n)
        {
          inside = inside && buffers.indices[n] >= piece.lowVertex && buffers.indices[n] <= piece.highVertex;
        }
        CHECK(inside);
        if (piece.end < buffers.indices.size())
        {
          // Adding the next triangle would have passed the limit.
          const DrawPiece longer = NextDrawPiece(buffers, first, std::size_t(-1));
          CHECK(longer.end > piece.end);
        }
        copied += piece.bytes;
        ++pieces;
        first = piece.end;
      }
    }
    std::printf(
      "%s: pieces of at most %zu bytes: %zu, copying %zu bytes of %zu\n", path.c_str(), limit, pieces, copied, bytes);
    CHECK(limit < PieceBytes ? copied <= 2 * bytes : copied == bytes);
  }
}

/// Loading on a core kept busy: the standby rescues the starved idle loader, and the essential
/// loader alone brings the tables.
void TestCacheOnBusyCore(const std::shared_ptr<const MultiresolutionFile>& file, const std::vector<std::size_t>& leaves,
  const std::vector<std::size_t>& roots)
{
  using namespace std::chrono;
  // A core kept busy by an ordinary thread: the idle loader gets almost nothing there, and
  // the standby loads in its place (Linux, where the loader runs at nice 19). The loaders
  // inherit this thread's CPU set, pinned to one core with the spinners: on free cores the
  // few ms this model's leaves take could slip through (a clean-clone run loaded them in
  // 10 ms with every core "busy").
#ifdef __linux__
  cpu_set_t saved, one;
  const bool pinned = sched_getaffinity(0, sizeof(saved), &saved) == 0;
  const int core = sched_getcpu();
  CPU_ZERO(&one);
  CPU_SET(core >= 0 ? core : 0, &one);
  const bool isolated = pinned && sched_setaffinity(0, sizeof(one), &one) == 0;
#endif
  // Eight spinners: at this test's nice 10 (make test) one spinner weighs 110 to the nice 19
  // loader's 15, which leaves the loader an eighth of the core, over the starvation line;
  // eight leave it under 2%, so it cannot finish this model's leaves within a window.
  std::atomic<bool> spin{ true };
  std::atomic<int> spinning{ 0 };
  std::vector<std::thread> spinners;
  for (int s = 0; s < 8; ++s)
    spinners.emplace_back([&] {
      volatile uint64_t n = 0;
      ++spinning;
      while (spin.load(std::memory_order_relaxed))
        n = n + 1;
    });
  while (spinning < 8)
    std::this_thread::yield();
  const auto start = steady_clock::now();
  uint64_t rescues = 0;
  bool loaded = false;
  {
    RegionCache cache(file, nullptr, SIZE_MAX);
    cache.SetStarvationWindow(std::chrono::milliseconds(10));
    CHECK(cache.WaitIdle(seconds(30)));
    cache.Request(leaves);
    loaded = cache.WaitIdle(seconds(30));
    loaded = loaded && cache.ResidentCount() == roots.size() + leaves.size() && cache.LastError().empty();
    rescues = cache.StandbyRescues();
  }
  const double took = duration<double>(steady_clock::now() - start).count();
  // What the picture needs (the roots, the hash and normal tables) is read by the essential
  // loader alone, at this thread's priority, even while the idle loader is starved and no
  // standby rescues it: an idle loader that took the tables held them, and the colours,
  // for as long as it starved (minutes on a busy 2-core machine).
  double tablesSeconds = -1;
  {
    RegionCache cache(file, nullptr, SIZE_MAX);
    cache.SetStarvationWindow(std::chrono::hours(1));
    const auto opened = steady_clock::now();
    while (!cache.Tables() && steady_clock::now() - opened < seconds(30))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (cache.Tables())
      tablesSeconds = duration<double>(steady_clock::now() - opened).count();
  }
  // An urgent request's wanted regions are read by the essential loader too; the same
  // request not urgent waits on the starved idle loader (no rescue either).
  double urgentSeconds = -1;
  std::size_t plainLoaded = 0;
  const std::size_t all = roots.size() + leaves.size();
  for (const bool urgent : { true, false })
  {
    RegionCache cache(file, nullptr, SIZE_MAX);
    cache.SetStarvationWindow(std::chrono::hours(1));
    const auto opened = steady_clock::now();
    while ((!cache.Tables() || cache.RootsMissing()) && steady_clock::now() - opened < seconds(30))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const auto asked = steady_clock::now();
    cache.Request(leaves, {}, {}, urgent);
    // The plain request gets as long as the urgent one took.
    const auto limit = urgent ? seconds(30) : duration_cast<steady_clock::duration>(duration<double>(urgentSeconds));
    while (cache.ResidentCount() < all && steady_clock::now() - asked < limit)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (urgent && cache.ResidentCount() == all)
      urgentSeconds = duration<double>(steady_clock::now() - asked).count();
    if (!urgent)
      plainLoaded = cache.ResidentCount() - roots.size();
  }
  spin = false;
  for (std::thread& spinner : spinners)
    spinner.join();
  std::printf("  tables on a core kept busy, no rescue: %.3f s\n", tablesSeconds);
  CHECK(tablesSeconds >= 0 && tablesSeconds < 0.2); // starved, the idle loader took about 0.5 s
  std::printf("  %zu leaves on a core kept busy, no rescue: urgent %.3f s; not urgent, %zu loaded meanwhile\n",
    leaves.size(), urgentSeconds, plainLoaded);
  CHECK(urgentSeconds >= 0);
#ifdef __linux__
  if (pinned)
    sched_setaffinity(0, sizeof(saved), &saved);
#endif
  CHECK(loaded);
  std::printf("  cache on a core kept busy: all loaded in %.2f s, standby rescues %llu\n", took,
    static_cast<unsigned long long>(rescues));
#ifdef __linux__
  // Spinners above nice 10 weigh too little against the nice 19 loader for it to starve:
  // only an ordinary priority makes the core busy enough.
  errno = 0;
  const int niceness = getpriority(PRIO_PROCESS, 0);
  if (errno == 0 && niceness > 10)
    std::printf("  (run at nice %d: the rescue is not required)\n", niceness);
  else
  {
    CHECK(!isolated || rescues > 0);
    CHECK(!isolated || plainLoaded < leaves.size());
  }
#endif
}

void TestCache(const std::string& path)
{
  using namespace std::chrono;
  const auto file = std::make_shared<const MultiresolutionFile>(path);
  const Model model(path);
  const auto leaves = model.Leaves();
  const auto roots = model.selector->Roots();
  const std::vector<std::size_t> sizes = RegionBytes(*file);
  std::size_t rootBytes = 0, leafBytes = 0;
  for (std::size_t r : roots)
    rootBytes += sizes[r];
  for (std::size_t r : leaves)
    leafBytes += sizes[r];
  {
    // Unlimited: the roots before any request, then every leaf.
    RegionCache cache(file, nullptr, SIZE_MAX);
    CHECK(cache.WaitIdle(seconds(10)));
    CHECK(cache.ResidentCount() == roots.size() && cache.ResidentBytes() == rootBytes);
    const auto start = steady_clock::now();
    cache.Request(leaves);
    CHECK(cache.WaitIdle(seconds(10)));
    const double seconds = duration<double>(steady_clock::now() - start).count();
    CHECK(cache.ResidentCount() == roots.size() + leaves.size());
    CHECK(cache.ResidentBytes() == rootBytes + leafBytes);
    CHECK(cache.Generation() == roots.size() + leaves.size());
    std::size_t sum = 0;
    for (std::size_t r = 0; r < file->Regions().size(); ++r)
      if (auto b = cache.Get(r))
        sum += b->Bytes();
    CHECK(sum == cache.ResidentBytes());
    const auto& o = file->Header().latticeOrigin;
    CHECK(cache.Origin() == (std::array<double, 3>{ o[0], o[1], -o[2] }));
    const auto expected = LoadRegionDrawBuffers(*file, leaves[0], cache.Origin(), TopologyHandedness(*file));
    CHECK(cache.Get(leaves[0]) && cache.Get(leaves[0])->vertices == expected.vertices &&
      cache.Get(leaves[0])->indices == expected.indices);
    CHECK(cache.LastError().empty());
    std::printf("  cache: %zu leaves (%zu bytes) + %zu roots (%zu bytes) loaded in %.3f s\n", leaves.size(), leafBytes,
      roots.size(), rootBytes, seconds);
  }
  TestCacheOnBusyCore(file, leaves, roots);
  {
    // A budget for the roots and the first n leaves: loading stops at leaf n.
    const std::size_t n = leaves.size() / 3;
    std::size_t budget = rootBytes;
    for (std::size_t i = 0; i < n; ++i)
      budget += sizes[leaves[i]];
    budget += sizes[leaves[n]] / 2;
    RegionCache cache(file, nullptr, budget);
    cache.Request(leaves);
    CHECK(cache.WaitIdle(seconds(10)) && !cache.Pending());
    CHECK(cache.ResidentBytes() <= std::max(budget, rootBytes));
    // The hash and normal tables come from the loader too, equal to the file's.
    const auto tables = cache.Tables();
    CHECK(tables && tables->hash.offsets == file->ReadHash().offsets &&
      tables->normals == file->ReadModelArray(ModelChunk::CellNormals));
    CHECK(cache.ResidentCount() == roots.size() + n);
    for (std::size_t i = 0; i < leaves.size(); ++i)
      CHECK(cache.IsResident(leaves[i]) == (i < n));
    // Raised: the rest loads; lowered: what is wanted stays, then a new request evicts.
    cache.SetBudget(SIZE_MAX);
    CHECK(cache.WaitIdle(seconds(10)) && cache.ResidentCount() == roots.size() + leaves.size());
    cache.SetBudget(budget);
    CHECK(cache.ResidentCount() == roots.size() + leaves.size());
    cache.Request({ leaves[0] });
    CHECK(cache.WaitIdle(seconds(10)));
    cache.SetBudget(budget - 1);
    CHECK(cache.ResidentBytes() <= budget - 1 && cache.IsResident(leaves[0]));
    // Budget below the roots: roots only.
    RegionCache tiny(file, nullptr, 1);
    tiny.Request(leaves);
    CHECK(tiny.WaitIdle(seconds(10)) && tiny.ResidentCount() == roots.size() && tiny.ResidentBytes() == rootBytes);
  }
  {
    // LRU: A, B, C fill the budget; D evicts A (the least recently requested); after B is
    // requested again and the budget is cut to what is resident, E evicts C.
    std::vector<std::size_t> bySize = leaves;
    std::sort(bySize.begin(), bySize.end(), [&](std::size_t a, std::size_t b) { return sizes[a] > sizes[b]; });
    const std::size_t A = bySize[0], B = bySize[1], C = bySize[2], D = bySize[3], E = bySize[4];
    RegionCache cache(file, nullptr, rootBytes + sizes[A] + sizes[B] + sizes[C]);
    CHECK(cache.WaitIdle(seconds(10)));
    uint64_t generation = cache.Generation();
    for (std::size_t r : { A, B, C })
    {
      cache.Request({ r });
      CHECK(cache.WaitIdle(seconds(10)) && cache.IsResident(r));
      CHECK(cache.Generation() == ++generation);
    }
    cache.Request({ D });
    CHECK(cache.WaitIdle(seconds(10)));
    CHECK(!cache.IsResident(A) && cache.IsResident(B) && cache.IsResident(C) && cache.IsResident(D));
    CHECK(cache.Generation() == generation + 2);
    cache.Request({ B });
    CHECK(cache.WaitIdle(seconds(10)));
    cache.SetBudget(cache.ResidentBytes());
    cache.Request({ E });
    CHECK(cache.WaitIdle(seconds(10)));
    CHECK(!cache.IsResident(C) && cache.IsResident(B) && cache.IsResident(D) && cache.IsResident(E));
    CHECK(cache.ResidentBytes() <= cache.Budget());
  }
  {
    // Destroyed while loading everything: returns at once.
    std::vector<std::size_t> all(file->Regions().size());
    for (std::size_t r = 0; r < all.size(); ++r)
      all[r] = r;
    const auto start = steady_clock::now();
    std::size_t loaded = 0;
    {
      RegionCache cache(file, nullptr, SIZE_MAX);
      cache.Request(all);
      std::this_thread::sleep_for(milliseconds(2));
      loaded = cache.ResidentCount();
    }
    const double ms = duration<double, std::milli>(steady_clock::now() - start).count();
    std::printf("  cache destroyed after %.1f ms with %zu of %zu regions loaded\n", ms, loaded, all.size());
    CHECK(ms < 500);
  }
}

void TestDamagedChunk(const std::string& path)
{
  using namespace std::chrono;
  const std::string damaged = Temp + "/damaged.resmr";
  std::size_t victim = 0;
  {
    const MultiresolutionFile file(path);
    const Model model(path);
    victim = model.Leaves()[model.Leaves().size() / 2];
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const ChunkRef& chunk = file.Regions()[victim].chunks[RegionRecord::Side];
    for (uint32_t b = 0; b < std::min<uint32_t>(chunk.stored, 8); ++b)
      bytes[chunk.offset + chunk.stored / 2 + b] ^= 0x5a;
    std::ofstream(damaged, std::ios::binary) << bytes;
  }
  const auto file = std::make_shared<const MultiresolutionFile>(damaged);
  const auto& record = file->Regions()[victim];
  const Model model(path);
  RegionCache cache(file, nullptr, SIZE_MAX);
  cache.Request(model.Leaves());
  CHECK(cache.WaitIdle(seconds(10)));
  const std::string error = cache.LastError();
  std::printf("  damaged chunk: %s\n", error.c_str());
  CHECK(error.find("damaged.resmr") != std::string::npos);
  CHECK(error.find("level " + std::to_string(record.level) + ", index " + std::to_string(record.index)) !=
    std::string::npos);
  CHECK(!cache.IsResident(victim) && !cache.Pending());
  CHECK(cache.ResidentCount() == model.selector->Roots().size() + model.Leaves().size() - 1);
}

/// Bit-equal float arrays (NaN where a slot has no value).
bool Same(const std::vector<float>& a, const std::vector<float>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * 4) == 0;
}

void TestProperties()
{
  using namespace std::chrono;
  const std::string egrid = Data + "/spe9/opmflow2022_run_of_opm-data_SPE9_CP/SPE9_CP.EGRID";
  const std::string geometry = Build(egrid, "spe9");
  const std::string propertyPath = Temp + "/spe9.resmrp";
  std::remove(propertyPath.c_str());
  CHECK(Run(Tool + " add-properties '" + geometry + "' '" + egrid + "' > /dev/null 2>&1") == 0);
  const auto file = std::make_shared<const MultiresolutionFile>(geometry);
  const auto properties = std::make_shared<const PropertyFile>(propertyPath);
  RegionCache cache(file, properties, SIZE_MAX);
  CHECK(cache.Property() == nullptr);
  cache.RequestProperty("PRESSURE", 0);
  CHECK(cache.WaitIdle(seconds(10)));
  const auto first = cache.Property();
  CHECK(first && first->name == "PRESSURE" && first->step == 0);
  CHECK(
    first && Same(first->values, properties->ReadPacked(static_cast<std::size_t>(properties->Find("PRESSURE", 0)))));
  cache.RequestProperty("PRESSURE", 1);
  const auto meanwhile = cache.Property(); // the previous table or the new one, never none
  CHECK(meanwhile && meanwhile->name == "PRESSURE");
  CHECK(cache.WaitIdle(seconds(10)));
  const auto second = cache.Property();
  CHECK(second && second->step == 1 &&
    Same(second->values, properties->ReadPacked(static_cast<std::size_t>(properties->Find("PRESSURE", 1)))));
  CHECK(first->step == 0); // the old table is untouched for whoever still holds it
  // A layer's 2D table for the single-layer view.
  cache.RequestProperty("PRESSURE", 1, 2);
  CHECK(cache.WaitIdle(seconds(10)));
  const auto layer = cache.Property();
  const auto& dims = file->Header().dims;
  CHECK(layer && layer->layer == 2 && layer->step == 1 && layer->values.size() == std::size_t(dims[0] * dims[1]) &&
    Same(layer->values, properties->ReadLayer(static_cast<std::size_t>(properties->Find("PRESSURE", 1)), 2)));
  cache.RequestProperty("NOSUCH", 3);
  CHECK(cache.WaitIdle(seconds(10)));
  CHECK(cache.Property() == nullptr);
  CHECK(cache.LastError().find("NOSUCH") != std::string::npos && cache.LastError().find("3") != std::string::npos);
  std::printf("  properties: PRESSURE steps 0 and 1 (%zu slots); missing: %s\n", second ? second->values.size() : 0,
    cache.LastError().c_str());
}
/// Single-layer buffers (Sec. 4.1, 6.1) of every leaf region for the first, a middle and the
/// last layer: every cell coordinate lies in the layer (k + 0.5 on top and bottom faces, k to
/// k + 1 on side faces); over the leaves, the top and bottom
/// faces name each active cell of the layer exactly once (two triangles each) and nothing
/// else; every side triangle names an active cell of the layer whose side on the triangle's
/// plane is open; every side of an active cell with no active cell across in the layer (or
/// the model's limit across) is drawn.
void TestLayerBuffers(const std::string& path)
{
  const MultiresolutionFile file(path);
  const int handedness = TopologyHandedness(file);
  const auto& dims = file.Header().dims;
  const auto& o = file.Header().latticeOrigin;
  const std::array<double, 3> origin{ o[0], o[1], -o[2] };
  const double w[3] = { 1.0 / 3 + std::sqrt(2.0) * 1e-3, 1.0 / 3 + std::sqrt(3.0) * 1e-3, 0 };
  const double w2 = 1 - w[0] - w[1];
  std::vector<std::size_t> leaves;
  for (std::size_t r = 0; r < file.Regions().size(); ++r)
    if (file.Regions()[r].level == file.Header().leafLevel)
      leaves.push_back(r);
  for (const int64_t k : { int64_t(0), dims[2] / 2, dims[2] - 1 })
  {
    const std::vector<uint8_t> active = file.ReadActiveLayer(k);
    const auto isActive = [&](int64_t i, int64_t j) {
      return i >= 0 && j >= 0 && i < dims[0] && j < dims[1] && active[std::size_t(i + dims[0] * j)] != 0;
    };
    std::vector<int> tops(std::size_t(dims[0] * dims[1]), 0), bottoms(tops.size(), 0);
    std::set<std::tuple<int64_t, int64_t, int, int>> sides; // i, j, axis, low (0) or high (1) side
    std::size_t bad = 0, triangles = 0, outside = 0;
    for (std::size_t r : leaves)
    {
      const RegionMesh mesh = file.ReadRegion(r);
      const RegionDrawBuffers buffers = PrepareLayerDrawBuffers(mesh, int32_t(k), origin, handedness);
      RegionSurface top, bottom, side;
      ExtractLayerSurfaces(mesh, int32_t(k), top, bottom, side);
      CHECK(buffers.layer == k && buffers.sideIndices == 6 * side.quads.size());
      CHECK(buffers.topIndices == 6 * top.quads.size() && buffers.bottomIndices == 6 * bottom.quads.size());
      // Top and bottom vertices sit half a layer in; side vertices on the layer's interfaces.
      for (std::size_t t = 0; t < buffers.indices.size(); ++t)
      {
        const float ck = buffers.vertices[buffers.indices[t] * 6 + 5];
        outside += t < buffers.topIndices + buffers.bottomIndices ? ck != float(k + 0.5) : ck < k || ck > k + 1;
      }
      for (std::size_t t = 0; t < buffers.indices.size(); t += 3)
      {
        ++triangles;
        double point[3] = { 0, 0, 0 };
        for (int v = 0; v < 3; ++v)
          for (int a = 0; a < 3; ++a)
            point[a] += (v == 2 ? w2 : w[v]) * buffers.vertices[buffers.indices[t + v] * 6 + 3 + a];
        const int64_t i = int64_t(std::floor(point[0])), j = int64_t(std::floor(point[1]));
        bool ok = int64_t(std::floor(point[2])) == k && isActive(i, j);
        if (ok && t < buffers.topIndices)
          ++tops[std::size_t(i + dims[0] * j)];
        else if (ok && t < buffers.topIndices + buffers.bottomIndices)
          ++bottoms[std::size_t(i + dims[0] * j)];
        else if (ok)
        {
          // The quad's plane (from its first vertex) must be the cell's low or high side on
          // the axis along which the quad's nodes share their topological coordinate.
          const std::size_t s = (t - buffers.topIndices - buffers.bottomIndices) / 6;
          const auto& quad = side.quads[s];
          const uint32_t perNode = uint32_t(mesh.layers + 1);
          const auto& a = mesh.topology[quad[0] / perNode];
          const auto& b = mesh.topology[quad[3] / perNode];
          const int axis = a[0] == b[0] ? 0 : a[1] == b[1] ? 1 : -1;
          const int64_t low = axis == 0 ? i : j;
          ok = axis >= 0 && (a[axis] == double(low) || a[axis] == double(low + 1));
          if (ok)
            sides.insert({ i, j, axis, a[axis] == double(low) ? 0 : 1 });
        }
        bad += !ok;
      }
    }
    std::size_t cells = 0, wrongTop = 0, missingSides = 0, faultSides = 0;
    for (int64_t j = 0; j < dims[1]; ++j)
      for (int64_t i = 0; i < dims[0]; ++i)
      {
        const std::size_t c = std::size_t(i + dims[0] * j);
        cells += isActive(i, j);
        wrongTop += isActive(i, j) ? (tops[c] != 2) + (bottoms[c] != 2) : (tops[c] != 0) + (bottoms[c] != 0);
        if (!isActive(i, j))
          continue;
        const int64_t across[4][2] = { { i - 1, j }, { i + 1, j }, { i, j - 1 }, { i, j + 1 } };
        for (int n = 0; n < 4; ++n)
        {
          const bool drawn = sides.count({ i, j, n / 2, n % 2 }) != 0;
          missingSides += !isActive(across[n][0], across[n][1]) && !drawn;
          faultSides += isActive(across[n][0], across[n][1]) && drawn;
        }
      }
    std::printf(
      "  layer %lld of %s: %zu active cells, %zu triangles, %zu misplaced, %zu cells without exactly one "
      "top and bottom, %zu open sides missing, %zu sides against an active cell (faults), %zu vertices off the layer\n",
      static_cast<long long>(k + 1), path.c_str(), cells, triangles, bad, wrongTop, missingSides, faultSides, outside);
    CHECK(cells > 0 && bad == 0 && wrongTop == 0 && missingSides == 0 && outside == 0);
  }
}

/// The cache's layers: out-of-range layers refused; a switch returns at once and keeps the
/// whole model's buffers; the new layer's roots load first, its requested regions as asked
/// (equal to LoadRegionDrawBuffers of that layer), the roots of the layers around it after;
/// resident bytes are every (region, layer) held; a budget that holds the whole model's leaves
/// evicts them, least recently requested first, for the layer's.
void TestLayerCache(const std::string& path)
{
  using namespace std::chrono;
  const auto file = std::make_shared<const MultiresolutionFile>(path);
  const Model model(path);
  const auto leaves = model.Leaves();
  const auto roots = model.selector->Roots();
  const int32_t nk = int32_t(file->Header().dims[2]);
  const int32_t k = nk / 2;
  const int handedness = TopologyHandedness(*file);
  RegionCache cache(file, nullptr, SIZE_MAX);
  CHECK(cache.WaitIdle(seconds(10)) && cache.Layer() == -1);
  CHECK(!cache.SetLayer(nk) && !cache.SetLayer(-2) && cache.Layer() == -1);
  cache.Request(leaves);
  CHECK(cache.WaitIdle(seconds(10)));
  const uint64_t generation = cache.Generation();
  const auto start = steady_clock::now();
  CHECK(cache.SetLayer(k) && cache.Layer() == k);
  const double switchMs = duration<double, std::milli>(steady_clock::now() - start).count();
  CHECK(cache.Generation() > generation);
  CHECK(cache.Get(leaves[0], -1) != nullptr); // the whole model's stay
  CHECK(cache.WaitIdle(seconds(10)));
  for (std::size_t r : roots)
  {
    const auto buffers = cache.Get(r);
    const auto expected = LoadRegionDrawBuffers(*file, r, cache.Origin(), handedness, k);
    CHECK(buffers && buffers == cache.Get(r, k) && buffers->layer == k && buffers->vertices == expected.vertices &&
      buffers->indices == expected.indices);
  }
  CHECK(!cache.IsResident(leaves[0])); // nothing of the layer asked for yet but its roots
  const auto loadStart = steady_clock::now();
  cache.Request(leaves);
  CHECK(cache.WaitIdle(seconds(30)));
  const double loadMs = duration<double, std::milli>(steady_clock::now() - loadStart).count();
  std::size_t held = 0;
  for (std::size_t r : leaves)
  {
    const auto buffers = cache.Get(r);
    CHECK(buffers && buffers->layer == k);
  }
  const auto expected = LoadRegionDrawBuffers(*file, leaves.back(), cache.Origin(), handedness, k);
  const auto last = cache.Get(leaves.back());
  CHECK(last->vertices == expected.vertices && last->indices == expected.indices);
  for (std::size_t r : roots)
    for (const int32_t l : { k - 1, k + 1 })
      CHECK(l < 0 || l >= nk || cache.Get(r, l) != nullptr);
  for (std::size_t r = 0; r < file->Regions().size(); ++r)
    for (int32_t l = -1; l < nk; ++l)
      if (const auto buffers = cache.Get(r, l))
        held += buffers->Bytes();
  CHECK(held == cache.ResidentBytes());
  CHECK(cache.LastError().empty());
  // Back to the whole model: everything it wanted is still there.
  CHECK(cache.SetLayer(-1) && !cache.Pending() && cache.IsResident(leaves[0]));
  std::printf("  layer cache %s: switch to layer %d in %.3f ms, its %zu leaves loaded in %.1f ms, %zu bytes held over "
              "3 layers and the whole model\n",
    path.c_str(), k + 1, switchMs, leaves.size(), loadMs, held);
  CHECK(switchMs < 50);

  // A budget that holds the layer's roots (and those of the layers either side), the whole
  // model's leaves and half the layer's: showing the layer, its leaves come in and some of
  // the whole model's go. (Before the switch the whole model's roots may not fit beside its
  // leaves: the coarsest levels keep every fault's columns, so they can outweigh a set of
  // leaves, and the roots always stay.)
  std::size_t wholeBytes = 0, layerBytes = 0, layerRootBytes = 0;
  for (std::size_t r : leaves)
  {
    wholeBytes += cache.Get(r, -1)->Bytes();
    layerBytes += cache.Get(r, k)->Bytes();
  }
  for (std::size_t r : roots)
    for (const int32_t l : { k - 1, k, k + 1 })
      if (l >= 0 && l < nk)
        layerRootBytes += cache.Get(r, l)->Bytes();
  const std::size_t budget = wholeBytes + layerRootBytes + layerBytes / 2;
  RegionCache small(file, nullptr, budget);
  small.Request(leaves);
  CHECK(small.WaitIdle(seconds(10)));
  CHECK(small.SetLayer(k));
  small.Request(leaves);
  CHECK(small.WaitIdle(seconds(30)));
  std::size_t wholeLeft = 0, layerLeaves = 0;
  for (std::size_t r : leaves)
  {
    wholeLeft += small.Get(r, -1) != nullptr;
    layerLeaves += small.Get(r, k) != nullptr;
  }
  std::printf("  layer cache under %zu bytes: %zu of %zu whole-model leaves left, %zu layer leaves, %zu bytes "
              "resident\n",
    budget, wholeLeft, leaves.size(), layerLeaves, small.ResidentBytes());
  CHECK(layerLeaves == leaves.size() && wholeLeft < leaves.size() && small.ResidentBytes() <= budget);
}

/// The controller against a modelled renderer whose frame costs fixed + work / tolerance^2
/// seconds (triangles fall as the square of the tolerance).
void TestFrameRateController()
{
  const auto run = [](double fixed, double work, double startPixels, int frames, double& worst) {
    FrameRateController controller;
    controller.SetTargetFramesPerSecond(10);
    controller.Reset(startPixels);
    worst = 0;
    for (int f = 0; f < frames; ++f)
    {
      const double pixels = controller.Tolerance();
      const double seconds = fixed + work / (pixels * pixels);
      if (f >= 20)
      {
        worst = std::max(worst, seconds);
      }
      controller.Update(seconds);
    }
    return controller.Tolerance();
  };
  double worst = 0;
  // Reachable: after a few frames every frame is within the band's top (85% of the target, a
  // margin for the jitter a real renderer adds), and not far below it.
  const double band = FrameRateController::HighFraction * 0.1;
  const double settled = run(0.03, 0.5, 1, 200, worst);
  const double settledSeconds = 0.03 + 0.5 / (settled * settled);
  std::printf("  controller: settled at %.2f px (%.3f s a frame), slowest frame after 20 %.3f s\n", settled,
    settledSeconds, worst);
  CHECK(worst <= band && settledSeconds >= FrameRateController::LowFraction * 0.1);
  // A view far heavier than the old 256 px cap allowed (a low flight over kilometre errors):
  // the tolerance keeps rising until the target holds.
  const double heavy = run(0.03, 2e4, 8, 200, worst);
  std::printf("  controller, heavy view: %.0f px, slowest frame after 20 %.3f s\n", heavy, worst);
  CHECK(heavy > 256 && heavy <= FrameRateController::MaximumPixels && worst <= band);
  // Back to a light view from the heaviest tolerance: down to the minimum within 100 frames.
  CHECK(run(0.01, 1e-6, FrameRateController::MaximumPixels, 100, worst) == FrameRateController::MinimumPixels);
  // A renderer slower than the target at any tolerance: the tolerance stops at the maximum.
  CHECK(run(0.2, 1, 1, 100, worst) == FrameRateController::MaximumPixels);
  // The quality floor: under the same slow renderer the tolerance stops at the user's ceiling,
  // even when it starts above it; raising the ceiling lets it go on.
  {
    FrameRateController floor;
    floor.SetTargetFramesPerSecond(10);
    floor.SetMaximumPixels(32);
    floor.Reset(1000);
    CHECK(floor.Tolerance() == 32);
    for (int f = 0; f < 100; ++f)
    {
      floor.Update(0.2 + 1 / (floor.Tolerance() * floor.Tolerance()), true, CutRange(), f % 2 == 0);
      CHECK(floor.Tolerance() <= 32);
    }
    CHECK(floor.Tolerance() == 32);
    floor.SetMaximumPixels(FrameRateController::MaximumPixels);
    floor.Update(0.2, true, CutRange(), false);
    CHECK(floor.Tolerance() > 32);
    floor.SetMaximumPixels(8);
    CHECK(floor.Tolerance() == 8 && floor.MaximumTolerance() == 8);
  }
  // Fill-bound (a software rasterizer at the roots of a billion-cell model): a moving frame
  // costs 10 ms + 120 ms x scale^2 whatever the tolerance. The scale goes first and the
  // tolerance stays; frames settle inside the band; still frames leave the scale alone.
  {
    FrameRateController fill;
    fill.SetTargetFramesPerSecond(10);
    fill.Reset(64);
    const auto cost = [](double scale, double pixels) { return 0.01 + 0.12 * scale * scale + 1e-3 / pixels; };
    double slowest = 0;
    for (int f = 0; f < 60; ++f)
    {
      const double s = cost(fill.Scale(), fill.Tolerance());
      if (f >= 5)
      {
        slowest = std::max(slowest, s);
      }
      fill.Update(s, true, CutRange(), true);
    }
    std::printf("  controller, fill-bound: scale %.2f, %.2f px, slowest moving frame after 5 %.3f s\n", fill.Scale(),
      fill.Tolerance(), slowest);
    CHECK(fill.Scale() < 1 && fill.Scale() >= FrameRateController::DefaultScaleFloor && slowest <= band);
    // Still frames (full resolution, slow) coarsen the tolerance as before, never the scale.
    const double movingScale = fill.Scale();
    fill.Update(cost(1, fill.Tolerance()), true, CutRange(), false);
    CHECK(fill.Scale() == movingScale);
    // Headroom: the geometry refines first; the scale returns only once nothing can split.
    fill.Reset(8);
    fill.Update(0.3, true, CutRange(), true);
    CHECK(fill.Scale() < 1 && fill.Tolerance() == 8);
    const double lowered = fill.Scale();
    CutRange splittable;
    splittable.refineBelow = 4;
    fill.Update(0.02, true, splittable, true);
    CHECK(fill.Scale() == lowered && fill.Tolerance() < 8);
    CutRange finest;
    finest.refineBelow = 0;
    for (int f = 0; f < 10; ++f)
    {
      fill.Update(0.02, true, finest, true);
    }
    CHECK(fill.Scale() == 1);
    // A floor of 1 (the user's choice): never reduced; the tolerance coarsens at once.
    FrameRateController full;
    full.SetTargetFramesPerSecond(10);
    full.SetScaleFloor(1);
    full.Reset(8);
    full.Update(0.3, true, CutRange(), true);
    CHECK(full.Scale() == 1 && full.Tolerance() > 8);
  }

  // Meshes still loading: frames draw the roots only (fast whatever the tolerance), so they
  // must not refine it; once all is loaded, the frame at the kept tolerance is within the band
  // and refinement resumes from there. Slow incomplete frames still coarsen it.
  FrameRateController loading;
  loading.SetTargetFramesPerSecond(10);
  loading.Reset(8);
  for (int f = 0; f < 50; ++f)
  {
    loading.Update(0.01, false);
  }
  std::printf("  controller, 50 fast frames while loading: %.2f px\n", loading.Tolerance());
  CHECK(loading.Tolerance() == 8);
  loading.Update(0.3, false);
  CHECK(loading.Tolerance() > 8);
  const double coarse = loading.Tolerance();
  loading.Update(0.01, true);
  CHECK(loading.Tolerance() < coarse);

  // Steps act on the cut. A view whose diamonds' projected errors are 1, 2, 4, ... 4096 px,
  // each split adding as many triangles as all coarser ones: only the tolerance's power of
  // two matters. A frame costs 40 ms plus 1 ms per 4,000 triangles.
  const auto triangles = [](double pixels) {
    double count = 1000;
    for (double error = 4096; error >= 1; error /= 2)
      count += error > pixels ? count : 0;
    return std::min(count, 1e9);
  };
  const auto range = [](double pixels) {
    CutRange same;
    same.refineBelow = 0;
    same.coarsenAt = std::numeric_limits<double>::infinity();
    for (double error = 4096; error >= 1; error /= 2)
    {
      if (error > pixels)
        same.coarsenAt = std::min(same.coarsenAt, error);
      else
        same.refineBelow = std::max(same.refineBelow, error);
    }
    return same;
  };
  const auto seconds = [&](double pixels) { return 0.04 + triangles(pixels) / 4e6; };
  // Far too coarse: from the maximum, fast frames' steps reach below the finest diamond
  // drawn whole within 3 frames, a quarter at most each (without the range, 0.8 a step: 13).
  FrameRateController steps;
  steps.SetTargetFramesPerSecond(10);
  steps.Reset(FrameRateController::MaximumPixels);
  int fastFrames = 0;
  while (triangles(steps.Tolerance()) == triangles(FrameRateController::MaximumPixels) && fastFrames < 50)
  {
    const double before = steps.Tolerance();
    steps.Update(seconds(steps.Tolerance()), true, range(steps.Tolerance()));
    CHECK(steps.Tolerance() >= FrameRateController::MaxRefineStep * before);
    ++fastFrames;
  }
  std::printf("  controller, cut range: %d fast frames from %.0f px to %.0f px\n", fastFrames,
    FrameRateController::MaximumPixels, steps.Tolerance());
  CHECK(fastFrames <= 3);
  // Too fine: a slow frame's step passes the nearest split diamond, so it merges.
  steps.Reset(1.5);
  const double slow = 0.5;
  const double before = triangles(steps.Tolerance());
  steps.Update(slow, true, range(steps.Tolerance()));
  CHECK(steps.Tolerance() >= 2 && triangles(steps.Tolerance()) < before);
  // Over frames: settles inside the band from either end within 20 frames, and stays.
  for (double start : { 0.5, FrameRateController::MaximumPixels })
  {
    steps.Reset(start);
    double slowest = 0, fastest = 1;
    for (int f = 0; f < 100; ++f)
    {
      const double s = seconds(steps.Tolerance());
      if (f >= 20)
      {
        slowest = std::max(slowest, s);
        fastest = std::min(fastest, s);
      }
      steps.Update(s, true, range(steps.Tolerance()));
    }
    std::printf("  controller, cut range from %.1f px: frames %.3f-%.3f s after 20\n", start, fastest, slowest);
    CHECK(slowest <= FrameRateController::HighFraction * 0.1);
    CHECK(fastest >= 0.5 * FrameRateController::LowFraction * 0.1);
  }
}

void TestEstimateSteering()
{
  // The floor on the estimated error: a renderer slow at any tolerance, a cut whose bound is
  // the tolerance and whose estimate a tenth of it. With an estimate floor of 2 px the
  // tolerance stops at 16 px, where the estimate reaches the aim (0.8 of the floor), under a
  // bound ceiling far above; a view where the estimate is a half of the bound (coming closer
  // to what was simplified, 0.6 of the bound) refines to 8/3 px, the aim, in two frames (a
  // quarter at most each) although every frame is slow; the bound's ceiling still holds where the estimate allows more.
  {
    FrameRateController steer;
    steer.SetTargetFramesPerSecond(10);
    steer.SetMaximumEstimatedPixels(2);
    steer.Reset(1);
    const auto cut = [&](double share) {
      CutRange same;
      same.bound = steer.Tolerance();
      same.estimate = share * steer.Tolerance();
      return same;
    };
    for (int f = 0; f < 100; ++f)
    {
      steer.Update(0.3, true, cut(0.1), true);
      CHECK(steer.Tolerance() <= 16 * (1 + 1e-9));
    }
    CHECK(std::abs(steer.Tolerance() - 16) < 1e-9);
    int frames = 0;
    while (0.6 * steer.Tolerance() > 2 && frames < 10)
    {
      steer.Update(0.3, true, cut(0.6), true);
      ++frames;
    }
    CHECK(frames == 2 && std::abs(steer.Tolerance() - 8.0 / 3) < 1e-9);
    steer.Update(0.3, true, cut(0.6), true); // at the aim, slow: it stays
    CHECK(std::abs(steer.Tolerance() - 8.0 / 3) < 1e-9);
    // A frame still loading (complete = false) does not refine on its estimate.
    steer.Reset(16);
    steer.Update(0.3, false, cut(0.5), true);
    CHECK(steer.Tolerance() >= 16);
    // Before a frame is drawn its ideal cut refines it at once, past the quarter a frame
    // (64 to 12.8 px, the aim).
    steer.Reset(64);
    steer.HoldEstimateFloor(cut(0.125));
    CHECK(std::abs(steer.Tolerance() - 12.8) < 1e-9);
    steer.Reset(64);
    CHECK(steer.HoldEstimateFloor(cut(0.025)) == 64); // 1.6 px: within the floor
    steer.SetMaximumPixels(12);
    steer.Reset(1);
    for (int f = 0; f < 100; ++f)
    {
      steer.Update(0.3, true, cut(0.01), true);
    }
    CHECK(steer.Tolerance() == 12);
    // No estimate (a cut of leaves, or 0 as the floor): the bound alone.
    steer.SetMaximumPixels(FrameRateController::MaximumPixels);
    steer.SetMaximumEstimatedPixels(0);
    steer.Reset(20);
    steer.Update(0.3, true, cut(0.5), false);
    CHECK(steer.Tolerance() > 20);
  }
}

/// The buffers of `region` under `filter` as LoadRegionDrawBuffers draws them, from the region's
/// whole mesh (every layer decoded): what its read of a window of layers must equal.
RegionDrawBuffers WholeMeshBuffers(
  const MultiresolutionFile& file, std::size_t region, const CellFilter& filter, int handedness)
{
  RegionMesh mesh = file.ReadRegion(region);
  if (!(mesh.sealedPinchThickness > 0))
    mesh.sealedPinchThickness = std::numeric_limits<double>::min();
  CellBox box;
  if (filter.HasValues())
  {
    box = ReadCellBox(mesh, filter, file.Header().dims);
    MaskToFilter(mesh, filter, &box);
  }
  else
    MaskToRange(mesh, filter.range);
  UseOriginalSideFaces(mesh);
  RegionDrawBuffers out = PrepareRegionDrawBuffers(mesh, { 0, 0, 0 }, handedness);
  if (filter.HasValues() && filter.paintTable >= 0)
    out.faceValues = FaceValues(out.vertices, out.indices, box);
  return out;
}

/// A masked coarse region's side merged in K (MergedSides.h): its quads cover every exact side
/// quad of some thickness and no other face, each once, and a quad of several layers is no
/// taller than `height` at either node. Counts the exact and merged quads into `counts`.
void CheckMergedSide(RegionMesh mesh, double height, std::array<std::size_t, 2>& counts)
{
  UseOriginalSideFaces(mesh);
  const uint32_t perNode = uint32_t(mesh.layers + 1);
  const auto at = [&](uint32_t vertex) { return &mesh.positions[std::size_t(vertex) * 3]; };
  const auto same = [&](uint32_t a, uint32_t b) { return std::equal(at(a), at(a) + 3, at(b)); };
  const auto length = [&](uint32_t a, uint32_t b) {
    double sum = 0;
    for (int n = 0; n < 3; ++n)
      sum += (at(a)[n] - at(b)[n]) * (at(a)[n] - at(b)[n]);
    return std::sqrt(sum);
  };
  std::set<std::array<uint32_t, 3>> exact, thick; // node a, node b, layer
  for (const auto& q : mesh.side.quads)
  {
    exact.insert({ q[0] / perNode, q[3] / perNode, q[0] % perNode });
    if (!same(q[0], q[1]) || !same(q[2], q[3]))
      thick.insert({ q[0] / perNode, q[3] / perNode, q[0] % perNode });
  }
  const auto merged = MergedSideTriangles(mesh, height);
  CHECK(merged.size() % 2 == 0);
  std::set<std::array<uint32_t, 3>> covered;
  bool once = true, low = true, turned = true;
  for (std::size_t t = 0; t + 1 < merged.size(); t += 2)
  {
    // (a top, a bottom, b bottom), (a top, b bottom, b top)
    const auto& u = merged[t];
    const auto& v = merged[t + 1];
    turned = turned && u[0] == v[0] && u[2] == v[1] && u[1] / perNode == u[0] / perNode &&
      v[2] / perNode == v[1] / perNode && u[1] % perNode == u[2] % perNode && v[2] % perNode == u[0] % perNode;
    const uint32_t a = u[0] / perNode, b = v[2] / perNode, top = u[0] % perNode, bottom = u[1] % perNode;
    low = low && (bottom == top + 1 || (length(u[0], u[1]) <= height && length(v[2], v[1]) <= height));
    for (uint32_t k = top; k < bottom; ++k)
      once = covered.insert({ a, b, k }).second && once;
  }
  CHECK(turned && once && low);
  CHECK(std::includes(covered.begin(), covered.end(), thick.begin(), thick.end()));
  CHECK(std::includes(exact.begin(), exact.end(), covered.begin(), covered.end()));
  counts[0] += exact.size();
  counts[1] += merged.size() / 2;
}

bool SameBuffers(const RegionDrawBuffers& a, const RegionDrawBuffers& b)
{
  const auto sameValue = [](float x, float y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  return a.vertices == b.vertices && a.indices == b.indices && a.topIndices == b.topIndices &&
    a.bottomIndices == b.bottomIndices && a.sideIndices == b.sideIndices &&
    a.faceValues.size() == b.faceValues.size() &&
    std::equal(a.faceValues.begin(), a.faceValues.end(), b.faceValues.begin(), sameValue);
}

} // namespace

void TestUploadPacer()
{
  UploadPacer pacer;
  const std::size_t MB = std::size_t(1) << 20;
  // Before any copy was timed: the first mesh of a frame always goes, however large; the next
  // only while the initial estimate keeps it within the budget and the bytes within the cap.
  pacer.BeginFrame(10, 8 * MB);
  CHECK(pacer.Admit(40 * MB));
  pacer.Record(2 * MB, 2 * UploadPacer::InitialMsPerMB);
  CHECK(pacer.Admit(3 * MB) && !pacer.Admit(4 * MB)); // 4 ms spent, 2 ms a MB
  // Fresh memory (4.4 ms a MB): the estimate rises at once, and the frame takes one such mesh.
  pacer.BeginFrame(10, 8 * MB);
  pacer.Record(2 * MB, 8.8);
  CHECK(std::abs(pacer.MsPerMB() - 4.4) < 1e-9);
  CHECK(!pacer.Admit(1 * MB) && pacer.Admit(MB / 4));
  // Reused memory (0.1 ms a MB): one cheap copy does not undo it; many bring it down, and then
  // the byte cap bounds the frame.
  pacer.BeginFrame(10, 8 * MB);
  pacer.Record(1 * MB, 0.1);
  CHECK(pacer.MsPerMB() > 3.5 && !pacer.Admit(3 * MB));
  for (int f = 0; f < 60; ++f)
  {
    pacer.BeginFrame(10, 8 * MB);
    pacer.Record(1 * MB, 0.1);
  }
  CHECK(pacer.MsPerMB() < 0.2);
  CHECK(pacer.Admit(7 * MB) && !pacer.Admit(7 * MB + 1));
  // Work already charged to the frame (the model's tables) counts against both bounds, but
  // the frame's first mesh still goes, however slow the estimate (else nothing would teach it
  // otherwise while the tables stream); after it, a frame that spent its time admits nothing
  // more. Tiny copies and bad timings teach nothing.
  pacer.BeginFrame(10, 8 * MB);
  pacer.Spend(4 * MB, 9.95);
  CHECK(pacer.Admit(1 * MB));
  pacer.BeginFrame(10, 8 * MB);
  pacer.Spend(4 * MB, 9.95);
  pacer.Record(2 * MB, 0.5);
  CHECK(!pacer.Admit(MB / 8) && !pacer.Admit(2 * MB));
  const double before = pacer.MsPerMB();
  pacer.Record(1024, 500);
  pacer.Record(2 * MB, std::numeric_limits<double>::quiet_NaN());
  pacer.Record(2 * MB, -1);
  CHECK(pacer.MsPerMB() == before);
  CHECK(pacer.SpentBytes() == 4 * MB + 2 * MB + 1024 + 4 * MB);
  // A new frame starts a new account: its first mesh goes again.
  pacer.BeginFrame(10, 8 * MB);
  CHECK(pacer.SpentBytes() == 0 && pacer.SpentMs() == 0 && pacer.Admit(100 * MB));
}

/// The I/J/K range view (CellRange.h): the file's footprints are the node boxes of a region
/// and its descendants together, and a region's widened own box holds every leaf column below it;
/// with everything resident and a tolerance no region splits by, every drawn region a side of
/// a random range crosses is a leaf, none lies outside, and every leaf column in the range is
/// drawn by itself or by an ancestor wholly inside; a leaf's masked mesh keeps exactly the
/// active cells in the range, with their sides open towards the cells out of it.
void TestRanges(const Model& model)
{
  // The range as the descriptor carries it: the box, then the excluded boxes, from 1.
  {
    CellRange parsed;
    CHECK(ParseCellRange("2 5 1 3 4 4\nexclude 3 4 1 2 1 9\nexclude 1 1 1 1 1 1", { 9, 8, 9 }, parsed));
    CHECK(parsed.lo == (std::array<int64_t, 3>{ 1, 0, 3 }) && parsed.hi == (std::array<int64_t, 3>{ 4, 2, 3 }));
    CHECK(parsed.excluded.size() == 2 && parsed.excluded[0] == (CellBoxBounds{ 2, 3, 0, 1, 0, 8 }));
    CHECK(
      parsed.Contains(1, 0, 3) && !parsed.Contains(2, 1, 3) && parsed.Contains(2, 2, 3) && !parsed.Contains(1, 0, 4));
    CHECK(parsed.Describe() == "I 2-5, J 1-3, K 4-4 without I 3-4, J 1-2, K 1-9 without I 1-1, J 1-1, K 1-1");
    CellRange onlyExcluded;
    CHECK(ParseCellRange("\nexclude 1 9 1 8 2 9", { 9, 8, 9 }, onlyExcluded) && onlyExcluded.hi[0] == 8);
    CHECK(!onlyExcluded.Whole({ 9, 8, 9 }) && !onlyExcluded.Empty({ 9, 8, 9 }) && onlyExcluded.Contains(8, 7, 0));
    onlyExcluded.excluded[0][4] = 0; // every layer: nothing left
    CHECK(onlyExcluded.Empty({ 9, 8, 9 }));
    CellRange untouched;
    for (const char* bad :
      { "1 2 3 4 5", "exclude 1 2 3 4 5", "1 2 3 4 5 6 7", "1 2 3 4 5 6\n1 2 3 4 5 6", "x 1 2 3 4 5 6" })
      CHECK(!ParseCellRange(bad, { 9, 8, 9 }, untouched) && untouched.excluded.empty() && untouched.hi[0] == -1);
  }
  const auto& regions = model.file->Regions();
  const auto& header = model.file->Header();
  const std::array<int64_t, 3> dims{ header.dims[0], header.dims[1], header.dims[2] };
  std::vector<std::array<float, 4>> footprints(regions.size());
  std::vector<std::array<float, 4>> columns(regions.size(), { 1e30f, -1e30f, 1e30f, -1e30f }); // raw, leaves
  for (std::size_t r = 0; r < regions.size(); ++r)
  {
    const RegionMesh mesh = model.file->ReadRegion(r);
    footprints[r] = RegionFootprint(mesh);
    for (std::size_t c = 0; regions[r].level == header.leafLevel && c < mesh.corners.size(); ++c)
    {
      const auto cell = mesh.ColumnCell(c);
      columns[r] = { std::min(columns[r][0], cell[0]), std::max(columns[r][1], cell[0] + 1),
        std::min(columns[r][2], cell[1]), std::max(columns[r][3], cell[1] + 1) };
    }
  }
  for (const std::size_t leaf : model.Leaves())
  {
    for (int64_t a = static_cast<int64_t>(leaf); a >= 0 && columns[leaf][0] <= columns[leaf][1];
         a = model.Parent(static_cast<std::size_t>(a)))
    {
      const auto& f = footprints[static_cast<std::size_t>(a)];
      CHECK(
        f[0] <= columns[leaf][0] && f[1] >= columns[leaf][1] && f[2] <= columns[leaf][2] && f[3] >= columns[leaf][3]);
    }
  }
  // The file's footprints: the node boxes of each region and its descendants together, exactly.
  const std::vector<std::array<float, 4>> exact = model.file->ReadFootprints();
  CHECK(exact.size() == regions.size());
  std::vector<std::array<float, 4>> united(regions.size(), { 0.f, -1.f, 0.f, -1.f });
  for (std::size_t region = 0; region < regions.size(); ++region)
  {
    const std::array<float, 4> box = TopologyBox(model.file->ReadRegion(region));
    for (int64_t a = static_cast<int64_t>(region); a >= 0 && box[0] <= box[1];
         a = model.Parent(static_cast<std::size_t>(a)))
    {
      auto& u = united[static_cast<std::size_t>(a)];
      u = u[1] < u[0] ? box
                      : std::array<float, 4>{ std::min(u[0], box[0]), std::max(u[1], box[1]), std::min(u[2], box[2]),
                          std::max(u[3], box[3]) };
    }
  }
  for (std::size_t r = 0; r < regions.size() && r < exact.size(); ++r)
  {
    CHECK(exact[r] == united[r]);
  }
  std::mt19937 random(7);
  ViewParameters view;
  view.worldToClip = Everything(1e-9);
  view.parallel = true;
  view.direction = { 0, 0, -1 };
  view.tolerancePixels = 1e30; // only the range splits
  for (int trial = 0; trial < 24; ++trial)
  {
    const bool fromFile = trial % 2 == 1; // the file's footprints, or the widened own boxes
    CellRange range;
    for (int a = 0; a < 3; ++a)
    {
      std::uniform_int_distribution<int64_t> pick(0, dims[a] - 1);
      int64_t lo = pick(random), hi = pick(random);
      if (trial % 3 == 0 && a < 2)
        hi = lo; // a slice
      range.lo[a] = std::min(lo, hi);
      range.hi[a] = std::max(lo, hi);
    }
    // Excluded boxes in a third of the trials (two in some): anywhere, a slab in K or every layer.
    for (int e = 0; e < (trial % 3 == 1 ? 1 + trial % 2 : 0); ++e)
    {
      CellBoxBounds box{};
      for (int a = 0; a < 3; ++a)
      {
        std::uniform_int_distribution<int64_t> pick(0, dims[a] - 1);
        const int64_t lo = pick(random), hi = pick(random);
        box[2 * a] = std::min(lo, hi);
        box[2 * a + 1] = std::max(lo, hi);
      }
      if (e == 1)
      {
        box[4] = 0;
        box[5] = dims[2] - 1;
      }
      range.excluded.push_back(box);
    }
    std::vector<RangeClass> classes(regions.size());
    for (std::size_t r = 0; r < regions.size(); ++r)
      classes[r] =
        fromFile ? ClassifyFootprint(exact[r], range, dims, 1) : ClassifyFootprint(footprints[r], range, dims);
    ViewSelector selector(*model.file);
    selector.SetRangeClassifier([&](std::vector<RangeClass>& out) { out = classes; });
    const ViewSelection selection = selector.Select(view, AllResident);
    std::set<std::size_t> drawn;
    for (const auto& d : selection.drawn)
    {
      drawn.insert(d.region);
      CHECK(classes[d.region] != RangeClass::Outside);
      CHECK(classes[d.region] != RangeClass::Crossed || regions[d.region].level == header.leafLevel);
      // No excluded box's I or J side passes through a coarse region drawn (its leaves' cells
      // all in the box or all out of it), unless the box misses the range's layers.
      const auto& u = exact[d.region];
      for (const CellBoxBounds& e : range.excluded)
      {
        const bool layers = e[4] <= range.hi[2] && e[5] >= range.lo[2];
        const bool meets = u[0] < float(e[1] + 1) && u[1] > float(e[0]) && u[2] < float(e[3] + 1) && u[3] > float(e[2]);
        const bool held =
          u[0] >= float(e[0]) && u[1] <= float(e[1] + 1) && u[2] >= float(e[2]) && u[3] <= float(e[3] + 1);
        CHECK(regions[d.region].level == header.leafLevel || !layers || !meets || held);
      }
    }
    for (const std::size_t leaf : model.Leaves())
    {
      const auto& box = columns[leaf];
      const bool touches =
        box[0] < range.hi[0] + 1 && box[1] > range.lo[0] && box[2] < range.hi[1] + 1 && box[3] > range.lo[1];
      // A leaf an excluded box holds, with every layer of the range, keeps nothing.
      bool excluded = false;
      for (const CellBoxBounds& e : range.excluded)
        excluded = excluded ||
          (box[0] >= float(e[0]) && box[1] <= float(e[1] + 1) && box[2] >= float(e[2]) && box[3] <= float(e[3] + 1) &&
            e[4] <= range.lo[2] && e[5] >= range.hi[2]);
      if (!touches || excluded || drawn.count(leaf))
        continue;
      bool covered = false;
      for (int64_t a = model.Parent(leaf); a >= 0 && !covered; a = model.Parent(static_cast<std::size_t>(a)))
        covered =
          drawn.count(static_cast<std::size_t>(a)) && classes[static_cast<std::size_t>(a)] == RangeClass::Inside;
      CHECK(covered);
    }
    CellFilter filter;
    filter.range = range;
    const int handedness = TopologyHandedness(*model.file);
    for (const std::size_t leaf : drawn)
    {
      if (regions[leaf].level != header.leafLevel)
        continue;
      // Only the range's layers are decoded: the same buffers as from every layer.
      CHECK(SameBuffers(LoadRegionDrawBuffers(*model.file, leaf, { 0, 0, 0 }, handedness, -1, true, &filter),
        WholeMeshBuffers(*model.file, leaf, filter, handedness)));
      const RegionMesh original = model.file->ReadRegion(leaf);
      RegionMesh masked = original;
      MaskToRange(masked, range);
      const std::size_t layers = static_cast<std::size_t>(original.layers);
      for (std::size_t c = 0; c < original.corners.size(); ++c)
      {
        const auto cell = original.ColumnCell(c);
        for (std::size_t k = 0; k < layers; ++k)
        {
          const bool in = range.Contains(int64_t(cell[0]), int64_t(cell[1]), int64_t(k));
          CHECK(masked.active[c * layers + k] == (original.active[c * layers + k] && in));
          for (int e = 0; in && masked.active[c * layers + k] && e < 4; ++e)
          {
            // The edge's two corners in (i, j): on a side of the range, the side is open.
            const auto& p = original.topology[original.corners[c][e]];
            const auto& q = original.topology[original.corners[c][(e + 1) % 4]];
            const bool onSide = (p[0] == q[0] && (p[0] == float(range.lo[0]) || p[0] == float(range.hi[0] + 1))) ||
              (p[1] == q[1] && (p[1] == float(range.lo[1]) || p[1] == float(range.hi[1] + 1)));
            const bool onGrid = (p[0] == q[0] && (p[0] == 0 || p[0] == float(dims[0]))) ||
              (p[1] == q[1] && (p[1] == 0 || p[1] == float(dims[1])));
            if (onSide && !onGrid)
              CHECK(masked.openSides[c * layers + k] & (1u << e));
            // Across an edge into an excluded box: open too (the hole's faces are drawn).
            const int64_t ci = int64_t(cell[0]), cj = int64_t(cell[1]);
            const int64_t ni = p[0] == q[0] ? (int64_t(p[0]) == ci ? ci - 1 : ci + 1) : ci;
            const int64_t nj = p[0] == q[0] ? cj : (int64_t(p[1]) == cj ? cj - 1 : cj + 1);
            if (ni >= 0 && nj >= 0 && ni < dims[0] && nj < dims[1] && range.Excluded(ni, nj, int64_t(k)))
              CHECK(masked.openSides[c * layers + k] & (1u << e));
          }
        }
      }
    }
  }
}

/// Property filters (PropertyFilter.h) on the synthetic model with its properties: each
/// region's class from the block ranges holds against its cells' values (Outside: no active
/// cell of its footprint, widened by one, passes; Inside: every one does); coarse regions it
/// crosses keep every passing cell's coarse cell and only those near a passing cell; at every leaf, every
/// triangle of the filtered buffers belongs to an active cell that passes and carries that
/// cell's value, and every passing cell beside an active cell of its leaf the filter removes
/// (one step in I, J or K) shows a face.
void TestValueFilters(const Model& model)
{
  // The filter text Multiresolution Threshold writes, one filter a line; names may hold spaces.
  {
    std::vector<ValueFilter> parsed;
    CHECK(ParseValueFilters("0.25 0.5 PORO\n\n-1e+30 7 MY ARRAY \n", parsed) && parsed.size() == 2);
    CHECK(parsed.size() == 2 && parsed[0].name == "PORO" && parsed[0].low == 0.25f && parsed[0].high == 0.5f);
    CHECK(parsed.size() == 2 && parsed[1].name == "MY ARRAY" && parsed[1].low == -1e30f && parsed[1].high == 7);
    std::vector<ValueFilter> none;
    CHECK(ParseValueFilters("", none) && none.empty());
    for (const char* bad : { "low high PORO", "0.1 PORO", "0.1 0.2", "0.1 0.2PORO", "0.1 0.2 \n" })
    {
      std::vector<ValueFilter> refused;
      CHECK(!ParseValueFilters(bad, refused) && refused.empty());
    }
  }
  const std::string properties = Temp + "/synth.resmrp";
  std::remove(properties.c_str());
  CHECK(Run(Tool + " add-properties '" + model.path + "' synth:96x80x10:5:1 -o '" + properties +
          "' > /dev/null 2>&1") == 0);
  const auto file = std::make_shared<const PropertyFile>(properties);
  const auto& header = model.file->Header();
  const std::array<int64_t, 3> dims{ header.dims[0], header.dims[1], header.dims[2] };
  const std::vector<float> all = file->ReadBox(static_cast<std::size_t>(FindFilterTable(*file, "PORO", 0)), { 0, 0, 0 },
    { dims[0] - 1, dims[1] - 1, dims[2] - 1 });
  const auto value = [&](int64_t i, int64_t j, int64_t k) {
    return all[static_cast<std::size_t>(i + dims[0] * (j + dims[1] * k))];
  };
  const std::vector<std::array<float, 4>> footprints = model.file->ReadFootprints();
  const int handedness = TopologyHandedness(*model.file);
  std::size_t crossedLeaves = 0, triangles = 0, exposed = 0, coarseCells = 0, keptCoarse = 0;
  std::array<std::size_t, 2> mergedSides{ 0, 0 }; // exact side quads, merged quads
  std::size_t narrowed = 0;                       // crossed leaves decoded in fewer layers
  for (const std::array<float, 2> quantiles : { std::array<float, 2>{ 0.5f, 1.f }, { 0.2f, 0.4f } })
  {
    std::vector<float> sorted;
    std::copy_if(all.begin(), all.end(), std::back_inserter(sorted), [](float v) { return !std::isnan(v); });
    std::sort(sorted.begin(), sorted.end());
    const ValueFilter filter{ "PORO", sorted[std::size_t(quantiles[0] * float(sorted.size() - 1))],
      sorted[std::size_t(quantiles[1] * float(sorted.size() - 1))] };
    CellFilter cells;
    cells.range.hi = { dims[0] - 1, dims[1] - 1, dims[2] - 1 };
    cells.values = std::make_shared<ValueFilterSet>(file, std::vector<ValueFilter>{ filter }, 0);
    cells.paintTable = FindFilterTable(*file, "PORO", 0);
    for (std::size_t r = 0; r < model.file->Regions().size(); ++r)
    {
      const RangeClass c = cells.values->Classify(footprints[r], 1);
      const auto& f = footprints[r];
      bool any = false, every = true;
      for (int64_t k = 0; k < dims[2]; ++k)
        for (int64_t j = std::max<int64_t>(0, int64_t(f[2]) - 1);
             j < std::min<int64_t>(dims[1], int64_t(std::ceil(f[3])) + 1); ++j)
          for (int64_t i = std::max<int64_t>(0, int64_t(f[0]) - 1);
               i < std::min<int64_t>(dims[0], int64_t(std::ceil(f[1])) + 1); ++i)
          {
            const float v = value(i, j, k);
            if (std::isnan(v))
              continue;
            any = any || filter.Passes(v);
            every = every && filter.Passes(v);
          }
      CHECK(c != RangeClass::Outside || !any);
      CHECK(c != RangeClass::Inside || every);
    }
    // Coarse regions the filter crosses, masked by layer blocks: every passing cell's coarse
    // cell stays; a coarse cell that stays has a passing cell of its layer within its column's
    // cells widened by a layer block.
    for (std::size_t r = 0; r < model.file->Regions().size(); ++r)
    {
      if (model.file->Regions()[r].level >= header.leafLevel ||
        cells.values->Classify(footprints[r], 1) != RangeClass::Crossed)
        continue;
      const RegionMesh original = model.file->ReadRegion(r);
      RegionMesh masked = original;
      MaskToFilter(masked, cells, nullptr);
      const std::size_t layers = std::size_t(dims[2]);
      for (std::size_t c = 0; c < original.corners.size(); ++c)
      {
        std::array<float, 2> low = original.topology[original.corners[c][0]], high = low;
        for (const uint32_t node : original.corners[c])
          for (int a = 0; a < 2; ++a)
          {
            low[a] = std::min(low[a], original.topology[node][a]);
            high[a] = std::max(high[a], original.topology[node][a]);
          }
        const auto anyPasses = [&](int64_t k, int64_t margin) {
          for (int64_t j = std::max<int64_t>(0, int64_t(std::floor(low[1])) - margin);
               j < std::min<int64_t>(dims[1], int64_t(std::ceil(high[1])) + margin); ++j)
            for (int64_t i = std::max<int64_t>(0, int64_t(std::floor(low[0])) - margin);
                 i < std::min<int64_t>(dims[0], int64_t(std::ceil(high[0])) + margin); ++i)
              if (filter.Passes(value(i, j, k)))
                return true;
          return false;
        };
        for (std::size_t k = 0; k < layers; ++k)
        {
          if (!original.active[c * layers + k])
            continue;
          ++coarseCells;
          const bool kept = masked.active[c * layers + k];
          CHECK(kept || !anyPasses(int64_t(k), 0));
          CHECK(!kept || anyPasses(int64_t(k), LayerBlockSide));
          keptCoarse += kept;
        }
      }
      CheckMergedSide(masked, model.file->Regions()[r].ownError, mergedSides);
    }
    for (const std::size_t leaf : model.Leaves())
    {
      if (cells.values->Classify(footprints[leaf], 1) != RangeClass::Crossed)
        continue;
      ++crossedLeaves;
      const RegionDrawBuffers buffers =
        LoadRegionDrawBuffers(*model.file, leaf, { 0, 0, 0 }, handedness, -1, true, &cells);
      CHECK(buffers.faceValues.size() == buffers.indices.size() / 3);
      {
        // With a range of some layers, only those are decoded and read: the same buffers and
        // values as from every layer.
        CellFilter slab = cells;
        slab.range.lo[2] = 1 + int64_t(leaf % 3);
        slab.range.hi[2] = dims[2] - 2;
        CHECK(SameBuffers(LoadRegionDrawBuffers(*model.file, leaf, { 0, 0, 0 }, handedness, -1, true, &slab),
          WholeMeshBuffers(*model.file, leaf, slab, handedness)));
      }
      std::set<std::array<int64_t, 3>> shown;
      for (std::size_t t = 0; t < buffers.indices.size() / 3 && t < buffers.faceValues.size(); ++t)
      {
        std::array<double, 3> centroid{ 0, 0, 0 };
        for (int v = 0; v < 3; ++v)
          for (int a = 0; a < 3; ++a)
            centroid[a] += buffers.vertices[std::size_t(buffers.indices[3 * t + v]) * 6 + 3 + a] / 3.0;
        const std::array<int64_t, 3> cell{ int64_t(std::floor(centroid[0])), int64_t(std::floor(centroid[1])),
          int64_t(std::floor(centroid[2])) };
        const float v = value(cell[0], cell[1], cell[2]);
        CHECK(filter.Passes(v));
        CHECK(v == buffers.faceValues[t]);
        shown.insert(cell);
        ++triangles;
      }
      // Passing cells beside a removed active cell of this leaf show a face.
      const RegionMesh mesh = model.file->ReadRegion(leaf);
      std::set<std::array<int64_t, 3>> active;
      for (std::size_t c = 0; c < mesh.corners.size(); ++c)
        for (int64_t k = 0; k < dims[2]; ++k)
          if (mesh.active[c * std::size_t(dims[2]) + std::size_t(k)])
            active.insert({ int64_t(mesh.ColumnCell(c)[0]), int64_t(mesh.ColumnCell(c)[1]), k });
      // The layers decoded for the filter hold every passing cell of the leaf.
      const std::array<int32_t, 2> decoded = FilterLayers(cells, mesh.topology, dims);
      narrowed += decoded[1] - decoded[0] + 1 < dims[2];
      for (const auto& cell : active)
        CHECK(!filter.Passes(value(cell[0], cell[1], cell[2])) || (cell[2] >= decoded[0] && cell[2] <= decoded[1]));
      for (const auto& cell : active)
      {
        if (!filter.Passes(value(cell[0], cell[1], cell[2])))
          continue;
        bool besideRemoved = false;
        for (int a = 0; a < 3 && !besideRemoved; ++a)
          for (int d = -1; d <= 1 && !besideRemoved; d += 2)
          {
            auto other = cell;
            other[a] += d;
            besideRemoved = active.count(other) && !filter.Passes(value(other[0], other[1], other[2]));
          }
        exposed += besideRemoved;
        CHECK(!besideRemoved || shown.count(cell));
      }
    }
  }
  std::printf("  value filters: %zu crossed leaves, %zu triangles, %zu cells beside removed ones shown; coarse crossed "
              "regions keep %zu of %zu active coarse cells\n",
    crossedLeaves, triangles, exposed, keptCoarse, coarseCells);
  CHECK(crossedLeaves > 0 && exposed > 0 && keptCoarse > 0 && keptCoarse < coarseCells);
  std::printf("  masked coarse sides: %zu quads merged in K to %zu; %zu crossed leaves decoded in fewer layers\n",
    mergedSides[0], mergedSides[1], narrowed);
  CHECK(narrowed > 0);
  CHECK(mergedSides[1] > 0 && mergedSides[1] < mergedSides[0]);
}

int main(int argc, char** argv)
{
  if (argc < 4)
  {
    std::fprintf(stderr, "usage: TestViewSelection RESMR DATA_DIR TEMP_DIR\n");
    return 2;
  }
  Tool = argv[1];
  Data = argv[2];
  Temp = argv[3];
  mkdir(Temp.c_str(), 0755);
  const auto start = std::chrono::steady_clock::now();
  const std::string reek = Build(Data + "/reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID", "reek");
  const std::string reek64 = Build(Data + "/reek/res2df_sim/eclipse/model/2_R001_REEK-0.EGRID", "reek64", "--cmax 64");
  const std::string brugge = Build(Data + "/brugge/Real0/BRUGGE_0000.EGRID", "brugge");
  const std::string synth = Build("synth:96x80x10:5", "synth", "--cmax 96");
  const std::string left = Build(Data + "/format_variants/xtgeo_etc/sixcells_lefthanded_hdr1.grdecl", "left");
  const std::string right = Build(Data + "/format_variants/xtgeo_etc/sixcells2_rhand_hdr1.grdecl", "right");
  std::vector<std::unique_ptr<Model>> models;
  for (const auto& path : { reek64, brugge, synth })
    models.emplace_back(new Model(path));
  const bool ok = resmr_testing::RunNamedTests({
    { "Extremes",
      [&] {
        for (const auto& m : models)
          TestExtremes(*m);
      } },
    { "Conformity",
      [&] {
        for (const auto& m : models)
          TestConformity(*m);
      } },
    { "Ranges",
      [&] {
        for (const auto& m : models)
          TestRanges(*m);
      } },
    { "ValueFilters", [&] { TestValueFilters(*models[2]); } },
    { "ToleranceInterval",
      [&] {
        for (const auto& m : models)
          TestToleranceInterval(*m);
      } },
    { "Frustum",
      [&] {
        for (const auto& m : models)
          TestFrustum(*m);
      } },
    { "NormalCones",
      [&] {
        for (const auto& m : models)
          TestNormalCones(*m);
      } },
    { "Fallback",
      [&] {
        for (const auto& m : models)
          TestFallback(*m);
      } },
    { "SelectWithinFloor",
      [&] {
        for (const auto& m : models)
          TestSelectWithinFloor(*m);
      } },
    { "BackFaces",
      [&] {
        for (const auto& m : models)
          TestBackFaces(*m);
      } },
    { "Prediction", [&] { TestPrediction(); } },
    { "FrameRateController", [&] { TestFrameRateController(); } },
    { "EstimateSteering", [&] { TestEstimateSteering(); } },
    { "UploadPacer", [&] { TestUploadPacer(); } },
    { "DrawBuffers",
      [&] {
        TestDrawBuffers(reek, 0);
        TestDrawBuffers(brugge, 0);
        TestDrawBuffers(synth, 0);
        const int l = TopologyHandedness(MultiresolutionFile(left));
        const int r = TopologyHandedness(MultiresolutionFile(right));
        CHECK(l == -r);
        TestDrawBuffers(left, l);
        TestDrawBuffers(right, r);
      } },
    { "CoarseSides",
      [&] {
        TestCoarseSides(reek);
        TestCoarseSides(synth);
        TestSimplifiedSides(synth);
        TestDrawPieces(reek);
        TestDrawPieces(synth);
      } },
    { "Cache", [&] { TestCache(reek64); } },
    { "DamagedChunk", [&] { TestDamagedChunk(reek); } },
    { "Properties", [&] { TestProperties(); } },
    { "LayerBuffers",
      [&] {
        TestLayerBuffers(reek);
        TestLayerBuffers(brugge);
        TestLayerBuffers(synth);
      } },
    { "LayerCache", [&] { TestLayerCache(reek64); } },
  });
  std::printf("total %.2f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (!ok)
  {
    std::fprintf(stderr, "%d checks failed\n", resmr_testing::Failures);
    return 1;
  }
  return 0;
}
