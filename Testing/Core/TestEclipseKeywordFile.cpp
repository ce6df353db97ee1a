// Unit tests of the Core ECLIPSE keyword-file reader, EGRID reader and results index: every
// data type, block splits (standard and not), formatted files, a small EGRID + INIT +
// unified and per-step restarts, and bad input giving errors that name file and keyword.
#include "CoreTesting.h"
#include "EclipseGrid.h"
#include "EclipseKeywordFile.h"
#include "EclipseKeywordWriter.h"
#include "EclipseResults.h"
#include "Errors.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <sys/resource.h>
#include <unistd.h>
#include <vector>

namespace
{
std::string Directory;

// ------------------------------------------------------------------ file writers

void Put32(std::string& out, uint32_t value)
{
  for (int shift = 24; shift >= 0; shift -= 8)
  {
    out.push_back(static_cast<char>((value >> shift) & 0xff));
  }
}

void Put64(std::string& out, uint64_t value)
{
  Put32(out, static_cast<uint32_t>(value >> 32));
  Put32(out, static_cast<uint32_t>(value));
}

/// One element's big-endian bytes.
using Element = std::string;

Element Int(int32_t v)
{
  std::string s;
  Put32(s, static_cast<uint32_t>(v));
  return s;
}
Element Real(float v)
{
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  std::string s;
  Put32(s, bits);
  return s;
}
Element Doub(double v)
{
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  std::string s;
  Put64(s, bits);
  return s;
}
Element Text(const std::string& v, std::size_t width = 8)
{
  std::string s = v;
  s.resize(width, ' ');
  return s;
}

/// An unformatted keyword: header record, then data records of `perBlock` elements.
std::string Keyword(const std::string& name, const std::string& type, const std::vector<Element>& elements,
  std::size_t perBlock = 0, int32_t declaredCount = INT32_MIN)
{
  std::string out;
  Put32(out, 16);
  out += Text(name);
  Put32(out, static_cast<uint32_t>(declaredCount != INT32_MIN ? declaredCount : static_cast<int32_t>(elements.size())));
  out += type;
  Put32(out, 16);
  if (perBlock == 0)
  {
    perBlock = type[0] == 'C' ? 105 : 1000; // CHAR and C0nn: 105 strings per record
  }
  for (std::size_t first = 0; first < elements.size(); first += perBlock)
  {
    std::string block;
    for (std::size_t e = first; e < std::min(elements.size(), first + perBlock); ++e)
    {
      block += elements[e];
    }
    Put32(out, static_cast<uint32_t>(block.size()));
    out += block;
    Put32(out, static_cast<uint32_t>(block.size()));
  }
  return out;
}

template<typename T, typename F>
std::vector<Element> Elements(const std::vector<T>& values, F&& make)
{
  std::vector<Element> out;
  for (const T& v : values)
  {
    out.push_back(make(v));
  }
  return out;
}

std::string Write(const std::string& name, const std::string& bytes)
{
  const std::string path = Directory + "/" + name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

void ExpectError(
  const std::string& label, const std::function<void()>& action, const std::vector<std::string>& fragments)
{
  resmr_testing::ExpectError<resmr::InputError>(label, action, fragments);
}

// ------------------------------------------------------------------ tests

void TestEveryType()
{
  const std::string bytes = Keyword("INTS", "INTE", Elements<int32_t>({ -1, 0, 2147483647 }, Int)) +
    Keyword("REALS", "REAL", Elements<float>({ 1.5f, -2.25e10f }, Real)) +
    Keyword("DOUBS", "DOUB", Elements<double>({ 1e-300, M_PI }, Doub)) +
    Keyword("LOGIS", "LOGI", Elements<int32_t>({ 1, 0 }, Int)) +
    Keyword("CHARS", "CHAR", { Text("METRES"), Text("A B") }) + Keyword("LONG", "C010", { Text("TEN CHARS!", 10) }) +
    Keyword("MESSAGE", "MESS", {}) + Keyword("EMPTY", "INTE", {});
  const resmr::EclipseKeywordFile file(Write("types.bin", bytes));
  CHECK(!file.IsFormatted());
  CHECK(file.Records().size() == 8);
  std::vector<double> values;
  file.ReadNumbers(*file.Find("INTS"), values);
  CHECK(values == std::vector<double>({ -1, 0, 2147483647 }));
  std::vector<float> reals(2);
  file.Read(*file.Find("REALS"), reals.data());
  CHECK(reals[0] == 1.5f && reals[1] == -2.25e10f);
  file.ReadNumbers(*file.Find("DOUBS"), values);
  CHECK(values[0] == 1e-300 && values[1] == M_PI);
  std::vector<int32_t> logicals(2);
  file.Read(*file.Find("LOGIS"), logicals.data());
  CHECK(logicals[0] == 1 && logicals[1] == 0);
  CHECK(file.ReadStrings(*file.Find("CHARS")) == std::vector<std::string>({ "METRES", "A B" }));
  CHECK(file.ReadStrings(*file.Find("LONG")) == std::vector<std::string>({ "TEN CHARS!" }));
  CHECK(file.Find("MESSAGE")->type == resmr::EclipseDataType::Message);
  CHECK(file.Find("EMPTY")->count == 0);
  ExpectError("strings read as numbers", [&] { file.ReadNumbers(*file.Find("CHARS"), values); },
    { "types.bin", "CHARS", "numeric" });
}

void TestBlockSplits()
{
  std::vector<int32_t> ints(2500);
  std::vector<std::string> names(250);
  for (int i = 0; i < 2500; ++i)
  {
    ints[i] = i * 7 - 3;
  }
  for (int i = 0; i < 250; ++i)
  {
    names[i] = "N" + std::to_string(i);
  }
  std::vector<Element> texts;
  for (const std::string& n : names)
  {
    texts.push_back(Text(n));
  }
  // Standard blocks (1000 numbers / 105 strings), and odd ones a writer might use.
  for (std::size_t perBlock : { std::size_t(0), std::size_t(333) })
  {
    const std::string bytes = Keyword("BIG", "INTE", Elements(ints, Int), perBlock) +
      Keyword("NAMES", "CHAR", texts, perBlock ? 50 : 0) + Keyword("AFTER", "INTE", { Int(42) });
    const resmr::EclipseKeywordFile file(Write("blocks.bin", bytes));
    CHECK(file.Records().size() == 3);
    std::vector<int32_t> back(2500);
    file.Read(*file.Find("BIG"), back.data());
    CHECK(back == ints);
    CHECK(file.ReadStrings(*file.Find("NAMES")) == names);
    std::vector<double> after;
    file.ReadNumbers(*file.Find("AFTER"), after);
    CHECK(after.size() == 1 && after[0] == 42);
    const int64_t expectedBigEnd = perBlock == 0 ? 24 + 2500 * 4 + 3 * 8 : 24 + 2500 * 4 + 8 * 8;
    CHECK(file.Find("BIG")->endOffset == expectedBigEnd);
  }
}

void TestFormatted()
{
  const std::string text = " 'INTS    '           3 'INTE'\n           -1           0  2147483647\n"
                           " 'REALS   '           2 'REAL'\n   0.15000000E+01  -0.22500000E+11\n"
                           " 'DOUBS   '           2 'DOUB'\n   0.10000000000000D-299   0.31415926535898D+01\n"
                           " 'LOGIS   '           2 'LOGI'\n  T  F\n"
                           " 'CHARS   '           2 'CHAR'\n 'METRES  ' 'A B     '\n"
                           " 'MESSAGE '           0 'MESS'\n";
  const resmr::EclipseKeywordFile file(Write("types.FINIT", text));
  CHECK(file.IsFormatted());
  CHECK(file.Records().size() == 6);
  std::vector<double> values;
  file.ReadNumbers(*file.Find("INTS"), values);
  CHECK(values == std::vector<double>({ -1, 0, 2147483647 }));
  std::vector<float> reals(2);
  file.Read(*file.Find("REALS"), reals.data());
  CHECK(reals[0] == 1.5f && reals[1] == -2.25e10f);
  file.ReadNumbers(*file.Find("DOUBS"), values);
  CHECK(values[0] == 1e-300 && std::fabs(values[1] - 3.1415926535898) < 1e-15);
  file.ReadNumbers(*file.Find("LOGIS"), values);
  CHECK(values == std::vector<double>({ 1, 0 }));
  CHECK(file.ReadStrings(*file.Find("CHARS")) == std::vector<std::string>({ "METRES", "A B" }));

  ExpectError("formatted count too large",
    [&] { resmr::EclipseKeywordFile(Write("short.FEGRID", " 'COORD   '           5 'REAL'\n 1.0 2.0\n")); },
    { "short.FEGRID", "COORD", "file ends after 2 of 5" });
  ExpectError("formatted bad number",
    [&] {
      const resmr::EclipseKeywordFile bad(Write("bad.FEGRID", " 'COORD   '           2 'REAL'\n 1.0 x.5\n"));
      std::vector<double> v;
      bad.ReadNumbers(bad.Records()[0], v);
    },
    { "bad.FEGRID", "COORD", "'x.5' is not a valid REAL" });
}

void TestBadUnformatted()
{
  const std::string good = Keyword("ZCORN", "REAL", Elements<float>(std::vector<float>(1500, 1.0f), Real));
  const auto write = [&](const std::string& name, std::string bytes) { return Write(name, bytes); };
  ExpectError("truncated", [&] { resmr::EclipseKeywordFile(write("truncated.bin", good.substr(0, 3000))); },
    { "truncated.bin", "ZCORN", "too short" });
  std::string markers = good;
  markers[24 + 4 + 4000 + 3] = 1; // first block's end marker
  ExpectError("markers",
    [&] {
      const resmr::EclipseKeywordFile file(write("markers.bin", markers));
      std::vector<double> v;
      file.ReadNumbers(file.Records()[0], v);
    },
    { "markers.bin", "ZCORN", "marker" });
  ExpectError("count",
    [&] {
      resmr::EclipseKeywordFile(
        write("count.bin", Keyword("ZCORN", "REAL", Elements<float>({ 1.0f }, Real), 0, 1 << 30)));
    },
    { "count.bin", "ZCORN", "too short" });
  ExpectError("negative count",
    [&] { resmr::EclipseKeywordFile(write("negative.bin", Keyword("ZCORN", "REAL", {}, 0, -5))); },
    { "negative.bin", "ZCORN", "negative" });
  ExpectError("type", [&] { resmr::EclipseKeywordFile(write("type.bin", Keyword("COORD", "QUAD", {}))); },
    { "type.bin", "COORD", "unknown data type 'QUAD'" });
  ExpectError("C000", [&] { resmr::EclipseKeywordFile(write("c000.bin", Keyword("NAMES", "C000", {}))); },
    { "c000.bin", "NAMES", "unknown data type 'C000'" });
  std::string header = good + Keyword("PORO", "REAL", {});
  header[good.size() + 20 + 3] = 17; // second header's end marker
  ExpectError("header marker", [&] { resmr::EclipseKeywordFile(write("header.bin", header)); },
    { "header.bin", "record markers disagree", std::to_string(good.size()) });
  ExpectError(
    "missing", [&] { resmr::EclipseKeywordFile(Directory + "/nowhere.EGRID"); }, { "nowhere.EGRID", "cannot open" });
}

// A 2 x 1 x 1 grid, second cell inactive.
std::string SmallGrid()
{
  std::vector<int32_t> gridhead(100, 0);
  gridhead[0] = 1;
  gridhead[1] = 2;
  gridhead[2] = 1;
  gridhead[3] = 1;
  std::vector<float> coord;
  for (int j = 0; j <= 1; ++j)
  {
    for (int i = 0; i <= 2; ++i)
    {
      for (float z : { 1000.0f, 1010.0f })
      {
        coord.push_back(100.0f * i);
        coord.push_back(100.0f * j);
        coord.push_back(z);
      }
    }
  }
  std::vector<float> zcorn(16);
  for (int c = 0; c < 16; ++c)
  {
    zcorn[c] = c < 8 ? 1000.0f : 1010.0f;
  }
  return Keyword("FILEHEAD", "INTE", Elements(std::vector<int32_t>(100, 0), Int)) +
    Keyword("GRIDUNIT", "CHAR", { Text("METRES"), Text("") }) + Keyword("GRIDHEAD", "INTE", Elements(gridhead, Int)) +
    Keyword("COORD", "REAL", Elements(coord, Real)) + Keyword("ZCORN", "REAL", Elements(zcorn, Real)) +
    Keyword("ACTNUM", "INTE", Elements<int32_t>({ 1, 0 }, Int)) + Keyword("ENDGRID", "INTE", {}) +
    Keyword("LGR", "CHAR", { Text("LOCAL1") }) + Keyword("GRIDHEAD", "INTE", Elements(gridhead, Int)) +
    Keyword("ENDGRID", "INTE", {}) + Keyword("ENDLGR", "INTE", {});
}

std::vector<Element> Header(int active, int day, int month, int year)
{
  std::vector<int32_t> head(411, 0);
  head[11] = active;
  head[64] = day;
  head[65] = month;
  head[66] = year;
  return Elements(head, Int);
}

std::string Step(int seqnum, int active, double days, int day, float pressure, bool unified)
{
  return (unified ? Keyword("SEQNUM", "INTE", { Int(seqnum) }) : std::string()) +
    Keyword("INTEHEAD", "INTE", Header(active, day, 1, 2020)) +
    Keyword("DOUBHEAD", "DOUB", Elements<double>({ days, 0.0 }, Doub)) + Keyword("STARTSOL", "MESS", {}) +
    Keyword("PRESSURE", "REAL", Elements<float>(std::vector<float>(active, pressure), Real)) +
    Keyword("ENDSOL", "MESS", {}) + Keyword("LGR", "CHAR", { Text("LOCAL1") }) +
    Keyword("PRESSURE", "REAL", Elements<float>({ -1.0f }, Real)) + Keyword("ENDLGR", "INTE", {});
}

void TestGridAndResults()
{
  const std::string gridPath = Write("SMALL.EGRID", SmallGrid());
  Write("SMALL.INIT",
    Keyword("INTEHEAD", "INTE", Header(1, 1, 1, 2020)) + Keyword("PORO", "REAL", Elements<float>({ 0.25f }, Real)) +
      Keyword("PORV", "REAL", Elements<float>({ 5.0f, 0.0f }, Real)) +
      Keyword("SATNUM", "INTE", Elements<int32_t>({ 3 }, Int)) + Keyword("TABDIMS", "INTE", { Int(1) }));
  Write("SMALL.UNRST", Step(1, 1, 31.0, 1, 200.0f, true) + Step(2, 1, 60.0, 1, 190.0f, true));

  const resmr::EclipseGrid grid = resmr::ReadEclipseGrid(gridPath);
  CHECK(grid.deck.dims[0] == 2 && grid.deck.dims[1] == 1 && grid.deck.dims[2] == 1);
  CHECK(grid.activeCells == 1 && !grid.dualPorosity);
  CHECK(grid.localGridNames == std::vector<std::string>({ "LOCAL1" }));
  CHECK(grid.units == "METRES");
  CHECK(grid.deck.coord.size() == 36 && grid.deck.zcornSingle.size() == 16 && grid.deck.zcorn.empty());

  const resmr::EclipseResults results(gridPath, grid);
  CHECK(results.UnifiedRestart());
  CHECK(results.StaticArrays().size() == 3); // PORO, PORV, SATNUM; not TABDIMS
  CHECK(results.DynamicArrays().size() == 1 && results.DynamicArrays()[0].name == "PRESSURE");
  CHECK(results.Steps().size() == 2);
  CHECK(results.Steps()[1].reportNumber == 2 && results.Steps()[1].days == 60.0);
  float values[2];
  CHECK(results.ReadStatic("PORO", values, -9.0f));
  CHECK(values[0] == 0.25f && values[1] == -9.0f);
  CHECK(results.ReadStatic("PORV", values, -9.0f));
  CHECK(values[0] == 5.0f && values[1] == 0.0f);
  int32_t regions[2];
  CHECK(results.ReadStatic("SATNUM", regions, int32_t(0)));
  CHECK(regions[0] == 3 && regions[1] == 0);
  CHECK(results.ReadDynamic(1, "PRESSURE", values, -9.0f));
  CHECK(values[0] == 190.0f && values[1] == -9.0f); // the LGR's -1 never leaks in
  CHECK(!results.ReadDynamic(0, "SWAT", values, -9.0f));

  // Per-step restarts; one of another grid (2 active cells) is refused with a warning.
  const std::string stepsPath = Write("STEPS.EGRID", SmallGrid());
  Write("STEPS.X0000", Step(0, 1, 0.0, 1, 300.0f, false));
  Write("STEPS.X0003", Step(3, 2, 90.0, 1, 100.0f, false));
  const resmr::EclipseGrid stepsGrid = resmr::ReadEclipseGrid(stepsPath);
  const resmr::EclipseResults steps(stepsPath, stepsGrid);
  CHECK(!steps.UnifiedRestart() && steps.RestartPaths().size() == 2);
  CHECK(steps.Steps().size() == 2 && steps.Steps()[1].reportNumber == 3);
  CHECK(steps.ReadDynamic(0, "PRESSURE", values, -9.0f) && values[0] == 300.0f);
  CHECK(!steps.ReadDynamic(1, "PRESSURE", values, -9.0f));
  bool warnedInit = false, warnedForeign = false;
  for (const std::string& warning : steps.Warnings())
  {
    warnedInit |= warning.find("no INIT file") != std::string::npos;
    warnedForeign |= warning.find("STEPS.X0003") != std::string::npos &&
      warning.find("INTEHEAD") != std::string::npos && warning.find("2 active cells") != std::string::npos;
  }
  CHECK(warnedInit && warnedForeign);

  // Grid errors name file and keyword.
  std::string grid3 = SmallGrid();
  const std::size_t actnum = grid3.find("ACTNUM");
  grid3[actnum - 4 + 4 + 8 + 3] = 3; // ACTNUM count 3 for 2 cells
  ExpectError("ACTNUM count", [&] { resmr::ReadEclipseGrid(Write("BAD.EGRID", grid3)); }, { "BAD.EGRID", "ACTNUM" });
  std::string nanGrid = SmallGrid();
  const std::size_t zcornData = nanGrid.find("ZCORN") - 4 + 24 + 4; // first depth
  const float nan = std::nanf("");
  const Element bits = Real(nan);
  nanGrid.replace(zcornData + 4 * 5, 4, bits); // 6th depth
  ExpectError("ZCORN NaN", [&] { resmr::ReadEclipseGrid(Write("NAN.EGRID", nanGrid)); },
    { "NAN.EGRID", "ZCORN", "value 6 is not finite" });
  ExpectError("no GRIDHEAD", [&] { resmr::ReadEclipseGrid(Write("INIT.EGRID", Keyword("PORO", "REAL", {}))); },
    { "INIT.EGRID", "GRIDHEAD" });
}
// Large records are split over threads by block ranges; with the threshold lowered, a grid
// of 2400 cells (every 7th inactive) reads through the parallel paths and must equal the
// file value for value.
void TestParallelPieces()
{
  resmr::EclipseKeywordFile::SetParallelMinimumValues(1000);
  const int nx = 60, ny = 40;
  std::vector<int32_t> gridhead(100, 0);
  gridhead[0] = 1;
  gridhead[1] = nx;
  gridhead[2] = ny;
  gridhead[3] = 1;
  std::vector<float> coord, zcorn(8 * nx * ny);
  for (int j = 0; j <= ny; ++j)
  {
    for (int i = 0; i <= nx; ++i)
    {
      for (float z : { 1000.0f, 1010.0f })
      {
        coord.insert(coord.end(), { 10.0f * i, 10.0f * j, z });
      }
    }
  }
  for (std::size_t c = 0; c < zcorn.size(); ++c)
  {
    zcorn[c] = c < zcorn.size() / 2 ? 1000.0f + 0.001f * static_cast<float>(c) : 1010.0f;
  }
  std::vector<int32_t> actnum(nx * ny);
  std::vector<float> poro;
  std::vector<float> porv(nx * ny);
  for (int cell = 0; cell < nx * ny; ++cell)
  {
    actnum[cell] = cell % 7 != 0;
    porv[cell] = 0.5f * static_cast<float>(cell);
    if (actnum[cell])
    {
      poro.push_back(static_cast<float>(cell) + 0.25f);
    }
  }
  const std::string gridPath = Write("WIDE.EGRID",
    Keyword("FILEHEAD", "INTE", Elements(std::vector<int32_t>(100, 0), Int)) +
      Keyword("GRIDHEAD", "INTE", Elements(gridhead, Int)) + Keyword("COORD", "REAL", Elements(coord, Real)) +
      Keyword("ZCORN", "REAL", Elements(zcorn, Real)) + Keyword("ACTNUM", "INTE", Elements(actnum, Int)) +
      Keyword("ENDGRID", "INTE", {}));
  Write("WIDE.INIT",
    Keyword("INTEHEAD", "INTE", Header(static_cast<int>(poro.size()), 1, 1, 2020)) +
      Keyword("PORO", "REAL", Elements(poro, Real)) + Keyword("PORV", "REAL", Elements(porv, Real)));
  const resmr::EclipseGrid grid = resmr::ReadEclipseGrid(gridPath);
  CHECK(grid.deck.zcornSingle == zcorn);
  CHECK(grid.actnum == actnum);
  const resmr::EclipseResults results(gridPath, grid);
  std::vector<float> values(nx * ny);
  CHECK(results.ReadStatic("PORO", values.data(), -1.0f));
  bool same = true;
  for (int cell = 0; cell < nx * ny; ++cell)
  {
    same &= values[cell] == (actnum[cell] ? static_cast<float>(cell) + 0.25f : -1.0f);
  }
  CHECK(same);
  CHECK(results.ReadStatic("PORV", values.data(), -1.0f));
  CHECK(values == porv);
  resmr::EclipseKeywordFile::SetParallelMinimumValues(int64_t(4) << 20);
}
// The streamed writer: every type, pieces of odd sizes crossing record boundaries, read
// back by the reader value for value; errors leave no file under the final name.
void TestWriter()
{
  const std::string path = Directory + "/WRITTEN.EGRID";
  std::vector<int32_t> ints(2345);
  std::vector<double> doubles(1001);
  std::vector<std::string> names(230);
  for (std::size_t i = 0; i < ints.size(); ++i)
  {
    ints[i] = static_cast<int32_t>(i * 37) - 5000;
  }
  for (std::size_t i = 0; i < doubles.size(); ++i)
  {
    doubles[i] = 1.0 / (1.0 + static_cast<double>(i));
  }
  for (std::size_t i = 0; i < names.size(); ++i)
  {
    names[i] = "W" + std::to_string(i);
  }
  {
    resmr::EclipseKeywordWriter writer(path);
    writer.Write("INTS", "INTE", ints);
    writer.Begin("REALS", "REAL", 2345);
    for (std::size_t first = 0; first < ints.size(); first += 333) // odd pieces
    {
      const std::size_t count = std::min<std::size_t>(333, ints.size() - first);
      std::vector<float> piece(count);
      for (std::size_t i = 0; i < count; ++i)
      {
        piece[i] = 0.5f * static_cast<float>(ints[first + i]);
      }
      writer.Append(piece.data(), static_cast<int64_t>(count));
    }
    writer.Write("DOUBS", "DOUB", doubles);
    writer.Write("FLAGS", "LOGI", std::vector<int32_t>{ 1, 0, 1 });
    writer.WriteStrings("NAMES", names);
    writer.Begin("ENDSOL", "MESS", 0);
    CHECK(access(path.c_str(), F_OK) != 0); // nothing under the final name before Commit
    writer.Commit();
  }
  const resmr::EclipseKeywordFile file(path);
  CHECK(file.Records().size() == 6);
  std::vector<int32_t> intsBack(ints.size());
  file.Read(*file.Find("INTS"), intsBack.data());
  CHECK(intsBack == ints);
  CHECK(file.Find("INTS")->standardBlocks && file.Find("REALS")->standardBlocks);
  std::vector<float> realsBack(ints.size());
  file.Read(*file.Find("REALS"), realsBack.data());
  bool same = true;
  for (std::size_t i = 0; i < ints.size(); ++i)
  {
    same &= realsBack[i] == 0.5f * static_cast<float>(ints[i]);
  }
  CHECK(same);
  std::vector<double> doublesBack;
  file.ReadNumbers(*file.Find("DOUBS"), doublesBack);
  CHECK(doublesBack == doubles);
  file.ReadNumbers(*file.Find("FLAGS"), doublesBack);
  CHECK(doublesBack == std::vector<double>({ 1, 0, 1 }));
  CHECK(file.ReadStrings(*file.Find("NAMES")) == names);

  // Errors: the writer removes its temporary and never touches the final name.
  const std::string failed = Directory + "/FAILED.EGRID";
  ExpectError("short keyword",
    [&] {
      resmr::EclipseKeywordWriter writer(failed);
      writer.Begin("ZCORN", "REAL", 10);
      writer.Append(std::vector<float>(4).data(), 4);
      writer.Commit();
    },
    { "FAILED.EGRID", "6 values missing" });
  ExpectError("too many",
    [&] {
      resmr::EclipseKeywordWriter writer(failed);
      writer.Begin("ZCORN", "REAL", 2);
      writer.Append(std::vector<float>(3).data(), 3);
    },
    { "FAILED.EGRID", "ZCORN", "only 2 left" });
  ExpectError("32-bit count",
    [&] {
      resmr::EclipseKeywordWriter writer(failed);
      writer.Begin("ZCORN", "REAL", int64_t(1) << 31);
    },
    { "FAILED.EGRID", "ZCORN", "32-bit count" });
  ExpectError("unwritable folder", [&] { resmr::EclipseKeywordWriter(Directory + "/no/such/X.EGRID"); },
    { "X.EGRID", "cannot create" });
  // A full disk, simulated by a file-size limit: writes past 64 KiB fail (EFBIG).
  struct rlimit saved;
  getrlimit(RLIMIT_FSIZE, &saved);
  struct rlimit small = saved;
  small.rlim_cur = 64 << 10;
  std::signal(SIGXFSZ, SIG_IGN);
  setrlimit(RLIMIT_FSIZE, &small);
  ExpectError("disk full",
    [&] {
      resmr::EclipseKeywordWriter writer(failed);
      std::vector<float> values(100000, 1.0f);
      writer.Write("ZCORN", "REAL", values);
      writer.Commit();
    },
    { "FAILED.EGRID", "write failed" });
  setrlimit(RLIMIT_FSIZE, &saved);
  CHECK(access(failed.c_str(), F_OK) != 0);
  int leftovers = 0;
  for (const char* pattern : { "/FAILED.EGRID.partial-*" })
  {
    const std::string command = "ls " + Directory + pattern + " 2>/dev/null | wc -l";
    if (std::FILE* pipe = popen(command.c_str(), "r"))
    {
      leftovers = std::fgetc(pipe) - '0';
      pclose(pipe);
    }
  }
  CHECK(leftovers == 0);
}
} // namespace

int main()
{
  char pattern[] = "/tmp/resmr-eclipse-test-XXXXXX";
  Directory = mkdtemp(pattern);
  TestEveryType();
  TestBlockSplits();
  TestFormatted();
  TestBadUnformatted();
  TestGridAndResults();
  TestParallelPieces();
  TestWriter();
  std::system(("rm -rf '" + Directory + "'").c_str());
  if (resmr_testing::Failures)
  {
    std::fprintf(stderr, "%d check(s) failed\n", resmr_testing::Failures);
    return 1;
  }
  std::printf("all ECLIPSE keyword file checks passed\n");
  return 0;
}
