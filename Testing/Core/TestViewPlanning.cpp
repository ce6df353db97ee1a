// The renderer's non-GL planning (paper Sec. 6.2-6.3), against hand-computed values: 4x4
// matrix products, transposes and inverses; the camera carried into model coordinates
// (eye, direction, near distance, pixels per unit, clip matrix) and a known perspective
// projection; the per-frame upload plan (time budget, table slabs, mesh pieces of given byte
// counts, piece admission); the frame time the controller is told; the memory budget's
// split, which GPU copies go when the mirror is full, which property table is asked for and
// which may stand in, and which index runs of a region are drawn; which triangle chunks the
// pick pass draws for a pixel.
#include "CoreTesting.h"

#include "CellInspection.h"

#include "FramePlanning.h"
#include "PropertyFile.h"
#include "Residency.h"
#include "ViewTransforms.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <sys/wait.h>

using namespace resmr;

namespace
{
std::string Tool, Temp;

bool Near(double a, double b, double tolerance = 1e-12)
{
  return std::abs(a - b) <= tolerance * std::max(1.0, std::abs(b));
}

bool SameMatrix(const Matrix4& a, const Matrix4& b, double tolerance = 1e-12)
{
  for (int i = 0; i < 16; ++i)
  {
    if (!Near(a[i], b[i], tolerance))
    {
      std::fprintf(stderr, "element %d: %.17g, expected %.17g\n", i, a[i], b[i]);
      return false;
    }
  }
  return true;
}

void TestMatrices()
{
  Matrix4 a{};
  for (int i = 0; i < 16; ++i)
  {
    a[i] = i + 1; // rows (1 2 3 4), (5 6 7 8), ...
  }
  const Matrix4 t = Transpose(a);
  CHECK(t[1] == 5 && t[4] == 2 && t[3] == 13 && t[12] == 4 && t[0] == 1 && t[15] == 16);
  CHECK(Transpose(t) == a);
  // a * a^T: dot products of a's rows.
  const Matrix4 aat = Multiply(a, t);
  CHECK(
    aat[0] == 30 && aat[1] == 70 && aat[4] == 70 && aat[5] == 174 && aat[15] == 13 * 13 + 14 * 14 + 15 * 15 + 16 * 16);
  CHECK(Multiply(a, IdentityMatrix()) == a && Multiply(IdentityMatrix(), a) == a);
  // Order matters: shear then translate differs from translate then shear.
  const Matrix4 shear{ 1, 2, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  const Matrix4 move = TranslationMatrix({ 3, 4, 5 });
  CHECK(SameMatrix(Multiply(shear, move), { 1, 2, 0, 11, 0, 1, 0, 4, 0, 0, 1, 5, 0, 0, 0, 1 }));
  CHECK(SameMatrix(Multiply(move, shear), { 1, 2, 0, 3, 0, 1, 0, 4, 0, 0, 1, 5, 0, 0, 0, 1 }));

  // Inverses: scale and translation, a quarter turn, a general matrix, a singular one.
  Matrix4 inverse{};
  CHECK(Invert({ 2, 0, 0, 1, 0, 2, 0, 2, 0, 0, 2, 3, 0, 0, 0, 1 }, inverse));
  CHECK(SameMatrix(inverse, { 0.5, 0, 0, -0.5, 0, 0.5, 0, -1, 0, 0, 0.5, -1.5, 0, 0, 0, 1 }));
  const Matrix4 turn{ 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  CHECK(Invert(turn, inverse) && SameMatrix(inverse, Transpose(turn)));
  const Matrix4 general{ 2, 1, 0, 3, 1, 3, 1, 0, 0, 1, 4, 1, 1, 0, 1, 5 };
  CHECK(Invert(general, inverse) && SameMatrix(Multiply(general, inverse), IdentityMatrix(), 1e-14));
  Matrix4 untouched = IdentityMatrix();
  CHECK(!Invert(a, untouched) && untouched == IdentityMatrix()); // a's rows are dependent

  const std::array<double, 4> moved = Transform(move, { 1, 1, 1, 1 });
  CHECK(moved[0] == 4 && moved[1] == 5 && moved[2] == 6 && moved[3] == 1);
  const std::array<double, 4> direction = Transform(move, { 1, 1, 1, 0 });
  CHECK(direction[0] == 1 && direction[1] == 1 && direction[2] == 1 && direction[3] == 0);

  // MAPAXES placement: origin (10, 20), y axis reversed.
  const Matrix4 placement = PlacementMatrix({ 10, 20, 1, 0, 0, -1 });
  const std::array<double, 4> mapped = Transform(placement, { 3, 4, 7, 1 });
  CHECK(mapped[0] == 13 && mapped[1] == 16 && mapped[2] == 7 && mapped[3] == 1);
  CHECK(LinearDeterminant(placement) == -1);
  CHECK(LinearDeterminant(turn) == 1);
  CHECK(LinearDeterminant({ 2, 0, 0, 9, 0, 3, 0, 9, 0, 0, 4, 9, 0, 0, 0, 1 }) == 24);

  // OpenGL's layout: the translation in elements 12-14.
  const std::array<float, 16> packed = ColumnMajor(move);
  CHECK(packed[12] == 3 && packed[13] == 4 && packed[14] == 5 && packed[3] == 0 && packed[15] == 1);
  const std::array<float, 16> sheared = ColumnMajor(shear);
  CHECK(sheared[4] == 2 && sheared[1] == 0);

  // Normal matrices: a scale's is its inverse; a shear's inverse transpose, column-major.
  const std::array<float, 9> scaled = NormalMatrix({ 2, 0, 0, 7, 0, 4, 0, 7, 0, 0, 1, 7, 0, 0, 0, 1 });
  CHECK(scaled[0] == 0.5f && scaled[4] == 0.25f && scaled[8] == 1.f && scaled[1] == 0 && scaled[3] == 0);
  const std::array<float, 9> normal = NormalMatrix(shear);
  const std::array<float, 9> expected{ 1, -2, 0, 0, 1, 0, 0, 0, 1 }; // shear by 2
  CHECK(normal == expected);
}

void TestCameraToView()
{
  // Perspective: eye at (0, 0, 10) looking down -z, 90 degrees, 600 px high, near plane 0.5;
  // the model scaled by 2 and moved by (100, 0, 0) in the world.
  CameraState camera;
  camera.worldToClip = TranslationMatrix({ 0, 0, -10 });
  camera.position = { 0, 0, 10 };
  camera.directionOfProjection = { 0, 0, -1 };
  camera.nearClip = 0.5;
  camera.viewAngleDegrees = 90;
  camera.viewportHeight = 600;
  const Matrix4 modelToWorld{ 2, 0, 0, 100, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1 };
  ViewParameters view = ViewFromCamera(camera, modelToWorld);
  CHECK(SameMatrix(view.worldToClip, { 2, 0, 0, 100, 0, 2, 0, 0, 0, 0, 2, -10, 0, 0, 0, 1 }));
  CHECK(Near(view.eye[0], -50) && Near(view.eye[1], 0) && Near(view.eye[2], 5));
  CHECK(Near(view.direction[0], 0) && Near(view.direction[1], 0) && Near(view.direction[2], -1));
  CHECK(Near(view.nearDistance, 0.25)); // half a model unit a world unit
  CHECK(!view.parallel);
  CHECK(Near(view.pixelsPerUnit, 300, 1e-12)); // 600 / (2 tan 45 degrees)

  // Parallel: 600 px show 2 x 50 world units.
  camera.parallel = true;
  camera.parallelScale = 50;
  view = ViewFromCamera(camera, IdentityMatrix());
  CHECK(view.parallel && Near(view.pixelsPerUnit, 6));
  CHECK(Near(view.eye[2], 10) && Near(view.nearDistance, 0.5));

  // A known projection: OpenGL's perspective of 90 degrees, square, near 1, far 100, from the
  // origin looking down -z. A point 1 unit off the axis at distance 2 lands half way to the
  // edge, and pixelsPerUnit predicts the same: 1 unit at distance 2 covers ppu / 2 pixels,
  // a quarter of the height, which is half of the half-height.
  const double n = 1, f = 100;
  camera = CameraState();
  camera.worldToClip = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -(f + n) / (f - n), -2 * f * n / (f - n), 0, 0, -1, 0 };
  camera.viewAngleDegrees = 90;
  camera.viewportHeight = 800;
  camera.nearClip = n;
  view = ViewFromCamera(camera, IdentityMatrix());
  const std::array<double, 4> clip = Transform(view.worldToClip, { 0, 1, -2, 1 });
  CHECK(Near(clip[1] / clip[3], 0.5));
  CHECK(Near(clip[1] / clip[3] * camera.viewportHeight / 2, view.pixelsPerUnit * 1 / 2));
  const std::array<double, 4> nearPoint = Transform(view.worldToClip, { 0, 0, -n, 1 });
  CHECK(Near(nearPoint[2] / nearPoint[3], -1)); // the near plane at depth -1

  // Map placement with a mirror: the eye carried back through it.
  camera = CameraState();
  camera.position = { 13, 16, 7 };
  view = ViewFromCamera(camera, PlacementMatrix({ 10, 20, 1, 0, 0, -1 }));
  CHECK(Near(view.eye[0], 3) && Near(view.eye[1], 4) && Near(view.eye[2], 7));
}

void TestUploadPlan()
{
  CHECK(UploadBudgetMs(0) == 10);
  CHECK(Near(UploadBudgetMs(20), 5));
  // A still view behind slow frames (software rendering) copies half a frame's time, in bytes
  // in proportion; a fast frame keeps the fixed allowance; a frame-rate target ignores both.
  CHECK(Near(UploadBudgetMs(0, 300), 150) && UploadBudgetMs(0, 12) == 10 && Near(UploadBudgetMs(20, 300), 5));
  CHECK(UploadBudgetMs(0, std::nan("")) == 10);
  CHECK(UploadByteCap(10) == UploadBytesPerFrame && UploadByteCap(5) == UploadBytesPerFrame);
  CHECK(UploadByteCap(150) == 15 * UploadBytesPerFrame && TableByteCap(150) == 15 * TableBytesPerFrame);
  CHECK(TableByteCap(UploadBudgetMs(10, 500)) == TableBytesPerFrame);
  CHECK(UploadBytesPerFrame == 8u << 20 && TableBytesPerFrame == 4u << 20 && PieceBytes == 1u << 20);

  // Table slabs: 1 MB slices, 4 MB a frame.
  const std::size_t mb = std::size_t(1) << 20;
  std::size_t budget = 4 * mb;
  CHECK(SlicesThisFrame(10, mb, budget, false) == 4 && budget == 0);
  CHECK(SlicesThisFrame(6, mb, budget, false) == 0 && budget == 0); // spent
  budget = mb / 2;
  CHECK(SlicesThisFrame(6, mb, budget, false) == 1 && budget == 0); // at least one
  budget = 3 * mb + mb / 2;
  CHECK(SlicesThisFrame(2, mb, budget, false) == 2 && budget == mb + mb / 2); // the rest only
  budget = 0;
  CHECK(SlicesThisFrame(10, mb, budget, true) == 10 && budget == 0); // still renders: all
  budget = 4 * mb;
  CHECK(SlicesThisFrame(0, mb, budget, false) == 0 && budget == 4 * mb);

  // Mesh pieces: four triangles of three vertices each, 3 x 24 + 3 x 4 = 84 bytes each.
  RegionDrawBuffers buffers;
  buffers.vertices.assign(12 * 6, 0.f);
  for (uint32_t v = 0; v < 12; ++v)
  {
    buffers.indices.push_back(v);
  }
  DrawPieceCursor pairs(buffers, 170); // two triangles (168 bytes) a piece
  CHECK(!pairs.Done());
  CHECK(pairs.Next().first == 0 && pairs.Next().end == 6 && pairs.Next().lowVertex == 0 &&
    pairs.Next().highVertex == 5 && pairs.Next().bytes == 168);
  CHECK(pairs.Advance() == 168 && !pairs.Done());
  CHECK(pairs.Next().first == 6 && pairs.Next().end == 12 && pairs.Next().lowVertex == 6);
  CHECK(pairs.Advance() == 168 && pairs.Done());
  DrawPieceCursor singles(buffers, 10); // smaller than a triangle: still one a piece
  std::size_t pieces = 0, bytes = 0;
  while (!singles.Done())
  {
    bytes += singles.Advance();
    ++pieces;
  }
  CHECK(pieces == 4 && bytes == 4 * 84);
  DrawPieceCursor whole(buffers); // 1 MB: one piece
  CHECK(whole.Advance() == 12 * 24 + 12 * 4 && whole.Done());
  // Shared vertices are copied once within a piece.
  RegionDrawBuffers strip;
  strip.vertices.assign(4 * 6, 0.f);
  strip.indices = { 0, 1, 2, 2, 1, 3 };
  DrawPieceCursor shared(strip);
  CHECK(shared.Advance() == 4 * 24 + 6 * 4);

  // Admission: after a copy that used up the frame's time, only roots (and still renders)
  // go on, and never past the GPU's share.
  UploadPacer pacer;
  pacer.BeginFrame(10, 8 * mb);
  CHECK(MayCopyPiece(true, false, pacer, mb, 0, 100 * mb)); // the first copy always
  pacer.Record(4 * mb, 40);
  CHECK(!MayCopyPiece(true, false, pacer, mb, 4 * mb, 100 * mb));
  CHECK(MayCopyPiece(true, true, pacer, mb, 4 * mb, 100 * mb));
  CHECK(MayCopyPiece(false, false, pacer, mb, 4 * mb, 100 * mb));
  CHECK(!MayCopyPiece(false, true, pacer, mb, 4 * mb, 4 * mb + mb - 1));
  CHECK(MayCopyPiece(false, true, pacer, mb, 4 * mb, 5 * mb));
}

void TestControllerInputs()
{
  CHECK(ControllerStartTolerance(1) == 64 && ControllerStartTolerance(100) == 100);
  // 30 fps: back to back below 100 ms apart.
  CHECK(MeasuredFrameMs(5, 12, 40, 30, false) == 40);
  CHECK(MeasuredFrameMs(5, 12, 150, 30, false) == 12);
  CHECK(MeasuredFrameMs(20, 12, 150, 30, false) == 20);
  CHECK(MeasuredFrameMs(5, 12, 40, 30, true) == 5); // after an allocation: its own time
  // A still view's refresh: a frame's time while the loaders read (30 ms to 1 s), 30 ms when
  // only copies to the GPU remain, however slow the frame.
  CHECK(RefreshWaitMs(350, true) == 350 && RefreshWaitMs(5, true) == 30 && RefreshWaitMs(4000, true) == 1000);
  CHECK(RefreshWaitMs(350, false) == 30 && RefreshWaitMs(NAN, true) == 30);
}

void TestResidency()
{
  CHECK(MainMemoryShare(1024) == std::size_t(512) << 20 && GpuShare(1024) == std::size_t(512) << 20);
  CHECK(MainMemoryShare(16) + GpuShare(16) == std::size_t(16) << 20);

  // Copies not wanted go, in the mirror's order, until the piece fits.
  const std::vector<std::pair<std::size_t, std::size_t>> mirrored{ { 1, 100 }, { 2, 200 }, { 3, 300 }, { 4, 50 } };
  CHECK((CopiesToRelease(mirrored, { 2, 4 }, 2, 650, 100, 500) == std::vector<std::size_t>{ 1, 3 }));
  CHECK((CopiesToRelease(mirrored, { 2, 4 }, 2, 650, 100, 700) == std::vector<std::size_t>{ 1 }));
  CHECK(CopiesToRelease(mirrored, { 2, 4 }, 2, 650, 100, 750).empty());
  // Not enough even so: everything not wanted, and uploads then wait.
  CHECK((CopiesToRelease(mirrored, { 2, 4 }, 2, 650, 100, 100) == std::vector<std::size_t>{ 1, 3 }));
  // Then copies the frame needs less than the one at `position` (later in the order), the
  // last first; never one before it.
  CHECK((CopiesToRelease(mirrored, { 5, 4, 2, 3 }, 0, 650, 100, 500) == std::vector<std::size_t>{ 1, 3 }));
  CHECK((CopiesToRelease(mirrored, { 5, 4, 2, 3 }, 0, 650, 100, 300) == std::vector<std::size_t>{ 1, 3, 2 }));
  CHECK((CopiesToRelease(mirrored, { 4, 2, 5, 3 }, 2, 650, 100, 100) == std::vector<std::size_t>{ 1, 3 }));

  // Tables: the one asked for, earlier steps of the same property and layer stand in.
  PropertyRequest request;
  request.wanted = true;
  request.name = "SWAT";
  request.step = 3;
  PropertyTableData table;
  table.name = "SWAT";
  table.step = 3;
  CHECK(IsRequested(&table, request) && MayStandIn(&table, request));
  table.step = 2;
  CHECK(!IsRequested(&table, request) && MayStandIn(&table, request));
  table.layer = 4;
  CHECK(!IsRequested(&table, request) && !MayStandIn(&table, request));
  table.layer = -1;
  table.name = "PRESSURE";
  CHECK(!MayStandIn(&table, request));
  CHECK(!IsRequested(nullptr, request) && !MayStandIn(nullptr, request));
  request.wanted = false;
  table.name = "SWAT";
  CHECK(!MayStandIn(&table, request));
  const PropertyRequest none = RequestFor(nullptr, "PORO", 2, -1);
  CHECK(!none.wanted && none.step == 2);

  // Parts: top, bottom, exact side; in files before SidesInPlaceVersion the simplified side
  // past CoarseSidePixels.
  RegionDrawBuffers buffers;
  buffers.topIndices = 30;
  buffers.bottomIndices = 60;
  buffers.sideIndices = 90;
  buffers.coarseSideIndices = 12;
  DrawnRegion drawn;
  drawn.top = false;
  drawn.projectedError = CoarseSidePixels;
  const RegionRecord record{};
  const ViewParameters view;
  const uint32_t before = MultiresolutionHeader::SidesInPlaceVersion - 1, now = MultiresolutionHeader::Version;
  std::array<DrawPart, 3> parts = PartsToDraw(buffers, drawn, false, record, view, before);
  CHECK(!parts[0].shown && parts[0].first == 0 && parts[0].count == 30 && parts[0].kind == 0);
  CHECK(parts[1].shown && parts[1].first == 30 && parts[1].count == 60 && parts[1].kind == 1);
  CHECK(parts[2].shown && parts[2].first == 90 && parts[2].count == 90 && parts[2].kind == 2);
  drawn.projectedError = 2.5;
  parts = PartsToDraw(buffers, drawn, false, record, view, before);
  CHECK(parts[2].first == 180 && parts[2].count == 12);
  // From SidesInPlaceVersion also where twice the error is within a tolerance past
  // CoarseSidePixels (6 px here); never at 1 px or 0 px.
  CHECK(MultiresolutionHeader::Version >= MultiresolutionHeader::SidesInPlaceVersion);
  ViewParameters moving;
  moving.tolerancePixels = 6;
  drawn.projectedError = 0.25;
  parts = PartsToDraw(buffers, drawn, false, record, moving, now);
  CHECK(parts[2].first == 180 && parts[2].count == 12);
  parts = PartsToDraw(buffers, drawn, false, record, moving, before);
  CHECK(parts[2].first == 90 && parts[2].count == 90);
  parts = PartsToDraw(buffers, drawn, false, record, view, now);
  CHECK(view.tolerancePixels == 1 && parts[2].first == 90 && parts[2].count == 90);
  moving.tolerancePixels = 3;
  drawn.projectedError = 1.75;
  parts = PartsToDraw(buffers, drawn, false, record, moving, now);
  CHECK(parts[2].first == 90 && parts[2].count == 90);
  ViewParameters exact;
  exact.tolerancePixels = 0;
  parts = PartsToDraw(buffers, drawn, false, record, exact, now);
  CHECK(parts[2].first == 90 && parts[2].count == 90);
  CHECK(
    DrawsSimplifiedSide(now, 2.5, exact) && !DrawsSimplifiedSide(now, 0, exact) && !DrawsSimplifiedSide(now, 0, view));
  CHECK(DrawsSimplifiedSide(now, 1.5, moving) && DrawsSimplifiedSide(now, 0, moving));
  CHECK(!DrawsSimplifiedSide(before, CoarseSidePixels, view) && DrawsSimplifiedSide(before, 2.5, exact));
  buffers.exactSides = false; // loaded without its exact side: the simplified one meanwhile
  parts = PartsToDraw(buffers, drawn, false, record, exact, now);
  CHECK(parts[2].first == 180 && parts[2].count == 12);
  buffers.exactSides = true;
  buffers.coarseSideIndices = 0; // none stored: the exact side
  parts = PartsToDraw(buffers, drawn, false, record, view, now);
  CHECK(parts[2].first == 90 && parts[2].count == 90);
  // A layer's top and bottom go by their own cones: an empty cone (cosine -2) is culled.
  buffers.topCone = { 0.f, 0.f, 1.f, -2.f };
  buffers.bottomCone = { 0.f, 0.f, 1.f, -2.f };
  drawn.top = drawn.bottom = true;
  parts = PartsToDraw(buffers, drawn, true, record, view, now);
  CHECK(!parts[0].shown && !parts[1].shown && parts[2].shown);
  buffers.topCone = { 0.f, 0.f, 1.f, 1.f }; // every top normal straight up
  RegionRecord box{};
  box.bounds = { 0, 0, 0, 1, 1, 1 }; // x, y, depth: z from -1 to 0
  ViewParameters above;
  above.eye = { 0.5, 0.5, 10 };
  parts = PartsToDraw(buffers, drawn, true, box, above, now);
  CHECK(parts[0].shown && !parts[1].shown);
  ViewParameters below;
  below.eye = { 0.5, 0.5, -10 };
  parts = PartsToDraw(buffers, drawn, true, box, below, now);
  CHECK(!parts[0].shown);
  // Back faces: the top seen from above and the bottom seen from below keep theirs (folds of
  // the visible sheet, seen edge-on); the sides and the surface facing away may lose them.
  parts = PartsToDraw(buffers, drawn, false, box, above, now);
  CHECK(!parts[0].cullBackFaces && parts[1].cullBackFaces && parts[2].cullBackFaces);
  parts = PartsToDraw(buffers, drawn, false, box, below, now);
  CHECK(parts[0].cullBackFaces && !parts[1].cullBackFaces && parts[2].cullBackFaces);
  ViewParameters level; // the eye level with the box: neither surface faces away as a whole
  level.eye = { 5, 0.5, -0.5 };
  parts = PartsToDraw(buffers, drawn, false, box, level, now);
  CHECK(!parts[0].cullBackFaces && !parts[1].cullBackFaces && parts[2].cullBackFaces);
  ViewParameters up; // parallel, looking up
  up.parallel = true;
  up.direction = { 0, 0, 1 };
  parts = PartsToDraw(buffers, drawn, false, box, up, now);
  CHECK(parts[0].cullBackFaces && !parts[1].cullBackFaces);
}

int Run(const std::string& command)
{
  std::fprintf(stderr, "$ %s\n", command.c_str());
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void TestPropertyRequests()
{
  // A synthetic model: static INIT arrays (PORO) and PRESSURE and SWAT at steps 0 and 1.
  const std::string spec = "synth:6x5x3:7:2";
  const std::string geometry = Temp + "/synth.resmr", properties = Temp + "/synth.resmrp";
  CHECK(Run(Tool + " build " + spec + " -o '" + geometry + "' --quiet > /dev/null") == 0);
  CHECK(Run(Tool + " add-properties '" + geometry + "' " + spec + " -o '" + properties + "' > /dev/null 2>&1") == 0);
  const PropertyFile file(properties);
  PropertyRequest request = RequestFor(&file, "PORO", 1, -1);
  CHECK(request.wanted && request.step == -1 && request.name == "PORO" && request.layer == -1);
  request = RequestFor(&file, "SWAT", 1, 2);
  CHECK(request.wanted && request.step == 1 && request.layer == 2);
  request = RequestFor(&file, "SWAT", 9, -1); // no such step, and not static
  CHECK(!request.wanted && request.step == -1);
  request = RequestFor(&file, "NOSUCH", 0, -1);
  CHECK(!request.wanted);
  request = RequestFor(&file, "", 0, -1);
  CHECK(!request.wanted && request.step == 0);
}
} // namespace

/// Chunk boxes of 600 triangles in three clusters (x near 0, 100, 200): a pixel over the middle
/// cluster keeps only its chunk; a part starting mid-chunk keeps its own indices only.
void TestPickChunks()
{
  RegionDrawBuffers buffers;
  for (int t = 0; t < 600; ++t)
  {
    const float x = t < 256 ? 0.f : t < 512 ? 100.f : 200.f;
    for (int v = 0; v < 3; ++v)
    {
      const float corner[6] = { x + float(v == 1), float(v == 2), float(t % 7), 0, 0, 0 };
      buffers.vertices.insert(buffers.vertices.end(), corner, corner + 6);
      buffers.indices.push_back(static_cast<uint32_t>(3 * t + v));
    }
  }
  const auto boxes = TriangleChunkBoxes(buffers);
  CHECK(boxes.size() == 3);
  CHECK(boxes[0][0] == 0.f && boxes[0][3] == 1.f && boxes[1][0] == 100.f && boxes[1][3] == 101.f);
  CHECK(boxes[2][0] == 200.f && boxes[2][4] == 1.f && boxes[2][5] == 6.f);
  // Orthographic: x from -10 to 210 and y from -10 to 10 across a 220 x 20 pixel viewport.
  Matrix4 toClip{};
  toClip[0] = 2.0 / 220;
  toClip[3] = -200.0 / 220;
  toClip[5] = 2.0 / 20;
  toClip[10] = -0.01;
  toClip[15] = 1;
  const auto runs = IndexRunsCoveringPixel(boxes, 0, 1800, toClip, 110.5, 10.5, 220, 20);
  CHECK(runs.size() == 1 && runs[0].first == 768 && runs[0].second == 768);
  // The pixel a few pixels off the cluster's box: nothing.
  CHECK(IndexRunsCoveringPixel(boxes, 0, 1800, toClip, 115.5, 10.5, 220, 20).empty());
  // A part from triangle 300 to 550 over the last two clusters' pixels: its own indices only.
  const auto late = IndexRunsCoveringPixel(boxes, 900, 750, toClip, 210.5, 10.5, 220, 20);
  CHECK(late.size() == 1 && late[0].first == 1536 && late[0].second == 114);
  const auto both = IndexRunsCoveringPixel(boxes, 900, 750, toClip, 110.5, 10.5, 220, 20);
  CHECK(both.size() == 1 && both[0].first == 900 && both[0].second == 636);
  // A box reaching behind the eye may cover anything.
  Matrix4 perspective{};
  perspective[0] = perspective[5] = 1;
  perspective[10] = -1;
  perspective[14] = -1; // w = -z: the eye at z = 0 looking down -z
  CHECK(BoxMayCoverPixel({ -1, -1, -1 }, { 1, 1, 1 }, perspective, 0.5, 0.5, 10, 10));
  CHECK(!BoxMayCoverPixel({ 5, 5, -2 }, { 6, 6, -1 }, perspective, 0.5, 0.5, 10, 10));
}

int main(int argc, char** argv)
{
  if (argc != 3)
  {
    std::fprintf(stderr, "usage: %s RESMR_TOOL TEMP_DIR\n", argv[0]);
    return 2;
  }
  Tool = argv[1];
  Temp = argv[2];
  Run("rm -rf '" + Temp + "' && mkdir -p '" + Temp + "'"); // nothing of an earlier run
  const bool passed = resmr_testing::RunNamedTests({
    { "Matrices", TestMatrices },
    { "CameraToView", TestCameraToView },
    { "UploadPlan", TestUploadPlan },
    { "ControllerInputs", TestControllerInputs },
    { "Residency", TestResidency },
    { "PropertyRequests", TestPropertyRequests },
    { "PickChunks", TestPickChunks },
  });
  return passed ? 0 : 1;
}
