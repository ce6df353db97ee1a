// Unit tests of the Core GRDECL tokenizer, parser and corner-point geometry: every keyword
// form, and every kind of bad input giving an error that names the file, line and keyword.
#include "CoreTesting.h"
#include "CornerPointGeometry.h"
#include "Errors.h"
#include "GrdeclParser.h"
#include "GrdeclTokenizer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <unistd.h>
#include <vector>

namespace
{
std::string Directory;

std::string Write(const std::string& name, const std::string& text)
{
  const std::string path = Directory + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

resmr::CornerPointModel Parse(const std::string& name, const std::string& text)
{
  return resmr::ParseGrdeclFile(Write(name, text));
}

/// Expects parsing to throw a InputError whose message holds every fragment.
void ExpectError(const std::string& name, const std::string& text, const std::vector<std::string>& fragments,
  resmr::GrdeclParseOptions options = {})
{
  const std::string path = Write(name, text);
  try
  {
    resmr::CornerPointModel deck = resmr::ParseGrdeclFile(path, options);
    resmr::CornerPointGeometry::FromDeck(deck, true);
    std::fprintf(stderr, "expected an error for %s, got none\n", name.c_str());
    ++resmr_testing::Failures;
  }
  catch (const resmr::InputError& error)
  {
    const std::string message = error.what();
    for (const std::string& fragment : fragments)
    {
      if (message.find(fragment) == std::string::npos)
      {
        std::fprintf(stderr, "error for %s lacks '%s': %s\n", name.c_str(), fragment.c_str(), message.c_str());
        ++resmr_testing::Failures;
      }
    }
  }
}

/// A 2 x 1 x 1 corner-point grid with vertical pillars, cells 1 m apart.
const char* TwoCells = R"(SPECGRID
 2 1 1 1 F /
COORD
 0 0 0  0 0 10
 1 0 0  1 0 10
 2 0 0  2 0 10
 0 1 0  0 1 10
 1 1 0  1 1 10
 2 1 0  2 1 10 /
ZCORN
 4*100 4*100
 4*101 4*101 /
)";

void TestNumbers()
{
  resmr::NumberToken number;
  CHECK(resmr::ParseNumberToken("3*0.25", number) && number.repeat == 3 && number.value == 0.25);
  CHECK(resmr::ParseNumberToken("4*", number) && number.repeat == 4 && number.isDefault);
  CHECK(resmr::ParseNumberToken("-1.5E+03", number) && number.value == -1500.0);
  CHECK(resmr::ParseNumberToken("2.5D-1", number) && number.value == 0.25);
  CHECK(resmr::ParseNumberToken("+7", number) && number.value == 7.0);
  CHECK(resmr::ParseNumberToken(".5", number) && number.value == 0.5);
  CHECK(!resmr::ParseNumberToken("nan", number));
  CHECK(!resmr::ParseNumberToken("inf", number));
  CHECK(!resmr::ParseNumberToken("1e999", number));
  CHECK(!resmr::ParseNumberToken("1.2.3", number));
  CHECK(!resmr::ParseNumberToken("*3", number));
  CHECK(!resmr::ParseNumberToken("0*3", number));
  CHECK(!resmr::ParseNumberToken("abc", number));
  // Correct rounding on the slow path (more than 19 digits) and the fast path.
  double value = 0;
  CHECK(resmr::ParseDouble("6543210.123456789012345678", value) && value == 6543210.123456789);
  CHECK(resmr::ParseDouble("0.1", value) && value == 0.1);
  CHECK(resmr::ParseDouble("5938932.679", value) && value == 5938932.679);
}

void TestTokenizer()
{
  const std::string path =
    Write("tokens.txt", "KEY -- comment / not a slash\n  'quoted name' 1 2*3/ trailing comment\nNEXT\n");
  resmr::GrdeclTokenizer tokens(path, 4096);
  const resmr::Token* t = &tokens.Next();
  CHECK(t->kind == resmr::TokenKind::Word && t->text == "KEY" && t->atLineStart && t->line == 1);
  t = &tokens.Next();
  CHECK(t->kind == resmr::TokenKind::String && t->text == "quoted name" && t->line == 2);
  t = &tokens.Next();
  CHECK(t->kind == resmr::TokenKind::Word && t->text == "1" && !t->atLineStart);
  t = &tokens.Next();
  CHECK(t->kind == resmr::TokenKind::Word && t->text == "2*3");
  t = &tokens.Next();
  CHECK(t->kind == resmr::TokenKind::Slash && t->line == 2);
  t = &tokens.Next();
  CHECK(t->kind == resmr::TokenKind::Word && t->text == "NEXT" && t->line == 3 && t->atLineStart);
  CHECK(tokens.Next().kind == resmr::TokenKind::End);

  // Tokens that straddle the chunk boundary come out whole.
  std::string many;
  for (int i = 0; i < 5000; ++i)
  {
    many += std::to_string(i * 1.25) + (i % 7 == 0 ? "\n" : " ");
  }
  resmr::GrdeclTokenizer chunked(Write("chunked.txt", many), 4096);
  int count = 0;
  bool allRight = true;
  for (const resmr::Token* token = &chunked.Next(); token->kind != resmr::TokenKind::End; token = &chunked.Next())
  {
    double v = 0;
    allRight &= resmr::ParseDouble(token->text, v) && v == count * 1.25;
    ++count;
  }
  CHECK(count == 5000 && allRight);
}

void TestCornerPointDeck()
{
  resmr::CornerPointModel deck =
    Parse("two.grdecl", std::string(TwoCells) + "ACTNUM\n 1 0 /\nPORO\n 0.25 0.5 /\nSATNUM\n 2*3 /\nNTG\n 2* /\n");
  CHECK(deck.dims[0] == 2 && deck.dims[1] == 1 && deck.dims[2] == 1);
  CHECK(deck.zcorn.size() == 16 && deck.coord.size() == 36);
  const resmr::CellArray* poro = deck.FindArray("PORO");
  CHECK(poro && !poro->isInteger && poro->values[0] == 0.25 && poro->values[1] == 0.5);
  const resmr::CellArray* satnum = deck.FindArray("SATNUM");
  CHECK(satnum && satnum->isInteger && satnum->values[1] == 3);
  const resmr::CellArray* ntg = deck.FindArray("NTG");
  CHECK(ntg && std::isnan(ntg->values[0])); // N* defaults leave values undefined
  CHECK(deck.FindArray("ACTNUM")->values[1] == 0);

  resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(deck, true);
  double corners[8][3];
  geometry.CellCorners(1, 0, 0, corners);
  CHECK(corners[0][0] == 1 && corners[1][0] == 2 && corners[3][1] == 1);
  CHECK(corners[0][2] == 100 && corners[7][2] == 101);
  // i east, j north, k down: ECLIPSE's left-handed orientation.
  CHECK(geometry.IsLeftHanded());
  const auto shared = geometry.BuildSharedCorners();
  CHECK(shared.points.size() == 3 * 12);                   // 6 pillars x 2 depths
  CHECK(shared.cellPoints[1] == shared.cellPoints[8 + 0]); // common face shares points
}

void TestFaultedSharing()
{
  // Second column thrown down by 0.5: the common face must not share points.
  const std::string faulted = R"(SPECGRID
 2 1 1 1 F /
COORD
 0 0 0  0 0 10  1 0 0  1 0 10  2 0 0  2 0 10
 0 1 0  0 1 10  1 1 0  1 1 10  2 1 0  2 1 10 /
ZCORN
 100 100 100.5 100.5  100 100 100.5 100.5
 101 101 101.5 101.5  101 101 101.5 101.5 /
FAULTS
 'F1' 1 1 1 1 1 1 I /
 'F1' 1 1 1 1 1 1 X+ /
 'F2' 2 2 1 1 1 1 I- /
/
)";
  resmr::CornerPointModel deck = Parse("faulted.grdecl", faulted);
  CHECK(deck.faults.size() == 2 && deck.faults[0].name == "F1" && deck.faults[0].faces.size() == 2);
  CHECK(deck.faults[1].faces[0].face == resmr::FaultFace::IMinus);
  CHECK(deck.faults[0].faces[0].box[0] == 0 && deck.faults[0].faces[0].face == resmr::FaultFace::IPlus);
  const auto shared = resmr::CornerPointGeometry::FromDeck(deck, true).BuildSharedCorners();
  CHECK(shared.cellPoints[1] != shared.cellPoints[8 + 0]);
  CHECK(shared.points.size() == 3 * 16); // the middle pillars carry 4 depths each
}

void TestCartesianAndEdits()
{
  const std::string deckText = R"(RUNSPEC
TITLE
PORO IS NOT A KEYWORD HERE
DIMENS
 3 2 2 /
OIL
GRID    ==== junk after a section keyword
DXV
 3*10 /
DYV
 2*20 /
DZ
 6*1 6*2 /
TOPS
 6*1000 /
EQUALS
 PORO 0.2 /
 PERMX 100 1 3 1 2 1 1 /
 PERMX 50 4* 2 2 /
/
BOX
 1 1 1 1 1 2 /
PORO
 2*0.3 /
ENDBOX
COPY
 'PERMX' 'PERMY' /
/
MULTIPLY
 'permy' 0.5 /
/
ADD
 PORO 0.01 1 1 1 1 1 1 /
/
PROPS
SWOF
 0 0 1 0
 1 1 0 0 /
REGIONS
FIPNUM
 12*1 /
SCHEDULE
PORO
 this would be an error if parsed /
)";
  resmr::CornerPointModel deck = Parse("cartesian.DATA", deckText);
  CHECK(deck.dims[0] == 3 && deck.dims[2] == 2);
  const auto& poro = deck.FindArray("PORO")->values;
  CHECK(poro[0] == 0.3 + 0.01 && poro[6] == 0.3 && poro[1] == 0.2);
  const auto& permx = deck.FindArray("PERMX")->values;
  CHECK(permx[0] == 100 && permx[6] == 50);
  const auto& permy = deck.FindArray("PERMY")->values;
  CHECK(permy[0] == 50 && permy[11] == 25);
  CHECK(deck.FindArray("FIPNUM") && deck.FindArray("FIPNUM")->isInteger);
  CHECK(!deck.FindArray("SWOF"));
  resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(deck, true);
  double corners[8][3];
  geometry.CellCorners(2, 1, 1, corners);
  CHECK(corners[0][0] == 20 && corners[1][0] == 30 && corners[0][1] == 20);
  CHECK(corners[0][2] == 1001 && corners[4][2] == 1003); // TOPS of layer 2 = 1000 + DZ
}

void TestIncludesAndMapAxes()
{
  Write("inc_grid.inc", std::string(TwoCells));
  Write("inc_props.INC", "PORO\n 0.1 0.2 /\n");
  Write("sub/nested.inc", "");
  std::system(("mkdir -p '" + Directory + "/sub'").c_str());
  Write("sub/nested.inc", "INCLUDE\n 'leaf.inc' /\n");
  Write("sub/leaf.inc", "NTG\n 2*0.9 /\n");
  resmr::CornerPointModel deck = Parse("includes.DATA",
    "MAPAXES\n 100 201 100 200 101 200 /\nGRIDUNIT\n 'METRES' ' ' /\n"
    "INCLUDE\n 'inc_grid.inc' /\nINCLUDE\n inc_props.INC /\nINCLUDE\n \"sub/nested.inc\" /\n");
  CHECK(deck.files.size() == 5);
  CHECK(deck.FindArray("NTG") && deck.FindArray("NTG")->values[1] == 0.9);
  CHECK(deck.hasMapAxes && deck.mapAxes.origin[1] == 200);
  resmr::CornerPointGeometry geometry = resmr::CornerPointGeometry::FromDeck(deck, true);
  double corners[8][3];
  geometry.CellCorners(1, 0, 0, corners);
  CHECK(corners[0][0] == 101 && corners[0][1] == 200 && corners[3][1] == 201);
  geometry.SetMapAxesApplied(false);
  geometry.CellCorners(1, 0, 0, corners);
  CHECK(corners[0][0] == 1 && corners[0][1] == 0);
}

void TestBinaryGrdecl()
{
  // SPECGRID (INTE) and ... written as Fortran big-endian records.
  std::string bytes;
  const auto be32 = [&](uint32_t v) {
    for (int s = 24; s >= 0; s -= 8)
    {
      bytes += static_cast<char>((v >> s) & 0xff);
    }
  };
  const auto header = [&](const char* name, uint32_t count, const char* type) {
    be32(16);
    bytes += std::string(name) + std::string(8 - std::string(name).size(), ' ');
    be32(count);
    bytes += type;
    be32(16);
  };
  const auto floats = [&](const std::vector<float>& values) {
    be32(static_cast<uint32_t>(4 * values.size()));
    for (float v : values)
    {
      uint32_t bits;
      std::memcpy(&bits, &v, 4);
      be32(bits);
    }
    be32(static_cast<uint32_t>(4 * values.size()));
  };
  header("SPECGRID", 4, "INTE");
  be32(16);
  for (uint32_t v : { 2u, 1u, 1u, 1u })
  {
    be32(v);
  }
  be32(16);
  header("COORD", 36, "REAL");
  floats({ 0, 0, 0, 0, 0, 10, 1, 0, 0, 1, 0, 10, 2, 0, 0, 2, 0, 10, 0, 1, 0, 0, 1, 10, 1, 1, 0, 1, 1, 10, 2, 1, 0, 2, 1,
    10 });
  header("ZCORN", 16, "REAL");
  floats({ 100, 100, 100, 100, 100, 100, 100, 100, 101, 101, 101, 101, 101, 101, 101, 101 });
  header("PORO", 2, "REAL");
  floats({ 0.25f, 0.5f });
  resmr::CornerPointModel deck = Parse("binary.bgrdecl", bytes);
  CHECK(deck.dims[0] == 2 && deck.zcorn.size() == 16 && deck.zcorn[15] == 101);
  CHECK(deck.FindArray("PORO") && deck.FindArray("PORO")->values[1] == 0.5);
  // Truncated copy: a clear error naming the byte offset.
  ExpectError("truncated.bgrdecl", bytes.substr(0, bytes.size() - 6), { "truncated.bgrdecl", "PORO", "byte" });
  std::string corrupt = bytes;
  corrupt[24 + 3] = '\x7f'; // low byte of SPECGRID's data record marker
  ExpectError("corrupt.bgrdecl", corrupt, { "corrupt.bgrdecl", "SPECGRID" });
}

void TestBadInput()
{
  ExpectError("missing_slash.grdecl", "SPECGRID\n 2 1 1 1 F /\nZCORN\n 1 2 3\nPORO\n 1 2 /\n",
    { "missing_slash.grdecl:5", "ZCORN", "missing '/'" });
  ExpectError("unterminated.grdecl", "SPECGRID\n 2 1 1 1 F /\nZCORN\n 1 2 3\n",
    { "unterminated.grdecl", "ZCORN", "end of file" });
  ExpectError(
    "count.grdecl", std::string(TwoCells) + "PORO\n 0.1 0.2 0.3 /\n", { "count.grdecl:14", "PORO", "too many values" });
  ExpectError("few.grdecl", std::string(TwoCells) + "PORO\n 0.1 /\n", { "few.grdecl", "PORO", "expected 2, got 1" });
  ExpectError("garbage.grdecl", "SPECGRID\n 2 1 1 1 F /\nCOORD\n 0 0 0 0 0 1 x$%! /\n",
    { "garbage.grdecl:4", "COORD", "expected a number", "x$%!" });
  ExpectError("nan.grdecl", "SPECGRID\n 2 1 1 1 F /\nCOORD\n 0 0 0 nan 0 1 /\n", { "nan.grdecl:4", "COORD", "'nan'" });
  ExpectError("inf.grdecl", "SPECGRID\n 2 1 1 1 F /\nCOORD\n 0 0 1e400 /\n", { "inf.grdecl:4", "COORD", "'1e400'" });
  ExpectError("zero.grdecl", "SPECGRID\n 0 1 1 1 F /\n", { "zero.grdecl:1", "SPECGRID", "between 1" });
  ExpectError("negative.grdecl", "DIMENS\n 4 -2 1 /\n", { "negative.grdecl:1", "DIMENS" });
  ExpectError("overflow.grdecl", "SPECGRID\n 2000000000 2000000000 2000000000 1 F /\n",
    { "overflow.grdecl:1", "SPECGRID", "larger than this machine" });
  ExpectError("huge.grdecl", "SPECGRID\n 100000 100000 1000 1 F /\n",
    { "huge.grdecl:1", "SPECGRID", "larger than this machine" });
  ExpectError("redefined.grdecl", "DIMENS\n 2 2 2 /\nBOX\n 2 2 2 2 2 2 /\nSPECGRID\n 1 1 1 1 F /\n",
    { "redefined.grdecl:5", "SPECGRID", "differ from the 2 x 2 x 2" });
  ExpectError("record.grdecl", "SPECGRID\n 2 1 1 1 F\nCOORD\n 1 2 3 /\n",
    { "record.grdecl:3", "SPECGRID", "not terminated by '/'" });
  CHECK(resmr::LooksLikeGrdeclFile(Write("looks.inc", "-- header\nPORO\n 1 /\n")));
  CHECK(!resmr::LooksLikeGrdeclFile(Write("plain.txt", "just some text, no keyword\n")));
  ExpectError("mapaxes.grdecl", std::string("MAPAXES\n 0 0 0 0 1 0 /\n") + TwoCells,
    { "mapaxes.grdecl", "MAPAXES", "coincide with the origin" });
  ExpectError("noint.grdecl", "SPECGRID\n 2.5 1 1 1 F /\n", { "noint.grdecl:1", "must be an integer" });
  ExpectError("include.DATA", "INCLUDE\n 'does_not_exist.inc' /\n",
    { "include.DATA", "no SPECGRID", "INCLUDE of 'does_not_exist.inc' at", "include.DATA:1 was not found" });
  Write("self.inc", "INCLUDE\n 'self.inc' /\n");
  ExpectError("cycle.DATA", "INCLUDE\n 'self.inc' /\n", { "self.inc:1", "INCLUDE", "nested deeper" });
  ExpectError("before.grdecl", "PORO\n 1 2 /\n", { "before.grdecl:1", "PORO", "before SPECGRID" });
  ExpectError("nogeometry.grdecl", "SPECGRID\n 2 1 1 1 F /\n", { "no grid geometry" });
  ExpectError("badface.grdecl", "SPECGRID\n 2 1 1 1 F /\nFAULTS\n 'F' 1 1 1 1 1 1 Q /\n/\n",
    { "badface.grdecl:3", "FAULTS", "unknown face 'Q'" });
  ExpectError("badbox.grdecl", "SPECGRID\n 2 1 1 1 F /\nFAULTS\n 'F' 1 3 1 1 1 1 I /\n/\n",
    { "badbox.grdecl:3", "FAULTS", "outside the grid" });
  ExpectError("multiply.grdecl", std::string(TwoCells) + "MULTIPLY\n PERMZ 0.1 /\n/\n",
    { "multiply.grdecl", "MULTIPLY", "PERMZ has not been defined" });
  ExpectError("binary_garbage.grdecl",
    std::string("SPECGRID\n 2 1 1 1 F /\nZCORN\n") + std::string("\x01\x02\xff\xfe", 4) + " /\n",
    { "binary_garbage.grdecl:4", "ZCORN", "expected a number" });
  ExpectError(
    "long_token.grdecl", "SPECGRID\n" + std::string(3 << 20, 'A') + "\n", { "long_token.grdecl", "longer than 1 MiB" });
  // A missing INCLUDE is tolerated with a warning naming it; refused on request.
  resmr::GrdeclParseOptions strict;
  strict.skipMissingIncludes = false;
  ExpectError("strict.DATA", std::string(TwoCells) + "INCLUDE\n 'gone.inc' /\n",
    { "strict.DATA:13", "INCLUDE", "gone.inc", "not found" }, strict);
  resmr::GrdeclParseOptions lenient;
  resmr::CornerPointModel deck =
    resmr::ParseGrdeclFile(Write("lenient.DATA", std::string(TwoCells) + "INCLUDE\n 'gone.inc' /\n"), lenient);
  CHECK(deck.warnings.size() == 1 && deck.warnings[0].find("gone.inc") != std::string::npos);
}

/// Counts the warnings holding every fragment.
int WarningsWith(const resmr::CornerPointModel& deck, const std::vector<std::string>& fragments)
{
  int count = 0;
  for (const std::string& warning : deck.warnings)
  {
    bool all = true;
    for (const std::string& fragment : fragments)
    {
      all = all && warning.find(fragment) != std::string::npos;
    }
    count += all;
  }
  return count;
}

/// A 3 x 2 x 2 Cartesian deck with every edit keyword and every keyword the viewer skips.
const char* EditedDeck = R"(RUNSPEC
DIMENS
 3 2 2 /
GRID
DX
 12*10 /
DY
 12*10 /
DZ
 12*1 /
TOPS
 6*1000 /
PORO
 0.1 0.2 0.3 0.4 0.5 0.6  6*0.9 /
PERMX
 1 2 3 4 5 6 7 8 9 10 11 12 /
COPYBOX
PORO 1 3 1 2 1 1  1 3 1 2 2 2 /
/
MINVALUE
 PERMX 3 /
/
MAXVALUE
 PERMX 10 /
/
OPERATE
 PERMY 1* 1* 1* 1* 1* 1* MULTA PERMX 2 1 /
 PERMZ 1 3 1 2 1 1 MULTX PERMX 0.5 /
 PERMY 1 1 1 1 1 1 POLY PERMX 1 2 /
 NTG 4* 2 2 INV PERMX /
/
EQUALS
 MULTNUM 1 /
 MULTNUM 2 1 1 1 2 1 2 /
 MULTX 0.5 1 1 1 1 1 1 /
 FOOBAR 7 /
/
MULTIPLY
 TRANX 0.5 /
/
BOX
 1 2 1 1 1 1 /
MULTZ
 2*0.1 /
ENDBOX
MULTFLT
 'F1' 0.1 /
/
MULTREGT
 1 2 0.5 XYZ 'ALL' M /
/
NNC
 1 1 1 3 2 2 0.5 /
/
MINPV
 1e-3 /
PINCH
 0.001 GAP 1* TOPBOT TOP /
CARFIN
 'LGR1' 1 1 1 1 1 1 2 2 2 /
PORO
 8*0.7 /
EQUALS
 'PERMX' 99 /
/
ENDFIN
AQUNUM
 1 3 2 2 1e6 1e3 0.3 100 2000 200 1 1 /
/
AQUCON
 1 1 1 1 1 1 1 'I-' /
/
EDIT
MULTIPLY
 TRANY 0.5 1 1 1 1 1 1 /
/
EQUALS
 PORV 1000 1 1 1 1 1 1 /
/
ADD
 DEPTH 1 /
/
MULTREGP
 1 0.5 M /
/
EDITNNC
 1 1 1 2 1 1 0.5 /
/
PROPS
EQUALS
 SWL 0.1 /
/
OPERATER
 SWL 2 MULTX SWL 3 1* M /
/
REGIONS
EQUALS
 SATNUM 1 /
 OPERNUM 1 /
/
EQUALREG
 SATNUM 5 2 M /
/
MULTIREG
 SATNUM 3 1 /
/
ADDREG
 SATNUM 10 2 M /
/
COPYREG
 SATNUM FIPNUM 1 M /
/
EQUALREG
 PVTNUM 4 1 /
/
SOLUTION
THPRES
 1 2 1* /
/
MULTIPLY
 MULTPV 2 /
/
)";

/// 1-based line of the last line of the first occurrence of `text` in `deck`, as a string.
std::string LineOf(const char* deck, const char* text)
{
  const std::string all(deck);
  const std::size_t at = all.find(text);
  CHECK(at != std::string::npos);
  const std::string upTo = all.substr(0, at + std::strlen(text));
  const std::size_t lastChar = upTo.find_last_not_of('\n');
  return std::to_string(1 + std::count(upTo.begin(), upTo.begin() + lastChar, '\n'));
}

void TestDeckEditsAndSkips()
{
  const std::string path = Write("edited.DATA", EditedDeck);
  const resmr::CornerPointModel deck = resmr::ParseGrdeclFile(path);
  const auto values = [&](const char* name) {
    const resmr::CellArray* array = deck.FindArray(name);
    CHECK(array != nullptr);
    return array ? array->values : std::vector<double>(12, -1.0);
  };
  // COPYBOX: layer 1 of PORO copied onto layer 2; the CARFIN block's PORO is not read.
  const std::vector<double> poro = values("PORO");
  for (int c = 0; c < 6; ++c)
  {
    CHECK(poro[c] == poro[c + 6] && std::fabs(poro[c] - 0.1 * (c + 1)) < 1e-12);
  }
  // MINVALUE 3, MAXVALUE 10; the CARFIN block's EQUALS PERMX 99 is not applied.
  const std::vector<double> permx = values("PERMX");
  const double clamped[12] = { 3, 3, 3, 4, 5, 6, 7, 8, 9, 10, 10, 10 };
  for (int c = 0; c < 12; ++c)
  {
    CHECK(permx[c] == clamped[c]);
  }
  // OPERATE: MULTA over the grid, POLY on cell 1 (adds 1 x PERMX^2), MULTX in layer 1, INV in
  // layer 2 (cells outside the box have no value).
  const std::vector<double> permy = values("PERMY"), permz = values("PERMZ"), ntg = values("NTG");
  CHECK(permy[0] == 2 * 3 + 1 + 3 * 3);
  for (int c = 1; c < 12; ++c)
  {
    CHECK(permy[c] == 2 * clamped[c] + 1);
  }
  for (int c = 0; c < 12; ++c)
  {
    CHECK(c < 6 ? permz[c] == 0.5 * clamped[c] : std::isnan(permz[c]));
    CHECK(c >= 6 ? std::fabs(ntg[c] - 1.0 / clamped[c]) < 1e-15 : std::isnan(ntg[c]));
  }
  // Regions (1 where not given): MULTNUM 2 in column I = 1. SATNUM: 1, then 5 in region 2, then x3
  // in region 1, then +10 in region 2; FIPNUM copied from SATNUM in region 1 only; PVTNUM 4
  // in region 1 only. OPERATER: SWL x3 in MULTNUM region 2.
  const std::vector<double> satnum = values("SATNUM"), fipnum = values("FIPNUM");
  const std::vector<double> pvtnum = values("PVTNUM"), swl = values("SWL");
  for (int c = 0; c < 12; ++c)
  {
    const bool region2 = c % 3 == 0;
    CHECK(satnum[c] == (region2 ? 15 : 3));
    CHECK(fipnum[c] == (region2 ? 1 : 3)); // region arrays not given are 1
    CHECK(pvtnum[c] == (region2 ? 1 : 4));
    CHECK(std::fabs(swl[c] - (region2 ? 0.3 : 0.1)) < 1e-15);
  }
  // Nothing the viewer does not build became an array.
  for (const char* name : { "MULTX", "MULTZ", "TRANX", "TRANY", "PORV", "DEPTH", "FOOBAR", "MULTPV" })
  {
    CHECK(deck.FindArray(name) == nullptr);
  }
  // One warning each, naming the file, the line, the keyword and the array.
  const std::string file = path + ":";
  CHECK(WarningsWith(
          deck, { file + LineOf(EditedDeck, "MULTX 0.5") + ":", "keyword EQUALS", "MULTX", "flow multiplier" }) == 1);
  CHECK(WarningsWith(deck,
          { file + LineOf(EditedDeck, " FOOBAR 7") + ":", "keyword EQUALS", "FOOBAR",
            "not an array the viewer knows" }) == 1);
  CHECK(
    WarningsWith(deck,
      { file + LineOf(EditedDeck, "MULTIPLY\n TRANX") + ":", "keyword MULTIPLY", "TRANX", "transmissibility" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "MULTZ\n") + ":", "keyword MULTZ", "MULTZ" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "MULTFLT") + ":", "keyword MULTFLT" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "MULTREGT") + ":", "keyword MULTREGT" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "NNC\n") + ":", "keyword NNC" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "MINPV") + ":", "keyword MINPV", "inactive" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "PINCH") + ":", "keyword PINCH" }) == 1);
  CHECK(
    WarningsWith(deck, { file + LineOf(EditedDeck, "CARFIN") + ":", "keyword CARFIN", "'LGR1'", "global grid" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "AQUNUM") + ":", "keyword AQUNUM" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "AQUCON") + ":", "keyword AQUCON" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "MULTIPLY\n TRANY") + ":", "keyword MULTIPLY", "TRANY" }) == 1);
  CHECK(WarningsWith(
          deck, { file + LineOf(EditedDeck, "EQUALS\n PORV") + ":", "keyword EQUALS", "PORV", "pore volume" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "ADD\n DEPTH") + ":", "keyword ADD", "DEPTH", "depth" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "MULTREGP") + ":", "keyword MULTREGP" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "EDITNNC") + ":", "keyword EDITNNC" }) == 1);
  CHECK(WarningsWith(deck, { file + LineOf(EditedDeck, "THPRES") + ":", "keyword THPRES" }) == 1);
  CHECK(
    WarningsWith(deck, { file + LineOf(EditedDeck, "MULTIPLY\n MULTPV") + ":", "keyword MULTIPLY", "MULTPV" }) == 1);
  CHECK(deck.warnings.size() == 19);
  for (const std::string& warning : deck.warnings)
  {
    std::printf("  warning: %s\n", warning.c_str());
  }

  // The bounded-memory parse (resmr build) gives the same warnings.
  const std::string spoolFolder = Directory + "/spool";
  std::system(("mkdir -p '" + spoolFolder + "'").c_str());
  resmr::GrdeclGridSpool spool;
  const resmr::CornerPointModel streamed = resmr::ParseGrdeclGrid(path, spoolFolder, spool);
  CHECK(streamed.warnings == deck.warnings);

  // Edits the viewer cannot honour on arrays it needs stay errors naming file, line, keyword.
  const std::string twoCells(TwoCells);
  ExpectError("copy_tran.grdecl", twoCells + "COPY\n TRANX PORO /\n/\n",
    { "copy_tran.grdecl:13", "keyword COPY", "source array TRANX has not been defined" });
  ExpectError("operate.grdecl", twoCells + "PORO\n 2*0.1 /\nOPERATE\n PORO 4* 1 1 SQRT PORO /\n/\n",
    { "operate.grdecl:15", "keyword OPERATE", "unknown operation 'SQRT'" });
  ExpectError("operate_poly.grdecl", twoCells + "PORO\n 2*0.1 /\nOPERATE\n NTG 4* 1 1 POLY PORO 1 1 /\n/\n",
    { "operate_poly.grdecl:15", "keyword OPERATE", "array NTG has not been defined" });
  ExpectError("minvalue.grdecl", twoCells + "MINVALUE\n PORO 0.1 /\n/\n",
    { "minvalue.grdecl:13", "keyword MINVALUE", "array PORO has not been defined" });
  ExpectError("copybox.grdecl", twoCells + "PORO\n 2*0.1 /\nCOPYBOX\n PORO 1 1 1 1 1 1 1 2 1 1 1 1 /\n/\n",
    { "copybox.grdecl:15", "keyword COPYBOX", "differ in size along I" });
  ExpectError("carfin.grdecl", twoCells + "CARFIN\n 'L1' 1 1 1 1 1 1 2 2 2 /\nPORO\n 8*0.1 /\n",
    { "carfin.grdecl:13", "keyword CARFIN", "'L1' has no ENDFIN" });
  ExpectError("region.grdecl", twoCells + "EQUALREG\n PORO 0.1 1 Q /\n/\n",
    { "region.grdecl:13", "keyword EQUALREG", "region array 'Q'" });

  // A missing INCLUDE is a warning; when it held what the grid needs, the error names it.
  Write("grid_only.inc", twoCells);
  const resmr::CornerPointModel missingSolution =
    Parse("missing_solution.DATA", "GRID\nINCLUDE\n 'grid_only.inc' /\nSOLUTION\nINCLUDE\n 'not_shipped.inc' /\n");
  CHECK(WarningsWith(missingSolution, { "missing_solution.DATA:5", "INCLUDE", "not_shipped.inc", "not found" }) == 1);
  CHECK(missingSolution.CellCount() == 2);
  ExpectError("missing_grid.DATA", "GRID\nINCLUDE\n 'gone_grid.inc' /\nPORO\n 2*0.1 /\n",
    { "missing_grid.DATA:4", "PORO", "before SPECGRID", "INCLUDE of 'gone_grid.inc' at",
      "missing_grid.DATA:2 was not found" });
  ExpectError("missing_zcorn.DATA", "SPECGRID\n 2 1 1 1 F /\nINCLUDE\n 'gone_zcorn.inc' /\n",
    { "missing_zcorn.DATA", "no grid geometry", "INCLUDE of 'gone_zcorn.inc'" });
  ExpectError("missing_poro.DATA", twoCells + "INCLUDE\n 'gone_poro.inc' /\nMULTIPLY\n PORO 2 /\n/\n",
    { "missing_poro.DATA:15", "keyword MULTIPLY", "PORO has not been defined", "gone_poro.inc" });
}
} // namespace

int main()
{
  char pattern[] = "/tmp/resmr-core-test-XXXXXX";
  if (!mkdtemp(pattern))
  {
    return 2;
  }
  Directory = pattern;
  const std::vector<std::pair<const char*, std::function<void()>>> tests = { { "numbers", TestNumbers },
    { "tokenizer", TestTokenizer }, { "corner-point deck", TestCornerPointDeck },
    { "faulted sharing", TestFaultedSharing }, { "cartesian and edits", TestCartesianAndEdits },
    { "includes and mapaxes", TestIncludesAndMapAxes }, { "binary grdecl", TestBinaryGrdecl },
    { "bad input", TestBadInput }, { "deck edits and skipped keywords", TestDeckEditsAndSkips } };
  const bool passed = resmr_testing::RunNamedTests(tests);
  std::system(("rm -rf '" + Directory + "'").c_str());
  return passed ? 0 : 1;
}
